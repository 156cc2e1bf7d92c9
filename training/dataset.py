"""Training windows for the PR model, cut from measurement CSV files.

Every sequence file is grouped by ground-truth id (the generator's object id, like a
RadarScenes track id). For an object with measurements ``m_0 .. m_{n-1}`` (time order) and every
anchor ``j`` with at least one later measurement, the history is ``m_{max(0, j-4)} .. m_j``
(oldest first, at most five, none before a gap longer than ``max_gap_s``: a tracker deletes a
track that coasts that long) and the prediction time ``tau`` is the time of one of the next
``max_horizon`` measurements ``m_{j+h}`` no more than ``max_horizon_s`` after ``m_j``.

Positions are taken in the world frame: each row's vehicle-frame position (and true position) is
mapped with that row's ego pose (``ego_x, ego_y, ego_yaw``), as primm's tracker does when frames
carry a pose (``frame="vehicle"`` keeps the vehicle frame; rows without a pose stay as they are).

Each window is laid out exactly like ``PredictionRequest`` (``eq:pr_input``): rows ``0..len``
hold ``[x_l - x_j, y_l - y_j, v_r_l, RCS_l, t_l - tau]``, rows ``len..`` are zero (right
padding), and ``valid`` marks the rows ``0..len``. Windows are kept in the world frame; before a
window goes into the model, :func:`input_frames` and :func:`to_model_frame` rotate it into the
model's input axes (primm-predictor's ``InputRotation``), and displacements are rotated the same
way. The axes are those of the latest measurement's line of sight (x from the radar that took it
to the measured position, :func:`line_of_sight_frames`), where the latest radial velocity is the
velocity's x component, or, for models trained before that, those of the latest motion
(:func:`motion_frames`).

Each row's radar position comes from its ``sensor_id`` and the sensor mounts of the tracker's
configuration (``config/primm.toml``, ``[[frame.sensors]]``), mapped with the row's ego pose as
the tracker maps it; a row without a known mount is seen from the vehicle's reference point.
An object measured more than once in a scan (an extended object's several reflections) keeps its
first measurement of that scan: a track is updated by one measurement a frame.

Two displacement labels are kept per window:

* ``true``: ``p_{j+h} - p_j`` from the ``true_x``/``true_y`` columns (box centre), the label
  the model is trained on (see ``training/README.md`` for why);
* ``measured``: ``z_{j+h} - z_j``, what a data set without ground-truth positions offers; it is
  reported next to the true label to show how much of it is measurement noise.
"""

from __future__ import annotations

import csv
import glob
import os
from dataclasses import dataclass

import numpy as np

try:
    import tomllib
except ModuleNotFoundError:  # Python < 3.11
    tomllib = None

MAX_HISTORY = 5
FEATURES = 5
# Shortest distance between a window's last two measurements that gives it a direction of motion,
# m (primm-predictor's MIN_HEADING_DISTANCE_M).
MIN_HEADING_DISTANCE_M = 0.01
CLASSES = {"car": 0, "pedestrian": 1, "two_wheeler": 2}
# Shortest distance from a radar to a measurement that gives the measurement a line of sight, m
# (primm-predictor's MIN_LINE_OF_SIGHT_DISTANCE_M).
MIN_LINE_OF_SIGHT_DISTANCE_M = 0.01
# The model input axes a model can be trained in (primm-predictor's InputFrame; the ONNX file
# names its own in the metadata entry onnx_graph.INPUT_FRAME_KEY).
INPUT_FRAMES = ("line_of_sight", "latest_motion")
DEFAULT_CONFIG = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "config", "primm.toml")


def read_sensor_mounts(path: str = DEFAULT_CONFIG) -> dict[int, tuple[float, float]]:
    """The position of every configured radar on the vehicle, ``{sensor id: (x_m, y_m)}``, from
    the ``[[frame.sensors]]`` tables of a tracker configuration file."""
    if tomllib is None:
        raise RuntimeError("reading the sensor mounts needs Python 3.11 or newer (tomllib)")
    with open(path, "rb") as handle:
        config = tomllib.load(handle)
    sensors = config.get("frame", {}).get("sensors", [])
    return {int(s["id"]): (float(s.get("x_m", 0.0)), float(s.get("y_m", 0.0))) for s in sensors}


@dataclass
class Windows:
    """A set of windows as parallel arrays (N windows)."""

    features: np.ndarray  # [N, 5, 5] float32, eq:pr_input rows, zero padded at the end
    valid: np.ndarray  # [N, 5] float32, 1 for rows 0..len
    length: np.ndarray  # [N] int64, 1..5
    horizon: np.ndarray  # [N] int64, h: prediction at the h-th next measurement
    dt_s: np.ndarray  # [N] float64, tau - t_j
    true_displacement: np.ndarray  # [N, 2] float32, p_{j+h} - p_j (m)
    measured_displacement: np.ndarray  # [N, 2] float32, z_{j+h} - z_j (m)
    previous_measured: np.ndarray  # [N, 2] float32, z_j - z_{j-1} (m), NaN for length 1
    previous_dt_s: np.ndarray  # [N] float64, t_j - t_{j-1}, NaN for length 1
    object_class: np.ndarray  # [N] int64, CLASSES code
    line_of_sight: np.ndarray  # [N, 2] float64, unit vector from the radar to m_j, NaN if none
    frames_ahead: np.ndarray  # [N] int64, frames (radar scans) from m_j to m_{j+h}
    sequence: np.ndarray  # [N] int64, index of the file in the sorted file list

    def __len__(self) -> int:
        return len(self.length)

    def subset(self, mask: np.ndarray) -> "Windows":
        return Windows(**{name: getattr(self, name)[mask] for name in self.__dataclass_fields__})

    @staticmethod
    def concatenate(parts: list["Windows"]) -> "Windows":
        """The windows of all ``parts``, in order (``sequence`` keeps each part's file index)."""
        return Windows(
            **{name: np.concatenate([getattr(p, name) for p in parts]) for name in Windows.__dataclass_fields__}
        )


def to_world(row: dict, x: float, y: float) -> tuple[float, float]:
    """A vehicle-frame point of ``row`` in the world frame of the row's ego pose (unchanged without
    a pose)."""
    if row.get("ego_x", "") in ("", None):
        return x, y
    yaw = float(row["ego_yaw"])
    c, s = np.cos(yaw), np.sin(yaw)
    return float(row["ego_x"]) + c * x - s * y, float(row["ego_y"]) + s * x + c * y


def sensor_position(row: dict, mounts: dict[int, tuple[float, float]], frame: str) -> tuple[float, float]:
    """Where the radar of ``row`` is, as the tracker places it: its mount (the vehicle's
    reference point without a known mount), in the world frame of the row's pose (``frame="world"``
    and a pose) or in the vehicle frame."""
    sensor = row.get("sensor_id", "")
    x, y = mounts.get(int(sensor), (0.0, 0.0)) if sensor not in ("", None) else (0.0, 0.0)
    return to_world(row, x, y) if frame == "world" else (x, y)


def read_objects(
    path: str, frame: str = "world", mounts: dict[int, tuple[float, float]] | None = None
) -> list[np.ndarray]:
    """Per ground-truth object, its measurements in time order as rows
    ``[t, x, y, vr, rcs, true_x, true_y, class, frame, sensor_x, sensor_y]``, positions (the
    radar's too) in the world frame (or the vehicle frame with ``frame="vehicle"``), one
    measurement per object and scan (the first). Rows without a ground-truth id or a true
    position are skipped. ``mounts`` defaults to :func:`read_sensor_mounts`."""
    if mounts is None:
        mounts = read_sensor_mounts()
    objects: dict[int, list[list[float]]] = {}
    seen: set[tuple[int, str]] = set()
    with open(path, newline="") as handle:
        rows = csv.DictReader(line for line in handle if not line.startswith("#"))
        for row in rows:
            gt = row.get("gt_id", "")
            if gt in ("", "-1") or row.get("x", "") == "" or row.get("true_x", "") == "":
                continue
            if (int(gt), row["frame"]) in seen:
                continue
            seen.add((int(gt), row["frame"]))
            x, y = float(row["x"]), float(row["y"])
            sensor_x, sensor_y = sensor_position(row, mounts, frame)
            true_x, true_y = float(row["true_x"]), float(row["true_y"])
            if frame == "world":
                x, y = to_world(row, x, y)
                true_x, true_y = to_world(row, true_x, true_y)
            objects.setdefault(int(gt), []).append(
                [
                    float(row["t"]),
                    x,
                    y,
                    float(row["vr"]),
                    float(row["rcs"]),
                    true_x,
                    true_y,
                    float(CLASSES[row["class"]]),
                    float(row["frame"]),
                    sensor_x,
                    sensor_y,
                ]
            )
    result = []
    for gt in sorted(objects):
        array = np.asarray(objects[gt], dtype=np.float64)
        result.append(array[np.argsort(array[:, 0], kind="stable")])
    return result


def object_windows(m: np.ndarray, max_horizon: int, max_horizon_s: float, max_gap_s: float) -> dict[str, list]:
    """All windows of one object (see the module documentation)."""
    out: dict[str, list] = {k: [] for k in Windows.__dataclass_fields__ if k != "sequence"}
    n = len(m)
    gap_after = np.diff(m[:, 0]) > max_gap_s  # gap_after[i]: a gap between m_i and m_{i+1}
    for j in range(n - 1):
        start = max(0, j - MAX_HISTORY + 1)
        while start < j and gap_after[start:j].any():
            start += 1
        history = m[start : j + 1]
        length = len(history)
        for h in range(1, max_horizon + 1):
            if j + h >= n:
                break
            tau = m[j + h, 0]
            dt = tau - m[j, 0]
            if dt > max_horizon_s:
                break
            if dt <= 0.0:
                continue
            features = np.zeros((MAX_HISTORY, FEATURES), dtype=np.float32)
            features[:length, 0] = history[:, 1] - m[j, 1]
            features[:length, 1] = history[:, 2] - m[j, 2]
            features[:length, 2] = history[:, 3]
            features[:length, 3] = history[:, 4]
            features[:length, 4] = history[:, 0] - tau
            valid = np.zeros(MAX_HISTORY, dtype=np.float32)
            valid[:length] = 1.0
            out["features"].append(features)
            out["valid"].append(valid)
            out["length"].append(length)
            out["horizon"].append(h)
            out["dt_s"].append(dt)
            out["true_displacement"].append(m[j + h, 5:7] - m[j, 5:7])
            out["measured_displacement"].append(m[j + h, 1:3] - m[j, 1:3])
            if j >= 1:
                out["previous_measured"].append(m[j, 1:3] - m[j - 1, 1:3])
                out["previous_dt_s"].append(m[j, 0] - m[j - 1, 0])
            else:
                out["previous_measured"].append([np.nan, np.nan])
                out["previous_dt_s"].append(np.nan)
            out["object_class"].append(int(m[j, 7]))
            out["line_of_sight"].append(unit_line_of_sight(m[j, 1:3] - m[j, 9:11]))
            out["frames_ahead"].append(int(m[j + h, 8] - m[j, 8]))
    return out


def unit_line_of_sight(offset: np.ndarray) -> list[float]:
    """The unit vector of ``offset`` (radar to measurement), NaN when it is shorter than
    ``MIN_LINE_OF_SIGHT_DISTANCE_M`` or not finite."""
    length = float(np.hypot(offset[0], offset[1]))
    if not (length >= MIN_LINE_OF_SIGHT_DISTANCE_M and np.isfinite(length)):
        return [np.nan, np.nan]
    return [float(offset[0]) / length, float(offset[1]) / length]


def load_split(
    directory: str,
    max_horizon: int,
    max_horizon_s: float,
    max_gap_s: float = 1.0,
    frame: str = "world",
    mounts: dict[int, tuple[float, float]] | None = None,
) -> tuple[Windows, list[str]]:
    """Windows of every ``*.csv`` file in ``directory`` (sorted by name), positions in ``frame``,
    radars placed by ``mounts`` (default: :func:`read_sensor_mounts`)."""
    if mounts is None:
        mounts = read_sensor_mounts()
    files = sorted(glob.glob(os.path.join(directory, "*.csv")))
    if not files:
        raise FileNotFoundError(f"no measurement CSV files in {directory}")
    parts: dict[str, list] = {k: [] for k in Windows.__dataclass_fields__}
    for index, path in enumerate(files):
        for m in read_objects(path, frame, mounts):
            windows = object_windows(m, max_horizon, max_horizon_s, max_gap_s)
            for key, values in windows.items():
                parts[key].extend(values)
            parts["sequence"].extend([index] * len(windows["length"]))
    dtypes = {
        "features": np.float32,
        "valid": np.float32,
        "length": np.int64,
        "horizon": np.int64,
        "dt_s": np.float64,
        "true_displacement": np.float32,
        "measured_displacement": np.float32,
        "previous_measured": np.float32,
        "previous_dt_s": np.float64,
        "object_class": np.int64,
        "line_of_sight": np.float64,
        "frames_ahead": np.int64,
        "sequence": np.int64,
    }
    arrays = {}
    for key, dtype in dtypes.items():
        values = parts[key]
        arrays[key] = np.asarray(values, dtype=dtype)
    arrays["features"] = arrays["features"].reshape(-1, MAX_HISTORY, FEATURES)
    arrays["valid"] = arrays["valid"].reshape(-1, MAX_HISTORY)
    for key in ("true_displacement", "measured_displacement", "previous_measured", "line_of_sight"):
        arrays[key] = arrays[key].reshape(-1, 2)
    return Windows(**arrays), files


def truncate(features: np.ndarray, valid: np.ndarray, length: np.ndarray, new_length: np.ndarray):
    """Keeps only the latest ``new_length`` rows of each window (``new_length <= length``),
    re-anchored to the same latest measurement: the rows move to the front and the rest is zero.
    Positions stay relative to the latest row, so only the row order changes."""
    n = len(length)
    out_f = np.zeros_like(features)
    out_v = np.zeros_like(valid)
    rows = np.arange(MAX_HISTORY)
    # Source row of target row r: (length - new_length) + r, for r < new_length.
    source = (length - new_length)[:, None] + rows[None, :]
    keep = rows[None, :] < new_length[:, None]
    source = np.where(keep, source, 0)
    gathered = features[np.arange(n)[:, None], source]
    out_f[keep] = gathered[keep]
    out_v[keep] = 1.0
    return out_f, out_v


def motion_frames(features: np.ndarray, length: np.ndarray, rng: np.random.Generator | None = None):
    """``(cos, sin)`` of each window's latest motion, from its second-latest to its latest row
    (positions are relative to the latest row, so the motion is minus the second-latest row's
    position). Windows without one (one row, or the last two rows closer than
    ``MIN_HEADING_DISTANCE_M``) get the identity, or a random direction when ``rng`` is given
    (training: the model then sees such windows in every orientation)."""
    n = len(length)
    previous = features[np.arange(n), np.maximum(length - 2, 0), :2].astype(np.float64)
    motion = -previous
    norm = np.hypot(motion[:, 0], motion[:, 1])
    has = (length >= 2) & (norm >= MIN_HEADING_DISTANCE_M)
    safe = np.where(has, norm, 1.0)
    cos = np.where(has, motion[:, 0] / safe, 1.0)
    sin = np.where(has, motion[:, 1] / safe, 0.0)
    return randomised_where_missing(cos, sin, has, rng)


def randomised_where_missing(cos: np.ndarray, sin: np.ndarray, has: np.ndarray, rng: np.random.Generator | None):
    """``(cos, sin)`` with the windows without a direction (``has`` false) turned to a random
    direction when ``rng`` is given (training), left as they are otherwise."""
    if rng is None:
        return cos, sin
    angle = rng.uniform(-np.pi, np.pi, len(has))
    return np.where(has, cos, np.cos(angle)), np.where(has, sin, np.sin(angle))


def line_of_sight_frames(line_of_sight: np.ndarray, rng: np.random.Generator | None = None):
    """``(cos, sin)`` of each window's line of sight (``[N, 2]`` unit vectors from
    :func:`load_split`). Windows without one (NaN) get the identity, or a random direction when
    ``rng`` is given, as in :func:`motion_frames`."""
    has = np.isfinite(line_of_sight).all(axis=1)
    cos = np.where(has, np.nan_to_num(line_of_sight[:, 0], nan=1.0), 1.0)
    sin = np.where(has, np.nan_to_num(line_of_sight[:, 1]), 0.0)
    return randomised_where_missing(cos, sin, has, rng)


def input_frames(
    input_frame: str,
    features: np.ndarray,
    length: np.ndarray,
    line_of_sight: np.ndarray,
    rng: np.random.Generator | None = None,
):
    """``(cos, sin)`` of each window's model input axes: :func:`line_of_sight_frames` for
    ``"line_of_sight"``, :func:`motion_frames` for ``"latest_motion"``."""
    if input_frame == "line_of_sight":
        return line_of_sight_frames(line_of_sight, rng)
    if input_frame == "latest_motion":
        return motion_frames(features, length, rng)
    raise ValueError(f"unknown input frame {input_frame!r}; expected one of {INPUT_FRAMES}")


def to_model_frame(features: np.ndarray, cos: np.ndarray, sin: np.ndarray) -> np.ndarray:
    """The windows with their positions rotated by ``(x, y) -> (c x + s y, -s x + c y)`` (padding
    rows stay zero)."""
    out = features.copy()
    x = features[:, :, 0].astype(np.float64)
    y = features[:, :, 1].astype(np.float64)
    c, s = cos[:, None], sin[:, None]
    out[:, :, 0] = (c * x + s * y).astype(np.float32)
    out[:, :, 1] = (-s * x + c * y).astype(np.float32)
    return out


def vectors_to_model_frame(vectors: np.ndarray, cos: np.ndarray, sin: np.ndarray) -> np.ndarray:
    """``[N, 2]`` displacements rotated like :func:`to_model_frame`."""
    x, y = vectors[:, 0].astype(np.float64), vectors[:, 1].astype(np.float64)
    return np.stack([cos * x + sin * y, -sin * x + cos * y], axis=1).astype(np.float32)


def scale_time(features: np.ndarray, k: np.ndarray) -> np.ndarray:
    """Windows of the same paths travelled ``k`` times slower: times ``t_l - tau`` times ``k`` and
    radial velocities divided by ``k`` (positions, RCS and the displacement label unchanged; the
    horizon becomes ``k`` times longer). Padding rows stay zero."""
    out = features.copy()
    out[:, :, 2] = (features[:, :, 2] / k[:, None]).astype(np.float32)
    out[:, :, 4] = (features[:, :, 4] * k[:, None]).astype(np.float32)
    return out


def vectors_from_model_frame(vectors: np.ndarray, cos: np.ndarray, sin: np.ndarray) -> np.ndarray:
    """``[N, 2]`` displacements rotated back from the model's frame."""
    x, y = vectors[:, 0].astype(np.float64), vectors[:, 1].astype(np.float64)
    return np.stack([cos * x - sin * y, sin * x + cos * y], axis=1).astype(np.float32)
