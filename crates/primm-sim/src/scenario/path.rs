//! Planned paths: chains of straight and circular legs with event marks along them.

use std::collections::VecDeque;
use std::f64::consts::PI;

use glam::DVec2;

use super::road::{Axis, JunctionId};

/// One piece of a path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Leg {
    /// Straight segment from `a` to `b`.
    Line { a: DVec2, b: DVec2 },
    /// Circular arc around `centre`, starting at angle `start` and sweeping `sweep` radians
    /// (positive counter-clockwise).
    Arc { centre: DVec2, radius: f64, start: f64, sweep: f64 },
}

impl Leg {
    pub(crate) fn length(&self) -> f64 {
        match *self {
            Leg::Line { a, b } => a.distance(b),
            Leg::Arc { radius, sweep, .. } => radius * sweep.abs(),
        }
    }

    pub(crate) fn point_at(&self, u: f64) -> DVec2 {
        let u = u.clamp(0.0, self.length());
        match *self {
            Leg::Line { a, b } => {
                let len = a.distance(b);
                if len <= 0.0 {
                    a
                } else {
                    a + (b - a) * (u / len)
                }
            }
            Leg::Arc { centre, radius, start, sweep } => {
                let angle = start + sweep.signum() * u / radius;
                centre + DVec2::from_angle(angle) * radius
            }
        }
    }

    /// Arc-length parameter of the leg point closest to `p`.
    pub(crate) fn project(&self, p: DVec2) -> f64 {
        match *self {
            Leg::Line { a, b } => {
                let d = b - a;
                let len2 = d.length_squared();
                if len2 <= 0.0 {
                    0.0
                } else {
                    ((p - a).dot(d) / len2).clamp(0.0, 1.0) * len2.sqrt()
                }
            }
            Leg::Arc { centre, radius, start, sweep } => {
                let angle = (p - centre).to_angle();
                let mut delta = (angle - start) * sweep.signum();
                delta = delta.rem_euclid(2.0 * PI);
                // Points beyond the end of the arc map to the nearer end.
                if delta > sweep.abs() {
                    let past_end = delta - sweep.abs();
                    let before_start = 2.0 * PI - delta;
                    delta = if past_end < before_start { sweep.abs() } else { 0.0 };
                }
                delta * radius
            }
        }
    }

    /// Unit tangent (direction of travel) at arc length `u`.
    pub(crate) fn tangent_at(&self, u: f64) -> DVec2 {
        match *self {
            Leg::Line { a, b } => (b - a).normalize_or_zero(),
            Leg::Arc { radius, start, sweep, .. } => {
                let angle = start + sweep.signum() * u.clamp(0.0, self.length()) / radius;
                DVec2::from_angle(angle).perp() * sweep.signum()
            }
        }
    }

    /// Radius of curvature, or `None` for a straight leg.
    pub(crate) fn radius(&self) -> Option<f64> {
        match *self {
            Leg::Line { .. } => None,
            Leg::Arc { radius, .. } => Some(radius),
        }
    }
}

/// Something that happens at a point of a path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum MarkKind {
    /// A signalised stop line for traffic along `axis` at junction `junction` (vehicles).
    StopLine { junction: JunctionId, axis: Axis },
    /// The start of a signalised crosswalk walked along `axis` (pedestrians).
    Crosswalk { junction: JunctionId, axis: Axis, length_m: f64 },
    /// Stand still for a while (pedestrians).
    Wait { duration_s: f64 },
    /// Change the walking speed from here on (pedestrians).
    SetSpeed { speed_mps: f64 },
}

/// A mark at path coordinate `s`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Mark {
    pub s: f64,
    pub kind: MarkKind,
}

/// A chain of legs, addressed by the path coordinate `s` (metres since the path began).
#[derive(Debug, Clone, Default)]
pub(crate) struct Path {
    legs: VecDeque<(f64, Leg)>,
    end_s: f64,
    pub marks: VecDeque<Mark>,
}

impl Path {
    /// Path coordinate of the end of the last leg.
    pub(crate) fn end_s(&self) -> f64 {
        self.end_s
    }

    /// End point of the path, if it has any leg.
    pub(crate) fn end_point(&self) -> Option<DVec2> {
        self.legs.back().map(|(_, leg)| leg.point_at(leg.length()))
    }

    pub(crate) fn is_empty(&self) -> bool {
        self.legs.is_empty()
    }

    /// Appends a leg; legs shorter than a millimetre are dropped.
    pub(crate) fn push(&mut self, leg: Leg) {
        let len = leg.length();
        if len < 1e-3 {
            return;
        }
        self.legs.push_back((self.end_s, leg));
        self.end_s += len;
    }

    /// Adds a mark; marks are kept sorted by `s`.
    pub(crate) fn add_mark(&mut self, mark: Mark) {
        let index = self.marks.iter().position(|m| m.s > mark.s).unwrap_or(self.marks.len());
        self.marks.insert(index, mark);
    }

    fn leg_index(&self, s: f64) -> Option<usize> {
        if self.legs.is_empty() {
            return None;
        }
        let index = self.legs.iter().position(|(start, leg)| s < start + leg.length());
        Some(index.unwrap_or(self.legs.len() - 1))
    }

    /// Point at path coordinate `s` (clamped to the path's ends).
    pub(crate) fn point_at(&self, s: f64) -> Option<DVec2> {
        let index = self.leg_index(s)?;
        let (start, leg) = &self.legs[index];
        Some(leg.point_at(s - start))
    }

    /// Advances the progress `s` of an agent at `position`: projects onto the leg holding `s`
    /// and, when that leg is finished (or its end is within `reach_m`), onto the following ones.
    /// Never moves backwards.
    pub(crate) fn advance(&self, s: f64, position: DVec2, reach_m: f64) -> f64 {
        let Some(mut index) = self.leg_index(s) else {
            return s;
        };
        let mut best = s;
        loop {
            let (start, leg) = &self.legs[index];
            let len = leg.length();
            let mut u = leg.project(position);
            if reach_m > 0.0 && leg.point_at(len).distance(position) < reach_m {
                u = len;
            }
            best = best.max(start + u);
            if u < len - 1e-6 || index + 1 >= self.legs.len() {
                break;
            }
            index += 1;
        }
        best
    }

    /// The point `distance` ahead of `s` along the path, but never beyond a corner where the
    /// direction turns by more than `max_turn` radians (so that a walker aims at the corner
    /// instead of cutting back along a reversal).
    pub(crate) fn lookahead(&self, s: f64, distance: f64, max_turn: f64) -> Option<DVec2> {
        let mut index = self.leg_index(s)?;
        let target = s + distance;
        loop {
            let (start, leg) = &self.legs[index];
            let len = leg.length();
            if target < start + len || index + 1 >= self.legs.len() {
                return Some(leg.point_at(target - start));
            }
            let (_, next) = &self.legs[index + 1];
            let turn = leg.tangent_at(len).angle_to(next.tangent_at(0.0)).abs();
            if turn > max_turn {
                return Some(leg.point_at(len));
            }
            index += 1;
        }
    }

    /// Drops legs that ended more than `keep_m` before `s`.
    pub(crate) fn prune(&mut self, s: f64, keep_m: f64) {
        while self.legs.len() > 1 {
            let (start, leg) = &self.legs[0];
            if start + leg.length() < s - keep_m {
                self.legs.pop_front();
            } else {
                break;
            }
        }
    }

    /// Arcs overlapping `[s, s + horizon]`: (distance from `s` to the arc start, clamped at 0,
    /// radius).
    pub(crate) fn arcs_ahead(&self, s: f64, horizon_m: f64) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.legs.iter().filter_map(move |(start, leg)| {
            let end = start + leg.length();
            if end < s || *start > s + horizon_m {
                return None;
            }
            leg.radius().map(|r| ((start - s).max(0.0), r))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arc_points_and_projection_agree() {
        let leg = Leg::Arc { centre: DVec2::new(1.0, 2.0), radius: 8.0, start: -PI / 2.0, sweep: PI / 2.0 };
        assert!((leg.length() - 4.0 * PI).abs() < 1e-12);
        for k in 0..=10 {
            let u = leg.length() * k as f64 / 10.0;
            let p = leg.point_at(u);
            assert!((leg.project(p) - u).abs() < 1e-9);
        }
        let cw = Leg::Arc { centre: DVec2::ZERO, radius: 5.0, start: PI / 2.0, sweep: -PI / 2.0 };
        let end = cw.point_at(cw.length());
        assert!(end.distance(DVec2::new(5.0, 0.0)) < 1e-9);
    }

    #[test]
    fn path_advances_across_legs() {
        let mut path = Path::default();
        path.push(Leg::Line { a: DVec2::ZERO, b: DVec2::new(10.0, 0.0) });
        path.push(Leg::Arc { centre: DVec2::new(10.0, 5.0), radius: 5.0, start: -PI / 2.0, sweep: PI / 2.0 });
        let s = path.advance(0.0, DVec2::new(12.0, 0.3), 0.0);
        assert!(s > 10.0 && s < 10.0 + 5.0 * PI / 2.0, "s = {s}");
        assert!(path.point_at(s).unwrap().distance(DVec2::new(12.0, 0.3)) < 0.6);
        assert_eq!(path.arcs_ahead(0.0, 20.0).count(), 1);
        assert_eq!(path.arcs_ahead(0.0, 5.0).count(), 0);
    }
}
