//! Latency histograms of the tracking service (HdrHistogram, 3 significant digits, 1 ns to
//! 60 s), filled without allocating and summarised as [`LatencyReport`]s and a text table.

use hdrhistogram::Histogram;
use primm_core::stage_timing::{Stage, StageObserver};
use primm_wire::{LatencyReport, StageLatency, STAGE_CAPACITY};
use std::fmt::Write as _;

/// Highest latency a histogram records exactly, ns; larger values are clamped to it.
pub const MAX_TRACKABLE_NS: u64 = 60_000_000_000;

/// One histogram per [`Stage`], allocated once.
#[derive(Debug, Clone)]
pub struct LatencyHistograms {
    stages: Vec<Histogram<u64>>,
}

impl Default for LatencyHistograms {
    fn default() -> Self {
        Self::new()
    }
}

impl LatencyHistograms {
    /// Empty histograms.
    pub fn new() -> Self {
        let stages = Stage::ALL
            .iter()
            .map(|_| Histogram::new_with_bounds(1, MAX_TRACKABLE_NS, 3).expect("valid histogram bounds"))
            .collect();
        Self { stages }
    }

    /// Records one latency (clamped into the trackable range; never allocates).
    #[inline]
    pub fn record(&mut self, stage: Stage, latency_ns: u64) {
        self.stages[stage.index()].saturating_record(latency_ns.max(1));
    }

    /// The histogram of `stage`.
    pub fn histogram(&self, stage: Stage) -> &Histogram<u64> {
        &self.stages[stage.index()]
    }

    /// The percentiles of `stage`.
    pub fn summary(&self, stage: Stage) -> StageLatency {
        summarise(stage.name(), self.histogram(stage))
    }

    /// Writes every stage's percentiles into `report.stages` (allocation-free).
    pub fn fill_report(&self, report: &mut LatencyReport) {
        for stage in Stage::ALL {
            report.stages[stage.index()] = self.summary(stage);
        }
        for slot in &mut report.stages[Stage::COUNT..STAGE_CAPACITY] {
            *slot = StageLatency::named("");
        }
        report.stage_count = Stage::COUNT as u32;
    }

    /// A text table of every stage with samples.
    pub fn table(&self) -> String {
        let rows: Vec<StageLatency> = Stage::ALL.iter().map(|&stage| self.summary(stage)).collect();
        format_table(&rows)
    }
}

/// The percentiles of a histogram under `name`.
///
/// One pass over the recorded values gives the four quantiles and the mean (the same values as
/// `Histogram::value_at_quantile` and `Histogram::mean`, which would scan the whole histogram
/// five times): the service computes this for every stage on the tracking thread each time it
/// publishes a latency report.
pub fn summarise(name: &str, histogram: &Histogram<u64>) -> StageLatency {
    const QUANTILES: [f64; 4] = [0.5, 0.9, 0.99, 0.999];
    let mut entry = StageLatency::named(name);
    entry.count = histogram.len();
    if entry.count == 0 {
        return entry;
    }
    let total = entry.count;
    // The rank of each quantile as `value_at_quantile` computes it.
    let ranks = QUANTILES.map(|q| ((q * total as f64).ceil() as u64).max(1));
    let mut values = [0u64; 4];
    let mut next = 0;
    let mut cumulative = 0u64;
    let mut mean = 0.0f64;
    for value in histogram.iter_recorded() {
        let count = value.count_at_value();
        cumulative += count;
        mean += histogram.median_equivalent(value.value_iterated_to()) as f64 * count as f64 / total as f64;
        while next < ranks.len() && cumulative >= ranks[next] {
            values[next] = histogram.highest_equivalent(value.value_iterated_to());
            next += 1;
        }
    }
    [entry.p50_ns, entry.p90_ns, entry.p99_ns, entry.p999_ns] = values;
    entry.max_ns = histogram.max();
    entry.mean_ns = mean.round() as u64;
    entry
}

/// A fixed-width table (µs) of stage percentiles; stages without samples are left out.
pub fn format_table(rows: &[StageLatency]) -> String {
    format_named_table(rows.iter().map(|row| (row.name_str(), row)))
}

/// [`format_table`] with each row's name given beside it (for names longer than a
/// [`StageLatency`] holds).
pub fn format_named_table<'a>(rows: impl IntoIterator<Item = (&'a str, &'a StageLatency)>) -> String {
    let rows: Vec<(&str, &StageLatency)> = rows.into_iter().filter(|(_, row)| row.count > 0).collect();
    let width = rows.iter().map(|(name, _)| name.chars().count()).max().unwrap_or(0).max(24);
    let us = |ns: u64| ns as f64 / 1000.0;
    let mut table = String::new();
    let _ = writeln!(
        table,
        "{:<width$} {:>9} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10}",
        "stage", "count", "p50 µs", "p90 µs", "p99 µs", "p99.9 µs", "max µs", "mean µs"
    );
    for (name, row) in rows {
        let _ = writeln!(
            table,
            "{:<width$} {:>9} {:>10.1} {:>10.1} {:>10.1} {:>10.1} {:>10.1} {:>10.1}",
            name,
            row.count,
            us(row.p50_ns),
            us(row.p90_ns),
            us(row.p99_ns),
            us(row.p999_ns),
            us(row.max_ns),
            us(row.mean_ns)
        );
    }
    table
}

/// Times the tracker's stages with [`monotonic_ns`](super::clock::monotonic_ns): each
/// stage's latency is the time since the previous stage ended (or since `start_ns`).
#[derive(Debug)]
pub struct StageTimer<'a> {
    histograms: &'a mut LatencyHistograms,
    last_ns: u64,
}

impl<'a> StageTimer<'a> {
    /// A timer whose first stage starts at `start_ns`.
    pub fn new(histograms: &'a mut LatencyHistograms, start_ns: u64) -> Self {
        Self { histograms, last_ns: start_ns }
    }

    /// When the last stage ended (or the start time), ns.
    pub fn last_ns(&self) -> u64 {
        self.last_ns
    }
}

impl StageObserver for StageTimer<'_> {
    #[inline]
    fn stage_finished(&mut self, stage: Stage) {
        let now = super::clock::monotonic_ns();
        self.histograms.record(stage, now.saturating_sub(self.last_ns));
        self.last_ns = now;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_of_known_samples() {
        let mut histograms = LatencyHistograms::new();
        for value in 1..=1000u64 {
            histograms.record(Stage::Associate, value * 1000);
        }
        let summary = histograms.summary(Stage::Associate);
        assert_eq!(summary.name_str(), "associate");
        assert_eq!(summary.count, 1000);
        // 3 significant digits: within 0.1 %.
        assert!((summary.p50_ns as f64 - 500_000.0).abs() <= 500.0, "{}", summary.p50_ns);
        assert!((summary.p99_ns as f64 - 990_000.0).abs() <= 990.0, "{}", summary.p99_ns);
        assert!((summary.max_ns as f64 - 1_000_000.0).abs() <= 1000.0, "{}", summary.max_ns);
        assert_eq!(histograms.summary(Stage::Validate).count, 0);
    }

    #[test]
    fn values_beyond_the_range_are_clamped_not_lost() {
        let mut histograms = LatencyHistograms::new();
        histograms.record(Stage::EndToEnd, u64::MAX);
        histograms.record(Stage::EndToEnd, 0);
        let summary = histograms.summary(Stage::EndToEnd);
        assert_eq!(summary.count, 2);
        assert!(summary.max_ns >= MAX_TRACKABLE_NS);
    }

    #[test]
    fn the_table_lists_only_stages_with_samples() {
        let mut histograms = LatencyHistograms::new();
        histograms.record(Stage::Update, 2_500);
        let table = histograms.table();
        assert!(table.contains("update"), "{table}");
        assert!(!table.contains("validate"), "{table}");
        assert!(table.contains("2.5"), "{table}");
    }

    #[test]
    fn the_one_pass_summary_equals_hdrhistogram_s_own_quantiles_and_mean() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for case in 0..50 {
            let mut histogram = Histogram::<u64>::new_with_bounds(1, MAX_TRACKABLE_NS, 3).unwrap();
            for _ in 0..(1 + case * 40) {
                let magnitude = rng.random_range(0..7);
                histogram.record(rng.random_range(1..10u64.pow(magnitude + 2))).unwrap();
            }
            let entry = summarise("stage", &histogram);
            assert_eq!(entry.count, histogram.len());
            assert_eq!(entry.p50_ns, histogram.value_at_quantile(0.5), "case {case}");
            assert_eq!(entry.p90_ns, histogram.value_at_quantile(0.9), "case {case}");
            assert_eq!(entry.p99_ns, histogram.value_at_quantile(0.99), "case {case}");
            assert_eq!(entry.p999_ns, histogram.value_at_quantile(0.999), "case {case}");
            assert_eq!(entry.max_ns, histogram.max());
            assert!((entry.mean_ns as f64 - histogram.mean()).abs() <= 1.0, "case {case}");
        }
    }
}
