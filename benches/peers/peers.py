#!/usr/bin/env python3
"""Python trackers that a team would otherwise pick, run on primm's measurement CSV files.

Two peers share one tracking loop that mirrors primm's (``crates/primm-core/src/tracker/``): per class, the
association cost of ``eq:association_cost`` (distance to the predicted position plus
``velocity_weight_s * min(|dv_r|, velocity_cap_mps)``), the class gate, an optimal assignment
that first maximises the number of pairs and then minimises the cost, and primm's track
lifecycle (a new tentative track per unassigned measurement, confirmation after
``confirmation_hits`` hits, deletion after too many misses or too long a coast). Every parameter
comes from ``config/primm.toml``. What differs is the filter and assignment code:

* ``filterpy``: ``filterpy.kalman.IMMEstimator`` over two ``KalmanFilter`` objects, constant
  velocity and constant acceleration, in a shared 6-D state ``[x, y, vx, vy, ax, ay]``
  (filterpy's IMM needs one state size; the CV filter keeps acceleration at zero), with
  primm's transition probabilities, process noises and measurement noise; assignment by
  ``scipy.optimize.linear_sum_assignment``.
* ``stonesoup``: Stone Soup's ``KalmanPredictor`` / ``KalmanUpdater`` with a constant-velocity
  ``CombinedLinearGaussianTransitionModel`` (state ``[x, vx, y, vy]``) and a
  ``LinearGaussian`` measurement model; association by ``GNNWith2DAssignment`` over a
  ``DistanceHypothesiser`` (Euclidean distance between predicted and measured position, gated
  at the class gate). Stone Soup's hypothesiser has no radial-velocity term, so this peer's
  cost is the distance alone.

Output: one association CSV per sequence (``crates/primm-sim/src/io/association_csv.rs``), scored by
``primm score``; and one JSON line with the time spent in the per-frame tracking loop
(prediction, association, update, lifecycle; file reading and writing excluded).

Usage: peers.py --tracker filterpy|stonesoup --data DIR --out DIR [--sequences N] [--config FILE]
"""

from __future__ import annotations

import argparse
import csv
import datetime
import json
import math
import sys
import time
import tomllib
from pathlib import Path

import numpy as np
from scipy.optimize import linear_sum_assignment

ROOT = Path(__file__).resolve().parents[2]
HEADER = "frame,measurement,track_id,prior_x,prior_y"
FORBIDDEN = 1e9


# ----------------------------------------------------------------------------------------------
# Data
# ----------------------------------------------------------------------------------------------

def read_sequence(path: Path):
    """Frames as (frame index, time s, [(position in frame, class, x, y, v_r)]), file order."""
    frames = []
    with path.open(newline="") as handle:
        for row in csv.DictReader(handle):
            frame = int(row["frame"])
            if not frames or frames[-1][0] != frame:
                frames.append((frame, float(row["t"]), []))
            measurements = frames[-1][2]
            if not row["x"]:
                continue  # a frame without measurements
            measurements.append((len(measurements), row["class"], float(row["x"]), float(row["y"]), float(row["vr"])))
    return frames


def white_acceleration(dt: float) -> np.ndarray:
    """Integrated continuous white noise of one axis' [position, velocity], per unit PSD."""
    return np.array([[dt**3 / 3.0, dt**2 / 2.0], [dt**2 / 2.0, dt]])


def white_jerk(dt: float) -> np.ndarray:
    """Integrated continuous white jerk of one axis' [position, velocity, acceleration]."""
    return np.array(
        [
            [dt**5 / 20.0, dt**4 / 8.0, dt**3 / 6.0],
            [dt**4 / 8.0, dt**3 / 3.0, dt**2 / 2.0],
            [dt**3 / 6.0, dt**2 / 2.0, dt],
        ]
    )


def initial_velocity(cls: dict, x: float, y: float, vr: float):
    """primm's line-of-sight initial velocity (crates/primm-core/src/motion/mod.rs, InitialVelocity)."""
    rng = math.hypot(x, y)
    along = np.array([x / rng, y / rng]) if rng > 1e-6 else np.array([1.0, 0.0])
    across = np.array([-along[1], along[0]])
    mean = along * vr
    cov = np.outer(along, along) * cls["initial_radial_speed_std_mps"] ** 2 + np.outer(across, across) * cls[
        "initial_tangential_speed_std_mps"
    ] ** 2
    return mean, cov


# ----------------------------------------------------------------------------------------------
# Filters
# ----------------------------------------------------------------------------------------------

class FilterpyImm:
    """filterpy IMMEstimator over CV and CA Kalman filters in a shared 6-D state."""

    def __init__(self, config: dict, cls: dict, x: float, y: float, vr: float):
        from filterpy.kalman import IMMEstimator, KalmanFilter

        self.cls = cls
        velocity, velocity_cov = initial_velocity(cls, x, y, vr)
        r = np.array(cls["measurement_noise_covariance_m2"])
        filters = []
        for _ in range(2):
            f = KalmanFilter(dim_x=6, dim_z=2)
            f.x = np.array([x, y, velocity[0], velocity[1], 0.0, 0.0])
            p = np.zeros((6, 6))
            p[0:2, 0:2] = r
            p[2:4, 2:4] = velocity_cov
            f.P = p
            f.H = np.hstack([np.eye(2), np.zeros((2, 4))])
            f.R = r
            filters.append(f)
        filters[1].P[4, 4] = filters[1].P[5, 5] = cls["constant_acceleration"]["initial_acceleration_std_mps2"] ** 2
        filters[0].P[4, 4] = filters[0].P[5, 5] = 1e-9
        # primm's transition matrix restricted to CV and CA (mode order pr, cv, ca, ct), rows renormalised.
        full = np.array(config["imm"]["transition"])
        m = full[np.ix_([1, 2], [1, 2])]
        m = m / m.sum(axis=1, keepdims=True)
        mu = np.array(config["imm"]["initial_mode_probabilities"])[[1, 2]]
        self.imm = IMMEstimator(filters, mu / mu.sum(), m)
        self.filters = filters

    def predict(self, dt: float) -> np.ndarray:
        cv, ca = self.filters
        f = np.eye(6)
        f[0, 2] = f[1, 3] = dt
        f_cv = f.copy()
        f_cv[4, 4] = f_cv[5, 5] = 0.0
        cv.F = f_cv
        q = np.zeros((6, 6))
        block = white_acceleration(dt) * self.cls["constant_velocity"]["acceleration_psd_m2_per_s3"]
        for axis in range(2):
            idx = [axis, axis + 2]
            q[np.ix_(idx, idx)] = block
        q[4, 4] = q[5, 5] = 1e-9
        cv.Q = q
        f_ca = f.copy()
        f_ca[0, 4] = f_ca[1, 5] = 0.5 * dt * dt
        f_ca[2, 4] = f_ca[3, 5] = dt
        ca.F = f_ca
        q = np.zeros((6, 6))
        block = white_jerk(dt) * self.cls["constant_acceleration"]["jerk_psd_m2_per_s5"]
        for axis in range(2):
            idx = [axis, axis + 2, axis + 4]
            q[np.ix_(idx, idx)] = block
        ca.Q = q
        self.imm.predict()
        return self.imm.x[:2].copy()

    def update(self, x: float, y: float):
        self.imm.update(np.array([x, y]))


class StoneSoupKalman:
    """Stone Soup constant-velocity Kalman filter; the predictor and updater are shared per class."""

    def __init__(self, parts: dict, cls: dict, x: float, y: float, vr: float, t: float):
        from stonesoup.types.state import GaussianState
        from stonesoup.types.track import Track

        velocity, velocity_cov = initial_velocity(cls, x, y, vr)
        r = np.array(cls["measurement_noise_covariance_m2"])
        mean = np.array([[x], [velocity[0]], [y], [velocity[1]]])
        cov = np.zeros((4, 4))
        cov[np.ix_([0, 2], [0, 2])] = r
        cov[np.ix_([1, 3], [1, 3])] = velocity_cov
        self.parts = parts
        self.track = Track([GaussianState(mean, cov, timestamp=to_datetime(t))])


def to_datetime(t: float) -> datetime.datetime:
    return datetime.datetime(2020, 1, 1) + datetime.timedelta(seconds=t)


def stonesoup_parts(cls: dict) -> dict:
    from stonesoup.dataassociator.neighbour import GNNWith2DAssignment
    from stonesoup.hypothesiser.distance import DistanceHypothesiser
    from stonesoup.measures import Euclidean
    from stonesoup.models.measurement.linear import LinearGaussian
    from stonesoup.models.transition.linear import CombinedLinearGaussianTransitionModel, ConstantVelocity
    from stonesoup.predictor.kalman import KalmanPredictor
    from stonesoup.updater.kalman import KalmanUpdater

    q = cls["constant_velocity"]["acceleration_psd_m2_per_s3"]
    transition = CombinedLinearGaussianTransitionModel([ConstantVelocity(q), ConstantVelocity(q)])
    measurement_model = LinearGaussian(ndim_state=4, mapping=(0, 2), noise_covar=np.array(cls["measurement_noise_covariance_m2"]))
    predictor = KalmanPredictor(transition)
    updater = KalmanUpdater(measurement_model)
    hypothesiser = DistanceHypothesiser(predictor, updater, measure=Euclidean(mapping=(0, 1), mapping2=(0, 1)), missed_distance=cls["paper_gate_m"])
    return {
        "predictor": predictor,
        "updater": updater,
        "measurement_model": measurement_model,
        "associator": GNNWith2DAssignment(hypothesiser),
    }


# ----------------------------------------------------------------------------------------------
# The tracking loop (primm's lifecycle)
# ----------------------------------------------------------------------------------------------

class TrackRecord:
    def __init__(self, track_id: int, filter_, vr: float, t: float):
        self.id = track_id
        self.filter = filter_
        self.last_vr = vr
        self.last_update = t
        self.hits = 1
        self.misses = 0
        self.confirmed = False
        self.prior = None


class PeerTracker:
    def __init__(self, kind: str, config: dict):
        self.kind = kind
        self.config = config
        self.tracks: dict[str, list[TrackRecord]] = {}
        self.next_id = 1
        self.last_t = None
        self.parts = {}
        if kind == "stonesoup":
            self.parts = {name: stonesoup_parts(cls) for name, cls in config["classes"].items()}

    def reset(self):
        self.tracks = {}
        self.last_t = None

    def new_track(self, class_name: str, x: float, y: float, vr: float, t: float) -> TrackRecord:
        cls = self.config["classes"][class_name]
        if self.kind == "filterpy":
            filter_ = FilterpyImm(self.config, cls, x, y, vr)
        else:
            filter_ = StoneSoupKalman(self.parts[class_name], cls, x, y, vr, t)
        track = TrackRecord(self.next_id, filter_, vr, t)
        self.next_id += 1
        track.confirmed = track.hits >= self.config["tracker"]["confirmation_hits"]
        return track

    def step(self, t: float, measurements):
        """Tracks one frame; returns {position in frame: (track id, prior or None)}."""
        dt = 0.0 if self.last_t is None else t - self.last_t
        self.last_t = t
        association = self.config["association"]
        taken = {}
        by_class: dict[str, list] = {}
        for m in measurements:
            by_class.setdefault(m[1], []).append(m)
        for class_name in set(self.tracks) | set(by_class):
            cls = self.config["classes"][class_name]
            tracks = self.tracks.setdefault(class_name, [])
            detections = by_class.get(class_name, [])
            if self.kind == "filterpy":
                for track in tracks:
                    track.prior = track.filter.predict(dt) if dt > 0 else track.filter.imm.x[:2].copy()
                pairs = self.assign_scipy(tracks, detections, cls, association)
                for track, m in pairs:
                    track.filter.update(m[2], m[3])
            else:
                pairs = self.assign_stonesoup(tracks, detections, t, class_name)
            assigned_tracks = set()
            for track, m in pairs:
                taken[m[0]] = (track.id, track.prior)
                assigned_tracks.add(track.id)
                track.hits += 1
                track.misses = 0
                track.last_vr = m[4]
                track.last_update = t
                if track.hits >= self.config["tracker"]["confirmation_hits"]:
                    track.confirmed = True
            for track in tracks:
                if track.id not in assigned_tracks:
                    track.misses += 1
            for m in detections:
                if m[0] not in taken:
                    track = self.new_track(class_name, m[2], m[3], m[4], t)
                    tracks.append(track)
                    taken[m[0]] = (track.id, None)
            lifecycle = self.config["tracker"]
            kept = []
            for track in tracks:
                if track.confirmed:
                    limits = (lifecycle["confirmed_max_misses"], lifecycle["max_coast_s"])
                else:
                    limits = (lifecycle["tentative_max_misses"], lifecycle["tentative_max_coast_s"])
                if track.misses <= limits[0] and t - track.last_update <= limits[1]:
                    kept.append(track)
            self.tracks[class_name] = kept
        return taken

    @staticmethod
    def assign_scipy(tracks, detections, cls, association):
        if not tracks or not detections:
            return []
        cost = np.full((len(tracks), len(detections)), FORBIDDEN)
        for i, track in enumerate(tracks):
            for j, m in enumerate(detections):
                distance = math.hypot(m[2] - track.prior[0], m[3] - track.prior[1])
                c = distance + association["velocity_weight_s"] * min(abs(m[4] - track.last_vr), association["velocity_cap_mps"])
                if c <= cls["paper_gate_m"]:
                    cost[i, j] = c
        rows, cols = linear_sum_assignment(cost)
        return [(tracks[r], detections[c]) for r, c in zip(rows, cols) if cost[r, c] < FORBIDDEN]

    def assign_stonesoup(self, tracks, detections, t, class_name):
        from stonesoup.types.detection import Detection
        from stonesoup.types.update import Update

        parts = self.parts[class_name]
        timestamp = to_datetime(t)
        stone_tracks = {track.filter.track: track for track in tracks}
        for track in tracks:
            state = parts["predictor"].predict(track.filter.track.state, timestamp=timestamp)
            track.prior = (float(state.state_vector[0, 0]), float(state.state_vector[2, 0]))
        if not tracks:
            return []
        detection_of = {}
        stone_detections = set()
        for m in detections:
            detection = Detection(np.array([[m[2]], [m[3]]]), timestamp=timestamp, measurement_model=parts["measurement_model"])
            detection_of[detection] = m
            stone_detections.add(detection)
        hypotheses = parts["associator"].associate(set(stone_tracks), stone_detections, timestamp)
        pairs = []
        for stone_track, hypothesis in hypotheses.items():
            if hypothesis:
                stone_track.append(parts["updater"].update(hypothesis))
                pairs.append((stone_tracks[stone_track], detection_of[hypothesis.measurement]))
            else:
                stone_track.append(hypothesis.prediction)
        return pairs


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--tracker", choices=["filterpy", "stonesoup"], required=True)
    parser.add_argument("--data", type=Path, required=True)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--sequences", type=int, default=None)
    parser.add_argument("--config", type=Path, default=ROOT / "config" / "primm.toml")
    parser.add_argument("--timing", type=Path, help="append one line per frame with its step time in ns")
    args = parser.parse_args()
    config = tomllib.loads(args.config.read_text())
    files = sorted(args.data.glob("*.csv"))[: args.sequences]
    args.out.mkdir(parents=True, exist_ok=True)
    tracker = PeerTracker(args.tracker, config)
    # Import the library before the clock runs.
    if args.tracker == "filterpy":
        import filterpy.kalman  # noqa: F401
    else:
        import stonesoup.types.track  # noqa: F401
    step_ns = []
    for path in files:
        frames = read_sequence(path)
        tracker.reset()
        rows = []
        for frame, t, measurements in frames:
            start = time.perf_counter_ns()
            taken = tracker.step(t, measurements)
            step_ns.append(time.perf_counter_ns() - start)
            for m in measurements:
                track_id, prior = taken.get(m[0], (None, None))
                rows.append((frame, m[0], track_id, prior))
        with (args.out / path.name).open("w") as handle:
            handle.write(HEADER + "\n")
            for frame, index, track_id, prior in rows:
                track = "" if track_id is None else str(track_id)
                prior_text = "," if prior is None else f"{float(prior[0])!r},{float(prior[1])!r}"
                handle.write(f"{frame},{index},{track},{prior_text}\n")
    if args.timing:
        with args.timing.open("a") as handle:
            handle.writelines(f"{ns}\n" for ns in step_ns)
    steps = np.array(step_ns, dtype=float)
    total_s = steps.sum() * 1e-9
    print(
        json.dumps(
            {
                "tracker": args.tracker,
                "frames": len(step_ns),
                "step_seconds": total_s,
                "frames_per_second": len(step_ns) / total_s if total_s > 0 else 0.0,
                "step_p50_us": float(np.percentile(steps, 50) / 1000.0) if len(steps) else 0.0,
                "step_p99_us": float(np.percentile(steps, 99) / 1000.0) if len(steps) else 0.0,
                "step_max_us": float(steps.max() / 1000.0) if len(steps) else 0.0,
            }
        )
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
