//! Latency-by-percentile plots (SVG), as HdrHistogram's plotter draws them: the x axis is
//! 1/(1−p) on a log scale, labelled 0 %, 90 %, 99 %, 99.9 %, 99.99 %, so that every "nine" of
//! the tail gets the same width; the y axis is the latency in microseconds. One line per
//! histogram (a stage of one run, or the same stage of several runs).

use hdrhistogram::Histogram;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// The highest percentile plotted is 1 − 10^−`PLOT_NINES` (99.99 %).
pub const PLOT_NINES: u32 = 4;

/// Points per decade of 1/(1−p).
const POINTS_PER_DECADE: u32 = 100;

/// One line of a plot.
#[derive(Debug, Clone)]
pub struct PlotSeries {
    /// Legend entry.
    pub label: String,
    /// Latencies, ns.
    pub histogram: Histogram<u64>,
}

/// The latency axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LatencyAxis {
    /// Logarithmic (default: stages that differ by decades stay readable).
    #[default]
    Logarithmic,
    /// Linear from zero (the reference plotter's choice; differences in the tail stand out).
    Linear,
}

/// Why a plot could not be drawn.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// There is nothing to plot.
    #[error("no latency samples to plot into {0}")]
    Empty(PathBuf),
    /// Drawing or writing the SVG failed.
    #[error("cannot draw {path}: {message}")]
    Draw {
        /// The SVG file.
        path: PathBuf,
        /// What the drawing backend reported.
        message: String,
    },
}

/// The label of a tick at x = log10(1/(1−p)): 0 %, 90 %, 99 %, 99.9 %, 99.99 %.
pub fn percentile_tick_label(nines: f64) -> String {
    let rounded = nines.round();
    if (nines - rounded).abs() > 1e-6 || rounded < 0.0 {
        return String::new();
    }
    match rounded as u32 {
        0 => "0%".to_owned(),
        1 => "90%".to_owned(),
        n => format!("99.{}%", "9".repeat(n as usize - 2)).replace("99.%", "99%"),
    }
}

/// The points of `histogram`'s line: (log10(1/(1−p)), latency µs) from p = 0 to 99.99 %.
pub fn percentile_points(histogram: &Histogram<u64>) -> Vec<(f64, f64)> {
    let steps = PLOT_NINES * POINTS_PER_DECADE;
    (0..=steps)
        .map(|step| {
            let nines = f64::from(step) / f64::from(POINTS_PER_DECADE);
            let quantile = 1.0 - 10f64.powf(-nines);
            (nines, histogram.value_at_quantile(quantile) as f64 / 1000.0)
        })
        .collect()
}

/// Draws `series` into the SVG file `path` with a logarithmic latency axis.
pub fn plot_by_percentile(path: &Path, title: &str, series: &[PlotSeries]) -> Result<(), PlotError> {
    plot_by_percentile_with(path, title, series, LatencyAxis::Logarithmic)
}

/// Draws `series` into the SVG file `path`.
pub fn plot_by_percentile_with(
    path: &Path,
    title: &str,
    series: &[PlotSeries],
    axis: LatencyAxis,
) -> Result<(), PlotError> {
    let lines: Vec<(&str, Vec<(f64, f64)>)> = series
        .iter()
        .filter(|line| !line.histogram.is_empty())
        .map(|line| (line.label.as_str(), percentile_points(&line.histogram)))
        .collect();
    if lines.is_empty() {
        return Err(PlotError::Empty(path.to_owned()));
    }
    let draw_error =
        |error: &dyn std::fmt::Display| PlotError::Draw { path: path.to_owned(), message: error.to_string() };
    let highest = lines.iter().flat_map(|(_, points)| points.iter().map(|p| p.1)).fold(0.0f64, f64::max);
    let lowest =
        lines.iter().flat_map(|(_, points)| points.iter().map(|p| p.1)).fold(f64::INFINITY, f64::min);
    let root = SVGBackend::new(path, (900, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| draw_error(&e))?;
    let x_range = 0.0f64..f64::from(PLOT_NINES);
    let colours: Vec<RGBColor> = (0..lines.len()).map(colour).collect();
    let mut builder = ChartBuilder::on(&root);
    builder.caption(title, ("sans-serif", 20)).margin(16).x_label_area_size(44).y_label_area_size(70);
    macro_rules! draw {
        ($chart:expr) => {{
            let mut chart = $chart;
            chart
                .configure_mesh()
                .x_labels(PLOT_NINES as usize + 1)
                .x_label_formatter(&|v| percentile_tick_label(*v))
                .y_label_formatter(&|v| format_microseconds(*v))
                .x_desc("percentile (axis: 1/(1-p), log)")
                .y_desc(match axis {
                    LatencyAxis::Logarithmic => "latency, µs (log)",
                    LatencyAxis::Linear => "latency, µs",
                })
                .draw()
                .map_err(|e| draw_error(&e))?;
            for ((label, points), colour) in lines.iter().zip(&colours) {
                let style = colour.stroke_width(2);
                chart
                    .draw_series(LineSeries::new(points.iter().copied(), style))
                    .map_err(|e| draw_error(&e))?
                    .label(*label)
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], style));
            }
            chart
                .configure_series_labels()
                // The tail's low latencies: the corner lines rarely reach.
                .position(SeriesLabelPosition::LowerRight)
                .border_style(BLACK)
                .background_style(WHITE.mix(0.85))
                .draw()
                .map_err(|e| draw_error(&e))?;
        }};
    }
    match axis {
        LatencyAxis::Logarithmic => {
            let bottom = (lowest * 0.8).max(0.01);
            let top = (highest * 1.25).max(bottom * 10.0);
            draw!(builder
                .build_cartesian_2d(x_range, (bottom..top).log_scale())
                .map_err(|e| draw_error(&e))?)
        }
        LatencyAxis::Linear => {
            draw!(builder
                .build_cartesian_2d(x_range, 0.0..(highest * 1.1).max(1.0))
                .map_err(|e| draw_error(&e))?)
        }
    }
    root.present().map_err(|e| draw_error(&e))?;
    Ok(())
}

/// A tick label for a latency in µs.
fn format_microseconds(value: f64) -> String {
    if value >= 10.0 || value == 0.0 {
        format!("{value:.0}")
    } else if value >= 1.0 {
        format!("{value:.1}")
    } else {
        format!("{value:.2}")
    }
}

/// A distinct colour for line `index`.
fn colour(index: usize) -> RGBColor {
    const COLOURS: [RGBColor; 10] = [
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
        RGBColor(255, 127, 14),
        RGBColor(148, 103, 189),
        RGBColor(140, 86, 75),
        RGBColor(227, 119, 194),
        RGBColor(127, 127, 127),
        RGBColor(188, 189, 34),
        RGBColor(23, 190, 207),
    ];
    COLOURS[index % COLOURS.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_labelled_as_percentiles() {
        let labels: Vec<String> = (0..=4).map(|n| percentile_tick_label(f64::from(n))).collect();
        assert_eq!(labels, ["0%", "90%", "99%", "99.9%", "99.99%"]);
        assert_eq!(percentile_tick_label(1.5), "");
    }

    #[test]
    fn the_line_climbs_through_the_tail_and_ends_at_p99_99() {
        let mut histogram = Histogram::<u64>::new_with_bounds(1, 60_000_000_000, 3).unwrap();
        for value in 1..=100_000u64 {
            histogram.record(value * 10).unwrap();
        }
        let points = percentile_points(&histogram);
        assert_eq!(points.first().unwrap().0, 0.0);
        assert_eq!(points.last().unwrap().0, 4.0);
        assert!(points.windows(2).all(|pair| pair[0].1 <= pair[1].1));
        // p90 of 10 ns .. 1 ms uniform: 900 µs; p99.99: 999.9 µs (to 3 digits).
        let at = |nines: f64| points.iter().find(|p| (p.0 - nines).abs() < 1e-9).unwrap().1;
        assert!((at(1.0) - 900.0).abs() < 1.0, "{}", at(1.0));
        assert!((at(4.0) - 999.9).abs() < 1.0, "{}", at(4.0));
    }

    #[test]
    fn a_plot_is_an_svg_with_a_legend_entry_per_line() {
        let path = std::env::temp_dir().join(format!("primm-plot-{}.svg", std::process::id()));
        let mut fast = Histogram::<u64>::new_with_bounds(1, 60_000_000_000, 3).unwrap();
        let mut slow = fast.clone();
        for value in 1..=1000u64 {
            fast.record(value * 100).unwrap();
            slow.record(value * 1000).unwrap();
        }
        let series = [
            PlotSeries { label: "fast run".into(), histogram: fast },
            PlotSeries { label: "slow run".into(), histogram: slow },
        ];
        for axis in [LatencyAxis::Logarithmic, LatencyAxis::Linear] {
            plot_by_percentile_with(&path, "test", &series, axis).unwrap();
            let svg = std::fs::read_to_string(&path).unwrap();
            assert!(svg.starts_with("<svg"), "{}", &svg[..80.min(svg.len())]);
            for text in ["fast run", "slow run", "99.99%", "90%"] {
                assert!(svg.contains(text), "{text} missing");
            }
        }
        let empty = [PlotSeries { label: "none".into(), histogram: Histogram::new(3).unwrap() }];
        assert!(matches!(plot_by_percentile(&path, "t", &empty), Err(PlotError::Empty(_))));
        let _ = std::fs::remove_file(&path);
    }
}
