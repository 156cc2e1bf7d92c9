//! The association CSV format: which track took each measurement of a sequence, and that
//! track's prior. It is what any tracker (primm's or another one) has to write to be scored by
//! `primm score` with exactly the metrics of `primm eval`.
//!
//! ```text
//! frame,measurement,track_id,prior_x,prior_y,confirmed
//! 0,0,1,,,0
//! 1,0,1,10.31,-4.02,1
//! 1,1,,,,
//! ```
//!
//! One row per measurement of the measurement CSV, in any order: `frame` is the frame index of
//! the measurement CSV, `measurement` the measurement's position within its frame (0-based, in
//! file order). `track_id` is empty when no track took the measurement; `prior_x`, `prior_y`
//! (metres, vehicle frame) are the track's one-step prior position before the update, empty when
//! the measurement started the track. `confirmed` is `1` when the track was confirmed after this
//! frame's update (any status but tentative), `0` when it was tentative, and empty or `0` in a
//! row without a track; empty in a row with a track means unknown.
//!
//! Files with the older header without `confirmed` ([`LEGACY_ASSOCIATION_CSV_HEADER`]) are still
//! read: every track's status is then unknown, and `primm score` skips the metrics on confirmed
//! tracks for them (`docs/evaluation-metrics.md`).

use crate::eval::record::{counts_as_confirmed, AssociationRecord};
use crate::io::Sequence;
use glam::DVec2;
use primm_core::track::TrackOutput;
use std::collections::HashMap;
use std::io::{Read, Write};

/// The header line.
pub const ASSOCIATION_CSV_HEADER: &str = "frame,measurement,track_id,prior_x,prior_y,confirmed";

/// The header of files without the `confirmed` column; still read, with every track's status
/// unknown.
pub const LEGACY_ASSOCIATION_CSV_HEADER: &str = "frame,measurement,track_id,prior_x,prior_y";

/// One row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AssociationRow {
    /// Frame index (as in the measurement CSV).
    pub frame: u64,
    /// Position of the measurement within its frame.
    pub measurement: u16,
    /// The track that took it.
    pub track_id: Option<u64>,
    /// That track's prior position, m.
    pub prior_m: Option<DVec2>,
    /// Whether that track was confirmed after this frame's update; `None` when unknown (a legacy
    /// file, or an empty field) and in a row without a track.
    pub confirmed: Option<bool>,
}

/// Why an association CSV could not be read or does not fit its sequence.
#[derive(Debug, thiserror::Error)]
pub enum AssociationCsvError {
    /// Reading or writing failed.
    #[error("I/O error: {0}")]
    Io(#[from] std::io::Error),
    /// The CSV layer rejected the input.
    #[error("malformed CSV: {0}")]
    Csv(#[from] csv::Error),
    /// The header is neither [`ASSOCIATION_CSV_HEADER`] nor [`LEGACY_ASSOCIATION_CSV_HEADER`].
    #[error(
        "expected the header `{ASSOCIATION_CSV_HEADER}` (or `{LEGACY_ASSOCIATION_CSV_HEADER}`), found `{0}`"
    )]
    Header(String),
    /// A field could not be parsed.
    #[error("line {line}: invalid {column} `{value}`")]
    Field {
        /// 1-based line number.
        line: u64,
        /// The column.
        column: &'static str,
        /// The text found.
        value: String,
    },
    /// A row names a measurement the sequence does not have.
    #[error("frame {frame}, measurement {measurement}: no such measurement in sequence {sequence}")]
    UnknownMeasurement {
        /// The sequence.
        sequence: String,
        /// Frame index.
        frame: u64,
        /// Measurement position.
        measurement: u16,
    },
    /// Two rows name the same measurement.
    #[error("frame {frame}, measurement {measurement}: listed twice")]
    Duplicate {
        /// Frame index.
        frame: u64,
        /// Measurement position.
        measurement: u16,
    },
}

/// Writes association rows.
#[derive(Debug)]
pub struct AssociationCsvWriter<W: Write> {
    out: W,
}

impl<W: Write> AssociationCsvWriter<W> {
    /// A writer that starts with the header.
    pub fn new(mut out: W) -> std::io::Result<Self> {
        writeln!(out, "{ASSOCIATION_CSV_HEADER}")?;
        Ok(Self { out })
    }

    /// One row per measurement of a frame of `measurement_count` measurements, from the
    /// tracker's outputs for that frame.
    pub fn write_frame(
        &mut self,
        frame: u64,
        measurement_count: usize,
        outputs: &[TrackOutput],
    ) -> std::io::Result<()> {
        let mut taken: Vec<Option<&TrackOutput>> = vec![None; measurement_count];
        for output in outputs {
            if let Some(slot) = output.measurement_index.and_then(|index| taken.get_mut(usize::from(index))) {
                *slot = Some(output);
            }
        }
        for (index, output) in taken.iter().enumerate() {
            self.write_row(&AssociationRow {
                frame,
                measurement: index as u16,
                track_id: output.map(|o| o.id),
                prior_m: output.and_then(|o| o.prior_position_m),
                confirmed: output.map(|o| counts_as_confirmed(o.status)),
            })?;
        }
        Ok(())
    }

    /// One row. `confirmed` is written only in a row with a track.
    pub fn write_row(&mut self, row: &AssociationRow) -> std::io::Result<()> {
        let track = row.track_id.map(|id| id.to_string()).unwrap_or_default();
        let confirmed = match (row.track_id, row.confirmed) {
            (Some(_), Some(true)) => "1",
            (Some(_), Some(false)) => "0",
            _ => "",
        };
        match row.prior_m {
            Some(prior) => writeln!(
                self.out,
                "{},{},{track},{},{},{confirmed}",
                row.frame, row.measurement, prior.x, prior.y
            ),
            None => writeln!(self.out, "{},{},{track},,,{confirmed}", row.frame, row.measurement),
        }
    }

    /// Flushes and returns the writer.
    pub fn finish(mut self) -> std::io::Result<W> {
        self.out.flush()?;
        Ok(self.out)
    }
}

/// Reads the rows of an association CSV.
pub fn read_association_rows<R: Read>(reader: R) -> Result<Vec<AssociationRow>, AssociationCsvError> {
    let mut csv = csv::ReaderBuilder::new().has_headers(true).trim(csv::Trim::All).from_reader(reader);
    let header: Vec<String> = csv.headers()?.iter().map(str::to_string).collect();
    let with_confirmed = match header.join(",") {
        text if text == ASSOCIATION_CSV_HEADER => true,
        text if text == LEGACY_ASSOCIATION_CSV_HEADER => false,
        text => return Err(AssociationCsvError::Header(text)),
    };
    let mut rows = Vec::new();
    for (i, record) in csv.records().enumerate() {
        let record = record?;
        let line = i as u64 + 2;
        let field = |column: usize, name: &'static str| -> Result<Option<&str>, AssociationCsvError> {
            let value = record.get(column).ok_or(AssociationCsvError::Field {
                line,
                column: name,
                value: String::new(),
            })?;
            Ok(if value.is_empty() { None } else { Some(value) })
        };
        let bad = |name: &'static str, value: &str| AssociationCsvError::Field {
            line,
            column: name,
            value: value.to_string(),
        };
        let frame = field(0, "frame")?.ok_or_else(|| bad("frame", ""))?;
        let measurement = field(1, "measurement")?.ok_or_else(|| bad("measurement", ""))?;
        let track_id =
            field(2, "track_id")?.map(|v| v.parse::<u64>().map_err(|_| bad("track_id", v))).transpose()?;
        let number = |column: usize, name: &'static str| -> Result<Option<f64>, AssociationCsvError> {
            match field(column, name)? {
                None => Ok(None),
                Some(v) => match v.parse::<f64>() {
                    Ok(x) if x.is_finite() => Ok(Some(x)),
                    _ => Err(bad(name, v)),
                },
            }
        };
        let prior_m = match (number(3, "prior_x")?, number(4, "prior_y")?) {
            (Some(x), Some(y)) => Some(DVec2::new(x, y)),
            (None, None) => None,
            _ => return Err(bad("prior_x/prior_y", "only one of the two")),
        };
        let confirmed = if with_confirmed {
            match (field(5, "confirmed")?, track_id) {
                (None, _) | (Some("0"), None) => None,
                (Some("1"), Some(_)) => Some(true),
                (Some("0"), Some(_)) => Some(false),
                (Some(value), _) => return Err(bad("confirmed", value)),
            }
        } else {
            None
        };
        rows.push(AssociationRow {
            frame: frame.parse().map_err(|_| bad("frame", frame))?,
            measurement: measurement.parse().map_err(|_| bad("measurement", measurement))?,
            track_id,
            prior_m,
            confirmed,
        });
    }
    Ok(rows)
}

/// The evaluation records of `sequence` (one per measurement, as `primm eval` builds them)
/// with the track, prior and track status of each measurement taken from `rows`. Measurements
/// without a row were taken by no track. A track may take several measurements of one frame (a
/// tracker that groups a radar's detections); the metrics count it once per frame.
pub fn association_records_from_rows(
    sequence: &Sequence,
    rows: &[AssociationRow],
) -> Result<Vec<AssociationRecord>, AssociationCsvError> {
    let mut index: HashMap<(u64, u16), usize> = HashMap::new();
    let mut records = Vec::with_capacity(sequence.measurement_count());
    for recorded in &sequence.frames {
        for (position, m) in recorded.measurements.iter().enumerate() {
            index.insert((recorded.index, position as u16), records.len());
            records.push(recorded.unassigned_record(m));
        }
    }
    let mut seen = vec![false; records.len()];
    for row in rows {
        let Some(&i) = index.get(&(row.frame, row.measurement)) else {
            return Err(AssociationCsvError::UnknownMeasurement {
                sequence: sequence.name.clone(),
                frame: row.frame,
                measurement: row.measurement,
            });
        };
        if std::mem::replace(&mut seen[i], true) {
            return Err(AssociationCsvError::Duplicate { frame: row.frame, measurement: row.measurement });
        }
        records[i].track_id = row.track_id;
        records[i].prior = row.prior_m.filter(|_| row.track_id.is_some());
        records[i].track_confirmed = if row.track_id.is_some() { row.confirmed } else { Some(false) };
    }
    Ok(records)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::{RecordedFrame, RecordedMeasurement};
    use primm_core::measurement::{Measurement, ObjectClass};

    fn sequence() -> Sequence {
        let mut sequence = Sequence::new("s");
        for index in 0..2u64 {
            let mut frame = RecordedFrame::new(index, index as f64 * 0.1);
            for j in 0..2 {
                frame.measurements.push(RecordedMeasurement {
                    measurement: Measurement {
                        x_m: 10.0 + j as f64,
                        y_m: 0.0,
                        radial_velocity_mps: 0.0,
                        rcs_dbsm: 0.0,
                        class: ObjectClass::Car,
                        sensor_id: None,
                        ground_truth_id: Some(j),
                    },
                    true_position: None,
                    true_velocity: None,
                    origin: None,
                });
            }
            sequence.frames.push(frame);
        }
        sequence
    }

    fn rows(text: &str) -> Result<Vec<AssociationRow>, AssociationCsvError> {
        read_association_rows(format!("{ASSOCIATION_CSV_HEADER}\n{text}").as_bytes())
    }

    #[test]
    fn rows_read_back_into_records_in_measurement_order() {
        let rows = rows("1,1,7,10.5,0.25,1\n0,0,7,,,0\n0,1,,,,\n").unwrap();
        let records = association_records_from_rows(&sequence(), &rows).unwrap();
        assert_eq!(records.len(), 4);
        assert_eq!((records[0].track_id, records[0].prior), (Some(7), None));
        assert_eq!(records[0].track_confirmed, Some(false));
        assert_eq!((records[1].track_id, records[1].track_confirmed), (None, Some(false)));
        assert_eq!(records[2].track_id, None, "a measurement without a row was taken by no track");
        assert_eq!((records[3].track_id, records[3].prior), (Some(7), Some(DVec2::new(10.5, 0.25))));
        assert_eq!(records[3].track_confirmed, Some(true));
    }

    #[test]
    fn a_file_without_the_confirmed_column_still_reads_with_the_status_unknown() {
        let text = format!("{LEGACY_ASSOCIATION_CSV_HEADER}\n0,0,7,,\n1,0,7,10.5,0.25\n0,1,,,\n");
        let rows = read_association_rows(text.as_bytes()).unwrap();
        assert!(rows.iter().all(|row| row.confirmed.is_none()));
        let records = association_records_from_rows(&sequence(), &rows).unwrap();
        assert_eq!((records[0].track_id, records[0].track_confirmed), (Some(7), None));
        assert_eq!((records[1].track_id, records[1].track_confirmed), (None, Some(false)));
        assert_eq!(records[2].prior, Some(DVec2::new(10.5, 0.25)));
    }

    #[test]
    fn written_rows_read_back_with_their_status() {
        let written = [
            AssociationRow {
                frame: 0,
                measurement: 0,
                track_id: Some(3),
                prior_m: None,
                confirmed: Some(false),
            },
            AssociationRow {
                frame: 1,
                measurement: 0,
                track_id: Some(3),
                prior_m: Some(DVec2::new(1.5, -2.0)),
                confirmed: Some(true),
            },
            AssociationRow { frame: 1, measurement: 1, track_id: None, prior_m: None, confirmed: None },
        ];
        let mut writer = AssociationCsvWriter::new(Vec::new()).unwrap();
        for row in &written {
            writer.write_row(row).unwrap();
        }
        let bytes = writer.finish().unwrap();
        let text = String::from_utf8(bytes.clone()).unwrap();
        assert_eq!(text.lines().next(), Some(ASSOCIATION_CSV_HEADER));
        assert_eq!(read_association_rows(bytes.as_slice()).unwrap(), written);
    }

    #[test]
    fn a_confirmed_flag_other_than_0_or_1_or_one_without_a_track_is_an_error() {
        assert!(matches!(rows("0,0,1,,,yes"), Err(AssociationCsvError::Field { column: "confirmed", .. })));
        assert!(matches!(rows("0,0,,,,1"), Err(AssociationCsvError::Field { column: "confirmed", .. })));
        assert_eq!(rows("0,0,1,,,").unwrap()[0].confirmed, None, "empty means unknown");
        assert_eq!(rows("0,0,,,,0").unwrap()[0].confirmed, None);
    }

    #[test]
    fn a_wrong_header_a_bad_number_or_half_a_prior_is_an_error() {
        assert!(matches!(
            read_association_rows("frame,track\n".as_bytes()),
            Err(AssociationCsvError::Header(_))
        ));
        assert!(matches!(rows("0,0,x,,,"), Err(AssociationCsvError::Field { column: "track_id", .. })));
        assert!(matches!(rows("0,0,1,nan,1,1"), Err(AssociationCsvError::Field { column: "prior_x", .. })));
        assert!(matches!(rows("0,0,1,1.0,,1"), Err(AssociationCsvError::Field { .. })));
        assert!(matches!(rows("0,0,1,,"), Err(AssociationCsvError::Csv(_))), "a field short");
    }

    #[test]
    fn a_measurement_listed_twice_is_refused_and_a_track_may_take_several_of_a_frame() {
        let twice = rows("0,0,1,,,1\n0,0,2,,,1\n").unwrap();
        assert!(matches!(
            association_records_from_rows(&sequence(), &twice),
            Err(AssociationCsvError::Duplicate { .. })
        ));
        // A tracker that groups detections: track 1 takes both measurements of frame 0.
        let grouped = rows("0,0,1,,,1\n0,1,1,,,1\n").unwrap();
        let records = association_records_from_rows(&sequence(), &grouped).unwrap();
        assert_eq!((records[0].track_id, records[1].track_id), (Some(1), Some(1)));
        // Two objects, one track: one estimated object frame, matched to one of them.
        let counts = crate::eval::identity_counts(&records);
        assert_eq!((counts.gt_object_frames, counts.estimated_object_frames, counts.idtp), (4, 1, 1));
    }
}
