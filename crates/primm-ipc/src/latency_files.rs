//! Latency histograms as files that other HdrHistogram tools read: per stage an interval log
//! (`STAGE.hlog`) and a percentile distribution (`STAGE.hgrm`), plus one SVG plot of every
//! stage by percentile (`PROCESS.svg`, see [`latency_plot`](super::latency_plot)).
//!
//! Both formats follow the reference implementation (HdrHistogram's `HistogramLogWriter` and
//! `outputPercentileDistribution`):
//!
//! - `.hlog`: the lines `#[Histogram log format version 1.3]`, `#[StartTime: …]`,
//!   `#[BaseTime: …]`, the CSV legend, then one line per interval: start (s since BaseTime),
//!   length (s), the interval's maximum, and the interval histogram in the V2 compressed
//!   encoding (base64). The `hdrhistogram` crate's own log writer leaves out the version and
//!   legend lines, which HistogramLogAnalyzer and other readers expect, so this module writes the
//!   log itself and uses the crate only to encode each histogram.
//! - `.hgrm`: `Value Percentile TotalCount 1/(1-Percentile)` rows, five ticks per half
//!   distance, and the `#[Mean …]`, `#[Max …]`, `#[Buckets …]` footer.
//!
//! Units: the histograms record nanoseconds (the encoded histograms hold ns); every value
//! written as text (`Interval_Max`, the `.hgrm` columns and footer) is in microseconds, i.e. the
//! output value unit ratio of the reference tools is 1000 ([`OUTPUT_VALUE_UNIT_RATIO`]). Each
//! file says so in a comment line; with the Java `HistogramLogProcessor`, pass
//! `-outputValueUnitRatio 1000` to get microseconds from an `.hlog`.
//!
//! Intervals are written from cumulative histograms: at each boundary the interval is the
//! cumulative histogram minus its copy from the previous boundary, so that the recording path
//! (one `record` per stage and frame) is left exactly as it is. Writing costs a few hundred
//! microseconds per stage and allocates (the deflate step); it happens once per interval, after
//! a frame has been answered, and only when files were asked for.

use super::latency_plot::{self, PlotError, PlotSeries};
use hdrhistogram::serialization::{Serializer, V2DeflateSerializeError, V2DeflateSerializer};
use hdrhistogram::Histogram;
use std::fmt::Write as _;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

/// The ratio between recorded values (ns) and written values (µs).
pub const OUTPUT_VALUE_UNIT_RATIO: f64 = 1000.0;

/// The unit of written values.
pub const OUTPUT_UNIT: &str = "µs";

/// Percentile ticks per half distance of the `.hgrm` rows (the reference tools' default).
pub const PERCENTILE_TICKS_PER_HALF_DISTANCE: u32 = 5;

/// The interval-log format version written.
pub const LOG_FORMAT_VERSION: &str = "1.3";

/// The CSV legend line of an interval log.
pub const LOG_LEGEND: &str =
    "\"StartTimestamp\",\"Interval_Length\",\"Interval_Max\",\"Interval_Compressed_Histogram\"";

/// Why latency files could not be written.
#[derive(Debug, thiserror::Error)]
pub enum LatencyFilesError {
    /// The output directory or a file in it could not be created or written.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// A histogram could not be encoded.
    #[error("cannot encode the histogram of {path}: {source}")]
    Encode {
        /// The log being written.
        path: PathBuf,
        /// What the encoder reported.
        source: V2DeflateSerializeError,
    },
    /// The plot could not be drawn.
    #[error(transparent)]
    Plot(#[from] PlotError),
    /// A stage name cannot be a file name (empty, or with a path separator or dot).
    #[error("latency stage name `{0}` is not usable as a file name")]
    StageName(String),
    /// Two histograms differ in their bounds (an interval could not be formed).
    #[error("the histograms of stage `{0}` have different bounds")]
    Bounds(String),
}

/// One latency to write: its file name and what it measures (written as a comment).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StageDescription {
    /// File name without extension, e.g. `end_to_end`.
    pub name: String,
    /// What is measured, one line, e.g. "publisher send to tracker send".
    pub description: String,
}

impl StageDescription {
    /// A stage named `name` measuring `description`.
    pub fn new(name: impl Into<String>, description: impl Into<String>) -> Self {
        Self { name: name.into(), description: description.into() }
    }
}

/// An interval log being written (`.hlog`).
pub struct IntervalLog<W: Write> {
    writer: W,
    serializer: V2DeflateSerializer,
    encoded: Vec<u8>,
    text: String,
}

impl<W: Write + std::fmt::Debug> std::fmt::Debug for IntervalLog<W> {
    fn fmt(&self, formatter: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        formatter.debug_struct("IntervalLog").field("writer", &self.writer).finish_non_exhaustive()
    }
}

impl<W: Write> IntervalLog<W> {
    /// Starts a log on `writer`: the comment lines `comments` (each written as `#…`), the
    /// format version, start and base time (both `start`) and the legend.
    pub fn begin(mut writer: W, start: SystemTime, comments: &[String]) -> std::io::Result<Self> {
        for comment in comments {
            for line in comment.lines() {
                writeln!(writer, "#{line}")?;
            }
        }
        writeln!(writer, "#[Histogram log format version {LOG_FORMAT_VERSION}]")?;
        let seconds = seconds_since_epoch(start);
        writeln!(writer, "#[StartTime: {seconds:.3} (seconds since epoch), {}]", utc_text(start))?;
        writeln!(writer, "#[BaseTime: {seconds:.3} (seconds since epoch)]")?;
        writeln!(writer, "{LOG_LEGEND}")?;
        Ok(Self { writer, serializer: V2DeflateSerializer::new(), encoded: Vec::new(), text: String::new() })
    }

    /// Appends one interval histogram that started `start` after the base time and lasted
    /// `length`.
    pub fn write_interval(
        &mut self,
        histogram: &Histogram<u64>,
        start: Duration,
        length: Duration,
    ) -> Result<(), IntervalLogError> {
        use base64::Engine as _;
        self.encoded.clear();
        self.text.clear();
        self.serializer.serialize(histogram, &mut self.encoded).map_err(IntervalLogError::Encode)?;
        base64::engine::general_purpose::STANDARD.encode_string(&self.encoded, &mut self.text);
        let max = if histogram.is_empty() { 0.0 } else { histogram.max() as f64 / OUTPUT_VALUE_UNIT_RATIO };
        writeln!(
            self.writer,
            "{:.3},{:.3},{:.3},{}",
            start.as_secs_f64(),
            length.as_secs_f64(),
            max,
            self.text
        )
        .map_err(IntervalLogError::Io)
    }

    /// Flushes the writer.
    pub fn flush(&mut self) -> std::io::Result<()> {
        self.writer.flush()
    }
}

/// Why an interval could not be appended to a log.
#[derive(Debug, thiserror::Error)]
pub enum IntervalLogError {
    /// The histogram could not be encoded.
    #[error("cannot encode the histogram: {0}")]
    Encode(V2DeflateSerializeError),
    /// The writer failed.
    #[error(transparent)]
    Io(std::io::Error),
}

/// Writes `histogram`'s percentile distribution in the reference text format, values divided
/// by [`OUTPUT_VALUE_UNIT_RATIO`]. `comments` go first, each line prefixed with `#`.
pub fn write_percentile_distribution<W: Write>(
    mut writer: W,
    histogram: &Histogram<u64>,
    comments: &[String],
) -> std::io::Result<()> {
    for comment in comments {
        for line in comment.lines() {
            writeln!(writer, "#{line}")?;
        }
    }
    writeln!(
        writer,
        "{:>12} {:>14} {:>10} {:>14}\n",
        "Value", "Percentile", "TotalCount", "1/(1-Percentile)"
    )?;
    let digits = usize::from(histogram.sigfig());
    let total = histogram.len();
    if total > 0 {
        for step in histogram.iter_quantiles(PERCENTILE_TICKS_PER_HALF_DISTANCE) {
            let value = step.value_iterated_to() as f64 / OUTPUT_VALUE_UNIT_RATIO;
            let quantile = step.quantile_iterated_to();
            let count = (step.quantile() * total as f64).round() as u64;
            if quantile < 1.0 {
                writeln!(
                    writer,
                    "{value:>12.digits$} {quantile:>2.12} {count:>10} {:>14.2}",
                    1.0 / (1.0 - quantile)
                )?;
            } else {
                writeln!(writer, "{value:>12.digits$} {quantile:>2.12} {count:>10}")?;
            }
        }
    }
    let (mean, deviation, max) = if total > 0 {
        (
            histogram.mean() / OUTPUT_VALUE_UNIT_RATIO,
            histogram.stdev() / OUTPUT_VALUE_UNIT_RATIO,
            histogram.max() as f64 / OUTPUT_VALUE_UNIT_RATIO,
        )
    } else {
        (0.0, 0.0, 0.0)
    };
    writeln!(writer, "#[Mean    = {mean:>12.digits$}, StdDeviation   = {deviation:>12.digits$}]")?;
    writeln!(writer, "#[Max     = {max:>12.digits$}, Total count    = {total:>12}]")?;
    writeln!(
        writer,
        "#[Buckets = {:>12}, SubBuckets     = {:>12}]",
        histogram.buckets(),
        sub_bucket_count(histogram.sigfig())
    )?;
    Ok(())
}

/// The sub-bucket count of a histogram with `significant_digits` (as HdrHistogram sizes it:
/// the power of two that holds twice 10^digits).
pub fn sub_bucket_count(significant_digits: u8) -> u64 {
    let largest_single_unit = 2 * 10u64.pow(u32::from(significant_digits));
    largest_single_unit.next_power_of_two()
}

/// The unit comment of every file written here.
fn unit_comment() -> String {
    format!(
        "[Units: histograms record nanoseconds; values written as text are in microseconds \
         (output value unit ratio {OUTPUT_VALUE_UNIT_RATIO})]"
    )
}

/// One stage's interval log and the cumulative histogram seen at the last boundary.
#[derive(Debug)]
struct StageLog {
    stage: StageDescription,
    path: PathBuf,
    log: IntervalLog<BufWriter<File>>,
    previous: Histogram<u64>,
    interval: Histogram<u64>,
}

/// The latency files of one process in one directory: an interval log per stage, written at
/// every interval boundary, and at [`finish`](Self::finish) the percentile distributions and
/// a plot.
#[derive(Debug)]
pub struct LatencyFiles {
    directory: PathBuf,
    process: String,
    start_ns: u64,
    last_boundary_ns: u64,
    interval_ns: u64,
    stages: Vec<StageLog>,
}

impl LatencyFiles {
    /// Creates `directory` (if needed) and a `.hlog` per stage, their header written;
    /// intervals of `interval` start now (`now_ns`, on the clock the caller passes to
    /// [`write_due`](Self::write_due)). `process` names the plot (`PROCESS.svg`) and goes into
    /// every file's comments. Every histogram passed later must have the bounds of `template`.
    pub fn create(
        directory: &Path,
        process: &str,
        stages: &[StageDescription],
        template: &Histogram<u64>,
        interval: Duration,
        now_ns: u64,
    ) -> Result<Self, LatencyFilesError> {
        std::fs::create_dir_all(directory)
            .map_err(|source| LatencyFilesError::Io { path: directory.to_owned(), source })?;
        let start = SystemTime::now();
        let mut logs = Vec::with_capacity(stages.len());
        for stage in stages {
            if stage.name.is_empty() || stage.name.contains(['/', '\\', '.']) {
                return Err(LatencyFilesError::StageName(stage.name.clone()));
            }
            let path = directory.join(format!("{}.hlog", stage.name));
            let file =
                File::create(&path).map_err(|source| LatencyFilesError::Io { path: path.clone(), source })?;
            let comments =
                [format!("[primm {process}: {} ({})]", stage.name, stage.description), unit_comment()];
            let log = IntervalLog::begin(BufWriter::new(file), start, &comments)
                .map_err(|source| LatencyFilesError::Io { path: path.clone(), source })?;
            let mut empty = template.clone();
            empty.reset();
            logs.push(StageLog { stage: stage.clone(), path, log, previous: empty.clone(), interval: empty });
        }
        Ok(Self {
            directory: directory.to_owned(),
            process: process.to_owned(),
            start_ns: now_ns,
            last_boundary_ns: now_ns,
            interval_ns: interval.as_nanos().clamp(1, u128::from(u64::MAX)) as u64,
            stages: logs,
        })
    }

    /// The directory written to.
    pub fn directory(&self) -> &Path {
        &self.directory
    }

    /// Whether an interval has ended at `now_ns`.
    #[inline]
    pub fn due(&self, now_ns: u64) -> bool {
        now_ns.saturating_sub(self.last_boundary_ns) >= self.interval_ns
    }

    /// If an interval has ended at `now_ns`, appends it to every stage's log; `cumulative(i)`
    /// is stage `i`'s histogram since the start. Returns whether it wrote.
    pub fn write_due<'h>(
        &mut self,
        now_ns: u64,
        cumulative: impl Fn(usize) -> &'h Histogram<u64>,
    ) -> Result<bool, LatencyFilesError> {
        if !self.due(now_ns) {
            return Ok(false);
        }
        self.write_interval(now_ns, cumulative)?;
        Ok(true)
    }

    /// Appends the interval from the last boundary to `now_ns` to every stage's log.
    pub fn write_interval<'h>(
        &mut self,
        now_ns: u64,
        cumulative: impl Fn(usize) -> &'h Histogram<u64>,
    ) -> Result<(), LatencyFilesError> {
        let start = Duration::from_nanos(self.last_boundary_ns.saturating_sub(self.start_ns));
        let length = Duration::from_nanos(now_ns.saturating_sub(self.last_boundary_ns));
        self.last_boundary_ns = now_ns;
        for (index, stage) in self.stages.iter_mut().enumerate() {
            let current = cumulative(index);
            stage.interval.reset();
            let name = &stage.stage.name;
            stage.interval.add(current).map_err(|_| LatencyFilesError::Bounds(name.clone()))?;
            stage.interval.subtract(&stage.previous).map_err(|_| LatencyFilesError::Bounds(name.clone()))?;
            stage.previous.reset();
            stage.previous.add(current).map_err(|_| LatencyFilesError::Bounds(name.clone()))?;
            stage.log.write_interval(&stage.interval, start, length).map_err(|error| match error {
                IntervalLogError::Encode(source) => {
                    LatencyFilesError::Encode { path: stage.path.clone(), source }
                }
                IntervalLogError::Io(source) => LatencyFilesError::Io { path: stage.path.clone(), source },
            })?;
        }
        Ok(())
    }

    /// Writes the last (partial) interval, flushes the logs, writes each stage's `.hgrm` from
    /// its cumulative histogram and the plot `PROCESS.svg` of the stages with samples. Returns
    /// the files written.
    pub fn finish<'h>(
        mut self,
        now_ns: u64,
        cumulative: impl Fn(usize) -> &'h Histogram<u64>,
    ) -> Result<Vec<PathBuf>, LatencyFilesError> {
        if now_ns > self.last_boundary_ns {
            self.write_interval(now_ns, &cumulative)?;
        }
        let mut written = Vec::new();
        let mut series = Vec::new();
        for (index, stage) in self.stages.iter_mut().enumerate() {
            stage.log.flush().map_err(|source| LatencyFilesError::Io { path: stage.path.clone(), source })?;
            written.push(stage.path.clone());
            let histogram = cumulative(index);
            let path = self.directory.join(format!("{}.hgrm", stage.stage.name));
            let comments = [
                format!("[primm {}: {} ({})]", self.process, stage.stage.name, stage.stage.description),
                unit_comment(),
            ];
            let file =
                File::create(&path).map_err(|source| LatencyFilesError::Io { path: path.clone(), source })?;
            let mut writer = BufWriter::new(file);
            write_percentile_distribution(&mut writer, histogram, &comments)
                .and_then(|()| writer.flush())
                .map_err(|source| LatencyFilesError::Io { path: path.clone(), source })?;
            written.push(path);
            if !histogram.is_empty() {
                series.push(PlotSeries { label: stage.stage.name.clone(), histogram: histogram.clone() });
            }
        }
        if !series.is_empty() {
            let path = self.directory.join(format!("{}.svg", self.process));
            latency_plot::plot_by_percentile(
                &path,
                &format!("primm {} latency by percentile", self.process),
                &series,
            )?;
            written.push(path);
        }
        Ok(written)
    }
}

/// Why an interval log could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ReadLogError {
    /// The file could not be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// A line is neither a comment, the legend, a time line nor an interval.
    #[error("{path}: not an HdrHistogram interval log (unreadable at byte {offset})")]
    Parse {
        /// The file.
        path: PathBuf,
        /// Where reading stopped.
        offset: usize,
    },
    /// An interval's histogram is not valid base64 or not a V2 histogram.
    #[error("{path}: interval {interval} holds no readable histogram: {message}")]
    Histogram {
        /// The file.
        path: PathBuf,
        /// The interval (from 1).
        interval: usize,
        /// What the decoder reported.
        message: String,
    },
    /// The intervals' histograms cannot be added (their value ranges do not fit together).
    #[error("{path}: the histogram of interval {interval} does not fit the others")]
    Add {
        /// The file.
        path: PathBuf,
        /// The interval (from 1).
        interval: usize,
    },
    /// The log holds no interval.
    #[error("{0}: the log holds no interval")]
    Empty(PathBuf),
}

/// Reads an interval log and returns the sum of its intervals (values as recorded).
pub fn read_interval_log(path: &Path) -> Result<Histogram<u64>, ReadLogError> {
    use base64::Engine as _;
    use hdrhistogram::serialization::interval_log::{IntervalLogIterator, LogEntry, LogIteratorError};
    use hdrhistogram::serialization::Deserializer;
    let bytes = std::fs::read(path).map_err(|source| ReadLogError::Io { path: path.to_owned(), source })?;
    let mut deserializer = Deserializer::new();
    let mut total: Option<Histogram<u64>> = None;
    let mut intervals = 0;
    for entry in IntervalLogIterator::new(&bytes) {
        let interval = match entry {
            Ok(LogEntry::Interval(interval)) => interval,
            Ok(_) => continue,
            Err(LogIteratorError::ParseError { offset }) => {
                return Err(ReadLogError::Parse { path: path.to_owned(), offset })
            }
        };
        intervals += 1;
        let histogram_error =
            |message: String| ReadLogError::Histogram { path: path.to_owned(), interval: intervals, message };
        let raw = base64::engine::general_purpose::STANDARD
            .decode(interval.encoded_histogram())
            .map_err(|error| histogram_error(error.to_string()))?;
        let histogram: Histogram<u64> = deserializer
            .deserialize(&mut raw.as_slice())
            .map_err(|error| histogram_error(format!("{error:?}")))?;
        match &mut total {
            None => total = Some(histogram),
            Some(total) => total
                .add(&histogram)
                .map_err(|_| ReadLogError::Add { path: path.to_owned(), interval: intervals })?,
        }
    }
    total.ok_or_else(|| ReadLogError::Empty(path.to_owned()))
}

/// Seconds since the Unix epoch (negative before it).
fn seconds_since_epoch(time: SystemTime) -> f64 {
    match time.duration_since(UNIX_EPOCH) {
        Ok(after) => after.as_secs_f64(),
        Err(before) => -before.duration().as_secs_f64(),
    }
}

/// `time` as `YYYY-MM-DD HH:MM:SS UTC` (civil date from days since the epoch).
fn utc_text(time: SystemTime) -> String {
    let seconds = time.duration_since(UNIX_EPOCH).map(|d| d.as_secs()).unwrap_or(0);
    let (days, of_day) = (seconds / 86_400, seconds % 86_400);
    // Days to civil date (proleptic Gregorian), after Howard Hinnant's algorithm.
    let z = days as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let day_of_era = z.rem_euclid(146_097);
    let year_of_era = (day_of_era - day_of_era / 1460 + day_of_era / 36_524 - day_of_era / 146_096) / 365;
    let day_of_year = day_of_era - (365 * year_of_era + year_of_era / 4 - year_of_era / 100);
    let month_index = (5 * day_of_year + 2) / 153;
    let day = day_of_year - (153 * month_index + 2) / 5 + 1;
    let month = if month_index < 10 { month_index + 3 } else { month_index - 9 };
    let year = year_of_era + era * 400 + i64::from(month <= 2);
    let mut text = String::new();
    let _ = write!(
        text,
        "{year:04}-{month:02}-{day:02} {:02}:{:02}:{:02} UTC",
        of_day / 3600,
        of_day % 3600 / 60,
        of_day % 60
    );
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use hdrhistogram::serialization::interval_log::{IntervalLogIterator, LogEntry};
    use hdrhistogram::serialization::Deserializer;

    fn histogram() -> Histogram<u64> {
        Histogram::new_with_bounds(1, super::super::latency::MAX_TRACKABLE_NS, 3).unwrap()
    }

    #[test]
    fn the_log_has_the_reference_header_and_decodes_back_to_its_intervals() {
        let mut first = histogram();
        let mut second = histogram();
        for value in 1..=1000u64 {
            first.record(value * 1000).unwrap();
            second.record(value * 7).unwrap();
        }
        let mut bytes = Vec::new();
        let start = UNIX_EPOCH + Duration::from_secs(1_700_000_000);
        let mut log = IntervalLog::begin(&mut bytes, start, &["a comment".to_owned()]).unwrap();
        log.write_interval(&first, Duration::ZERO, Duration::from_secs(1)).unwrap();
        log.write_interval(&second, Duration::from_secs(1), Duration::from_millis(500)).unwrap();
        log.flush().unwrap();
        drop(log);
        let text = String::from_utf8(bytes.clone()).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "#a comment");
        assert_eq!(lines[1], "#[Histogram log format version 1.3]");
        assert!(
            lines[2]
                .starts_with("#[StartTime: 1700000000.000 (seconds since epoch), 2023-11-14 22:13:20 UTC]"),
            "{}",
            lines[2]
        );
        assert_eq!(lines[3], "#[BaseTime: 1700000000.000 (seconds since epoch)]");
        assert_eq!(lines[4], LOG_LEGEND);
        assert!(lines[5].starts_with("0.000,1.000,1000.447,HISTF"), "{}", lines[5]);
        assert!(lines[6].starts_with("1.000,0.500,7.003,HISTF"), "{}", lines[6]);

        let mut decoded = Vec::new();
        for entry in IntervalLogIterator::new(&bytes) {
            if let LogEntry::Interval(interval) = entry.unwrap() {
                use base64::Engine as _;
                let raw =
                    base64::engine::general_purpose::STANDARD.decode(interval.encoded_histogram()).unwrap();
                let histogram: Histogram<u64> = Deserializer::new().deserialize(&mut raw.as_slice()).unwrap();
                decoded.push(histogram);
            }
        }
        assert_eq!(decoded, vec![first, second]);
    }

    #[test]
    fn the_percentile_distribution_has_the_reference_columns_and_footer() {
        let mut histogram = histogram();
        for value in 1..=10_000u64 {
            histogram.record(value * 100).unwrap();
        }
        let mut bytes = Vec::new();
        write_percentile_distribution(&mut bytes, &histogram, &[]).unwrap();
        let text = String::from_utf8(bytes).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next().unwrap(), "       Value     Percentile TotalCount 1/(1-Percentile)");
        assert_eq!(lines.next().unwrap(), "");
        let rows: Vec<Vec<f64>> = text
            .lines()
            .skip(2)
            .filter(|line| !line.starts_with('#'))
            .map(|line| line.split_whitespace().map(|field| field.parse().unwrap()).collect())
            .collect();
        // The first row is the smallest value, the last the largest at percentile 1 with
        // every sample counted; counts and percentiles grow.
        assert_eq!(rows[0][0], 0.1);
        let last = rows.last().unwrap();
        assert_eq!(last.len(), 3);
        assert_eq!(last[1], 1.0);
        assert_eq!(last[2], 10_000.0);
        assert!(rows.windows(2).all(|pair| pair[0][1] <= pair[1][1] && pair[0][2] <= pair[1][2]));
        // The median row: value (µs) near 500, and the counts agree with the percentile.
        let median = rows.iter().find(|row| row[1] == 0.5).unwrap();
        assert!((median[0] - 500.0).abs() <= 0.5, "{median:?}");
        assert!((5000.0..=5003.0).contains(&median[2]), "{median:?}");
        assert!((median[3] - 2.0).abs() < 1e-9);
        let mean = histogram.mean() / 1000.0;
        assert!((mean - 500.05).abs() < 1.0, "{mean}");
        let footer =
            format!("#[Mean    = {mean:>12.3}, StdDeviation   = {:>12.3}]", histogram.stdev() / 1000.0);
        assert!(text.contains(&footer), "{text}");
        assert!(text.contains("#[Max     =     1000.447, Total count    =        10000]"), "{text}");
        assert!(text
            .contains(&format!("#[Buckets = {:>12}, SubBuckets     =         2048]", histogram.buckets())));
    }

    #[test]
    fn intervals_are_the_differences_of_the_cumulative_histograms_and_the_files_are_complete() {
        let directory = std::env::temp_dir().join(format!("primm-latency-files-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&directory);
        let stages = [StageDescription::new("alpha", "first"), StageDescription::new("beta", "second")];
        let mut cumulative = [histogram(), histogram()];
        let mut files =
            LatencyFiles::create(&directory, "test", &stages, &cumulative[0], Duration::from_secs(1), 0)
                .unwrap();
        cumulative[0].record(1000).unwrap();
        cumulative[1].record(2000).unwrap();
        assert!(!files.write_due(500_000_000, |i| &cumulative[i]).unwrap());
        assert!(files.write_due(1_000_000_000, |i| &cumulative[i]).unwrap());
        cumulative[0].record(3000).unwrap();
        cumulative[0].record(3000).unwrap();
        let written = files.finish(1_500_000_000, |i| &cumulative[i]).unwrap();
        for name in ["alpha.hlog", "alpha.hgrm", "beta.hlog", "beta.hgrm", "test.svg"] {
            assert!(written.contains(&directory.join(name)), "{name} in {written:?}");
        }
        let log = std::fs::read(directory.join("alpha.hlog")).unwrap();
        let mut counts = Vec::new();
        for entry in IntervalLogIterator::new(&log) {
            if let LogEntry::Interval(interval) = entry.unwrap() {
                use base64::Engine as _;
                let raw =
                    base64::engine::general_purpose::STANDARD.decode(interval.encoded_histogram()).unwrap();
                let histogram: Histogram<u64> = Deserializer::new().deserialize(&mut raw.as_slice()).unwrap();
                counts.push((interval.start_timestamp(), histogram.len(), histogram.max()));
            }
        }
        assert_eq!(counts.len(), 2);
        assert_eq!(counts[0].1, 1);
        assert_eq!(counts[1], (Duration::from_secs(1), 2, 3001));
        let text = std::fs::read_to_string(directory.join("alpha.hlog")).unwrap();
        assert!(text.contains("microseconds"), "{text}");
        let _ = std::fs::remove_dir_all(&directory);
    }

    #[test]
    fn a_log_reads_back_as_the_sum_of_its_intervals_and_a_foreign_file_is_refused() {
        let path = std::env::temp_dir().join(format!("primm-read-log-{}.hlog", std::process::id()));
        let mut first = histogram();
        let mut second = histogram();
        first.record(5_000).unwrap();
        second.record(70_000).unwrap();
        second.record(70_000).unwrap();
        let mut log = IntervalLog::begin(File::create(&path).unwrap(), SystemTime::now(), &[]).unwrap();
        log.write_interval(&first, Duration::ZERO, Duration::from_secs(1)).unwrap();
        log.write_interval(&second, Duration::from_secs(1), Duration::from_secs(1)).unwrap();
        log.flush().unwrap();
        drop(log);
        let total = read_interval_log(&path).unwrap();
        assert_eq!(total.len(), 3);
        assert_eq!(total.count_at(70_000), 2);
        std::fs::write(&path, "not a log\n").unwrap();
        assert!(matches!(read_interval_log(&path), Err(ReadLogError::Parse { .. })));
        std::fs::write(&path, "#[Histogram log format version 1.3]\n").unwrap();
        assert!(matches!(read_interval_log(&path), Err(ReadLogError::Empty(_))));
        std::fs::write(&path, "0.000,1.000,1.000,!!notbase64\n").unwrap();
        assert!(matches!(read_interval_log(&path), Err(ReadLogError::Histogram { .. })));
        let _ = std::fs::remove_file(&path);
    }

    #[test]
    fn a_stage_name_with_a_path_separator_is_refused() {
        let directory = std::env::temp_dir().join(format!("primm-latency-names-{}", std::process::id()));
        let stages = [StageDescription::new("../escape", "bad")];
        let error =
            LatencyFiles::create(&directory, "test", &stages, &histogram(), Duration::from_secs(1), 0)
                .unwrap_err();
        assert!(matches!(error, LatencyFilesError::StageName(_)), "{error}");
        let _ = std::fs::remove_dir_all(&directory);
    }
}
