"""Trains the PR model from scratch and exports it for primm.

    python training/train.py --data data --out models

reads ``DATA/train/*.csv`` and ``DATA/validation/*.csv`` (written by
``primm generate --output DATA``), trains with a fixed seed, keeps the epoch with the lowest
validation loss, and writes

* ``OUT/pr.onnx``: the model (opset 17, dynamic batch axis ``batch``);
* ``OUT/pr.json``: inputs, outputs, layout, normalisation, data, hyper-parameters, validation
  metrics and the validation residual covariance of the displacement (a value for ``Q_PR``);
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

import numpy as np
import torch

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from dataset import (  # noqa: E402
    CLASSES,
    MAX_HISTORY,
    Windows,
    load_split,
    motion_frames,
    to_model_frame,
    truncate,
    vectors_from_model_frame,
    vectors_to_model_frame,
)
from model import ExportGraph, PRModel, score_bound  # noqa: E402
import onnx_graph  # noqa: E402

OPSET = 17
INPUT_NAMES = ["features", "valid"]
OUTPUT_NAMES = ["displacement"]
BATCH_AXIS = "batch"
FEATURE_NAMES = ["x_minus_x_latest_m", "y_minus_y_latest_m", "radial_velocity_mps", "rcs_dbsm", "t_minus_t_prediction_s"]
PARITY_SAMPLES = 64
# Above this bound on the attention scores the exported softmax subtracts each row's maximum.
SCORE_BOUND_WITHOUT_MAX = 60.0


def parse_args(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--data", default="data", help="directory with train/ and validation/ CSV files")
    parser.add_argument("--out", default="models", help="output directory")
    parser.add_argument("--seed", type=int, default=20240607)
    parser.add_argument(
        "--data-seed-base",
        type=int,
        default=88314347343104,
        help="the --seed-base the data was generated with (recorded in pr.json; default: the preset's)",
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
    parser.add_argument("--threads", type=int, default=1, help="PyTorch threads (1 is fastest on a busy 2-core machine)")
    return parser.parse_args(argv)


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


def normalisation(train: Windows, target: str, rng: np.random.Generator):
    """Mean and standard deviation of each feature over the valid rows, and the per-axis RMS of
    the displacement label, both in the model's input frame."""
    cos, sin = motion_frames(train.features, train.length, rng)
    rows = to_model_frame(train.features, cos, sin)[train.valid > 0]
    mean = rows.mean(axis=0).astype(np.float64)
    std = rows.std(axis=0).astype(np.float64)
    std = np.where(std > 1e-6, std, 1.0)
    target = vectors_to_model_frame(labels(train, target), cos, sin)
    scale = np.sqrt((target.astype(np.float64) ** 2).mean(axis=0))
    return mean, std, scale


def predict_windows(model: PRModel, features: np.ndarray, valid: np.ndarray, length: np.ndarray) -> np.ndarray:
    """The model's displacements for windows given in the data's frame: each rotated into the
    frame of its latest motion, predicted, and rotated back (what primm-predictor does)."""
    cos, sin = motion_frames(features, length)
    return vectors_from_model_frame(predict(model, to_model_frame(features, cos, sin), valid), cos, sin)


def predict(model: PRModel, features: np.ndarray, valid: np.ndarray, batch: int = 4096) -> np.ndarray:
    model.eval()
    out = []
    with torch.no_grad():
        for start in range(0, len(features), batch):
            f = torch.from_numpy(features[start : start + batch])
            v = torch.from_numpy(valid[start : start + batch])
            out.append(model(f, v).numpy())
    return np.concatenate(out) if out else np.zeros((0, 2), np.float32)


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
    """Validation metrics of the model and of the baselines, against the true displacement."""
    prediction = predict_windows(model, windows.features, windows.valid, windows.length)
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
        by_length[str(length)] = rmse(predict_windows(model, f, v, new_length) - truth[mask])
    result["model"]["one_step_by_history_length"] = by_length
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


def train(args) -> None:
    started = time.time()
    seed_everything(args.seed)
    torch.set_num_threads(args.threads)
    print(f"loading windows from {args.data} ...", flush=True)
    train_windows, train_files = load_split(
        os.path.join(args.data, "train"), args.max_horizon, args.max_horizon_s, args.max_gap_s, args.frame
    )
    val_windows, val_files = load_split(
        os.path.join(args.data, "validation"), args.max_horizon, args.max_horizon_s, args.max_gap_s, args.frame
    )
    print(
        f"{len(train_windows)} training windows from {len(train_files)} sequences, "
        f"{len(val_windows)} validation windows from {len(val_files)} sequences ({time.time() - started:.1f} s)",
        flush=True,
    )
    mean, std, scale = normalisation(train_windows, args.target, np.random.default_rng(args.seed + 2))
    model = PRModel(args.d_model, args.heads, args.layers, args.d_ff, mean, std, scale)
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
    val_cos, val_sin = motion_frames(val_windows.features, val_windows.length)
    val_features = torch.from_numpy(to_model_frame(val_windows.features, val_cos, val_sin))
    val_valid = torch.from_numpy(val_windows.valid)
    val_target = torch.from_numpy(vectors_to_model_frame(labels(val_windows, args.target), val_cos, val_sin))
    train_weight = torch.from_numpy(loss_weight(train_windows.dt_s, args.full_weight_horizon_s))
    val_weight = torch.from_numpy(loss_weight(val_windows.dt_s, args.full_weight_horizon_s))
    rng = np.random.default_rng(args.seed)
    best = (math.inf, -1, None)
    history = []
    for epoch in range(args.epochs):
        epoch_started = time.time()
        # A fresh choice of shorter histories every epoch.
        cut = rng.random(len(train_windows)) < args.truncate_probability
        new_length = train_windows.length.copy()
        new_length[cut] = rng.integers(1, train_windows.length[cut] + 1)
        features, valid = truncate(train_windows.features, train_windows.valid, train_windows.length, new_length)
        # Into the frame of each window's latest motion (random for windows without one).
        cos, sin = motion_frames(features, new_length, rng)
        features, valid = torch.from_numpy(to_model_frame(features, cos, sin)), torch.from_numpy(valid)
        target = torch.from_numpy(vectors_to_model_frame(labels(train_windows, args.target), cos, sin))
        order = torch.from_numpy(rng.permutation(len(train_windows))[: args.samples_per_epoch])
        model.train()
        total, count = 0.0, 0
        for start in range(0, len(order), args.batch_size):
            index = order[start : start + args.batch_size]
            prediction = model(features[index], valid[index])
            loss = ((((prediction - target[index]) / target_scale) ** 2).sum(dim=1) * train_weight[index]).mean()
            loss = loss + 0.01 * torch.relu(score_bound(model) - args.score_bound_limit) ** 2
            optimiser.zero_grad(set_to_none=True)
            loss.backward()
            torch.nn.utils.clip_grad_norm_(model.parameters(), 1.0)
            optimiser.step()
            scheduler.step()
            total += loss.item() * len(index)
            count += len(index)
        model.eval()
        with torch.no_grad():
            val_prediction = torch.cat(
                [model(val_features[s : s + 4096], val_valid[s : s + 4096]) for s in range(0, len(val_features), 4096)]
            )
            val_loss = float(((((val_prediction - val_target) / target_scale) ** 2).sum(dim=1) * val_weight).mean())
            val_rmse = float(((val_prediction - val_target) ** 2).sum(dim=1).mean().sqrt())
        history.append({"epoch": epoch + 1, "train_loss": total / count, "validation_loss": val_loss, "validation_rmse_xy_m": val_rmse})
        improved = val_loss < best[0]
        if improved:
            best = (val_loss, epoch + 1, copy.deepcopy(model.state_dict()))
        print(
            f"epoch {epoch + 1:3d}/{args.epochs}  train loss {total / count:.4f}  validation loss {val_loss:.4f}  "
            f"validation RMSE {val_rmse:.4f} m  {'*' if improved else ' '}  "
            f"{time.time() - epoch_started:.1f} s (total {time.time() - started:.0f} s)",
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
    print(f"best epoch {best[1]} (validation loss {best[0]:.4f}); training took {training_seconds:.0f} s", flush=True)

    metrics = evaluate(model, val_windows)
    os.makedirs(args.out, exist_ok=True)
    onnx_path = os.path.join(args.out, "pr.onnx")
    logit_bound = export(model, onnx_path, val_windows)
    parity_path = os.path.join(args.out, "pr_parity.json")
    parity = write_parity(model, val_windows, parity_path, args.seed)
    runtime_check = check_with_onnxruntime(onnx_path, parity)
    write_metadata(args, model, mean, std, scale, train_windows, train_files, val_windows, val_files, metrics,
                   history, best, training_seconds, onnx_path, runtime_check, logit_bound)
    print_summary(metrics)


def export(model: PRModel, path: str, check: Windows) -> float:
    """Writes the trained model as the ONNX graph of :mod:`onnx_graph` (opset 17, dynamic batch
    axis only). Checks that the graph's NumPy reference computes the trained function and that
    no attention score can overflow ``exp``; returns the score bound."""
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
    with torch.no_grad():
        trained = model(torch.from_numpy(f), torch.from_numpy(v)).numpy()
    difference = float(np.abs(onnx_graph.reference_forward(weights, f, v, heads) - trained).max())
    print(f"graph reference vs trained model: max abs difference {difference:.2e} m", flush=True)
    if difference > 1e-4:
        raise RuntimeError("the export graph does not compute the trained function")
    onnx.save(onnx_graph.build_graph(weights, heads, subtract_max=subtract_max), path)
    print(f"wrote {path} ({os.path.getsize(path)} bytes)", flush=True)
    return bound


def write_parity(model: PRModel, windows: Windows, path: str, seed: int) -> dict:
    """PARITY_SAMPLES validation windows with every history length, and the model's outputs."""
    rng = np.random.default_rng(seed + 1)
    index = rng.choice(len(windows), PARITY_SAMPLES, replace=False)
    lengths = np.minimum(windows.length[index], 1 + np.arange(PARITY_SAMPLES) % MAX_HISTORY)
    features, valid = truncate(windows.features[index], windows.valid[index], windows.length[index], lengths)
    cos, sin = motion_frames(features, lengths)
    features = to_model_frame(features, cos, sin)
    output = predict(model, features, valid)
    parity = {
        "description": "PR model inputs (eq:pr_input rows, right padded, in the frame of the latest motion) "
        "and the PyTorch outputs, metres",
        "features": [[[float(v) for v in row] for row in sample] for sample in features],
        "valid": [[float(v) for v in sample] for sample in valid],
        "length": [int(v) for v in lengths],
        "displacement": [[float(v) for v in sample] for sample in output],
    }
    with open(path, "w") as handle:
        json.dump(parity, handle, indent=1)
        handle.write("\n")
    print(f"wrote {path}", flush=True)
    return parity


def check_with_onnxruntime(path: str, parity: dict):
    """Max abs difference between onnxruntime and PyTorch on the parity inputs (None without
    onnxruntime)."""
    try:
        import onnxruntime
    except ImportError:
        return None
    session = onnxruntime.InferenceSession(path, providers=["CPUExecutionProvider"])
    out = session.run(None, {"features": np.asarray(parity["features"], np.float32),
                             "valid": np.asarray(parity["valid"], np.float32)})[0]
    diff = float(np.abs(out - np.asarray(parity["displacement"], np.float32)).max())
    print(f"onnxruntime vs PyTorch on the parity inputs: max abs difference {diff:.2e} m", flush=True)
    return diff


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


def write_metadata(args, model, mean, std, scale, train_windows, train_files, val_windows, val_files, metrics,
                   history, best, training_seconds, onnx_path, runtime_check, logit_bound) -> None:
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
                "input_frame": (
                    "positions relative to the latest measurement, rotated so that the latest motion (second-latest "
                    "to latest measurement) points along +x; histories of one measurement or whose last two are "
                    "closer than 0.01 m unrotated (primm-predictor MotionFrame); the output displacement is in the "
                    "same frame and is rotated back by the caller"
                ),
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
                        "(true object-centre displacement)"},
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
        },
        "training": {
            "target": (
                "true displacement p_{j+h} - p_j (true_x, true_y columns) from the latest history measurement j"
                if args.target == "true"
                else "measured displacement z_{j+h} - z_j from the latest history measurement j"
            ),
            "horizons": f"the next 1..{args.max_horizon} measurements of the object, at most {args.max_horizon_s} s ahead",
            "loss": "squared displacement error divided by output_scale, summed over x and y, weighted by "
                    f"min(1, ({args.full_weight_horizon_s} s / horizon)^2), mean over windows",
            "max_gap_s": args.max_gap_s,
            "optimiser": "AdamW", "learning_rate": args.learning_rate, "weight_decay": args.weight_decay,
            "batch_size": args.batch_size, "epochs_max": args.epochs, "patience": args.patience,
            "truncate_probability": args.truncate_probability, "seed": args.seed,
            "samples_per_epoch": args.samples_per_epoch, "epochs_run": len(history),
            "full_weight_horizon_s": args.full_weight_horizon_s, "score_bound_limit": args.score_bound_limit,
            "best_epoch": best[1], "best_validation_loss": best[0], "seconds": round(training_seconds, 1),
            "threads": args.threads, "machine": platform.machine(), "processor_count": os.cpu_count(),
            "history": history,
        },
        "data": {
            "generator": "primm generate (default preset)",
            "seed_base": args.data_seed_base,
            "train": {"directory": os.path.join(args.data, "train"), "sequences": len(train_files),
                      "sha256_of_files": files_digest(train_files),
                      "windows": len(train_windows), "objects_note": "windows grouped by ground-truth id",
                      "first_file": os.path.basename(train_files[0]), "last_file": os.path.basename(train_files[-1])},
            "validation": {"directory": os.path.join(args.data, "validation"), "sequences": len(val_files),
                           "sha256_of_files": files_digest(val_files),
                           "windows": len(val_windows)},
            "scenario_seeds": "sequence i of split k uses seed_base + k * 2^40 + i (docs/scenario.md)",
        },
        "validation": metrics,
        "onnxruntime_max_abs_difference_m": runtime_check,
        "created": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
    }
    path = os.path.join(args.out, "pr.json")
    metadata["format"]["softmax_subtracts_row_max"] = logit_bound > SCORE_BOUND_WITHOUT_MAX
    with open(path, "w") as handle:
        json.dump(metadata, handle, indent=2)
        handle.write("\n")
    print(f"wrote {path}", flush=True)


def print_summary(metrics: dict) -> None:
    print("\nvalidation, one step, RMSE_xy against the true displacement:")
    for group, entry in metrics["model"].items():
        if isinstance(entry, dict) and "rmse_xy_m" in entry:
            print(f"  PR {group:40s} {entry['rmse_xy_m']:.4f} m  ({entry['samples']} windows)")
    for name, groups in metrics["baselines"].items():
        entry = groups["one_step"]
        print(f"  baseline {name:34s} {entry['rmse_xy_m']:.4f} m  ({entry['samples']} windows)")
    for length, entry in metrics["model"]["one_step_by_history_length"].items():
        print(f"  PR with history length {length}: {entry['rmse_xy_m']:.4f} m")
    print("residual covariance (m^2):", json.dumps(metrics["residual_covariance_m2"]))


if __name__ == "__main__":
    train(parse_args())
