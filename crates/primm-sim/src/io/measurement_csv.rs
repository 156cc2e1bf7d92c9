//! The measurement CSV format: one file per sequence, one row per object measurement.
//!
//! The format is specified in `docs/scenario.md`. In short, the header is
//!
//! ```text
//! frame,t,gt_id,class,x,y,vr,rcs,true_x,true_y,sensor_id,ego_x,ego_y,ego_yaw
//! ```
//!
//! followed by `true_vx,true_vy,origin`. The first ten columns are required; `sensor_id`,
//! `ego_x`, `ego_y`, `ego_yaw`, `true_vx`, `true_vy` and `origin` are optional and unknown
//! columns are ignored. The reader finds columns by name, so their order does not matter; the
//! writer always writes all seventeen in the order above.
//!
//! * `frame`: 0-based frame index, non-decreasing from row to row; all rows of one frame are
//!   consecutive and a larger index starts a new frame. Indices may skip values.
//! * `t`: frame time in seconds, identical on every row of a frame and non-decreasing from frame
//!   to frame.
//! * `gt_id`: ground-truth object id, a non-negative integer, or `-1` (or empty) when unknown.
//! * `class`: `car` or `pedestrian` (`two_wheeler` is accepted for the reserved class).
//! * `x`, `y`: position in the car frame (x forward, y left), metres.
//! * `vr`: ego-motion compensated radial velocity, m/s, positive moving away from the sensor.
//! * `rcs`: radar cross section, dBsm.
//! * `true_x`, `true_y`: true object centre in the car frame, metres, or both empty.
//! * `sensor_id`: radar that produced the frame (frame-level, same on every row of a frame).
//! * `ego_x`, `ego_y`, `ego_yaw`: ego pose in the world frame, metres and radians; all three or
//!   none (frame-level).
//! * `true_vx`, `true_vy`: true velocity over ground of the object's centre in the car frame's
//!   axes, m/s, or both empty.
//! * `origin`: what produced the measurement, where known: `object` (a real object), `clutter`
//!   or `ghost` (a multipath ghost); empty when unknown.
//!
//! A frame without measurements is written as one *empty-frame row*: `frame`, `t` and the
//! frame-level columns filled, every measurement column (`gt_id` … `true_y`, `true_vx`,
//! `true_vy`, `origin`) empty. Such a row must be the only row of its frame.
//!
//! Floats are written with Rust's shortest representation that parses back to the same `f64`,
//! so a write/read round trip is exact. Lines starting with `#` are comments.

use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

use glam::DVec2;

use super::recording::{EgoPose, MeasurementOrigin, RecordedFrame, RecordedMeasurement, Sequence};
use primm_core::measurement::{Measurement, ObjectClass, MAX_MEASUREMENTS_PER_FRAME};
use primm_core::readable_number::readable;

/// Columns every file must have.
pub const REQUIRED_COLUMNS: [&str; 10] =
    ["frame", "t", "gt_id", "class", "x", "y", "vr", "rcs", "true_x", "true_y"];

/// Optional frame-level columns understood by the reader.
pub const OPTIONAL_COLUMNS: [&str; 4] = ["sensor_id", "ego_x", "ego_y", "ego_yaw"];

/// Optional measurement columns understood by the reader: the true velocity, m/s.
pub const TRUE_VELOCITY_COLUMNS: [&str; 2] = ["true_vx", "true_vy"];

/// Optional measurement column understood by the reader: what produced the measurement
/// (`object`, `clutter`, `ghost`, or empty when unknown).
pub const ORIGIN_COLUMN: &str = "origin";

/// Columns holding measurement values; all empty on an empty-frame row.
const MEASUREMENT_COLUMNS: [&str; 8] = ["gt_id", "class", "x", "y", "vr", "rcs", "true_x", "true_y"];

/// What went wrong while reading or writing a measurement file.
#[derive(Debug, thiserror::Error)]
pub enum CsvErrorKind {
    /// The file could not be opened, read or written.
    #[error("I/O error: {0}")]
    Io(#[from] std::io::Error),
    /// The CSV layer rejected the input (e.g. a row with the wrong number of fields).
    #[error("malformed CSV: {0}")]
    Csv(csv::Error),
    /// A required header column is absent.
    #[error("missing header column `{0}`")]
    MissingColumn(&'static str),
    /// A known header column appears twice.
    #[error("header column `{0}` appears more than once")]
    DuplicateColumn(String),
    /// A value that should be a finite number is not.
    #[error("invalid number `{0}`")]
    BadNumber(String),
    /// A value that should be an integer is not (or is out of range).
    #[error("invalid integer `{0}`")]
    BadInteger(String),
    /// The class name is not one of the known classes.
    #[error("unknown object class `{0}` (expected `car`, `pedestrian` or `two_wheeler`, or one of their names in docs/scenario.md)")]
    UnknownClass(String),
    /// The `origin` value is not one of `object`, `clutter`, `ghost` (or empty).
    #[error("unknown origin `{0}` (expected `object`, `clutter`, `ghost` or an empty field)")]
    UnknownOrigin(String),
    /// A value required on this row is empty.
    #[error("missing value")]
    MissingValue,
    /// The rows of a frame are not contiguous, or (writing) a frame index appears twice. Frames
    /// may come in any order (arrival order: a late scan after a newer one), but each frame's
    /// rows come together, once.
    #[error("frame {frame} appears again after other frames; the rows of one frame must be contiguous and each frame index used once")]
    FrameRepeated {
        /// The frame.
        frame: u64,
    },
    /// Rows of one frame carry different timestamps.
    #[error(
        "timestamp {} differs from {}, the timestamp of the first row of frame {frame}",
        readable(.found),
        readable(.expected)
    )]
    TimeMismatch {
        /// The frame.
        frame: u64,
        /// Timestamp of the frame's first row.
        expected: f64,
        /// Timestamp of this row.
        found: f64,
    },
    /// A frame-level value (sensor id, ego pose) differs between rows of one frame.
    #[error("value `{found}` differs from `{expected}` given by the first row of frame {frame}")]
    FrameFieldMismatch {
        /// The frame.
        frame: u64,
        /// Value on the frame's first row.
        expected: String,
        /// Value on this row.
        found: String,
    },
    /// Only some of `ego_x`, `ego_y`, `ego_yaw` (or of `true_x`, `true_y`, or of `true_vx`,
    /// `true_vy`) are given.
    #[error("incomplete group: the columns {0} must be all given or all empty")]
    IncompleteGroup(&'static str),
    /// An empty-frame row shares its frame with other rows.
    #[error("frame {frame} mixes an empty-frame row with other rows")]
    PlaceholderMixed {
        /// The frame.
        frame: u64,
    },
    /// A frame holds more than [`MAX_MEASUREMENTS_PER_FRAME`] measurements.
    #[error("frame {frame} has more than {max} measurements", max = MAX_MEASUREMENTS_PER_FRAME)]
    TooManyMeasurements {
        /// The frame.
        frame: u64,
    },
    /// Writer: a value to be written is NaN or infinite.
    #[error("non-finite value {}", readable(.0))]
    NonFinite(f64),
}

/// An error while reading or writing a measurement file, with its location.
#[derive(Debug)]
pub struct CsvError {
    /// File the error occurred in, when reading from or writing to a file.
    pub path: Option<PathBuf>,
    /// 1-based line number of the offending row (reading) or of the row being written.
    pub line: Option<u64>,
    /// Name of the offending column, when one is to blame.
    pub column: Option<String>,
    /// What went wrong.
    pub kind: CsvErrorKind,
}

impl CsvError {
    fn new(kind: CsvErrorKind) -> Self {
        Self { path: None, line: None, column: None, kind }
    }

    fn at(line: u64, column: Option<&str>, kind: CsvErrorKind) -> Self {
        Self { path: None, line: Some(line), column: column.map(str::to_owned), kind }
    }

    fn with_path(mut self, path: &Path) -> Self {
        self.path = Some(path.to_path_buf());
        self
    }

    fn from_csv(err: csv::Error) -> Self {
        let line = err.position().map(|p| p.line());
        Self { path: None, line, column: None, kind: CsvErrorKind::Csv(err) }
    }
}

impl std::fmt::Display for CsvError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut prefix = false;
        if let Some(path) = &self.path {
            write!(f, "{}", path.display())?;
            prefix = true;
        }
        if let Some(line) = self.line {
            if prefix {
                write!(f, ":")?;
            }
            write!(f, "line {line}")?;
            prefix = true;
        }
        if let Some(column) = &self.column {
            if prefix {
                write!(f, ", ")?;
            }
            write!(f, "column `{column}`")?;
            prefix = true;
        }
        if prefix {
            write!(f, ": ")?;
        }
        write!(f, "{}", self.kind)
    }
}

impl std::error::Error for CsvError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match &self.kind {
            CsvErrorKind::Io(err) => Some(err),
            CsvErrorKind::Csv(err) => Some(err),
            _ => None,
        }
    }
}

// ------------------------------------------------------------------------------------------------
// Writing

fn fmt_f64(value: f64) -> Result<String, CsvErrorKind> {
    if value.is_finite() {
        Ok(format!("{value}"))
    } else {
        Err(CsvErrorKind::NonFinite(value))
    }
}

fn fmt_opt_f64(value: Option<f64>) -> Result<String, CsvErrorKind> {
    value.map_or(Ok(String::new()), fmt_f64)
}

/// Writes `sequence` as CSV (header plus one row per measurement, one empty-frame row per frame
/// without measurements).
pub fn write_sequence<W: Write>(writer: W, sequence: &Sequence) -> Result<(), CsvError> {
    let mut out = csv::WriterBuilder::new().has_headers(false).from_writer(writer);
    let header: Vec<&str> = REQUIRED_COLUMNS
        .iter()
        .chain(OPTIONAL_COLUMNS.iter())
        .chain(TRUE_VELOCITY_COLUMNS.iter())
        .chain(std::iter::once(&ORIGIN_COLUMN))
        .copied()
        .collect();
    out.write_record(&header).map_err(CsvError::from_csv)?;
    let mut line = 1u64;
    let mut written = std::collections::HashSet::new();
    for frame in &sequence.frames {
        if !written.insert(frame.index) {
            return Err(CsvError::at(
                line + 1,
                Some("frame"),
                CsvErrorKind::FrameRepeated { frame: frame.index },
            ));
        }
        let fail = |line: u64, kind| CsvError::at(line, None, kind);
        let frame_fields =
            [frame.index.to_string(), fmt_f64(frame.timestamp_s).map_err(|k| fail(line + 1, k))?];
        let sensor = frame.sensor_id.map(|s| s.to_string()).unwrap_or_default();
        let ego = match frame.ego_pose {
            Some(pose) => [
                fmt_f64(pose.x_m).map_err(|k| fail(line + 1, k))?,
                fmt_f64(pose.y_m).map_err(|k| fail(line + 1, k))?,
                fmt_f64(pose.yaw_rad).map_err(|k| fail(line + 1, k))?,
            ],
            None => Default::default(),
        };
        if frame.measurements.is_empty() {
            line += 1;
            let mut row: Vec<String> = frame_fields.to_vec();
            row.extend(std::iter::repeat_n(String::new(), MEASUREMENT_COLUMNS.len()));
            row.push(sensor.clone());
            row.extend(ego.iter().cloned());
            row.extend(std::iter::repeat_n(String::new(), TRUE_VELOCITY_COLUMNS.len() + 1));
            out.write_record(&row).map_err(CsvError::from_csv)?;
            continue;
        }
        for recorded in &frame.measurements {
            line += 1;
            let m = &recorded.measurement;
            let gt = match m.ground_truth_id {
                Some(id) => id.to_string(),
                None => "-1".to_owned(),
            };
            let row = [
                frame_fields[0].clone(),
                frame_fields[1].clone(),
                gt,
                m.class.name().to_owned(),
                fmt_f64(m.x_m).map_err(|k| fail(line, k))?,
                fmt_f64(m.y_m).map_err(|k| fail(line, k))?,
                fmt_f64(m.radial_velocity_mps).map_err(|k| fail(line, k))?,
                fmt_f64(m.rcs_dbsm).map_err(|k| fail(line, k))?,
                fmt_opt_f64(recorded.true_position.map(|p| p.x)).map_err(|k| fail(line, k))?,
                fmt_opt_f64(recorded.true_position.map(|p| p.y)).map_err(|k| fail(line, k))?,
                sensor.clone(),
                ego[0].clone(),
                ego[1].clone(),
                ego[2].clone(),
                fmt_opt_f64(recorded.true_velocity.map(|v| v.x)).map_err(|k| fail(line, k))?,
                fmt_opt_f64(recorded.true_velocity.map(|v| v.y)).map_err(|k| fail(line, k))?,
                recorded.origin.map(MeasurementOrigin::name).unwrap_or_default().to_owned(),
            ];
            out.write_record(&row).map_err(CsvError::from_csv)?;
        }
    }
    out.flush().map_err(|e| CsvError::new(CsvErrorKind::Io(e)))?;
    Ok(())
}

/// Writes `sequence` to the file `path` (created or truncated).
pub fn write_sequence_file(path: &Path, sequence: &Sequence) -> Result<(), CsvError> {
    let file = File::create(path).map_err(|e| CsvError::new(CsvErrorKind::Io(e)).with_path(path))?;
    write_sequence(BufWriter::new(file), sequence).map_err(|e| e.with_path(path))
}

// ------------------------------------------------------------------------------------------------
// Reading

/// Column positions found in the header.
struct Columns {
    required: [usize; 10],
    sensor_id: Option<usize>,
    ego: [Option<usize>; 3],
    true_velocity: [Option<usize>; 2],
    origin: Option<usize>,
}

impl Columns {
    fn from_header(header: &csv::StringRecord) -> Result<Self, CsvError> {
        let find = |name: &'static str| -> Result<Option<usize>, CsvError> {
            let mut found = None;
            for (index, field) in header.iter().enumerate() {
                if field == name {
                    if found.is_some() {
                        return Err(CsvError::at(
                            1,
                            Some(name),
                            CsvErrorKind::DuplicateColumn(name.to_owned()),
                        ));
                    }
                    found = Some(index);
                }
            }
            Ok(found)
        };
        let mut required = [0usize; 10];
        for (slot, name) in required.iter_mut().zip(REQUIRED_COLUMNS) {
            *slot =
                find(name)?.ok_or_else(|| CsvError::at(1, Some(name), CsvErrorKind::MissingColumn(name)))?;
        }
        Ok(Self {
            required,
            sensor_id: find("sensor_id")?,
            ego: [find("ego_x")?, find("ego_y")?, find("ego_yaw")?],
            true_velocity: [find("true_vx")?, find("true_vy")?],
            origin: find(ORIGIN_COLUMN)?,
        })
    }
}

/// One parsed row.
struct Row {
    frame: u64,
    t: f64,
    sensor_id: Option<u16>,
    ego: Option<EgoPose>,
    measurement: Option<RecordedMeasurement>,
}

struct RowParser<'a> {
    record: &'a csv::StringRecord,
    line: u64,
}

impl RowParser<'_> {
    fn field(&self, index: usize) -> &str {
        self.record.get(index).unwrap_or("")
    }

    fn error(&self, column: &str, kind: CsvErrorKind) -> CsvError {
        CsvError::at(self.line, Some(column), kind)
    }

    fn opt_f64(&self, index: usize, column: &str) -> Result<Option<f64>, CsvError> {
        let text = self.field(index);
        if text.is_empty() {
            return Ok(None);
        }
        match text.parse::<f64>() {
            Ok(value) if value.is_finite() => Ok(Some(value)),
            _ => Err(self.error(column, CsvErrorKind::BadNumber(text.to_owned()))),
        }
    }

    fn req_f64(&self, index: usize, column: &str) -> Result<f64, CsvError> {
        self.opt_f64(index, column)?.ok_or_else(|| self.error(column, CsvErrorKind::MissingValue))
    }

    fn parse(&self, columns: &Columns) -> Result<Row, CsvError> {
        let frame = self.frame_index(columns.required[0])?;
        let t = self.req_f64(columns.required[1], "t")?;
        let sensor_id = self.sensor_id(columns.sensor_id)?;
        let ego = self.ego(columns.ego)?;
        let measurement = self.measurement(columns, sensor_id)?;
        Ok(Row { frame, t, sensor_id, ego, measurement })
    }

    /// The `frame` column (required).
    fn frame_index(&self, index: usize) -> Result<u64, CsvError> {
        let frame_text = self.field(index);
        if frame_text.is_empty() {
            return Err(self.error("frame", CsvErrorKind::MissingValue));
        }
        frame_text
            .parse::<u64>()
            .map_err(|_| self.error("frame", CsvErrorKind::BadInteger(frame_text.to_owned())))
    }

    /// The optional `sensor_id` column.
    fn sensor_id(&self, index: Option<usize>) -> Result<Option<u16>, CsvError> {
        match index {
            Some(index) if !self.field(index).is_empty() => {
                let text = self.field(index);
                Ok(Some(
                    text.parse::<u16>()
                        .map_err(|_| self.error("sensor_id", CsvErrorKind::BadInteger(text.to_owned())))?,
                ))
            }
            _ => Ok(None),
        }
    }

    /// The optional `ego_x, ego_y, ego_yaw` group: all three or none.
    fn ego(&self, indices: [Option<usize>; 3]) -> Result<Option<EgoPose>, CsvError> {
        let ego_values = [
            indices[0].map(|i| self.opt_f64(i, "ego_x")).transpose()?.flatten(),
            indices[1].map(|i| self.opt_f64(i, "ego_y")).transpose()?.flatten(),
            indices[2].map(|i| self.opt_f64(i, "ego_yaw")).transpose()?.flatten(),
        ];
        match ego_values {
            [Some(x_m), Some(y_m), Some(yaw_rad)] => Ok(Some(EgoPose { x_m, y_m, yaw_rad })),
            [None, None, None] => Ok(None),
            _ => {
                let column = if ego_values[0].is_none() {
                    "ego_x"
                } else if ego_values[1].is_none() {
                    "ego_y"
                } else {
                    "ego_yaw"
                };
                Err(self.error(column, CsvErrorKind::IncompleteGroup("ego_x, ego_y, ego_yaw")))
            }
        }
    }

    /// The measurement columns; `None` for an empty-frame row (every measurement column empty).
    fn measurement(
        &self,
        columns: &Columns,
        sensor_id: Option<u16>,
    ) -> Result<Option<RecordedMeasurement>, CsvError> {
        let [_, _, c_gt, c_class, c_x, c_y, c_vr, c_rcs, c_tx, c_ty] = columns.required;
        let class_text = self.field(c_class);
        if class_text.is_empty() {
            // An empty-frame row: every measurement column must be empty.
            let indices = [c_gt, c_class, c_x, c_y, c_vr, c_rcs, c_tx, c_ty];
            let optional = columns.true_velocity.iter().chain(std::iter::once(&columns.origin)).flatten();
            if indices.iter().chain(optional).any(|&index| !self.field(index).is_empty()) {
                return Err(self.error("class", CsvErrorKind::MissingValue));
            }
            return Ok(None);
        }
        let class = class_from_label(class_text)
            .ok_or_else(|| self.error("class", CsvErrorKind::UnknownClass(class_text.to_owned())))?;
        let gt_text = self.field(c_gt);
        let ground_truth_id = if gt_text.is_empty() || gt_text == "-1" {
            None
        } else {
            Some(
                gt_text
                    .parse::<u64>()
                    .map_err(|_| self.error("gt_id", CsvErrorKind::BadInteger(gt_text.to_owned())))?,
            )
        };
        let x_m = self.req_f64(c_x, "x")?;
        let y_m = self.req_f64(c_y, "y")?;
        let radial_velocity_mps = self.req_f64(c_vr, "vr")?;
        let rcs_dbsm = self.req_f64(c_rcs, "rcs")?;
        let true_position = match (self.opt_f64(c_tx, "true_x")?, self.opt_f64(c_ty, "true_y")?) {
            (Some(x), Some(y)) => Some(DVec2::new(x, y)),
            (None, None) => None,
            (None, Some(_)) => {
                return Err(self.error("true_x", CsvErrorKind::IncompleteGroup("true_x, true_y")))
            }
            (Some(_), None) => {
                return Err(self.error("true_y", CsvErrorKind::IncompleteGroup("true_x, true_y")))
            }
        };
        let true_velocity = self.true_velocity(columns.true_velocity)?;
        let origin = self.origin(columns.origin)?;
        let measurement =
            Measurement { x_m, y_m, radial_velocity_mps, rcs_dbsm, class, sensor_id, ground_truth_id };
        Ok(Some(RecordedMeasurement { measurement, true_position, true_velocity, origin }))
    }

    /// The optional `origin` column: empty (or absent) when unknown.
    fn origin(&self, index: Option<usize>) -> Result<Option<MeasurementOrigin>, CsvError> {
        let text = index.map_or("", |index| self.field(index));
        if text.is_empty() {
            return Ok(None);
        }
        MeasurementOrigin::from_name(text)
            .map(Some)
            .ok_or_else(|| self.error(ORIGIN_COLUMN, CsvErrorKind::UnknownOrigin(text.to_owned())))
    }

    /// The optional `true_vx, true_vy` group: both or neither (absent columns count as empty).
    fn true_velocity(&self, indices: [Option<usize>; 2]) -> Result<Option<DVec2>, CsvError> {
        let vx = indices[0].map(|i| self.opt_f64(i, "true_vx")).transpose()?.flatten();
        let vy = indices[1].map(|i| self.opt_f64(i, "true_vy")).transpose()?.flatten();
        match (vx, vy) {
            (Some(x), Some(y)) => Ok(Some(DVec2::new(x, y))),
            (None, None) => Ok(None),
            (None, Some(_)) => Err(self.error("true_vx", CsvErrorKind::IncompleteGroup("true_vx, true_vy"))),
            (Some(_), None) => Err(self.error("true_vy", CsvErrorKind::IncompleteGroup("true_vx, true_vy"))),
        }
    }
}

/// State of the frame being assembled.
struct OpenFrame {
    frame: RecordedFrame,
    placeholder: bool,
}

impl OpenFrame {
    /// A frame started by its first row.
    fn start(row: Row) -> Self {
        let mut frame = RecordedFrame::new(row.frame, row.t);
        frame.sensor_id = row.sensor_id;
        frame.ego_pose = row.ego;
        let placeholder = row.measurement.is_none();
        frame.measurements.extend(row.measurement);
        Self { frame, placeholder }
    }

    /// Adds a further row of this frame: its frame fields must repeat the first row's, and it
    /// must carry a measurement (an empty-frame placeholder row stands alone).
    fn add_row(&mut self, parser: &RowParser<'_>, row: Row) -> Result<(), CsvError> {
        let frame = &mut self.frame;
        if row.t.to_bits() != frame.timestamp_s.to_bits() {
            return Err(parser.error(
                "t",
                CsvErrorKind::TimeMismatch { frame: row.frame, expected: frame.timestamp_s, found: row.t },
            ));
        }
        if row.sensor_id != frame.sensor_id {
            return Err(parser.error(
                "sensor_id",
                CsvErrorKind::FrameFieldMismatch {
                    frame: row.frame,
                    expected: fmt_opt(&frame.sensor_id),
                    found: fmt_opt(&row.sensor_id),
                },
            ));
        }
        if row.ego != frame.ego_pose {
            return Err(parser.error(
                "ego_x",
                CsvErrorKind::FrameFieldMismatch {
                    frame: row.frame,
                    expected: fmt_opt(&frame.ego_pose),
                    found: fmt_opt(&row.ego),
                },
            ));
        }
        match row.measurement {
            None => Err(parser.error("class", CsvErrorKind::PlaceholderMixed { frame: row.frame })),
            Some(_) if self.placeholder => {
                Err(parser.error("class", CsvErrorKind::PlaceholderMixed { frame: row.frame }))
            }
            Some(m) => {
                if frame.measurements.len() >= MAX_MEASUREMENTS_PER_FRAME {
                    return Err(parser.error("frame", CsvErrorKind::TooManyMeasurements { frame: row.frame }));
                }
                frame.measurements.push(m);
                Ok(())
            }
        }
    }
}

fn fmt_opt<T: std::fmt::Debug>(value: &Option<T>) -> String {
    match value {
        Some(v) => format!("{v:?}"),
        None => "(empty)".to_owned(),
    }
}

/// Reads one sequence from CSV text; `name` becomes [`Sequence::name`].
pub fn read_sequence<R: Read>(reader: R, name: &str) -> Result<Sequence, CsvError> {
    let mut input = csv::ReaderBuilder::new()
        .has_headers(true)
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(reader);
    let header = input.headers().map_err(CsvError::from_csv)?.clone();
    let columns = Columns::from_header(&header)?;
    let mut sequence = Sequence::new(name);
    let mut open: Option<OpenFrame> = None;
    let mut seen = std::collections::HashSet::new();
    let mut record = csv::StringRecord::new();
    loop {
        let more = input.read_record(&mut record).map_err(CsvError::from_csv)?;
        if !more {
            break;
        }
        let line = record.position().map_or(0, |p| p.line());
        let parser = RowParser { record: &record, line };
        let row = parser.parse(&columns)?;
        match &mut open {
            Some(current) if current.frame.index == row.frame => current.add_row(&parser, row)?,
            _ => {
                // Frames come in arrival order (a late scan may follow a newer one), each once.
                if !seen.insert(row.frame) {
                    return Err(parser.error("frame", CsvErrorKind::FrameRepeated { frame: row.frame }));
                }
                if let Some(previous) = open.take() {
                    sequence.frames.push(previous.frame);
                }
                open = Some(OpenFrame::start(row));
            }
        }
    }
    if let Some(last) = open {
        sequence.frames.push(last.frame);
    }
    Ok(sequence)
}

/// Reads the sequence stored in `path`; its name is the file stem.
pub fn read_sequence_file(path: &Path) -> Result<Sequence, CsvError> {
    let file = File::open(path).map_err(|e| CsvError::new(CsvErrorKind::Io(e)).with_path(path))?;
    let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    read_sequence(BufReader::new(file), &name).map_err(|e| e.with_path(path))
}

/// The `.csv` files directly inside `dir`, sorted by file name.
pub fn dataset_files(dir: &Path) -> Result<Vec<PathBuf>, CsvError> {
    let io_error = |e| CsvError::new(CsvErrorKind::Io(e)).with_path(dir);
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(io_error)? {
        let path = entry.map_err(io_error)?.path();
        let is_csv = path.extension().is_some_and(|ext| ext.eq_ignore_ascii_case("csv"));
        if is_csv && path.is_file() {
            files.push(path);
        }
    }
    files.sort_by(|a, b| a.file_name().cmp(&b.file_name()));
    Ok(files)
}

/// Reads a data set: every `.csv` file directly inside `dir`, in sorted file-name order.
pub fn read_dataset_dir(dir: &Path) -> Result<Vec<Sequence>, CsvError> {
    dataset_files(dir)?.iter().map(|path| read_sequence_file(path)).collect()
}

/// The class of a `class` cell: `car`, `pedestrian` or `two_wheeler`, or a name other datasets
/// and stacks give the same kind of object (docs/scenario.md), in any letter case, with `-` or a
/// space for `_`. A truck or a bus is tracked as a car, a cyclist as a two-wheeler. The mapping
/// is primm-core's [`ObjectClass::from_label`], which the C API shares.
pub fn class_from_label(text: &str) -> Option<ObjectClass> {
    ObjectClass::from_label(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The header of files without the true velocity columns (the tests' reading input).
    const HEADER: &str = "frame,t,gt_id,class,x,y,vr,rcs,true_x,true_y,sensor_id,ego_x,ego_y,ego_yaw\n";
    /// The header the writer writes.
    const WRITTEN_HEADER: &str =
        "frame,t,gt_id,class,x,y,vr,rcs,true_x,true_y,sensor_id,ego_x,ego_y,ego_yaw,true_vx,true_vy,origin\n";

    fn measurement(class: ObjectClass, id: Option<u64>, x: f64) -> RecordedMeasurement {
        RecordedMeasurement {
            measurement: Measurement {
                x_m: x,
                y_m: -1.0 / 3.0,
                radial_velocity_mps: -2.5e-7,
                rcs_dbsm: 12.345678901234567,
                class,
                sensor_id: Some(3),
                ground_truth_id: id,
            },
            true_position: id.map(|_| DVec2::new(x + 0.1, 0.7)),
            true_velocity: id.map(|_| DVec2::new(-13.25, 1.0 / 7.0)),
            origin: Some(if id.is_some() { MeasurementOrigin::Object } else { MeasurementOrigin::Ghost }),
        }
    }

    fn sample() -> Sequence {
        let mut sequence = Sequence::new("sample");
        let pose = EgoPose { x_m: 1e-3, y_m: -12.5, yaw_rad: std::f64::consts::PI / 7.0 };
        let mut f0 = RecordedFrame::new(0, 0.0071);
        f0.sensor_id = Some(3);
        f0.ego_pose = Some(pose);
        f0.measurements = vec![
            measurement(ObjectClass::Car, Some(4), 10.1),
            measurement(ObjectClass::Pedestrian, None, -0.0),
        ];
        let mut f1 = RecordedFrame::new(1, 0.0213);
        f1.sensor_id = Some(1);
        f1.ego_pose = Some(pose);
        let mut f3 = RecordedFrame::new(3, 0.05);
        f3.measurements = vec![measurement(ObjectClass::Car, Some(u64::MAX - 1), 1e-300)];
        for m in &mut f3.measurements {
            m.measurement.sensor_id = None;
        }
        sequence.frames = vec![f0, f1, f3];
        sequence
    }

    fn to_text(sequence: &Sequence) -> String {
        let mut bytes = Vec::new();
        write_sequence(&mut bytes, sequence).unwrap();
        String::from_utf8(bytes).unwrap()
    }

    fn read_err(text: &str) -> CsvError {
        read_sequence(text.as_bytes(), "bad").expect_err("should fail")
    }

    #[test]
    fn round_trip_is_exact_including_empty_frames_and_gaps() {
        let sequence = sample();
        let text = to_text(&sequence);
        assert!(text.starts_with(WRITTEN_HEADER));
        // The empty frame is one row with empty measurement fields.
        assert!(text.lines().any(|l| l.starts_with("1,0.0213,,,,,,,,,1,")), "{text}");
        assert!(text.lines().any(|l| l.ends_with(",-13.25,0.14285714285714285,object")), "{text}");
        assert!(text.lines().any(|l| l.ends_with(",,,ghost")), "{text}");
        let back = read_sequence(text.as_bytes(), "sample").unwrap();
        assert_eq!(back, sequence);
        assert!(back.frames[1].measurements.is_empty());
        assert_eq!(back.frames[2].index, 3);
        assert_eq!(back.frames[0].measurements[1].measurement.ground_truth_id, None);
        let frame = back.frames[0].to_frame().unwrap();
        assert_eq!(frame.measurements[0].ground_truth_id, Some(4));
    }

    #[test]
    fn columns_are_found_by_name_and_extra_columns_ignored() {
        let text = "t,frame,class,gt_id,x,y,vr,rcs,true_x,true_y,comment\n\
                    0.5,0,car,7,1.5,2,-0.5,10,,,hello\n\
                    0.5,0,pedestrian,-1,3,4,0.25,-5,3.1,4.2,world\n";
        let sequence = read_sequence(text.as_bytes(), "x").unwrap();
        assert_eq!(sequence.frames.len(), 1);
        let frame = &sequence.frames[0];
        assert_eq!(frame.sensor_id, None);
        assert_eq!(frame.ego_pose, None);
        assert_eq!(frame.measurements[0].measurement.ground_truth_id, Some(7));
        assert_eq!(frame.measurements[0].true_position, None);
        assert_eq!(frame.measurements[1].measurement.class, ObjectClass::Pedestrian);
        assert_eq!(frame.measurements[1].true_position, Some(DVec2::new(3.1, 4.2)));
    }

    #[test]
    fn true_velocity_columns_are_optional_and_read_in_any_order() {
        // Files without the columns (older files, converted recordings) have no velocity.
        let sequence = read_sequence(format!("{HEADER}0,0,3,car,1,2,3,4,5,6,,,,\n").as_bytes(), "x").unwrap();
        assert_eq!(sequence.frames[0].measurements[0].true_velocity, None);
        assert_eq!(sequence.frames[0].measurements[0].true_position, Some(DVec2::new(5.0, 6.0)));
        // By name, in any order, empty for rows without truth.
        let text = "true_vy,frame,t,gt_id,class,x,y,vr,rcs,true_x,true_y,true_vx\n\
                    -0.5,0,0.1,3,car,1,2,3,4,5,6,8.25\n\
                    ,0,0.1,-1,pedestrian,1,2,3,4,,,\n";
        let sequence = read_sequence(text.as_bytes(), "x").unwrap();
        let measurements = &sequence.frames[0].measurements;
        assert_eq!(measurements[0].true_velocity, Some(DVec2::new(8.25, -0.5)));
        assert_eq!(measurements[1].true_velocity, None);
        // Both or neither.
        let err = read_err(&format!("{}0,0,3,car,1,2,3,4,5,6,,,,,1.5,,\n", WRITTEN_HEADER));
        assert!(matches!(err.kind, CsvErrorKind::IncompleteGroup(_)));
        assert_eq!(err.column.as_deref(), Some("true_vy"));
        let err = read_err(&format!("{}0,0,3,car,1,2,3,4,5,6,,,,,abc,1,\n", WRITTEN_HEADER));
        assert!(matches!(err.kind, CsvErrorKind::BadNumber(_)));
        assert_eq!(err.column.as_deref(), Some("true_vx"));
        // An empty-frame row leaves them empty too.
        let err = read_err(&format!("{}0,0,,,,,,,,,,,,,1,2,\n", WRITTEN_HEADER));
        assert_eq!(err.column.as_deref(), Some("class"));
    }

    #[test]
    fn the_origin_column_is_optional_read_by_name_and_checked() {
        // Files without the column (older files, converted recordings): origin unknown.
        let sequence = read_sequence(format!("{HEADER}0,0,3,car,1,2,3,4,5,6,,,,\n").as_bytes(), "x").unwrap();
        assert_eq!(sequence.frames[0].measurements[0].origin, None);
        let text = "origin,frame,t,gt_id,class,x,y,vr,rcs,true_x,true_y\n\
                    ghost,0,0.1,-1,car,1,2,3,4,,\n\
                    clutter,0,0.1,-1,pedestrian,1,2,3,4,,\n\
                    object,0,0.1,5,car,1,2,3,4,,\n\
                    ,0,0.1,6,car,1,2,3,4,,\n";
        let origins: Vec<Option<MeasurementOrigin>> = read_sequence(text.as_bytes(), "x").unwrap().frames[0]
            .measurements
            .iter()
            .map(|m| m.origin)
            .collect();
        assert_eq!(
            origins,
            [
                Some(MeasurementOrigin::Ghost),
                Some(MeasurementOrigin::Clutter),
                Some(MeasurementOrigin::Object),
                None
            ]
        );
        let err = read_err(&format!("{}0,0,3,car,1,2,3,4,5,6,,,,,,,mirror\n", WRITTEN_HEADER));
        assert!(matches!(err.kind, CsvErrorKind::UnknownOrigin(ref o) if o == "mirror"), "{err}");
        assert_eq!((err.line, err.column.as_deref()), (Some(2), Some("origin")));
        // An empty-frame row leaves it empty.
        let err = read_err(&format!("{}0,0,,,,,,,,,,,,,,,ghost\n", WRITTEN_HEADER));
        assert_eq!(err.column.as_deref(), Some("class"));
        // Every origin survives a write and a read.
        for origin in MeasurementOrigin::ALL.map(Some).into_iter().chain([None]) {
            let mut sequence = sample();
            sequence.frames[0].measurements[0].origin = origin;
            let back = read_sequence(to_text(&sequence).as_bytes(), "sample").unwrap();
            assert_eq!(back.frames[0].measurements[0].origin, origin);
        }
    }

    #[test]
    fn comments_and_whitespace_are_accepted() {
        let text = format!("# generated\n{HEADER}0, 0.1 ,3,car,1,2,3,4,,,2,,,\n");
        let sequence = read_sequence(text.as_bytes(), "x").unwrap();
        assert_eq!(sequence.frames[0].timestamp_s, 0.1);
        assert_eq!(sequence.frames[0].sensor_id, Some(2));
    }

    #[test]
    fn missing_header_column_is_reported() {
        let err = read_err("frame,t,gt_id,class,x,y,vr,true_x,true_y\n0,0,1,car,1,2,3,,\n");
        assert!(matches!(err.kind, CsvErrorKind::MissingColumn("rcs")));
        assert_eq!(err.line, Some(1));
        assert!(err.to_string().contains("missing header column `rcs`"), "{err}");
    }

    #[test]
    fn duplicate_header_column_is_reported() {
        let err = read_err("frame,t,gt_id,class,x,y,vr,rcs,true_x,true_y,x\n");
        assert!(matches!(err.kind, CsvErrorKind::DuplicateColumn(ref c) if c == "x"));
    }

    #[test]
    fn bad_number_names_line_and_column() {
        let err = read_err(&format!("{HEADER}0,0,1,car,1,2,3,4,,,,,,\n0,0,2,car,1,abc,3,4,,,,,,\n"));
        assert!(matches!(err.kind, CsvErrorKind::BadNumber(ref v) if v == "abc"));
        assert_eq!(err.line, Some(3));
        assert_eq!(err.column.as_deref(), Some("y"));
        assert_eq!(err.to_string(), "line 3, column `y`: invalid number `abc`");
        let err = read_err(&format!("{HEADER}0,0,1,car,1,2,NaN,4,,,,,,\n"));
        assert!(matches!(err.kind, CsvErrorKind::BadNumber(_)));
        assert_eq!(err.column.as_deref(), Some("vr"));
    }

    #[test]
    fn bad_integers_are_reported() {
        let err = read_err(&format!("{HEADER}0.5,0,1,car,1,2,3,4,,,,,,\n"));
        assert!(matches!(err.kind, CsvErrorKind::BadInteger(_)));
        assert_eq!(err.column.as_deref(), Some("frame"));
        let err = read_err(&format!("{HEADER}0,0,-2,car,1,2,3,4,,,,,,\n"));
        assert_eq!(err.column.as_deref(), Some("gt_id"));
        let err = read_err(&format!("{HEADER}0,0,1,car,1,2,3,4,,,70000,,,\n"));
        assert_eq!(err.column.as_deref(), Some("sensor_id"));
    }

    #[test]
    fn unknown_class_is_reported() {
        let err = read_err(&format!("{HEADER}0,0,1,tram,1,2,3,4,,,,,,\n"));
        assert!(matches!(err.kind, CsvErrorKind::UnknownClass(ref c) if c == "tram"));
        assert_eq!((err.line, err.column.as_deref()), (Some(2), Some("class")));
        assert!(err.to_string().contains("two_wheeler"), "{err}");
    }

    #[test]
    fn other_names_of_the_classes_are_read_as_those_classes() {
        for (label, class) in [
            ("Truck", ObjectClass::Car),
            (" BUS ", ObjectClass::Car),
            ("passenger-car", ObjectClass::Car),
            ("Pedestrian Group", ObjectClass::Pedestrian),
            ("person", ObjectClass::Pedestrian),
            ("Bicycle", ObjectClass::TwoWheeler),
            ("motorcycle", ObjectClass::TwoWheeler),
            ("two_wheeler", ObjectClass::TwoWheeler),
        ] {
            let sequence =
                read_sequence(format!("{HEADER}0,0,1,{label},1,2,3,4,,,,,,\n").as_bytes(), "names")
                    .unwrap_or_else(|error| panic!("{label}: {error}"));
            assert_eq!(sequence.frames[0].measurements[0].measurement.class, class, "{label}");
        }
        for label in ["", "c a r", "cars", "pedestrians"] {
            assert_eq!(class_from_label(label), None, "{label}");
        }
    }

    #[test]
    fn missing_values_are_reported() {
        let err = read_err(&format!("{HEADER}0,0,1,car,,2,3,4,,,,,,\n"));
        assert!(matches!(err.kind, CsvErrorKind::MissingValue));
        assert_eq!(err.column.as_deref(), Some("x"));
        // An empty class with other measurement fields filled is not an empty-frame row.
        let err = read_err(&format!("{HEADER}0,0,1,,1,2,3,4,,,,,,\n"));
        assert_eq!(err.column.as_deref(), Some("class"));
        let err = read_err(&format!("{HEADER},0,1,car,1,2,3,4,,,,,,\n"));
        assert_eq!(err.column.as_deref(), Some("frame"));
    }

    #[test]
    fn frames_in_arrival_order_are_read_as_they_come() {
        let text = format!(
            "{HEADER}0,0,1,car,1,2,3,4,,,,,,\n2,0.1,1,car,1,2,3,4,,,,,,\n1,0.05,1,car,1,2,3,4,,,,,,\n"
        );
        let sequence = read_sequence(text.as_bytes(), "late").unwrap();
        let order: Vec<(u64, f64)> = sequence.frames.iter().map(|f| (f.index, f.timestamp_s)).collect();
        assert_eq!(order, vec![(0, 0.0), (2, 0.1), (1, 0.05)]);
    }

    #[test]
    fn a_frame_whose_rows_are_not_contiguous_is_reported() {
        let err = read_err(&format!(
            "{HEADER}0,0,1,car,1,2,3,4,,,,,,\n2,0.1,1,car,1,2,3,4,,,,,,\n0,0,1,car,1,2,3,4,,,,,,\n"
        ));
        assert!(matches!(err.kind, CsvErrorKind::FrameRepeated { frame: 0 }));
        assert_eq!(err.line, Some(4));
    }

    #[test]
    fn timestamp_mismatch_within_a_frame_is_reported() {
        let err = read_err(&format!("{HEADER}0,0.1,1,car,1,2,3,4,,,,,,\n0,0.2,2,car,1,2,3,4,,,,,,\n"));
        assert!(matches!(err.kind, CsvErrorKind::TimeMismatch { frame: 0, .. }));
        assert_eq!((err.line, err.column.as_deref()), (Some(3), Some("t")));
    }

    #[test]
    fn frame_level_field_mismatch_is_reported() {
        let err = read_err(&format!("{HEADER}0,0,1,car,1,2,3,4,,,1,,,\n0,0,2,car,1,2,3,4,,,2,,,\n"));
        assert!(matches!(err.kind, CsvErrorKind::FrameFieldMismatch { frame: 0, .. }));
        assert_eq!(err.column.as_deref(), Some("sensor_id"));
        let err = read_err(&format!("{HEADER}0,0,1,car,1,2,3,4,,,1,0,0,0\n0,0,2,car,1,2,3,4,,,1,0,0,0.5\n"));
        assert!(matches!(err.kind, CsvErrorKind::FrameFieldMismatch { .. }));
    }

    #[test]
    fn incomplete_groups_are_reported() {
        let err = read_err(&format!("{HEADER}0,0,1,car,1,2,3,4,,,1,5,,0\n"));
        assert!(matches!(err.kind, CsvErrorKind::IncompleteGroup(_)));
        assert_eq!(err.column.as_deref(), Some("ego_y"));
        let err = read_err(&format!("{HEADER}0,0,1,car,1,2,3,4,1.5,,,,,\n"));
        assert_eq!(err.column.as_deref(), Some("true_y"));
    }

    #[test]
    fn empty_frame_row_must_be_alone() {
        let err = read_err(&format!("{HEADER}0,0,,,,,,,,,,,,\n0,0,1,car,1,2,3,4,,,,,,\n"));
        assert!(matches!(err.kind, CsvErrorKind::PlaceholderMixed { frame: 0 }));
        let err = read_err(&format!("{HEADER}0,0,1,car,1,2,3,4,,,,,,\n0,0,,,,,,,,,,,,\n"));
        assert!(matches!(err.kind, CsvErrorKind::PlaceholderMixed { frame: 0 }));
    }

    #[test]
    fn too_many_measurements_in_a_frame_are_reported() {
        let mut text = HEADER.to_owned();
        for i in 0..=MAX_MEASUREMENTS_PER_FRAME {
            text.push_str(&format!("0,0,{i},car,1,2,3,4,,,,,,\n"));
        }
        let err = read_err(&text);
        assert!(matches!(err.kind, CsvErrorKind::TooManyMeasurements { frame: 0 }));
        assert_eq!(err.line, Some(MAX_MEASUREMENTS_PER_FRAME as u64 + 2));
    }

    #[test]
    fn ragged_rows_are_reported_with_their_line() {
        let err = read_err(&format!("{HEADER}0,0,1,car,1,2,3,4,,,,,,\n0,0,1,car\n"));
        assert!(matches!(err.kind, CsvErrorKind::Csv(_)));
        assert_eq!(err.line, Some(3));
    }

    #[test]
    fn writer_rejects_unordered_frames_and_non_finite_values() {
        let mut sequence = sample();
        sequence.frames[2].index = 1;
        let err = write_sequence(Vec::new(), &sequence).unwrap_err();
        assert!(matches!(err.kind, CsvErrorKind::FrameRepeated { frame: 1 }));
        let mut sequence = sample();
        sequence.frames[0].measurements[0].measurement.x_m = f64::INFINITY;
        let err = write_sequence(Vec::new(), &sequence).unwrap_err();
        assert!(matches!(err.kind, CsvErrorKind::NonFinite(_)));
    }

    #[test]
    fn dataset_directory_is_read_in_sorted_order() {
        let dir = std::env::temp_dir().join(format!("primm-csv-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut b = sample();
        b.name = "b_seq".into();
        let mut a = sample();
        a.name = "a_seq".into();
        a.frames.truncate(1);
        write_sequence_file(&dir.join("b_seq.csv"), &b).unwrap();
        write_sequence_file(&dir.join("a_seq.csv"), &a).unwrap();
        std::fs::write(dir.join("notes.txt"), "not a sequence").unwrap();
        let sequences = read_dataset_dir(&dir).unwrap();
        assert_eq!(sequences, vec![a, b]);
        std::fs::write(dir.join("c_bad.csv"), format!("{HEADER}0,0,1,tram,1,2,3,4,,,,,,\n")).unwrap();
        let err = read_dataset_dir(&dir).unwrap_err();
        assert_eq!(err.path.as_deref(), Some(dir.join("c_bad.csv").as_path()));
        assert!(err.to_string().contains("c_bad.csv:line 2, column `class`"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
