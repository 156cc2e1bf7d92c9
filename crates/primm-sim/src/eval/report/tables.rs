//! The report's tables as aligned text: the best value of each comparison marked with `*`,
//! a method without results printed as `n/a`.

use super::*;

impl EvaluationReport {
    /// Table II: one-step prior RMSE per method.
    pub fn table_prior_rmse(&self) -> String {
        let metrics: [(&str, RmseMetric); 3] = [
            ("RMSE_x [m]", RmseAccumulator::rmse_x),
            ("RMSE_y [m]", RmseAccumulator::rmse_y),
            ("RMSE_xy [m]", RmseAccumulator::rmse_xy),
        ];
        let mut header = vec!["Model".to_string()];
        header.extend(metrics.iter().map(|(name, _)| name.to_string()));
        header.push("N".into());
        let columns: Vec<Vec<Cell>> = metrics
            .iter()
            .map(|(_, metric)| {
                let values: Vec<Option<f64>> =
                    Method::ALL.iter().map(|m| self.result(*m).and_then(|r| metric(&r.rmse))).collect();
                mark_best(&values, Better::Lower, 3)
            })
            .collect();
        let rows = Method::ALL
            .iter()
            .enumerate()
            .map(|(row, method)| {
                let mut line = vec![method.row_label().to_string()];
                line.extend(columns.iter().map(|column| column[row].to_string()));
                line.push(match self.result(*method) {
                    Some(result) => group_thousands(result.rmse.count()),
                    None => "n/a".into(),
                });
                line
            })
            .collect::<Vec<_>>();
        let mut text = render_table("Table II. One-step prior prediction RMSE", &header, &rows);
        self.append_notes(&mut text, "* lowest value in its column");
        text
    }

    /// Table II by object class: RMSE_xy per class (rows) and method (columns), for the classes
    /// with rows.
    pub fn table_class_rmse(&self) -> String {
        let mut header = vec!["Class (prior samples)".to_string()];
        header.extend(Method::ALL.iter().map(|m| m.label().to_string()));
        let classes: Vec<ObjectClass> = ObjectClass::ALL
            .into_iter()
            .filter(|class| {
                Method::ALL.iter().any(|m| self.result(*m).is_some_and(|r| r.class_rmse.contains_key(class)))
            })
            .collect();
        let rows = classes
            .iter()
            .map(|class| {
                let values: Vec<Option<f64>> = Method::ALL
                    .iter()
                    .map(|m| {
                        self.result(*m).and_then(|r| r.class_rmse.get(class)).and_then(|acc| acc.rmse_xy())
                    })
                    .collect();
                let count = self.common_count(|r| r.class_rmse.get(class).map_or(0, |acc| acc.count()));
                let mut line = vec![format!("{} ({count})", class.name())];
                line.extend(mark_best(&values, Better::Lower, 3).iter().map(Cell::to_string));
                line
            })
            .collect::<Vec<_>>();
        let mut text =
            render_table("Table II by class. One-step prior prediction RMSE_xy [m]", &header, &rows);
        self.append_notes(&mut text, "* lowest value in its row");
        text
    }

    /// Table II, velocity: per method (rows) the velocity RMSE over all classes and per class
    /// (over the rows of the prior RMSE), and the speed RMSE, mean speed error and heading RMSE
    /// of confirmed tracks. Values are `n/a` where the data carry no true velocity.
    pub fn table_velocity(&self) -> String {
        let classes: Vec<ObjectClass> = ObjectClass::ALL
            .into_iter()
            .filter(|class| {
                Method::ALL
                    .iter()
                    .any(|m| self.result(*m).is_some_and(|r| r.class_velocity.contains_key(class)))
            })
            .collect();
        let mut header = vec!["Model".to_string(), "v RMSE [m/s]".to_string()];
        header.extend(classes.iter().map(|class| format!("{} [m/s]", class.name())));
        header.extend(
            ["N", "speed RMSE [m/s]", "speed bias [m/s]", "heading RMSE [deg]", "N confirmed"]
                .iter()
                .map(|s| s.to_string()),
        );
        let columns = self.velocity_columns(&classes);
        let motion_columns = self.confirmed_motion_columns();
        let rows = Method::ALL
            .iter()
            .enumerate()
            .map(|(row, method)| {
                let result = self.result(*method);
                let mut line = vec![method.row_label().to_string(), columns[0][row].to_string()];
                line.extend(columns[1..].iter().map(|column| column[row].to_string()));
                line.push(result.map_or_else(|| "n/a".into(), |r| group_thousands(r.velocity.count())));
                line.extend(motion_columns.iter().map(|column| column[row].to_string()));
                line.push(
                    result
                        .map_or_else(|| "n/a".into(), |r| group_thousands(r.confirmed_motion.speed_count())),
                );
                line
            })
            .collect::<Vec<_>>();
        let mut text = render_table(
            "Table II, velocity. Fused track velocity after the update against the true velocity",
            &header,
            &rows,
        );
        self.append_notes(
            &mut text,
            &format!(
                "* lowest value in its column; v RMSE over the rows of the prior RMSE (N); speed and \
                 heading of confirmed tracks (N confirmed; heading only where the true speed is at least \
                 {HEADING_MIN_TRUE_SPEED_MPS} m/s); speed bias = mean of estimated minus true speed"
            ),
        );
        if self.results.values().all(|r| r.velocity.count() == 0 && r.confirmed_motion.speed_count() == 0) {
            let _ = writeln!(text, "n/a: the data carry no true velocity (columns true_vx, true_vy)");
        }
        text
    }

    /// Table III: RMSE_xy per motion scenario (rows) and method (columns).
    pub fn table_scenario_rmse(&self) -> String {
        let mut header = vec!["Scenario (GT object frames)".to_string()];
        header.extend(Method::ALL.iter().map(|m| m.label().to_string()));
        let rows = MotionCategory::ALL
            .iter()
            .map(|category| {
                let values: Vec<Option<f64>> = Method::ALL
                    .iter()
                    .map(|m| self.result(*m).and_then(|r| r.scenario(*category).rmse_xy()))
                    .collect();
                let count = self.common_count(|r| r.scenario_frames(*category));
                let mut line = vec![format!("{} ({count})", category.label())];
                line.extend(mark_best(&values, Better::Lower, 3).iter().map(Cell::to_string));
                line
            })
            .collect::<Vec<_>>();
        let mut text = render_table("Table III. Scenario-wise prior prediction RMSE_xy [m]", &header, &rows);
        self.append_notes(&mut text, "* lowest value in its row");
        text
    }

    /// Table IV: overall IDSW and IDF1 per method.
    pub fn table_overall_mot(&self) -> String {
        let idsw: Vec<Option<f64>> =
            Method::ALL.iter().map(|m| self.result(*m).map(|r| r.identity.idsw as f64)).collect();
        let idf1: Vec<Option<f64>> =
            Method::ALL.iter().map(|m| self.result(*m).and_then(|r| r.identity.idf1())).collect();
        let idsw = mark_best(&idsw, Better::Lower, 0);
        let idf1 = mark_best(&idf1, Better::Higher, 4);
        let header: Vec<String> =
            ["Model", "IDSW", "IDF1", "IDTP", "IDFP", "IDFN"].iter().map(|s| s.to_string()).collect();
        let rows = Method::ALL
            .iter()
            .enumerate()
            .map(|(row, method)| {
                let mut line =
                    vec![method.row_label().to_string(), idsw[row].to_string(), idf1[row].to_string()];
                match self.result(*method) {
                    Some(r) => {
                        line.extend([r.identity.idtp, r.identity.idfp, r.identity.idfn].map(group_thousands))
                    }
                    None => line.extend(std::iter::repeat_n("n/a".to_string(), 3)),
                }
                line
            })
            .collect::<Vec<_>>();
        let count = self.common_count(|r| r.identity.gt_object_frames);
        let title =
            format!("Table IV. Overall multiple-object-tracking performance (GT object frames = {count})");
        let mut text = render_table(&title, &header, &rows);
        self.append_notes(&mut text, "* lowest IDSW / highest IDF1 in its column");
        text
    }

    /// Table V: IDSW and IDF1 per interaction or missed-detection scenario and method.
    pub fn table_scenario_mot(&self) -> String {
        let mut header = vec!["Scenario (GT object frames)".to_string(), "Metric".to_string()];
        header.extend(Method::ALL.iter().map(|m| m.label().to_string()));
        let mut rows = Vec::new();
        for (label, select) in self.identity_scenarios() {
            let counts: Vec<Option<IdentityCounts>> =
                Method::ALL.iter().map(|m| self.result(*m).and_then(&select)).collect();
            let frames = {
                let present: Vec<u64> = counts.iter().flatten().map(|c| c.gt_object_frames).collect();
                count_text(&present)
            };
            let idsw: Vec<Option<f64>> = counts.iter().map(|c| c.map(|c| c.idsw as f64)).collect();
            let idf1: Vec<Option<f64>> = counts.iter().map(|c| c.and_then(|c| c.idf1())).collect();
            rows.push(metric_row(format!("{label} ({frames})"), "IDSW", &idsw, Better::Lower, 0));
            rows.push(metric_row(String::new(), "IDF1", &idf1, Better::Higher, 4));
        }
        let mut text = render_table_aligned(
            "Table V. Scenario-wise multiple-object-tracking performance",
            &header,
            &rows,
            2,
        );
        self.append_notes(&mut text, "* lowest IDSW / highest IDF1 in its row");
        text
    }

    /// Identity, false tracks and fragmentations on confirmed tracks only, per method (rows):
    /// IDF1, IDSW, IDFP, false tracks, false tracks per minute, fragmentations, the clutter rows
    /// they took, confirmed tracks per object frame, the share born of a ghost (where the data
    /// mark ghosts) and confirmed tracks ([`super::confirmed`]).
    pub fn table_confirmed_tracks(&self) -> String {
        let counts: Vec<Option<ConfirmedTrackCounts>> =
            Method::ALL.iter().map(|m| self.result(*m).and_then(|r| r.confirmed)).collect();
        let column = |value: fn(&ConfirmedTrackCounts) -> Option<f64>, better: Better, digits: usize| {
            let values: Vec<Option<f64>> = counts.iter().map(|c| c.as_ref().and_then(value)).collect();
            mark_best(&values, better, digits)
        };
        let columns = [
            column(ConfirmedTrackCounts::idf1, Better::Higher, 4),
            column(|c| Some(c.identity.idsw as f64), Better::Lower, 0),
            column(|c| Some(c.identity.idfp as f64), Better::Lower, 0),
            column(|c| Some(c.false_tracks as f64), Better::Lower, 0),
            column(ConfirmedTrackCounts::false_tracks_per_minute, Better::Lower, 2),
            column(|c| Some(c.fragmentations as f64), Better::Lower, 0),
            column(|c| Some(c.clutter_rows_in_confirmed_tracks as f64), Better::Lower, 0),
            // One track per object frame is right; neither fewer nor more is better.
            column(ConfirmedTrackCounts::tracks_per_object_frame, Better::Lower, 2)
                .into_iter()
                .map(Cell::unmarked)
                .collect(),
            column(ConfirmedTrackCounts::ghost_born_share, Better::Lower, 3),
        ];
        let header: Vec<String> = [
            "Model",
            "IDF1",
            "IDSW",
            "IDFP",
            "False tracks",
            "False tracks/min",
            "Frag",
            "Clutter taken",
            "Tracks/object",
            "Ghost-born",
            "Tracks",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        let rows = Method::ALL
            .iter()
            .enumerate()
            .map(|(row, method)| {
                let mut line = vec![method.row_label().to_string()];
                line.extend(columns.iter().map(|column| column[row].to_string()));
                line.push(counts[row].map_or_else(|| "n/a".into(), |c| group_thousands(c.confirmed_tracks)));
                line
            })
            .collect::<Vec<_>>();
        let present: Vec<&ConfirmedTrackCounts> = counts.iter().flatten().collect();
        let gt_frames = count_text(&present.iter().map(|c| c.identity.gt_object_frames).collect::<Vec<_>>());
        let clutter = count_text(&present.iter().map(|c| c.clutter_rows).collect::<Vec<_>>());
        let minutes = match present.first() {
            Some(first) => format!("{:.1} min", first.duration_s / 60.0),
            None => "n/a".into(),
        };
        let title = format!(
            "Confirmed tracks (GT object frames = {gt_frames}, clutter rows = {clutter}, duration = {minutes})"
        );
        let mut text = render_table(&title, &header, &rows);
        self.append_notes(
            &mut text,
            "* highest IDF1 / lowest other value in its column (not Tracks/object); estimated object \
             frames are frames of confirmed tracks only",
        );
        for method in Method::ALL {
            if self.result(method).is_some_and(|r| r.confirmed.is_none()) {
                let _ = writeln!(
                    text,
                    "n/a {}: the rows do not say whether their track was confirmed",
                    method.label()
                );
            }
        }
        text
    }

    /// Mean posterior mode probabilities of PR-IMM (`fig:mode_probability`) as a small table.
    pub fn mode_probability_table(&self) -> String {
        let modes = self.result(Method::PrImm).map(|r| r.modes);
        let mean = modes.and_then(|m| m.mean());
        let samples = modes.map(|m| group_thousands(m.count())).unwrap_or_else(|| "n/a".into());
        let header: Vec<String> = ["Mode", "Mean probability", ""].iter().map(|s| s.to_string()).collect();
        let rows = MODE_NAMES
            .iter()
            .enumerate()
            .map(|(index, name)| match mean {
                Some(mean) => vec![
                    name.to_string(),
                    format!("{:.3}", mean[index]),
                    "#".repeat((mean[index] * 40.0).round().clamp(0.0, 40.0) as usize),
                ],
                None => vec![name.to_string(), "n/a".into(), String::new()],
            })
            .collect::<Vec<_>>();
        let title = format!("Mean mode probability of PR-IMM (updates = {samples})");
        let mut text = render_table(&title, &header, &rows);
        if mean.is_none() {
            let reason = match self.result(Method::PrImm) {
                Some(_) => "no row carries mode probabilities",
                None => self.unavailable_reason(Method::PrImm).unwrap_or("not evaluated"),
            };
            let _ = writeln!(text, "n/a PR-IMM: {reason}");
        }
        let by_class = self.mode_probability_by_class_table();
        if !by_class.is_empty() {
            text.push('\n');
            text.push_str(&by_class);
        }
        text
    }

    /// PR-IMM's mean posterior mode probabilities per object class (rows) and mode (columns);
    /// empty without updates. The classes' mixes differ between data sets, and the shipped
    /// configuration weighs PR per class, so this is the table to compare PR's weight across
    /// data sets with.
    pub fn mode_probability_by_class_table(&self) -> String {
        let Some(result) = self.result(Method::PrImm) else { return String::new() };
        let rows: Vec<Vec<String>> = result
            .class_modes
            .iter()
            .filter_map(|(class, acc)| {
                let mean = acc.mean()?;
                let mut row = vec![format!("{} ({})", class.name(), group_thousands(acc.count()))];
                row.extend(mean.iter().map(|p| format!("{p:.3}")));
                Some(row)
            })
            .collect();
        if rows.is_empty() {
            return String::new();
        }
        let mut header = vec!["Class (updates)".to_string()];
        header.extend(MODE_NAMES.iter().map(|name| name.to_string()));
        render_table("Mean mode probability of PR-IMM by class", &header, &rows)
    }

    /// Tables II and IV split by ego motion: RMSE_xy, IDSW and IDF1 per ego state (rows) and
    /// method (columns). Empty when no method has rows with a known ego motion.
    pub fn table_ego_motion(&self) -> String {
        let present = |motion: EgoMotion| {
            Method::ALL.iter().any(|m| self.result(*m).is_some_and(|r| r.ego_identity.contains_key(&motion)))
        };
        if !EgoMotion::ALL.into_iter().any(present) {
            return String::new();
        }
        let mut header = vec!["Ego motion (GT object frames)".to_string(), "Metric".to_string()];
        header.extend(Method::ALL.iter().map(|m| m.label().to_string()));
        let mut rows = Vec::new();
        for motion in EgoMotion::ALL.into_iter().filter(|motion| present(*motion)) {
            let results: Vec<Option<&MethodResult>> = Method::ALL.iter().map(|m| self.result(*m)).collect();
            let rmse: Vec<Option<f64>> = results
                .iter()
                .map(|r| r.and_then(|r| r.ego_rmse.get(&motion)).and_then(|acc| acc.rmse_xy()))
                .collect();
            let counts: Vec<Option<IdentityCounts>> =
                results.iter().map(|r| r.and_then(|r| r.ego_identity.get(&motion).copied())).collect();
            let frames: Vec<u64> = counts.iter().flatten().map(|c| c.gt_object_frames).collect();
            let idsw: Vec<Option<f64>> = counts.iter().map(|c| c.map(|c| c.idsw as f64)).collect();
            let idf1: Vec<Option<f64>> = counts.iter().map(|c| c.and_then(|c| c.idf1())).collect();
            let label = format!("{} ({})", motion.label(), count_text(&frames));
            rows.push(metric_row(label, "RMSE_xy", &rmse, Better::Lower, 3));
            rows.push(metric_row(String::new(), "IDSW", &idsw, Better::Lower, 0));
            rows.push(metric_row(String::new(), "IDF1", &idf1, Better::Higher, 4));
        }
        let mut text = render_table_aligned(
            "Table VI. Prior RMSE and identity by ego motion (|yaw rate| above 0.1 rad/s: turning)",
            &header,
            &rows,
            2,
        );
        self.append_notes(&mut text, "* best value in its row");
        text
    }

    /// Table V scenarios: label and how to pick the counts from a result.
    pub(super) fn identity_scenarios(&self) -> Vec<(String, CountsSelector)> {
        let mut scenarios: Vec<(String, CountsSelector)> = vec![
            ("Close Proximity".into(), Box::new(|r: &MethodResult| Some(r.close_proximity))),
            ("Crossing Motion".into(), Box::new(|r: &MethodResult| Some(r.crossing))),
        ];
        for percent in self.miss_percents() {
            scenarios.push((
                format!("{percent}% Miss"),
                Box::new(move |r: &MethodResult| r.missed_detection.get(&percent).copied()),
            ));
        }
        scenarios
    }

    /// A count that should be the same for every evaluated method, as text.
    pub(super) fn common_count(&self, count: impl Fn(&MethodResult) -> u64) -> String {
        let present: Vec<u64> = self.results.values().map(count).collect();
        count_text(&present)
    }

    pub(super) fn append_notes(&self, text: &mut String, best_note: &str) {
        let _ = writeln!(text, "{best_note}");
        for method in Method::ALL {
            if self.result(method).is_none() {
                let reason = self.unavailable_reason(method).unwrap_or("not evaluated");
                let _ = writeln!(text, "n/a {}: {reason}", method.label());
            }
        }
    }

    /// The velocity RMSE columns of Table II: overall, then per class in `classes`.
    fn velocity_columns(&self, classes: &[ObjectClass]) -> Vec<Vec<Cell>> {
        type Metric<'a> = Box<dyn Fn(&MethodResult) -> Option<f64> + 'a>;
        let mut metrics: Vec<(Metric, usize)> = vec![(Box::new(|r: &MethodResult| r.velocity.rmse_mps()), 3)];
        for class in classes {
            metrics.push((
                Box::new(move |r: &MethodResult| r.class_velocity.get(class).and_then(|a| a.rmse_mps())),
                3,
            ));
        }
        metrics
            .iter()
            .map(|(metric, digits)| {
                let values: Vec<Option<f64>> =
                    Method::ALL.iter().map(|m| self.result(*m).and_then(metric)).collect();
                mark_best(&values, Better::Lower, *digits)
            })
            .collect()
    }

    /// The speed and heading columns of Table II (confirmed tracks; the speed bias unmarked).
    fn confirmed_motion_columns(&self) -> Vec<Vec<Cell>> {
        let motion: [MotionColumn; 3] = [
            (SpeedHeadingAccumulator::speed_rmse_mps, 3, true),
            (SpeedHeadingAccumulator::speed_mean_error_mps, 3, false),
            (SpeedHeadingAccumulator::heading_rmse_deg, 2, true),
        ];
        motion
            .iter()
            .map(|(metric, digits, marked)| {
                let values: Vec<Option<f64>> = Method::ALL
                    .iter()
                    .map(|m| self.result(*m).and_then(|r| metric(&r.confirmed_motion)))
                    .collect();
                if *marked {
                    mark_best(&values, Better::Lower, *digits)
                } else {
                    mark_best(&values, Better::Lower, *digits).into_iter().map(Cell::unmarked).collect()
                }
            })
            .collect()
    }
}

/// One row of a scenario table: `first` (the scenario, or empty under it), the metric's name
/// and each method's value, the best one marked.
pub(super) fn metric_row(
    first: String,
    metric: &str,
    values: &[Option<f64>],
    better: Better,
    digits: usize,
) -> Vec<String> {
    let mut line = vec![first, metric.to_string()];
    line.extend(mark_best(values, better, digits).iter().map(Cell::to_string));
    line
}

/// A column of speed and heading errors: the metric, its decimals, and whether lower is better
/// (a bias is signed: no best value is marked).
pub(super) type MotionColumn = (fn(&SpeedHeadingAccumulator) -> Option<f64>, usize, bool);

/// Reads one RMSE value from an accumulator.
pub(super) type RmseMetric = fn(&RmseAccumulator) -> Option<f64>;

/// Picks the identity counts of one Table V scenario from a result.
pub(super) type CountsSelector = Box<dyn Fn(&MethodResult) -> Option<IdentityCounts>>;

/// Which direction is better.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Better {
    Lower,
    Higher,
}

/// A formatted table cell.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Cell {
    Missing,
    Value { text: String, best: bool },
}

impl Cell {
    /// The same cell without a best-value mark (for a signed quantity such as a bias, where
    /// lower is not better).
    fn unmarked(self) -> Cell {
        match self {
            Cell::Value { text, .. } => Cell::Value { text, best: false },
            Cell::Missing => Cell::Missing,
        }
    }
}

impl std::fmt::Display for Cell {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Cell::Missing => f.write_str("n/a"),
            Cell::Value { text, best: true } => write!(f, "{text}*"),
            Cell::Value { text, best: false } => f.write_str(text),
        }
    }
}

/// Formats values with `decimals` digits (integers grouped by thousands when `decimals == 0`)
/// and marks the best ones. Values are compared as displayed, so ties at the shown precision are
/// all marked; nothing is marked when fewer than two values are present.
pub(super) fn mark_best(values: &[Option<f64>], better: Better, decimals: usize) -> Vec<Cell> {
    let shown: Vec<Option<f64>> = values
        .iter()
        .map(|value| value.map(|v| format!("{v:.decimals$}").parse::<f64>().unwrap_or(v)))
        .collect();
    let present: Vec<f64> = shown.iter().flatten().copied().collect();
    let best = match better {
        Better::Lower => present.iter().copied().fold(f64::INFINITY, f64::min),
        Better::Higher => present.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    };
    values
        .iter()
        .zip(&shown)
        .map(|(value, shown)| match (value, shown) {
            (Some(value), Some(shown)) => Cell::Value {
                text: if decimals == 0 {
                    group_thousands(value.round() as u64)
                } else {
                    format!("{value:.decimals$}")
                },
                best: present.len() >= 2 && *shown == best,
            },
            _ => Cell::Missing,
        })
        .collect()
}

/// `17866` → `17,866`.
pub(crate) fn group_thousands(value: u64) -> String {
    let digits = value.to_string();
    let mut out = String::with_capacity(digits.len() + digits.len() / 3);
    for (index, digit) in digits.chars().enumerate() {
        if index > 0 && (digits.len() - index).is_multiple_of(3) {
            out.push(',');
        }
        out.push(digit);
    }
    out
}

/// The common value of counts that should agree, `n/a` without any, or the range when they differ.
pub(super) fn count_text(values: &[u64]) -> String {
    match (values.iter().min(), values.iter().max()) {
        (Some(min), Some(max)) if min == max => group_thousands(*min),
        (Some(min), Some(max)) => format!("{}–{}", group_thousands(*min), group_thousands(*max)),
        _ => "n/a".into(),
    }
}

/// Renders a title, a header and rows; the first column is left-aligned, the others right-aligned.
pub(super) fn render_table(title: &str, header: &[String], rows: &[Vec<String>]) -> String {
    render_table_aligned(title, header, rows, 1)
}

/// Renders a table whose first `left_columns` columns are left-aligned and the rest right-aligned.
pub(super) fn render_table_aligned(
    title: &str,
    header: &[String],
    rows: &[Vec<String>],
    left_columns: usize,
) -> String {
    let columns = header.len();
    let mut widths: Vec<usize> = header.iter().map(|h| h.chars().count()).collect();
    for row in rows {
        for (width, cell) in widths.iter_mut().zip(row) {
            *width = (*width).max(cell.chars().count());
        }
    }
    let format_row = |cells: &[String]| -> String {
        let mut line = String::new();
        for (index, width) in widths.iter().enumerate() {
            let cell = cells.get(index).map(String::as_str).unwrap_or("");
            let pad = width.saturating_sub(cell.chars().count());
            if index > 0 {
                line.push_str("  ");
            }
            if index < left_columns {
                line.push_str(cell);
                line.push_str(&" ".repeat(pad));
            } else {
                line.push_str(&" ".repeat(pad));
                line.push_str(cell);
            }
        }
        line.trim_end().to_string()
    };
    let total = widths.iter().sum::<usize>() + 2 * columns.saturating_sub(1);
    let rule = "-".repeat(total);
    let mut text = String::new();
    let _ = writeln!(text, "{title}");
    let _ = writeln!(text, "{rule}");
    let _ = writeln!(text, "{}", format_row(header));
    let _ = writeln!(text, "{rule}");
    for row in rows {
        let _ = writeln!(text, "{}", format_row(row));
    }
    let _ = writeln!(text, "{rule}");
    text
}
