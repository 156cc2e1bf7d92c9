"""Trains the PR model from scratch and exports it for primm.

    python training/train.py --data data --out models

reads the windows of every data set: ``DATA/NAME/train/*.csv`` and ``DATA/NAME/validation/*.csv``
for each training set ``--sets NAME ...`` (written by ``primm generate --output DATA/NAME``),
``DATA/NAME/validation/*.csv`` for each held-out set ``--held-out NAME ...`` (validation only,
never trained on); without ``--sets``, ``DATA/train`` and ``DATA/validation`` form the one set
``default``. Trains with a fixed seed on the pooled training windows, keeps the epoch with the
lowest loss on the validation split of ``--selection-set`` (default: ``default``), and writes

* ``OUT/pr.onnx``: the model (opset 17, dynamic batch axis ``batch``; outputs ``displacement`` and
  ``displacement_cholesky``);
* ``OUT/pr.json``: inputs, outputs, layout, normalisation, data, hyper-parameters, validation
  metrics per data set (RMSE, NLL, calibration of the predicted covariance) and the validation
  residual covariance of the displacement (a value for ``Q_PR``);
* ``OUT/pr_parity.json``: 64 inputs of mixed lengths with the PyTorch outputs, for the Rust
  parity test.

See ``training/README.md``.
"""

from __future__ import annotations

import argparse
import copy
import datetime
import hashlib
import json
import math
import os
import platform
import random
import sys
import time
import tomllib

import numpy as np
import torch

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from dataset import (  # noqa: E402
    CLASSES,
    DEFAULT_CONFIG,
    INPUT_FRAMES,
    MAX_HISTORY,
    read_sensor_mounts,
    Windows,
    load_split,
    input_frames,
    scale_time,
    to_model_frame,
    truncate,
    vectors_from_model_frame,
    vectors_to_model_frame,
)
from model import CHOLESKY_FLOOR_M, ExportGraph, PRModel, score_bound  # noqa: E402
import onnx_graph  # noqa: E402
from onnx_graph import INPUT_FRAME_KEY  # noqa: E402

OPSET = 17
INPUT_NAMES = ["features", "valid"]
OUTPUT_NAMES = ["displacement", "displacement_cholesky"]
BATCH_AXIS = "batch"
FEATURE_NAMES = ["x_minus_x_latest_m", "y_minus_y_latest_m", "radial_velocity_mps", "rcs_dbsm", "t_minus_t_prediction_s"]
PARITY_SAMPLES = 64
# Above this bound on the attention scores the exported softmax subtracts each row's maximum.
SCORE_BOUND_WITHOUT_MAX = 60.0
# Squared Mahalanobis distance inside which a 2-D Gaussian holds 95 % of its mass: -2 ln(0.05).
CHI2_2D_95 = -2.0 * math.log(0.05)
# What each model input axes mean (primm-predictor's InputFrame), for pr.json.
INPUT_FRAME_MEANING = {
    "line_of_sight": (
        "positions relative to the latest measurement, rotated so that the latest measurement's line of sight "
        "(from the radar that took it, its mount mapped with the ego pose, to the measured position) points "
        "along +x, so that the latest radial velocity is the velocity's x component; a measurement closer than "
        "0.01 m to its radar unrotated (primm-predictor InputRotation); the output displacement is in the same "
        "frame and is rotated back by the caller"
    ),
    "latest_motion": (
        "positions relative to the latest measurement, rotated so that the latest motion (second-latest "
        "to latest measurement) points along +x; histories of one measurement or whose last two are "
        "closer than 0.01 m unrotated (primm-predictor InputRotation); the output displacement is in the "
        "same frame and is rotated back by the caller"
    ),
}
# The default preset's seed base (crates/primm-sim ScenarioConfig::default).
DEFAULT_PRESET_SEED_BASE = 88314347343104


def parse_args(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument(
        "--data",
        default="data",
        help="directory with one sub-directory per data set (NAME/train, NAME/validation), or with "
        "train/ and validation/ directly (one set, `default`)",
    )
    parser.add_argument("--sets", nargs="*", default=None, help="training sets: DATA/NAME/{train,validation}")
    parser.add_argument(
        "--held-out", nargs="*", default=[], help="held-out sets, never trained on: DATA/NAME/validation only"
    )
    parser.add_argument("--selection-set", default="default", help="the set whose validation loss selects the epoch")
    parser.add_argument(
        "--scenario-dir",
        default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "scenarios"),
        help="where NAME.toml describes set NAME (recorded in pr.json; the default set is the default preset)",
    )
    parser.add_argument("--out", default="models", help="output directory")
    parser.add_argument("--seed", type=int, default=20240607)
    parser.add_argument(
        "--data-seed-base",
        type=int,
        default=88314347343104,
        help="the --seed-base the data was generated with (recorded in pr.json; default: the preset's)",
    )
    parser.add_argument(
        "--input-frame",
        choices=INPUT_FRAMES,
        default="line_of_sight",
        help="the model's input axes: along the latest measurement's line of sight (default) or along the "
        "latest motion (the earlier models); written into the ONNX file's metadata as " + INPUT_FRAME_KEY,
    )
    parser.add_argument(
        "--sensor-config",
        default=DEFAULT_CONFIG,
        help="tracker configuration whose [[frame.sensors]] place the radars (the line of sight starts there)",
    )
    parser.add_argument("--epochs", type=int, default=40)
    parser.add_argument("--patience", type=int, default=8, help="stop after this many epochs without improvement")
    parser.add_argument("--batch-size", type=int, default=256)
    parser.add_argument("--learning-rate", type=float, default=2e-3)
    parser.add_argument("--weight-decay", type=float, default=1e-4)
    parser.add_argument("--d-model", type=int, default=32)
    parser.add_argument("--heads", type=int, default=4)
    parser.add_argument("--layers", type=int, default=2)
    parser.add_argument("--d-ff", type=int, default=64)
    parser.add_argument("--max-horizon", type=int, default=3, help="targets at up to this many next measurements")
    parser.add_argument("--max-horizon-s", type=float, default=1.0, help="longest prediction interval, s")
    parser.add_argument("--max-gap-s", type=float, default=1.0, help="history rows before a longer gap are dropped, s")
    parser.add_argument(
        "--full-weight-horizon-s",
        type=float,
        default=0.1,
        help="windows predicting further ahead are weighted by (this / horizon)^2 (a velocity error)",
    )
    parser.add_argument(
        "--truncate-probability", type=float, default=0.3, help="chance per window and epoch of a shorter history"
    )
    parser.add_argument(
        "--samples-per-epoch", type=int, default=131072, help="training windows drawn (without replacement) per epoch"
    )
    parser.add_argument(
        "--target",
        choices=["true", "measured"],
        default="true",
        help="train on the true displacement (default) or the measured one z_{j+h} - z_j",
    )
    parser.add_argument(
        "--score-bound-limit",
        type=float,
        default=40.0,
        help="attention-score bound (from the weights) above which training is penalised, keeping the "
        "exported softmax free of a row maximum (see model.ExportGraph)",
    )
    parser.add_argument(
        "--frame",
        choices=["world", "vehicle"],
        default="world",
        help="frame the windows' positions are taken in (world: with each row's ego pose)",
    )
    parser.add_argument(
        "--loss",
        choices=["nll", "mse", "nll+mse"],
        default="nll+mse",
        help="nll: Gaussian negative log-likelihood of the true displacement under N(prediction, L L^T) "
        "(both heads); mse: the mean head by the scaled squared error and the covariance head by the NLL "
        "of the detached mean; nll+mse: the NLL of both heads plus the scaled squared error of the mean",
    )
    parser.add_argument(
        "--mse-warmup-epochs",
        type=int,
        default=1,
        help="with --loss nll: first epochs trained as with --loss mse (the mean settles before the NLL "
        "weights windows by their predicted precision)",
    )
    parser.add_argument(
        "--time-scale",
        type=float,
        default=1.0,
        help="time-scaling augmentation: times x k and radial velocities / k with log k uniform in "
        "[-log K, log K] (1: off); positions and label unchanged",
    )
    parser.add_argument("--time-scale-probability", type=float, default=0.5, help="share of windows time-scaled")
    parser.add_argument(
        "--mirror-probability",
        type=float,
        default=0.0,
        help="share of windows mirrored across the motion axis (y -> -y of positions and label)",
    )
    parser.add_argument("--threads", type=int, default=1, help="PyTorch threads (1 is fastest on a busy 2-core machine)")
    args = parser.parse_args(argv)
    args.mounts = read_sensor_mounts(args.sensor_config)
    return args


def seed_everything(seed: int) -> None:
    random.seed(seed)
    np.random.seed(seed)
    torch.manual_seed(seed)
    torch.use_deterministic_algorithms(True)


def loss_weight(horizon_s: np.ndarray, full_weight_horizon_s: float) -> np.ndarray:
    """Weight of each window in the loss: 1 up to ``full_weight_horizon_s``, then
    ``(full_weight_horizon_s / horizon)^2``, so a long prediction counts by its mean velocity
    error rather than by its (larger) displacement error and rare long coasts do not dominate."""
    return np.minimum(1.0, (full_weight_horizon_s / horizon_s) ** 2).astype(np.float32)


def labels(windows: Windows, target: str) -> np.ndarray:
    return windows.true_displacement if target == "true" else windows.measured_displacement


def normalisation(train: Windows, target: str, rng: np.random.Generator, input_frame: str):
    """Mean and standard deviation of each feature over the valid rows, and the per-axis RMS of
    the displacement label, both in the model's input frame."""
    cos, sin = input_frames(input_frame, train.features, train.length, train.line_of_sight, rng)
    rows = to_model_frame(train.features, cos, sin)[train.valid > 0]
    mean = rows.mean(axis=0).astype(np.float64)
    std = rows.std(axis=0).astype(np.float64)
    std = np.where(std > 1e-6, std, 1.0)
    target = vectors_to_model_frame(labels(train, target), cos, sin)
    scale = np.sqrt((target.astype(np.float64) ** 2).mean(axis=0))
    return mean, std, scale


def predict_windows(
    model: PRModel, features: np.ndarray, valid: np.ndarray, length: np.ndarray, line_of_sight: np.ndarray
):
    """The model's displacements and covariances for windows given in the data's frame: each
    window rotated into the model's input axes (``model.input_frame``), predicted, and the
    displacement rotated back (what primm-predictor does). Returns ``(displacement [N, 2],
    covariance [N, 2, 2])`` in the data's frame."""
    cos, sin = input_frames(model.input_frame, features, length, line_of_sight)
    displacement, cholesky = predict(model, to_model_frame(features, cos, sin), valid)
    return vectors_from_model_frame(displacement, cos, sin), covariance_from_model_frame(cholesky, cos, sin)


def predict(model: PRModel, features: np.ndarray, valid: np.ndarray, batch: int = 4096):
    """``(displacement [N, 2], cholesky [N, 3])`` in the model's frame."""
    model.eval()
    out, chol = [], []
    with torch.no_grad():
        for start in range(0, len(features), batch):
            f = torch.from_numpy(features[start : start + batch])
            v = torch.from_numpy(valid[start : start + batch])
            displacement, cholesky = model(f, v)
            out.append(displacement.numpy())
            chol.append(cholesky.numpy())
    if not out:
        return np.zeros((0, 2), np.float32), np.zeros((0, 3), np.float32)
    return np.concatenate(out), np.concatenate(chol)


def covariance_from_cholesky(cholesky: np.ndarray) -> np.ndarray:
    """``Sigma = L L^T`` ``[N, 2, 2]`` from ``[l_xx, l_yx, l_yy]``."""
    c = cholesky.astype(np.float64)
    lower = np.zeros((len(c), 2, 2))
    lower[:, 0, 0], lower[:, 1, 0], lower[:, 1, 1] = c[:, 0], c[:, 1], c[:, 2]
    return lower @ lower.transpose(0, 2, 1)


def covariance_from_model_frame(cholesky: np.ndarray, cos: np.ndarray, sin: np.ndarray) -> np.ndarray:
    """The covariance of the model's frame rotated back: ``R Sigma R^T``."""
    rotation = np.zeros((len(cos), 2, 2))
    rotation[:, 0, 0], rotation[:, 0, 1], rotation[:, 1, 0], rotation[:, 1, 1] = cos, -sin, sin, cos
    return rotation @ covariance_from_cholesky(cholesky) @ rotation.transpose(0, 2, 1)


def gaussian_nll(prediction, cholesky, target):
    """Per-window negative log-likelihood of ``target`` under ``N(prediction, L L^T)`` (torch,
    metres; includes ``log 2 pi``) and the squared Mahalanobis distance."""
    error = target - prediction
    z_x = error[:, 0] / cholesky[:, 0]
    z_y = (error[:, 1] - cholesky[:, 1] * z_x) / cholesky[:, 2]
    squared = z_x**2 + z_y**2
    return 0.5 * squared + torch.log(cholesky[:, 0]) + torch.log(cholesky[:, 2]) + math.log(2.0 * math.pi), squared


def calibration(error: np.ndarray, cov: np.ndarray) -> dict:
    """How well the predicted covariances describe the errors: mean squared Mahalanobis distance
    (2 for a calibrated 2-D Gaussian), the share inside the 95 % ellipse, the mean NLL (nats,
    metres), and the mean predicted and actual squared error."""
    if len(error) == 0:
        return {"samples": 0}
    e = error.astype(np.float64)
    solved = np.linalg.solve(cov, e[:, :, None])[:, :, 0]
    squared = (e * solved).sum(axis=1)
    log_det = np.log(np.linalg.det(cov))
    nll = 0.5 * squared + 0.5 * log_det + math.log(2.0 * math.pi)
    return {
        "mean_squared_mahalanobis": float(squared.mean()),
        "median_squared_mahalanobis": float(np.median(squared)),
        "fraction_inside_95_ellipse": float((squared <= CHI2_2D_95).mean()),
        "nll": float(nll.mean()),
        "mean_predicted_trace_m2": float(np.trace(cov, axis1=1, axis2=2).mean()),
        "mean_squared_error_m2": float((e**2).sum(axis=1).mean()),
        "samples": int(len(e)),
    }


def rmse(error: np.ndarray) -> dict:
    error = error.astype(np.float64)
    if len(error) == 0:
        return {"rmse_x_m": None, "rmse_y_m": None, "rmse_xy_m": None, "samples": 0}
    return {
        "rmse_x_m": float(np.sqrt((error[:, 0] ** 2).mean())),
        "rmse_y_m": float(np.sqrt((error[:, 1] ** 2).mean())),
        "rmse_xy_m": float(np.sqrt((error**2).sum(axis=1).mean())),
        "samples": int(len(error)),
    }


def covariance(error: np.ndarray) -> list:
    error = error.astype(np.float64)
    return [[float(v) for v in row] for row in (error.T @ error / max(len(error), 1))]


def baselines(windows: Windows) -> dict[str, np.ndarray]:
    """Displacement estimates that need no learning, for comparison."""
    n = len(windows)
    zero = np.zeros((n, 2))
    # Constant velocity from the last two measurements (NaN for a single measurement).
    velocity = windows.previous_measured / windows.previous_dt_s[:, None]
    cv_last_two = velocity * windows.dt_s[:, None]
    # Constant velocity fitted by least squares over the whole window (length >= 2).
    f, v = windows.features.astype(np.float64), windows.valid > 0
    t = np.where(v, f[:, :, 4], 0.0)
    count = v.sum(axis=1)
    t_mean = t.sum(axis=1) / count
    dt = np.where(v, f[:, :, 4] - t_mean[:, None], 0.0)
    denom = (dt**2).sum(axis=1)
    fitted = np.full((n, 2), np.nan)
    for axis in range(2):
        p = np.where(v, f[:, :, axis], 0.0)
        p_mean = p.sum(axis=1) / count
        slope = (dt * np.where(v, f[:, :, axis] - p_mean[:, None], 0.0)).sum(axis=1) / np.where(denom > 0, denom, np.nan)
        fitted[:, axis] = slope * windows.dt_s
    return {"zero": zero, "cv_last_two_measurements": cv_last_two, "cv_least_squares_window": fitted}


def evaluate(model: PRModel, windows: Windows) -> dict:
    """Validation metrics of the model and of the baselines, against the true displacement, and
    the calibration of the model's covariance."""
    prediction, predicted_cov = predict_windows(model, windows.features, windows.valid, windows.length, windows.line_of_sight)
    truth = windows.true_displacement.astype(np.float64)
    result = {"model": {}, "baselines": {}}
    one_step = windows.horizon == 1
    groups = {"all_horizons": np.ones(len(windows), bool), "one_step": one_step}
    for name, code in CLASSES.items():
        mask = one_step & (windows.object_class == code)
        if mask.any():
            groups[f"one_step_{name}"] = mask
    for group, mask in groups.items():
        result["model"][group] = rmse(prediction[mask] - truth[mask])
    for name, estimate in baselines(windows).items():
        result["baselines"][name] = {}
        for group, mask in groups.items():
            usable = mask & np.isfinite(estimate).all(axis=1)
            entry = rmse(estimate[usable] - truth[usable])
            entry["note"] = "windows of length >= 2 only" if name != "zero" else None
            result["baselines"][name][group] = entry
    # Against the measured displacement z_{j+1} - z_j: includes the noise of two measurements.
    result["model"]["one_step_against_measured_displacement"] = rmse(
        prediction[one_step] - windows.measured_displacement[one_step]
    )
    # Shorter histories: every one-step window cut to its latest L rows.
    by_length = {}
    for length in range(1, MAX_HISTORY + 1):
        mask = one_step & (windows.length >= length)
        new_length = np.full(mask.sum(), length)
        f, v = truncate(windows.features[mask], windows.valid[mask], windows.length[mask], new_length)
        by_length[str(length)] = rmse(predict_windows(model, f, v, new_length, windows.line_of_sight[mask])[0] - truth[mask])
    result["model"]["one_step_by_history_length"] = by_length
    # Calibration of the predicted covariance, by group.
    result["calibration"] = {
        group: calibration(prediction[mask] - truth[mask], predicted_cov[mask]) for group, mask in groups.items()
    }
    # Residual covariance of the one-step displacement, m^2, and what it suggests for Q_PR. The
    # tracker adds Q_PR once per frame (radar scan), and an object is measured only every few
    # frames, so the covariance per measurement interval is spread over the mean number of frames
    # in such an interval.
    residual = prediction[one_step] - truth[one_step]
    frames = windows.frames_ahead[one_step]
    result["residual_covariance_m2"] = {"all": covariance(residual)}
    result["mean_frames_per_measurement_interval"] = {"all": float(frames.mean())}
    result["suggested_process_noise_covariance_m2"] = {}
    for name, code in CLASSES.items():
        mask = windows.object_class[one_step] == code
        if mask.any():
            cov = np.asarray(covariance(residual[mask]))
            per_frame = float(frames[mask].mean())
            result["residual_covariance_m2"][name] = cov.tolist()
            result["mean_frames_per_measurement_interval"][name] = per_frame
            result["suggested_process_noise_covariance_m2"][name] = (cov / per_frame).tolist()
    return result


def evaluate_set(model: PRModel, windows: Windows) -> dict:
    """Short metrics of one data set's validation windows: RMSE one step and over all horizons,
    NLL and calibration."""
    prediction, predicted_cov = predict_windows(model, windows.features, windows.valid, windows.length, windows.line_of_sight)
    error = prediction - windows.true_displacement.astype(np.float64)
    one_step = windows.horizon == 1
    result = {
        "rmse_one_step": rmse(error[one_step]),
        "rmse_all_horizons": rmse(error),
        "calibration_one_step": calibration(error[one_step], predicted_cov[one_step]),
        "calibration_all_horizons": calibration(error, predicted_cov),
    }
    for name, code in CLASSES.items():
        mask = one_step & (windows.object_class == code)
        if mask.any():
            result[f"rmse_one_step_{name}"] = rmse(error[mask])
            result[f"calibration_one_step_{name}"] = calibration(error[mask], predicted_cov[mask])
    return result


class DataSet:
    """One generator configuration's windows: training (None for a held-out set) and validation."""

    def __init__(self, name: str, root: str, held_out: bool, args):
        self.name, self.held_out = name, held_out
        load = lambda split: load_split(  # noqa: E731
            os.path.join(root, split), args.max_horizon, args.max_horizon_s, args.max_gap_s, args.frame, args.mounts
        )
        self.root = root
        self.train, self.train_files = (None, []) if held_out else load("train")
        self.validation, self.validation_files = load("validation")
        scenario = os.path.join(args.scenario_dir, f"{name}.toml")
        if os.path.exists(scenario):
            with open(scenario, "rb") as handle:
                config = tomllib.load(handle)
            self.source = {
                "scenario_file": os.path.relpath(scenario, os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                "scenario_sha256": file_digest(scenario),
                "seed_base": config.get("splits", {}).get("seed_base", DEFAULT_PRESET_SEED_BASE),
            }
        elif name == "default":
            self.source = {"preset": "default", "seed_base": args.data_seed_base}
        else:
            # A generator preset of that name, with its own seed base (primm generate --preset NAME).
            self.source = {"preset": name, "seed_base": "the preset's own"}

    def describe(self) -> dict:
        entry = dict(self.source)
        entry["role"] = "held out (validation only, never trained on)" if self.held_out else "training"
        if self.train is not None:
            entry["train"] = {
                "directory": os.path.join(self.root, "train"), "sequences": len(self.train_files),
                "windows": len(self.train), "sha256_of_files": files_digest(self.train_files),
            }
        entry["validation"] = {
            "directory": os.path.join(self.root, "validation"), "sequences": len(self.validation_files),
            "windows": len(self.validation), "sha256_of_files": files_digest(self.validation_files),
        }
        return entry


def load_sets(args) -> list[DataSet]:
    if args.sets is None:
        if not os.path.isdir(os.path.join(args.data, "train")):
            raise SystemExit(f"{args.data} has no train/ directory; name the data sets with --sets")
        sets = [DataSet("default", args.data, False, args)]
    else:
        sets = [DataSet(name, os.path.join(args.data, name), False, args) for name in args.sets]
    sets += [DataSet(name, os.path.join(args.data, name), True, args) for name in args.held_out]
    if args.selection_set not in [d.name for d in sets if not d.held_out]:
        raise SystemExit(f"the selection set {args.selection_set} is not among the training sets")
    return sets


class Validation:
    """One validation split prepared for the per-epoch loss: windows in the model's frame."""

    def __init__(self, windows: Windows, args):
        cos, sin = input_frames(args.input_frame, windows.features, windows.length, windows.line_of_sight)
        self.features = torch.from_numpy(to_model_frame(windows.features, cos, sin))
        self.valid = torch.from_numpy(windows.valid)
        self.target = torch.from_numpy(vectors_to_model_frame(labels(windows, args.target), cos, sin))
        self.weight = torch.from_numpy(loss_weight(windows.dt_s, args.full_weight_horizon_s))

    def losses(self, model: PRModel, target_scale: torch.Tensor) -> dict:
        model.eval()
        with torch.no_grad():
            parts = [model(self.features[s : s + 4096], self.valid[s : s + 4096]) for s in range(0, len(self.features), 4096)]
            prediction = torch.cat([p[0] for p in parts])
            cholesky = torch.cat([p[1] for p in parts])
            mse = float(((((prediction - self.target) / target_scale) ** 2).sum(dim=1) * self.weight).mean())
            nll, squared = gaussian_nll(prediction, cholesky.double(), self.target.double())
            return {
                "mse_loss": mse,
                "nll_loss": float((nll * self.weight).mean()),
                "rmse_xy_m": float(((prediction - self.target) ** 2).sum(dim=1).mean().sqrt()),
                "mean_squared_mahalanobis": float(squared.mean()),
            }


def train(args) -> None:
    started = time.time()
    seed_everything(args.seed)
    torch.set_num_threads(args.threads)
    print(f"loading windows from {args.data} ...", flush=True)
    sets = load_sets(args)
    for d in sets:
        print(
            f"  {d.name:20s} {'held out' if d.held_out else 'training'}: "
            f"{0 if d.train is None else len(d.train)} training windows from {len(d.train_files)} sequences, "
            f"{len(d.validation)} validation windows from {len(d.validation_files)} sequences",
            flush=True,
        )
    training_sets = [d for d in sets if not d.held_out]
    selection = next(d for d in training_sets if d.name == args.selection_set)
    train_windows = Windows.concatenate([d.train for d in training_sets])
    print(f"{len(train_windows)} training windows in all ({time.time() - started:.1f} s)", flush=True)
    mean, std, scale = normalisation(train_windows, args.target, np.random.default_rng(args.seed + 2), args.input_frame)
    model = PRModel(args.d_model, args.heads, args.layers, args.d_ff, mean, std, scale)
    model.input_frame = args.input_frame
    print(f"model: {model.parameter_count()} parameters", flush=True)
    optimiser = torch.optim.AdamW(model.parameters(), lr=args.learning_rate, weight_decay=args.weight_decay)
    steps_per_epoch = math.ceil(min(len(train_windows), args.samples_per_epoch) / args.batch_size)
    total_steps = steps_per_epoch * args.epochs
    warmup = steps_per_epoch

    def learning_rate_factor(step: int) -> float:
        if step < warmup:
            return (step + 1) / warmup
        progress = (step - warmup) / max(1, total_steps - warmup)
        return 0.5 * (1.0 + math.cos(math.pi * min(1.0, progress)))

    scheduler = torch.optim.lr_scheduler.LambdaLR(optimiser, learning_rate_factor)
    target_scale = torch.from_numpy(scale.astype(np.float32))
    validations = {d.name: Validation(d.validation, args) for d in sets}
    selection_key = "mse_loss" if args.loss == "mse" else "nll_loss"
    train_labels = labels(train_windows, args.target)
    rng = np.random.default_rng(args.seed)
    best = (math.inf, -1, None)
    history = []
    for epoch in range(args.epochs):
        epoch_started = time.time()
        # This epoch's windows, drawn without replacement from the pooled training sets.
        order = rng.permutation(len(train_windows))[: args.samples_per_epoch]
        length = train_windows.length[order]
        # A fresh choice of shorter histories every epoch.
        new_length = length.copy()
        cut = rng.random(len(order)) < args.truncate_probability
        new_length[cut] = rng.integers(1, length[cut] + 1)
        features, valid = truncate(train_windows.features[order], train_windows.valid[order], length, new_length)
        # Into each window's model input axes (random for windows without a direction).
        cos, sin = input_frames(args.input_frame, features, new_length, train_windows.line_of_sight[order], rng)
        features = to_model_frame(features, cos, sin)
        target = vectors_to_model_frame(train_labels[order], cos, sin)
        horizon = train_windows.dt_s[order].copy()
        # Time scaling: the same paths travelled k times slower (k < 1: faster).
        k = np.ones(len(order))
        if args.time_scale > 1.0:
            scaled = rng.random(len(order)) < args.time_scale_probability
            k[scaled] = np.exp(rng.uniform(-math.log(args.time_scale), math.log(args.time_scale), scaled.sum()))
            features = scale_time(features, k)
            horizon = horizon * k
        # Mirroring across the motion axis.
        if args.mirror_probability > 0.0:
            mirrored = rng.random(len(order)) < args.mirror_probability
            features[mirrored, :, 1] *= -1.0
            target[mirrored, 1] *= -1.0
        features, valid = torch.from_numpy(features), torch.from_numpy(valid)
        target = torch.from_numpy(target)
        weight = torch.from_numpy(loss_weight(horizon, args.full_weight_horizon_s))
        joint = args.loss in ("nll", "nll+mse") and epoch >= args.mse_warmup_epochs
        model.train()
        total, count = 0.0, 0
        for start in range(0, len(order), args.batch_size):
            index = slice(start, start + args.batch_size)
            prediction, cholesky = model(features[index], valid[index])
            if joint:
                nll, _ = gaussian_nll(prediction, cholesky, target[index])
                if args.loss == "nll+mse":
                    nll = nll + (((prediction - target[index]) / target_scale) ** 2).sum(dim=1)
                loss = (nll * weight[index]).mean()
            else:
                mse = (((prediction - target[index]) / target_scale) ** 2).sum(dim=1)
                nll, _ = gaussian_nll(prediction.detach(), cholesky, target[index])
                loss = ((mse + nll) * weight[index]).mean()
            loss = loss + 0.01 * torch.relu(score_bound(model) - args.score_bound_limit) ** 2
            optimiser.zero_grad(set_to_none=True)
            loss.backward()
            torch.nn.utils.clip_grad_norm_(model.parameters(), 1.0)
            optimiser.step()
            scheduler.step()
            total += loss.item() * len(prediction)
            count += len(prediction)
        losses = {name: v.losses(model, target_scale) for name, v in validations.items()}
        selected = losses[selection.name][selection_key]
        entry = {"epoch": epoch + 1, "train_loss": total / count, "joint_nll": joint,
                 "validation_loss": selected, "validation": losses}
        history.append(entry)
        improved = selected < best[0]
        if improved:
            best = (selected, epoch + 1, copy.deepcopy(model.state_dict()))
        held_out = "".join(
            f"  held-out {d.name} NLL {losses[d.name]['nll_loss']:.3f} RMSE {losses[d.name]['rmse_xy_m']:.3f} m"
            for d in sets if d.held_out
        )
        others = [d.name for d in training_sets if d.name != selection.name]
        mean_other = float(np.mean([losses[n]["nll_loss"] for n in others])) if others else float("nan")
        print(
            f"epoch {epoch + 1:3d}/{args.epochs}  train loss {total / count:.4f}{'' if joint else ' (mse warm-up)'}  "
            f"{selection.name} validation NLL {losses[selection.name]['nll_loss']:.4f} "
            f"MSE loss {losses[selection.name]['mse_loss']:.4f} RMSE {losses[selection.name]['rmse_xy_m']:.4f} m "
            f"d2 {losses[selection.name]['mean_squared_mahalanobis']:.2f}  other sets NLL {mean_other:.3f}{held_out}  "
            f"{'*' if improved else ' '}  {time.time() - epoch_started:.1f} s (total {time.time() - started:.0f} s)",
            flush=True,
        )
        if epoch + 1 - best[1] >= args.patience:
            print(f"no improvement for {args.patience} epochs, stopping", flush=True)
            break
    model.load_state_dict(best[2])
    model.eval()
    os.makedirs(args.out, exist_ok=True)
    torch.save({"state_dict": best[2], "args": vars(args)}, os.path.join(args.out, "pr_training_state.pt"))
    training_seconds = time.time() - started
    print(f"best epoch {best[1]} ({selection.name} validation {selection_key} {best[0]:.4f}); "
          f"training took {training_seconds:.0f} s", flush=True)

    metrics = evaluate(model, selection.validation)
    per_set = {d.name: evaluate_set(model, d.validation) for d in sets}
    onnx_path = os.path.join(args.out, "pr.onnx")
    logit_bound = export(model, onnx_path, selection.validation)
    parity_path = os.path.join(args.out, "pr_parity.json")
    parity = write_parity(model, selection.validation, parity_path, args.seed)
    runtime_check = check_with_onnxruntime(onnx_path, parity)
    write_metadata(args, model, mean, std, scale, sets, selection, train_windows, metrics, per_set,
                   history, best, training_seconds, onnx_path, runtime_check, logit_bound, started)
    print_summary(metrics, per_set, sets)


def export(model: PRModel, path: str, check: Windows) -> float:
    """Writes the trained model as the ONNX graph of :mod:`onnx_graph` (opset 17, dynamic batch
    axis only). Checks that the graph's NumPy reference computes the trained function (both
    outputs) and that no attention score can overflow ``exp``; returns the score bound."""
    import onnx

    bound = ExportGraph(model).logit_bound()
    subtract_max = bound > SCORE_BOUND_WITHOUT_MAX
    print(
        f"attention score bound from the weights: {bound:.1f} (exp overflows above 88.7); "
        f"softmax {'subtracts' if subtract_max else 'needs no'} row maximum",
        flush=True,
    )
    weights = {name: value.detach().cpu().numpy() for name, value in model.state_dict().items()}
    heads = model.layers[0].attention.heads
    f, v = check.features[:4096], check.valid[:4096]
    cos, sin = input_frames(model.input_frame, f, check.length[:4096], check.line_of_sight[:4096])
    f = to_model_frame(f, cos, sin)
    with torch.no_grad():
        trained, trained_cholesky = (t.numpy() for t in model(torch.from_numpy(f), torch.from_numpy(v)))
    reference, reference_cholesky = onnx_graph.reference_forward(weights, f, v, heads)
    difference = float(np.abs(reference - trained).max())
    difference_cholesky = float(np.abs(reference_cholesky - trained_cholesky).max())
    print(f"graph reference vs trained model: max abs difference {difference:.2e} m (displacement), "
          f"{difference_cholesky:.2e} m (Cholesky factor)", flush=True)
    if max(difference, difference_cholesky) > 1e-4:
        raise RuntimeError("the export graph does not compute the trained function")
    onnx.save(onnx_graph.build_graph(weights, heads, subtract_max=subtract_max, input_frame=model.input_frame), path)
    print(f"wrote {path} ({os.path.getsize(path)} bytes)", flush=True)
    return bound


def write_parity(model: PRModel, windows: Windows, path: str, seed: int) -> dict:
    """PARITY_SAMPLES validation windows with every history length, and the model's outputs."""
    rng = np.random.default_rng(seed + 1)
    index = rng.choice(len(windows), PARITY_SAMPLES, replace=False)
    lengths = np.minimum(windows.length[index], 1 + np.arange(PARITY_SAMPLES) % MAX_HISTORY)
    features, valid = truncate(windows.features[index], windows.valid[index], windows.length[index], lengths)
    cos, sin = input_frames(model.input_frame, features, lengths, windows.line_of_sight[index])
    features = to_model_frame(features, cos, sin)
    output, cholesky = predict(model, features, valid)
    parity = {
        "description": f"PR model inputs (eq:pr_input rows, right padded, in the model's input axes: {model.input_frame}) "
        "and the PyTorch outputs: displacement [dx, dy] (m) and cholesky [l_xx, l_yx, l_yy] (m), the "
        "lower-triangular factor of the displacement error covariance",
        "features": [[[float(v) for v in row] for row in sample] for sample in features],
        "valid": [[float(v) for v in sample] for sample in valid],
        "length": [int(v) for v in lengths],
        "displacement": [[float(v) for v in sample] for sample in output],
        "cholesky": [[float(v) for v in sample] for sample in cholesky],
    }
    with open(path, "w") as handle:
        json.dump(parity, handle, indent=1)
        handle.write("\n")
    print(f"wrote {path}", flush=True)
    return parity


def check_with_onnxruntime(path: str, parity: dict):
    """Max abs difference between onnxruntime and PyTorch on the parity inputs, per output (None
    without onnxruntime)."""
    try:
        import onnxruntime
    except ImportError:
        return None
    session = onnxruntime.InferenceSession(path, providers=["CPUExecutionProvider"])
    names = [o.name for o in session.get_outputs()]
    if names != OUTPUT_NAMES:
        raise RuntimeError(f"the exported model's outputs are {names}, expected {OUTPUT_NAMES}")
    displacement, cholesky = session.run(None, {"features": np.asarray(parity["features"], np.float32),
                                                "valid": np.asarray(parity["valid"], np.float32)})
    result = {
        "displacement": float(np.abs(displacement - np.asarray(parity["displacement"], np.float32)).max()),
        "displacement_cholesky": float(np.abs(cholesky - np.asarray(parity["cholesky"], np.float32)).max()),
    }
    print(f"onnxruntime vs PyTorch on the parity inputs: max abs difference {result['displacement']:.2e} m "
          f"(displacement), {result['displacement_cholesky']:.2e} m (Cholesky factor)", flush=True)
    if max(result.values()) > 1e-4:
        raise RuntimeError("onnxruntime and PyTorch disagree on the parity inputs")
    return result


def files_digest(paths) -> str:
    """SHA-256 over the contents of the files, in order (identifies the data set)."""
    digest = hashlib.sha256()
    for path in paths:
        with open(path, "rb") as handle:
            digest.update(handle.read())
    return digest.hexdigest()


def file_digest(path: str) -> str:
    with open(path, "rb") as handle:
        return hashlib.sha256(handle.read()).hexdigest()


def write_metadata(args, model, mean, std, scale, sets, selection, train_windows, metrics, per_set,
                   history, best, training_seconds, onnx_path, runtime_check, logit_bound, started) -> None:
    held_out = [d.name for d in sets if d.held_out]
    metadata = {
        "model_file": os.path.basename(onnx_path),
        "model_sha256": file_digest(onnx_path),
        "format": {
            "onnx_opset": OPSET,
            "exporter": onnx_graph.EXPORTER,
            "graph": onnx_graph.GRAPH_DESCRIPTION,
            "attention_score_bound": logit_bound,
        },
        "inputs": [
            {
                "name": "features",
                "shape": [BATCH_AXIS, MAX_HISTORY, 5],
                "dtype": "float32",
                "layout": "eq:pr_input rows oldest first; rows 0..len valid, rows len..5 zero (right padding)",
                "features": FEATURE_NAMES,
                "input_frame": args.input_frame,
                "input_frame_meaning": INPUT_FRAME_MEANING[args.input_frame],
                "input_frame_onnx_metadata": {INPUT_FRAME_KEY: args.input_frame},
                "training_positions": (
                    "world frame (each measurement mapped with its frame's ego pose)"
                    if args.frame == "world"
                    else "vehicle frame"
                ),
            },
            {"name": "valid", "shape": [BATCH_AXIS, MAX_HISTORY], "dtype": "float32",
             "layout": "1.0 for rows 0..len, 0.0 for padded rows"},
        ],
        "outputs": [
            {"name": "displacement", "shape": [BATCH_AXIS, 2], "dtype": "float32",
             "meaning": "[dx, dy] in metres from the latest history measurement to the prediction time "
                        "(true object-centre displacement), in the input frame"},
            {"name": "displacement_cholesky", "shape": [BATCH_AXIS, 3], "dtype": "float32",
             "meaning": "[l_xx, l_yx, l_yy] in metres: the lower-triangular Cholesky factor L = [[l_xx, 0], "
                        "[l_yx, l_yy]] of the covariance Sigma = L L^T (m^2) of the error of the displacement "
                        "(true minus predicted), in the same frame as the displacement (rotate Sigma back with "
                        "R Sigma R^T)",
             "computed_as": "r = head_cholesky(final query outputs); l_xx = softplus(r_0) * output_scale_x + floor, "
                            "l_yx = r_1 * output_scale_y, l_yy = softplus(r_2) * output_scale_y + floor; softplus "
                            "as max(r, 0) + log(1 + exp(-|r|))",
             "diagonal_floor_m": CHOLESKY_FLOOR_M},
        ],
        "normalisation": {
            "note": "applied inside the graph as (features - mean) * (1 / std); the output is the head's value times output_scale",
            "feature_mean": [float(v) for v in mean],
            "feature_std": [float(v) for v in std],
            "output_scale_m": [float(v) for v in scale],
        },
        "hyper_parameters": {
            "d_model": args.d_model, "heads": args.heads, "layers": args.layers, "d_ff": args.d_ff,
            "norm": "pre-LayerNorm", "activation": "relu", "positional_embedding": "learned, one per history row",
            "query_tokens": 2, "parameters": model.parameter_count(),
            "uncertainty_head": "one linear layer from both query outputs [2 d] to [l_xx, l_yx, l_yy] (raw)",
        },
        "training": {
            "target": (
                "true displacement p_{j+h} - p_j (true_x, true_y columns) from the latest history measurement j"
                if args.target == "true"
                else "measured displacement z_{j+h} - z_j from the latest history measurement j"
            ),
            "sensor_mounts": {
                "file": os.path.relpath(os.path.abspath(args.sensor_config), os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                "mounts_m": {str(k): list(v) for k, v in sorted(args.mounts.items())},
            },
            "horizons": f"the next 1..{args.max_horizon} measurements of the object, at most {args.max_horizon_s} s ahead",
            "loss": (
                f"the first {args.mse_warmup_epochs} epoch(s): squared displacement error divided by output_scale "
                "(mean head) plus the Gaussian NLL of the true displacement under N(detached prediction, L L^T) "
                "(covariance head); then the Gaussian NLL under N(prediction, L L^T) for both heads"
                if args.loss == "nll"
                else f"the first {args.mse_warmup_epochs} epoch(s) as for mse; then the Gaussian NLL under "
                "N(prediction, L L^T) for both heads plus the squared displacement error divided by output_scale"
                if args.loss == "nll+mse"
                else "squared displacement error divided by output_scale (mean head) plus the Gaussian NLL of the "
                "true displacement under N(detached prediction, L L^T) (covariance head)"
            ) + f"; every window weighted by min(1, ({args.full_weight_horizon_s} s / horizon)^2), mean over windows",
            "loss_mode": args.loss, "mse_warmup_epochs": args.mse_warmup_epochs,
            "selection": f"lowest {'scaled squared error' if args.loss == 'mse' else 'NLL'} loss on the validation "
                         f"split of `{selection.name}`",
            "augmentation": {
                "truncate_probability": args.truncate_probability,
                "random_orientation": "windows without a direction (no line of sight, or no motion for "
                "latest_motion) get a random rotation every epoch",
                "time_scale": (
                    f"with probability {args.time_scale_probability}: times x k, radial velocities / k, log k "
                    f"uniform in [-log {args.time_scale}, log {args.time_scale}]; positions and label unchanged"
                    if args.time_scale > 1.0
                    else "off"
                ),
                "mirror_probability": args.mirror_probability,
            },
            "max_gap_s": args.max_gap_s,
            "optimiser": "AdamW", "learning_rate": args.learning_rate, "weight_decay": args.weight_decay,
            "batch_size": args.batch_size, "epochs_max": args.epochs, "patience": args.patience,
            "truncate_probability": args.truncate_probability, "seed": args.seed,
            "samples_per_epoch": args.samples_per_epoch, "epochs_run": len(history),
            "full_weight_horizon_s": args.full_weight_horizon_s, "score_bound_limit": args.score_bound_limit,
            "best_epoch": best[1], "best_validation_loss": best[0], "seconds": round(training_seconds, 1),
            "seconds_per_epoch": round(training_seconds / max(1, len(history)), 1),
            "threads": args.threads, "machine": platform.machine(), "processor_count": os.cpu_count(),
            "history": history,
        },
        "data": {
            "generator": "primm generate (--preset NAME: default, turning, clutter, extended, robustness; or --scenario training/scenarios/NAME.toml)",
            "sets": {d.name: d.describe() for d in sets},
            "training_windows": len(train_windows),
            "selection_set": selection.name,
            "held_out_sets": held_out,
            "objects_note": "windows grouped by ground-truth id; evaluation splits are never read",
            "scenario_seeds": "sequence i of split k uses seed_base + k * 2^40 + i (docs/scenario.md)",
        },
        "validation": metrics,
        "validation_by_set": per_set,
        "held_out": {name: per_set[name] for name in held_out},
        "onnxruntime_max_abs_difference_m": runtime_check,
        "created": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
    }
    metadata["training"]["seconds_total_with_evaluation"] = round(time.time() - started, 1)
    path = os.path.join(args.out, "pr.json")
    metadata["format"]["softmax_subtracts_row_max"] = logit_bound > SCORE_BOUND_WITHOUT_MAX
    with open(path, "w") as handle:
        json.dump(metadata, handle, indent=2)
        handle.write("\n")
    print(f"wrote {path}", flush=True)


def print_summary(metrics: dict, per_set: dict, sets: list) -> None:
    print("\nselection set, validation, RMSE_xy against the true displacement:")
    for group, entry in metrics["model"].items():
        if isinstance(entry, dict) and "rmse_xy_m" in entry:
            print(f"  PR {group:40s} {entry['rmse_xy_m']:.4f} m  ({entry['samples']} windows)")
    for name, groups in metrics["baselines"].items():
        entry = groups["one_step"]
        print(f"  baseline {name:34s} {entry['rmse_xy_m']:.4f} m  ({entry['samples']} windows)")
    for length, entry in metrics["model"]["one_step_by_history_length"].items():
        print(f"  PR with history length {length}: {entry['rmse_xy_m']:.4f} m")
    print("residual covariance (m^2):", json.dumps(metrics["residual_covariance_m2"]))
    print("\nper set (validation split): one-step RMSE_xy, all-horizon RMSE_xy, NLL, mean d^2, inside 95 % ellipse")
    for d in sets:
        e = per_set[d.name]
        c = e["calibration_all_horizons"]
        print(f"  {d.name:20s} {'(held out) ' if d.held_out else ''}{e['rmse_one_step']['rmse_xy_m']:.4f} m  "
              f"{e['rmse_all_horizons']['rmse_xy_m']:.4f} m  NLL {c['nll']:.3f}  d2 {c['mean_squared_mahalanobis']:.2f}  "
              f"{100 * c['fraction_inside_95_ellipse']:.1f} %")


if __name__ == "__main__":
    train(parse_args())
