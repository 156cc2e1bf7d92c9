//! SVG figures: ground-truth versus estimated trajectories per method (like the qualitative
//! figure `fig:tracking_results`) and the mean mode probabilities of PR-IMM
//! (`fig:mode_probability`).
//!
//! Figures are written with the plotters SVG backend; text is emitted as SVG `<text>` and laid
//! out by the viewer, so no font files are needed. Trajectory panels share one view of the scene
//! and keep an equal scale on both axes (one metre is as long horizontally as vertically).

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use glam::DVec2;
use plotters::coord::ranged1d::{IntoSegmentedCoord, SegmentValue};
use plotters::coord::Shift;
use plotters::prelude::*;

use super::modes::MODE_NAMES;
use super::record::{AssociationRecord, EvalError};

/// One position of a trajectory: ground-truth object id or track id, frame, position (metres).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrajectoryPoint {
    /// Ground-truth id or track id.
    pub id: u64,
    /// Frame index; orders the points of one trajectory.
    pub frame: u64,
    /// Position, metres.
    pub position: DVec2,
}

/// Estimated trajectories of one method.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TrajectoryPanel {
    /// Panel title, usually the method label.
    pub title: String,
    /// Fused posterior positions, keyed by track id.
    pub tracks: Vec<TrajectoryPoint>,
    /// Ground-truth object each track is drawn in the colour of (see [`majority_ground_truth`]);
    /// tracks without an entry are drawn in dark grey.
    pub track_to_ground_truth: BTreeMap<u64, u64>,
}

/// Size and labelling of the trajectory figure.
#[derive(Debug, Clone, PartialEq)]
pub struct TrajectoryPlotOptions {
    /// Figure title, drawn above the panels.
    pub title: Option<String>,
    /// Width of one panel, pixels.
    pub panel_width_px: u32,
    /// Height of one panel, pixels.
    pub panel_height_px: u32,
    /// Panels per row.
    pub columns: usize,
    /// Empty border around the data, metres.
    pub margin_m: f64,
    /// Horizontal axis label.
    pub x_label: String,
    /// Vertical axis label.
    pub y_label: String,
}

impl Default for TrajectoryPlotOptions {
    fn default() -> Self {
        Self {
            title: None,
            panel_width_px: 520,
            panel_height_px: 520,
            columns: 3,
            margin_m: 2.0,
            x_label: "x, longitudinal [m]".into(),
            y_label: "y, lateral [m]".into(),
        }
    }
}

/// Ground-truth trajectories of one sequence: the reference position of every labelled row.
pub fn ground_truth_points(records: &[AssociationRecord]) -> Vec<TrajectoryPoint> {
    records
        .iter()
        .filter_map(|record| {
            record.ground_truth_id.map(|id| TrajectoryPoint {
                id,
                frame: record.frame,
                position: record.reference_position(),
            })
        })
        .collect()
}

/// For every track, the ground-truth object it was matched with in most rows (ties: lowest id).
pub fn majority_ground_truth(records: &[AssociationRecord]) -> BTreeMap<u64, u64> {
    let mut votes: BTreeMap<u64, BTreeMap<u64, u64>> = BTreeMap::new();
    for record in records {
        if let (Some(gt), Some(track)) = (record.ground_truth_id, record.track_id) {
            *votes.entry(track).or_default().entry(gt).or_default() += 1;
        }
    }
    votes
        .into_iter()
        .filter_map(|(track, counts)| {
            // Iteration is in ascending gt order and `max_by_key` keeps the last maximum, so
            // reverse to prefer the lowest id on ties.
            counts.into_iter().rev().max_by_key(|&(_, count)| count).map(|(gt, _)| (track, gt))
        })
        .collect()
}

/// Draws ground truth (light, thick) under each panel's estimated trajectories (dark, thin) and
/// writes the SVG to `path`.
pub fn write_trajectory_svg(
    path: impl AsRef<Path>,
    ground_truth: &[TrajectoryPoint],
    panels: &[TrajectoryPanel],
    options: &TrajectoryPlotOptions,
) -> Result<(), EvalError> {
    let svg = trajectory_svg(ground_truth, panels, options)?;
    std::fs::write(path, svg)?;
    Ok(())
}

/// Height of the figure title strip, pixels.
const TITLE_PX: u32 = 40;
/// Height of the legend strip, pixels.
const LEGEND_PX: u32 = 44;
/// Height of a panel's caption strip, pixels.
const CAPTION_PX: u32 = 30;
/// Stroke width of ground-truth lines, pixels.
const GROUND_TRUTH_WIDTH: u32 = 7;
/// Stroke width of estimated lines, pixels.
const ESTIMATE_WIDTH: u32 = 2;
/// Radius of the marker at the start of an estimated track, pixels.
const START_MARKER_RADIUS: u32 = 5;

/// The trajectory figure as SVG text (see [`write_trajectory_svg`]).
pub fn trajectory_svg(
    ground_truth: &[TrajectoryPoint],
    panels: &[TrajectoryPanel],
    options: &TrajectoryPlotOptions,
) -> Result<String, EvalError> {
    if panels.is_empty() {
        return Err(EvalError::Plot("at least one panel is required".into()));
    }
    if options.columns == 0 || options.panel_width_px < 200 || options.panel_height_px < 200 {
        return Err(EvalError::Plot("columns must be positive and panels at least 200 x 200 pixels".into()));
    }
    let columns = options.columns.min(panels.len());
    let rows = panels.len().div_ceil(columns);
    let title_px = if options.title.is_some() { TITLE_PX } else { 0 };
    let width = options.panel_width_px * columns as u32;
    let height = title_px + options.panel_height_px * rows as u32 + LEGEND_PX;

    let all_points = ground_truth.iter().chain(panels.iter().flat_map(|panel| &panel.tracks));
    let bounds = Bounds::of(all_points.map(|point| point.position))
        .ok_or_else(|| EvalError::Plot("no positions to draw".into()))?
        .padded(options.margin_m.max(0.0));

    let gt_ids: Vec<u64> = {
        let mut ids: Vec<u64> = ground_truth.iter().map(|point| point.id).collect();
        ids.sort_unstable();
        ids.dedup();
        ids
    };
    let colour_index: HashMap<u64, usize> =
        gt_ids.iter().enumerate().map(|(index, &id)| (id, index)).collect();
    let gt_lines = group_lines(ground_truth);

    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error)?;
        let (title_area, rest) = root.split_vertically(title_px);
        if let Some(title) = &options.title {
            draw_centred_text(&title_area, title, 24)?;
        }
        let (grid, legend_area) = rest.split_vertically(options.panel_height_px * rows as u32);
        let cells = grid.split_evenly((rows, columns));
        for (panel, cell) in panels.iter().zip(&cells) {
            let (caption, chart_area) = cell.split_vertically(CAPTION_PX);
            draw_centred_text(&caption, &panel.title, 20)?;
            let (view, (plot_w, plot_h)) =
                draw_trajectory_panel(&chart_area, &bounds, &gt_lines, &colour_index, panel, options)?;
            debug_assert!(
                ((view.max.x - view.min.x) / f64::from(plot_w)
                    - (view.max.y - view.min.y) / f64::from(plot_h))
                .abs()
                    < 1e-9 * (view.max - view.min).max_element().max(1.0)
            );
        }
        draw_trajectory_legend(&legend_area)?;
        root.present().map_err(plot_error)?;
    }
    Ok(svg)
}

/// Axis-aligned bounds of positions, metres.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Bounds {
    min: DVec2,
    max: DVec2,
}

impl Bounds {
    fn of(points: impl Iterator<Item = DVec2>) -> Option<Self> {
        let mut bounds: Option<Bounds> = None;
        for point in points.filter(|p| p.is_finite()) {
            bounds = Some(match bounds {
                None => Bounds { min: point, max: point },
                Some(b) => Bounds { min: b.min.min(point), max: b.max.max(point) },
            });
        }
        bounds
    }

    fn padded(self, margin: f64) -> Self {
        // At least one metre of extent so that a single point still gives a usable view.
        let centre = 0.5 * (self.min + self.max);
        let half = (0.5 * (self.max - self.min)).max(DVec2::splat(0.5)) + DVec2::splat(margin);
        Bounds { min: centre - half, max: centre + half }
    }

    /// Grows the shorter side so that metres per pixel agree on both axes of a
    /// `width_px` × `height_px` plotting area.
    fn with_equal_aspect(self, width_px: u32, height_px: u32) -> Self {
        let extent = self.max - self.min;
        let metres_per_px =
            (extent.x / f64::from(width_px.max(1))).max(extent.y / f64::from(height_px.max(1)));
        let half = 0.5
            * DVec2::new(
                metres_per_px * f64::from(width_px.max(1)),
                metres_per_px * f64::from(height_px.max(1)),
            );
        let centre = 0.5 * (self.min + self.max);
        Bounds { min: centre - half, max: centre + half }
    }
}

/// Points grouped into polylines by id and ordered by frame.
fn group_lines(points: &[TrajectoryPoint]) -> BTreeMap<u64, Vec<(f64, f64)>> {
    let mut by_id: BTreeMap<u64, Vec<(u64, DVec2)>> = BTreeMap::new();
    for point in points.iter().filter(|point| point.position.is_finite()) {
        by_id.entry(point.id).or_default().push((point.frame, point.position));
    }
    by_id
        .into_iter()
        .map(|(id, mut line)| {
            line.sort_by_key(|(frame, _)| *frame);
            (id, line.into_iter().map(|(_, p)| (p.x, p.y)).collect())
        })
        .collect()
}

/// Ten well-separated hues (the Tableau 10 palette).
const PALETTE: [(u8, u8, u8); 10] = [
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
];

fn blend(colour: (u8, u8, u8), towards: (u8, u8, u8), amount: f64) -> RGBColor {
    let mix = |a: u8, b: u8| (f64::from(a) + (f64::from(b) - f64::from(a)) * amount).round() as u8;
    RGBColor(mix(colour.0, towards.0), mix(colour.1, towards.1), mix(colour.2, towards.2))
}

fn light(index: usize) -> RGBColor {
    blend(PALETTE[index % PALETTE.len()], (255, 255, 255), 0.6)
}

fn dark(index: usize) -> RGBColor {
    blend(PALETTE[index % PALETTE.len()], (0, 0, 0), 0.35)
}

const UNMATCHED_TRACK: RGBColor = RGBColor(60, 60, 60);

fn plot_error(error: impl std::fmt::Display) -> EvalError {
    EvalError::Plot(error.to_string())
}

fn draw_centred_text(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    text: &str,
    size: u32,
) -> Result<(), EvalError> {
    let (width, height) = area.dim_in_pixel();
    let style = TextStyle::from(("sans-serif", size).into_font()).color(&BLACK).pos(
        plotters::style::text_anchor::Pos::new(
            plotters::style::text_anchor::HPos::Center,
            plotters::style::text_anchor::VPos::Center,
        ),
    );
    area.draw(&Text::new(text.to_string(), (width as i32 / 2, height as i32 / 2), style)).map_err(plot_error)
}

/// Label-area sizes and margin of a trajectory chart, pixels.
const CHART_MARGIN: u32 = 12;
const X_LABEL_AREA: u32 = 42;
const Y_LABEL_AREA: u32 = 58;

fn draw_trajectory_panel(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    bounds: &Bounds,
    gt_lines: &BTreeMap<u64, Vec<(f64, f64)>>,
    colour_index: &HashMap<u64, usize>,
    panel: &TrajectoryPanel,
    options: &TrajectoryPlotOptions,
) -> Result<(Bounds, (u32, u32)), EvalError> {
    // Measure the plotting area first, then choose ranges with equal metres per pixel.
    let (plot_w, plot_h) = {
        let probe = chart_builder(area).build_cartesian_2d(0.0..1.0, 0.0..1.0).map_err(plot_error)?;
        probe.plotting_area().dim_in_pixel()
    };
    let view = bounds.with_equal_aspect(plot_w, plot_h);
    let mut chart = chart_builder(area)
        .build_cartesian_2d(view.min.x..view.max.x, view.min.y..view.max.y)
        .map_err(plot_error)?;
    // Whole metres on the ticks unless the view is only a few metres wide.
    let decimals = if (view.max - view.min).min_element() >= 8.0 { 0 } else { 1 };
    let tick = |value: &f64| format!("{value:.decimals$}");
    chart
        .configure_mesh()
        .x_desc(options.x_label.as_str())
        .y_desc(options.y_label.as_str())
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .max_light_lines(1)
        .label_style(("sans-serif", 13))
        .axis_desc_style(("sans-serif", 15))
        .light_line_style(RGBColor(235, 235, 235))
        .bold_line_style(RGBColor(210, 210, 210))
        .draw()
        .map_err(plot_error)?;

    for (id, line) in gt_lines {
        let colour = light(colour_index.get(id).copied().unwrap_or(0));
        let style = ShapeStyle::from(&colour).stroke_width(GROUND_TRUTH_WIDTH);
        draw_polyline(&mut chart, line, style, GROUND_TRUTH_WIDTH)?;
    }
    for (track, line) in group_lines(&panel.tracks) {
        let colour = panel
            .track_to_ground_truth
            .get(&track)
            .and_then(|gt| colour_index.get(gt))
            .map(|&index| dark(index))
            .unwrap_or(UNMATCHED_TRACK);
        let style = ShapeStyle::from(&colour).stroke_width(ESTIMATE_WIDTH);
        draw_polyline(&mut chart, &line, style, ESTIMATE_WIDTH + 1)?;
        // A hollow marker where the track starts makes fragmentation and switches visible.
        if line.len() > 1 {
            chart
                .draw_series(std::iter::once(Circle::new(line[0], START_MARKER_RADIUS, style)))
                .map_err(plot_error)?;
        }
    }
    Ok((view, chart.plotting_area().dim_in_pixel()))
}

type TrajectoryChart<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

fn chart_builder<'a, 'b>(
    area: &'a DrawingArea<SVGBackend<'b>, Shift>,
) -> ChartBuilder<'a, 'b, SVGBackend<'b>> {
    let mut builder = ChartBuilder::on(area);
    builder.margin(CHART_MARGIN).x_label_area_size(X_LABEL_AREA).y_label_area_size(Y_LABEL_AREA);
    builder
}

/// A line through the points, or a dot of `dot_radius` for a single point.
fn draw_polyline(
    chart: &mut TrajectoryChart<'_, '_>,
    line: &[(f64, f64)],
    style: ShapeStyle,
    dot_radius: u32,
) -> Result<(), EvalError> {
    match line {
        [] => Ok(()),
        [point] => chart
            .draw_series(std::iter::once(Circle::new(*point, dot_radius, style.filled())))
            .map(|_| ())
            .map_err(plot_error),
        _ => chart.draw_series(LineSeries::new(line.iter().copied(), style)).map(|_| ()).map_err(plot_error),
    }
}

fn draw_trajectory_legend(area: &DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), EvalError> {
    let (width, height) = area.dim_in_pixel();
    let y = height as i32 / 2;
    let left = width as i32 / 2 - 330;
    let text_style = TextStyle::from(("sans-serif", 16).into_font()).color(&BLACK).pos(
        plotters::style::text_anchor::Pos::new(
            plotters::style::text_anchor::HPos::Left,
            plotters::style::text_anchor::VPos::Center,
        ),
    );
    let lines = [
        (left, light(0), GROUND_TRUTH_WIDTH, "ground truth"),
        (left + 230, dark(0), ESTIMATE_WIDTH, "estimated track"),
    ];
    for (x, colour, stroke, label) in lines {
        area.draw(&PathElement::new(
            vec![(x, y), (x + 50, y)],
            ShapeStyle::from(&colour).stroke_width(stroke),
        ))
        .map_err(plot_error)?;
        area.draw(&Text::new(label.to_string(), (x + 60, y), text_style.clone())).map_err(plot_error)?;
    }
    let x = left + 480;
    area.draw(&Circle::new(
        (x + 25, y),
        START_MARKER_RADIUS,
        ShapeStyle::from(&dark(0)).stroke_width(ESTIMATE_WIDTH),
    ))
    .map_err(plot_error)?;
    area.draw(&Text::new("track start".to_string(), (x + 40, y), text_style)).map_err(plot_error)?;
    Ok(())
}

/// Bar chart of mean mode probabilities in PR, CV, CA, CT order, written to `path`.
pub fn write_mode_probability_svg(
    path: impl AsRef<Path>,
    means: [f64; 4],
    samples: u64,
) -> Result<(), EvalError> {
    let svg = mode_probability_svg(means, samples)?;
    std::fs::write(path, svg)?;
    Ok(())
}

/// The mode-probability bar chart as SVG text.
pub fn mode_probability_svg(means: [f64; 4], samples: u64) -> Result<String, EvalError> {
    if means.iter().any(|p| !p.is_finite() || *p < 0.0 || *p > 1.0 + 1e-9) {
        return Err(EvalError::Plot(format!("mode probabilities must lie in [0, 1], got {means:?}")));
    }
    let top = (means.iter().copied().fold(0.0, f64::max) * 1.25).clamp(0.1, 1.0);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (640, 440)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error)?;
        let title =
            format!("Mean mode probability of PR-IMM ({} updates)", super::report::group_thousands(samples));
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(50)
            .y_label_area_size(70)
            .build_cartesian_2d((0u32..3u32).into_segmented(), 0.0..top)
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_desc("IMM mode")
            .y_desc("mean posterior probability")
            .x_label_formatter(&|value| match value {
                SegmentValue::CenterOf(index) | SegmentValue::Exact(index) => {
                    MODE_NAMES.get(*index as usize).copied().unwrap_or("").to_string()
                }
                SegmentValue::Last => String::new(),
            })
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 16))
            .max_light_lines(1)
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(plot_error)?;
        for (index, &mean) in means.iter().enumerate() {
            let index = index as u32;
            let colour = blend(PALETTE[index as usize], (0, 0, 0), 0.1);
            let mut bar = Rectangle::new(
                [(SegmentValue::Exact(index), 0.0), (SegmentValue::Exact(index + 1), mean)],
                colour.filled(),
            );
            bar.set_margin(0, 0, 18, 18);
            chart.draw_series(std::iter::once(bar)).map_err(plot_error)?;
            let label_style = TextStyle::from(("sans-serif", 16).into_font()).color(&BLACK).pos(
                plotters::style::text_anchor::Pos::new(
                    plotters::style::text_anchor::HPos::Center,
                    plotters::style::text_anchor::VPos::Bottom,
                ),
            );
            chart
                .draw_series(std::iter::once(Text::new(
                    format!("{mean:.3}"),
                    (SegmentValue::CenterOf(index), mean + top * 0.015),
                    label_style,
                )))
                .map_err(plot_error)?;
        }
        root.present().map_err(plot_error)?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::record::test_support::identity_row;

    #[test]
    fn majority_vote_prefers_most_rows_then_lowest_id() {
        // Track 7: gt 1 twice, gt 2 once → 1. Track 8: gt 3 once, gt 2 once → tie → 2.
        let records = vec![
            identity_row(0, Some(1), Some(7)),
            identity_row(1, Some(1), Some(7)),
            identity_row(2, Some(2), Some(7)),
            identity_row(0, Some(3), Some(8)),
            identity_row(1, Some(2), Some(8)),
            identity_row(2, None, Some(9)),
        ];
        let majority = majority_ground_truth(&records);
        assert_eq!(majority, BTreeMap::from([(7, 1), (8, 2)]));
    }

    #[test]
    fn equal_aspect_bounds() {
        // 10 m × 2 m of data on a 400 × 200 px area: 10 m / 400 px = 0.025 m/px dominates,
        // so y grows to 0.025 · 200 = 5 m around its centre.
        let bounds = Bounds { min: DVec2::new(0.0, 0.0), max: DVec2::new(10.0, 2.0) };
        let view = bounds.with_equal_aspect(400, 200);
        assert!((view.max.x - view.min.x - 10.0).abs() < 1e-12);
        assert!((view.max.y - view.min.y - 5.0).abs() < 1e-12);
        assert!((0.5 * (view.min.y + view.max.y) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn drawn_panel_has_equal_metres_per_pixel() {
        // Render one panel of a wide scene onto a non-square area and check the final chart.
        let ground_truth: Vec<TrajectoryPoint> = (0..20)
            .map(|k| TrajectoryPoint { id: 1, frame: k, position: DVec2::new(k as f64 * 3.0, 1.0) })
            .collect();
        let panel = TrajectoryPanel { title: "CV".into(), ..TrajectoryPanel::default() };
        let bounds = Bounds::of(ground_truth.iter().map(|p| p.position)).unwrap().padded(2.0);
        let mut svg = String::new();
        let root = SVGBackend::with_string(&mut svg, (700, 300)).into_drawing_area();
        let colours = HashMap::from([(1, 0)]);
        let (view, (w, h)) = draw_trajectory_panel(
            &root,
            &bounds,
            &group_lines(&ground_truth),
            &colours,
            &panel,
            &TrajectoryPlotOptions::default(),
        )
        .unwrap();
        let x_scale = (view.max.x - view.min.x) / f64::from(w);
        let y_scale = (view.max.y - view.min.y) / f64::from(h);
        assert!((x_scale - y_scale).abs() < 1e-12, "{x_scale} vs {y_scale}");
        // The data (61 m wide) still fits horizontally.
        assert!(view.min.x <= -2.0 + 1e-9 && view.max.x >= 59.0 - 1e-9);
    }

    #[test]
    fn rejects_bad_input() {
        let options = TrajectoryPlotOptions::default();
        assert!(trajectory_svg(&[], &[], &options).is_err());
        let empty_panel = TrajectoryPanel { title: "CV".into(), ..TrajectoryPanel::default() };
        assert!(trajectory_svg(&[], &[empty_panel], &options).is_err());
        assert!(mode_probability_svg([0.5, 0.5, 1.5, 0.0], 1).is_err());
        assert!(mode_probability_svg([0.5, f64::NAN, 0.0, 0.0], 1).is_err());
    }
}
