#!/usr/bin/env python3
"""Tunes the physics modes' process noises and the association gates on validation data.

Coordinate descent over per-class parameters of ``config/primm.toml`` (cars and pedestrians):
the CV acceleration PSD, the CA jerk PSD, the CT acceleration and turn-rate PSDs, the gate and
the initial tangential speed spread. Each parameter in turn is multiplied by every factor of
``--factors`` while the others stay where they are; the best value is kept; the whole round is
repeated ``--rounds`` times. Every candidate is scored by ``primm eval --methods imm`` on each
directory of ``--data`` (validation splits only: the script refuses a directory named
``evaluation``), with the objective

    mean over the directories of  RMSE_xy + idf1_weight * max(0, IDF1_start - IDF1)

(RMSE_xy in metres against the true object centre; IDF1_start: the starting configuration's),
i.e. prior accuracy, without giving up identity. ``--velocity-weight-s W`` adds ``W * velocity
RMSE`` to each directory's term (W in seconds: the horizon over which a velocity error becomes a
position error; default 0, positions only), for users who plan on the tracks' velocities. The result is written as a complete TOML
file (the input with the chosen values substituted, comments kept) and a JSON log of every run.

    target/release/primm generate --output out/tune/default --split validation
    target/release/primm generate --output out/tune/turning --split validation --preset turning
    python3 tools/tune_physics.py --data out/tune/default/validation out/tune/turning/validation \\
        --out out/tune/primm.toml

``--parameters learned --method pr-imm`` tunes the learned mode's side instead, on the same
validation-only terms: the factor on the model's own displacement covariance
(``predictor.learned_process_noise_scale``) and the likelihood temperature
``imm.likelihood_temperature`` (the constant ``Q_PR`` is the ``pr-noise`` set's):

    python3 tools/tune_physics.py --data out/tune/default/validation --parameters learned \\
        --method pr-imm --config config/primm.toml --out out/tune/learned.toml

``--parameters pr-noise`` (scored with ``--method pr-imm``, its default; ``pr`` is allowed too)
tunes the PR mode's noise per class: the constant process noise ``Q_PR``
(``classes.<class>.learned.process_noise_covariance_m2``, used with
``predictor.process_noise = "constant"`` or a model without the covariance output) and the
measurement noise ``R_PR`` (``classes.<class>.learned.measurement_noise_covariance_m2``) of cars
and of pedestrians, four knobs. Each knob is a scale on its whole 2x2 matrix relative to the
starting configuration (so a diagonal or isotropic matrix stays so; entries rounded to 4
significant digits); the factors (default ``0.25 0.5 2 4``) multiply the knob's current scale:

    python3 tools/tune_physics.py --data out/tune/default/validation out/tune/robust/validation \\
        --parameters pr-noise --method pr-imm --rounds 1 --out out/tune/pr_noise.toml

``--parameters imm`` tunes the IMM side of PR-IMM (scored with ``--method pr-imm``): the Markov
transition matrix ``imm.transition`` and the initial mode probabilities
``imm.initial_mode_probabilities`` are generated from a few scalar knobs (mode order pr, cv, ca,
ct; see ``imm_arrays``), tuned together with the likelihood temperature
``imm.likelihood_temperature``:

    pr_leave        1 - pi[pr][pr], spread evenly over the active physics modes
    into_pr         pi[i][pr] for every physics mode i
    physics_switch  total probability of a physics mode moving to the other active physics modes
                    (spread evenly); pi[i][i] = 1 - into_pr - physics_switch
    initial_pr      initial probability of PR; the rest split evenly over the active physics modes
    temperature     the likelihood temperature tau

The probability knobs and tau are multiplied by the factors (``initial_pr`` through its odds), so
``--factors 0.25 0.5 2 4`` (the default of this set) spans a wide range in few runs. ``--modes``
lists candidate mode sets (each must contain pr); the mode set is one more coordinate of the
descent. ``primm eval --methods pr-imm`` runs all four modes whatever ``imm.modes`` says, so a
smaller set is realised in the matrices themselves: no probability flows into an inactive mode
(its column is zero) and it starts at 0, so its prior probability stays 0 and it never enters the
fused prior; ``imm.modes`` is written as well, for users of the configuration's mode set. The
matrix is shared: ``--method imm`` uses its cv, ca, ct rows and columns (renormalised), so a set
without ca or ct, or a changed physics_switch, changes the IMM too; score it alongside.

    python3 tools/tune_physics.py --data out/tune/default/validation out/tune/robust/validation \\
        --parameters imm --modes pr,cv,ca,ct pr,cv,ct pr,cv pr,ct --out out/tune/imm.toml

``--parameters imm-class`` (scored with ``--method pr-imm``) tunes the PR mode's weight per
class: for cars and for pedestrians, the knobs ``pr_leave``, ``into_pr`` and ``initial_pr`` of
the ``imm`` set, written as that class's overrides ``[classes.<class>.imm]`` (``transition`` and
``initial_mode_probabilities``; absent keys mean the ``[imm]`` values). The physics modes keep
the ``[imm]`` matrix among themselves: each physics row gives ``into_pr`` to PR and the rest in
the proportions of its ``[imm]`` row, and a new track's physics modes share ``1 - initial_pr`` in
the proportions of ``[imm]``, so ``--method imm`` (which renormalises over cv, ca, ct) is left as
it was, to the 1e-8 rounding (see ``class_imm_arrays``). The knobs start from the class's
overrides where present, else from ``[imm]``:

    python3 tools/tune_physics.py --data out/tune/default/validation out/tune/robust/validation \\
        --parameters imm-class --rounds 1 --out out/tune/imm_class.toml

``--parameters radial-velocity`` tunes the radial velocity's row in the physics modes' update
(``classes.<class>.radial_velocity_update``: ``std_mps`` and ``gate_std`` of cars and
pedestrians, for the classes whose row is ``enabled``), with the ``physics`` objective:

    python3 tools/tune_physics.py --data out/tune/default/validation out/tune/clutter_turning/validation \
        --parameters radial-velocity --rounds 1 --out out/tune/radial_velocity.toml

``--parameters extent`` tunes the extended-object model of cars (``classes.car.extent``: the
contour spread, the speed from which the heading counts, the nominal length and the margin of
extra detections), with the ``physics`` objective.

``--parameters tracks`` tunes how tracks are kept (scored with ``--method imm`` by default) on
what a user of the published tracks sees: the identity of confirmed tracks and how many of them
are false. Its knobs are the existence model's per-class detection probabilities and clutter
densities, the initial, confirmation and deletion existence probabilities, the persistence time
and the per-class gates (with ``association.cost = "likelihood"``: the chi-square gate and the
radial-velocity residual spreads instead of the gates). Probabilities move through their odds.
The objective is, averaged over the directories,

    (1 - confirmed IDF1) + false_track_weight * false tracks per minute
        + idf1_guard_weight * max(0, IDF1_guard - IDF1)

(confirmed-track metrics of ``primm eval``, docs/evaluation-metrics.md; the last term keeps the
paper's per-measurement IDF1 from falling below that of ``--guard-config``, by default the
starting configuration). The discrete choices (``association.cost``,
``association.stages``, ``tracker.lifecycle``) are the starting configuration's: tune each
combination from its own file and compare the objectives.

    python3 tools/tune_physics.py --data out/tune/clutter_turning/validation \
        out/tune/clutter/validation out/tune/default/validation out/tune/robust/validation \
        --parameters tracks --rounds 2 --guard-config config/primm.toml --out out/tune/tracks.toml

Needs only the Python standard library (3.11+) and a release build of primm.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import tomllib

# (section, key) of every tuned parameter of the physics modes.
PARAMETERS = [
    (f"classes.{cls}{sub}", key)
    for cls in ("car", "pedestrian")
    for sub, key in (
        (".constant_velocity", "acceleration_psd_m2_per_s3"),
        (".constant_acceleration", "jerk_psd_m2_per_s5"),
        (".coordinated_turn", "acceleration_psd_m2_per_s3"),
        (".coordinated_turn", "turn_rate_psd_rad2_per_s3"),
        ("", "paper_gate_m"),
        ("", "initial_tangential_speed_std_mps"),
    )
]


# (section, key) of every tuned parameter of the learned mode and the mode update.
LEARNED_PARAMETERS = [
    ("predictor", "learned_process_noise_scale"),
    ("imm", "likelihood_temperature"),
]

# Knobs that generate the [imm] section (see imm_arrays); section "imm" marks them as knobs.
IMM_PARAMETERS = [
    ("imm", "pr_leave"),
    ("imm", "into_pr"),
    ("imm", "physics_switch"),
    ("imm", "initial_pr"),
    ("imm", "likelihood_temperature"),
]

# (section, key) of the PR mode's per-class noise matrices (Q_PR, R_PR); each is scaled as a whole.
PR_NOISE_PARAMETERS = [
    (f"classes.{cls}.learned", key)
    for cls in ("car", "pedestrian")
    for key in ("process_noise_covariance_m2", "measurement_noise_covariance_m2")
]

# Per-class knobs of the PR mode's weight, written into [classes.<class>.imm] (see class_imm_arrays).
CLASS_IMM_KNOBS = ("pr_leave", "into_pr", "initial_pr")
CLASS_IMM_PARAMETERS = [(f"classes.{cls}.imm", key) for cls in ("car", "pedestrian") for key in CLASS_IMM_KNOBS]

# How tracks are kept: the existence model and the gates (paper cost), scored on confirmed tracks.
TRACK_PARAMETERS = [
    ("classes.car.existence", "detection_probability"),
    ("classes.pedestrian.existence", "detection_probability"),
    ("classes.car.existence", "clutter_density_per_m2"),
    ("classes.pedestrian.existence", "clutter_density_per_m2"),
    ("tracker", "initial_existence_probability"),
    ("tracker", "confirmation_existence_probability"),
    ("tracker", "deletion_existence_probability"),
    ("tracker", "existence_persistence_time_s"),
    ("classes.car", "paper_gate_m"),
    ("classes.pedestrian", "paper_gate_m"),
]
# The likelihood cost's gate and spreads, which replace the paper cost's gates in the set.
LIKELIHOOD_PARAMETERS = [
    ("association", "likelihood_gate_chi2"),
    ("classes.car", "likelihood_radial_velocity_std_mps"),
    ("classes.pedestrian", "likelihood_radial_velocity_std_mps"),
]
# The radial-velocity row of the physics modes' update, per class (scored like ``physics``).
RADIAL_VELOCITY_PARAMETERS = [
    (f"classes.{cls}.radial_velocity_update", key)
    for cls in ("car", "pedestrian")
    for key in ("std_mps", "gate_std")
]
# The extended-object model of cars (scored like ``physics``).
EXTENT_PARAMETERS = [
    ("classes.car.extent", key)
    for key in ("contour_std_m", "min_heading_speed_mps", "length_m", "absorb_margin_m")
]
# Keys whose values are probabilities: they move through their odds, so they stay in (0, 1).
PROBABILITY_KEYS = ("detection_probability", "initial_existence_probability",
                    "confirmation_existence_probability", "deletion_existence_probability")

PARAMETER_SETS = {"physics": PARAMETERS, "learned": LEARNED_PARAMETERS, "imm": IMM_PARAMETERS,
                  "pr-noise": PR_NOISE_PARAMETERS, "imm-class": CLASS_IMM_PARAMETERS,
                  "tracks": TRACK_PARAMETERS, "radial-velocity": RADIAL_VELOCITY_PARAMETERS,
                  "extent": EXTENT_PARAMETERS}
# Sets tuned with the wide factors and scored with pr-imm by default.
WIDE_SETS = ("imm", "pr-noise", "imm-class")

# Mode order of the vectors and matrices of [imm].
MODES = ("pr", "cv", "ca", "ct")
PHYSICS_MODES = MODES[1:]
# Upper bounds that keep the generated matrices sensible: no mode is left more often than it stays.
MAX_LEAVE = 0.5


def parse_modes(value: str) -> tuple:
    """A mode set from ``pr,cv,ct``, in the canonical order; must contain pr and a physics mode."""
    names = [name.strip() for name in value.split(",") if name.strip()]
    unknown = [name for name in names if name not in MODES]
    if unknown or "pr" not in names or len(set(names)) < 2:
        raise argparse.ArgumentTypeError(
            f"mode set {value!r}: list pr and at least one of cv, ca, ct, comma separated")
    return tuple(mode for mode in MODES if mode in names)


def imm_arrays(knobs: dict, modes: tuple) -> tuple:
    """The transition matrix (4x4, rows sum to 1) and initial mode probabilities for ``knobs``
    over the active ``modes`` (order pr, cv, ca, ct).

    PR stays with 1 - pr_leave and moves to each active physics mode with pr_leave / n (n active
    physics modes). A physics mode moves to PR with into_pr, to each other active physics mode
    with physics_switch / (n - 1), and stays with the rest (with n = 1 it keeps physics_switch
    too). No probability moves into an inactive mode; an inactive physics mode's row is that of
    an active one with no probability on itself, so it is left at once. New tracks start in PR
    with initial_pr and in each active physics mode with (1 - initial_pr) / n.
    Entries are rounded to 1e-8, the diagonal absorbing the rounding, so rows sum to 1."""
    physics = [mode for mode in PHYSICS_MODES if mode in modes]
    n = len(physics)
    if "pr" not in modes or n == 0:
        raise ValueError(f"mode set {modes}: needs pr and a physics mode")
    pr_leave, into_pr, switch = knobs["pr_leave"], knobs["into_pr"], knobs["physics_switch"]
    if not (0.0 <= pr_leave <= 1.0 and 0.0 <= into_pr and 0.0 <= switch and into_pr + switch <= 1.0):
        raise ValueError(f"knobs out of range: {knobs}")
    matrix = []
    for source in MODES:
        row = {mode: 0.0 for mode in MODES}
        if source == "pr":
            for mode in physics:
                row[mode] = pr_leave / n
        else:
            row["pr"] = into_pr
            others = [mode for mode in physics if mode != source]
            if source in physics and not others:
                pass  # the only physics mode: everything but into_pr stays
            else:
                for mode in others:
                    row[mode] = switch / len(others)
        row = {mode: round(value, 8) for mode, value in row.items()}
        if source in modes:
            row[source] = round(1.0 - sum(v for m, v in row.items() if m != source), 8)
        else:
            # Inactive physics mode: all of its row goes to the active modes, proportionally.
            total = sum(row.values())
            row = {mode: round(value / total, 8) for mode, value in row.items()}
            largest = max(physics + ["pr"], key=lambda mode: row[mode])
            row[largest] = round(1.0 - sum(v for m, v in row.items() if m != largest), 8)
        matrix.append([row[mode] for mode in MODES])
    initial_pr = knobs["initial_pr"]
    if not 0.0 < initial_pr < 1.0:
        raise ValueError(f"initial_pr {initial_pr} not in (0, 1)")
    initial = {mode: 0.0 for mode in MODES}
    for mode in physics:
        initial[mode] = round((1.0 - initial_pr) / n, 8)
    initial["pr"] = round(1.0 - sum(initial[mode] for mode in physics), 8)
    return matrix, [initial[mode] for mode in MODES]


def imm_knobs(config: dict) -> tuple:
    """The knobs and active modes that describe ``config``'s [imm] section (exactly, for matrices
    of the form imm_arrays writes; else the averages over the active modes)."""
    imm = config["imm"]
    modes = tuple(mode for mode in MODES if mode in imm["modes"])
    matrix = imm["transition"]
    physics = [MODES.index(mode) for mode in modes if mode != "pr"]
    pr_index = MODES.index("pr")
    active = [pr_index] + physics
    row_sum = lambda i: sum(matrix[i][j] for j in active)  # noqa: E731 (renormalised as primm does)
    pr_leave = sum(matrix[pr_index][j] for j in physics) / row_sum(pr_index)
    into_pr = sum(matrix[i][pr_index] / row_sum(i) for i in physics) / len(physics)
    switch = sum(matrix[i][j] / row_sum(i) for i in physics for j in physics if j != i) / len(physics)
    initial = imm["initial_mode_probabilities"]
    initial_pr = initial[pr_index] / sum(initial[j] for j in active)
    knobs = {"pr_leave": pr_leave, "into_pr": into_pr, "physics_switch": switch,
             "initial_pr": initial_pr, "likelihood_temperature": float(imm["likelihood_temperature"])}
    return {key: float(f"{value:.6g}") for key, value in knobs.items()}, modes


def class_imm_arrays(knobs: dict, modes: tuple, transition: list, initial: list) -> tuple:
    """A class's transition matrix and initial mode probabilities (order pr, cv, ca, ct) from the
    knobs pr_leave, into_pr and initial_pr, around the [imm] ``transition`` and ``initial`` over
    the active ``modes``.

    PR stays with 1 - pr_leave and moves to each active physics mode with pr_leave / n. A
    physics mode moves to PR with into_pr and shares 1 - into_pr among the physics modes in the
    proportions of its [imm] row, so the physics block renormalised over the physics modes (what
    ``--method imm`` uses) is that of [imm]. New tracks start in PR with initial_pr; the physics
    modes share 1 - initial_pr in the proportions of [imm]'s initial probabilities (evenly over
    the active ones where those are all 0). Entries are rounded to 1e-8, the diagonal (the
    largest physics entry for an inactive mode's row; the largest initial physics entry) absorbing
    the rounding, so rows and the initial probabilities sum to 1."""
    physics = [mode for mode in PHYSICS_MODES if mode in modes]
    n = len(physics)
    if "pr" not in modes or n == 0:
        raise ValueError(f"mode set {modes}: needs pr and a physics mode")
    pr_leave, into_pr, initial_pr = knobs["pr_leave"], knobs["into_pr"], knobs["initial_pr"]
    if not (0.0 <= pr_leave <= 1.0 and 0.0 <= into_pr < 1.0 and 0.0 < initial_pr < 1.0):
        raise ValueError(f"knobs out of range: {knobs}")
    matrix = []
    for i, source in enumerate(MODES):
        row = {mode: 0.0 for mode in MODES}
        if source == "pr":
            for mode in physics:
                row[mode] = round(pr_leave / n, 8)
            row["pr"] = round(1.0 - sum(row[mode] for mode in physics), 8)
        else:
            weights = {mode: float(transition[i][MODES.index(mode)]) for mode in PHYSICS_MODES}
            total = sum(weights.values())
            if total <= 0.0:
                raise ValueError(f"[imm] transition row {source} has no mass on the physics modes")
            row["pr"] = round(into_pr, 8)
            for mode in PHYSICS_MODES:
                row[mode] = round((1.0 - into_pr) * weights[mode] / total, 8)
            absorbing = source if source in modes else max(PHYSICS_MODES, key=lambda mode: row[mode])
            row[absorbing] = round(1.0 - sum(v for m, v in row.items() if m != absorbing), 8)
        matrix.append([row[mode] for mode in MODES])
    shares = {mode: float(initial[MODES.index(mode)]) for mode in physics}
    if sum(shares.values()) <= 0.0:
        shares = {mode: 1.0 for mode in physics}
    total = sum(shares.values())
    start = {mode: 0.0 for mode in MODES}
    for mode in physics:
        start[mode] = round((1.0 - initial_pr) * shares[mode] / total, 8)
    start["pr"] = round(initial_pr, 8)
    largest = max(physics, key=lambda mode: start[mode])
    start[largest] = round(1.0 - sum(v for m, v in start.items() if m != largest), 8)
    return matrix, [start[mode] for mode in MODES]


def class_imm_config(config: dict, cls: str) -> dict:
    """The [imm] section of ``config`` with ``[classes.<cls>.imm]`` applied, as primm applies it."""
    imm = dict(config["imm"])
    overrides = config.get("classes", {}).get(cls, {}).get("imm", {})
    for key in ("transition", "initial_mode_probabilities"):
        if key in overrides:
            imm[key] = overrides[key]
    return imm


def without_class_imm(text: str) -> str:
    """``text`` (TOML) without its ``[classes.<class>.imm]`` sections: one IMM for all classes."""
    kept, skipping = [], False
    for line in text.splitlines(keepends=True):
        header = re.match(r"\[\[?([A-Za-z_.]+)\]\]?\s*(#.*)?$", line)
        if header:
            skipping = re.fullmatch(r"classes\.[a-z_]+\.imm", header.group(1)) is not None
        if not skipping:
            kept.append(line)
    return "".join(kept)


def class_imm_knobs(config: dict) -> dict:
    """{class: {pr_leave, into_pr, initial_pr}} describing each tuned class's IMM (its overrides
    over [imm]), as imm_knobs reads them."""
    knobs = {}
    for cls in ("car", "pedestrian"):
        read, _ = imm_knobs({"imm": class_imm_config(config, cls)})
        knobs[cls] = {key: read[key] for key in CLASS_IMM_KNOBS}
    return knobs


def class_imm_text(text: str, cls: str, matrix: list, initial: list) -> str:
    """``text`` (TOML) with ``[classes.<cls>.imm]`` holding ``transition`` and
    ``initial_mode_probabilities``: substituted where the section and key exist, the key added
    under an existing section header, else the section appended to the class's block (after its
    last subsection), with a comment line."""
    section = f"classes.{cls}.imm"
    values = {"transition": format_matrix(matrix),
              "initial_mode_probabilities": "[" + ", ".join(repr(value) for value in initial) + "]"}
    lines = text.splitlines(keepends=True)
    headers = [(index, re.match(r"\s*\[([^\[\]]+)\]\s*(#.*)?$", line)) for index, line in enumerate(lines)]
    headers = [(index, match.group(1).strip()) for index, match in headers if match]
    if any(name == section for _, name in headers):
        for key, value in values.items():
            try:
                text = substitute_raw(text, section, key, value)
            except KeyError:
                lines = text.splitlines(keepends=True)
                at = next(index for index, line in enumerate(lines)
                          if re.match(rf"\s*\[{re.escape(section)}\]\s*(#.*)?$", line))
                lines.insert(at + 1, f"{key} = {value}\n")
                text = "".join(lines)
        return text
    block = [i for i, (index, name) in enumerate(headers) if name == f"classes.{cls}" or
             name.startswith(f"classes.{cls}.")]
    if not block:
        raise KeyError(f"[classes.{cls}] not found")
    following = block[-1] + 1
    end = headers[following][0] if following < len(headers) else len(lines)
    while end > 0 and lines[end - 1].strip() == "":
        end -= 1
    # Comment lines just above the next header belong to it.
    while end > 0 and lines[end - 1].lstrip().startswith("#") and following < len(headers):
        end -= 1
    while end > 0 and lines[end - 1].strip() == "":
        end -= 1
    if end > 0 and not lines[end - 1].endswith("\n"):
        lines[end - 1] += "\n"
    added = [f"[{section}]\n",
             f"# The PR mode's weight for {cls}s (tools/tune_physics.py --parameters imm-class); absent keys: [imm].\n",
             f"transition = {values['transition']}\n",
             f"initial_mode_probabilities = {values['initial_mode_probabilities']}\n"]
    lines[end:end] = added
    return "".join(lines)


def class_imm_full_text(text: str, knobs: dict, modes: tuple, transition: list, initial: list) -> str:
    """``text`` with ``[classes.<class>.imm]`` generated from ``knobs`` ({class: knobs}) for every
    class in ``knobs``."""
    for cls, class_knobs in knobs.items():
        matrix, start = class_imm_arrays(class_knobs, modes, transition, initial)
        text = class_imm_text(text, cls, matrix, start)
    return text


def format_matrix(matrix: list) -> str:
    rows = "".join(f"    [{', '.join(repr(value) for value in row)}],\n" for row in matrix)
    return f"[\n{rows}]"


def imm_text(text: str, knobs: dict, modes: tuple) -> str:
    """``text`` (TOML) with the [imm] keys generated from ``knobs`` over ``modes``."""
    matrix, initial = imm_arrays(knobs, modes)
    text = substitute_raw(text, "imm", "modes", "[" + ", ".join(f'"{mode}"' for mode in modes) + "]")
    text = substitute_raw(text, "imm", "transition", format_matrix(matrix))
    text = substitute_raw(text, "imm", "initial_mode_probabilities",
                          "[" + ", ".join(repr(value) for value in initial) + "]")
    return substitute(text, "imm", "likelihood_temperature", knobs["likelihood_temperature"])


def scaled_knob(key: str, base: float, factor: float):
    """``base`` scaled by ``factor`` as the knob ``key`` is tuned, or None where out of range:
    initial_pr through its odds, the others directly."""
    if key == "initial_pr":
        odds = base / (1.0 - base) * factor
        value = odds / (1.0 + odds)
        return float(f"{value:.4g}") if 0.001 <= value <= 0.999 else None
    value = float(f"{base * factor:.4g}")
    if key in ("pr_leave", "into_pr", "physics_switch") and not 0.0 < value <= MAX_LEAVE:
        return None
    return value


def parse_args(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--data", nargs="+", required=True, help="validation directories of measurement CSV files")
    parser.add_argument("--config", default="config/primm.toml", help="starting configuration")
    parser.add_argument("--primm", default="target/release/primm", help="the primm binary")
    parser.add_argument("--out", required=True, help="where to write the tuned configuration (TOML)")
    parser.add_argument("--factors", type=float, nargs="+", default=None,
                        help="factors tried on each parameter (default: 0.5 0.7 1.4 2; 0.25 0.5 2 4 for imm and "
                             "pr-noise)")
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--idf1-weight", type=float, default=20.0, help="metres of RMSE per unit of IDF1 lost")
    parser.add_argument("--velocity-weight-s", type=float, default=0.0,
                        help="seconds: metres of RMSE per m/s of velocity RMSE in the objective (the horizon "
                             "over which a velocity error becomes a position error; 0: positions only)")
    parser.add_argument("--false-track-weight", type=float, default=0.001,
                        help="--parameters tracks: objective per false confirmed track per minute")
    parser.add_argument("--guard-config", default=None,
                        help="--parameters tracks: the configuration whose per-measurement IDF1 the candidates must "
                             "not fall below (default: the starting one)")
    parser.add_argument("--idf1-guard-weight", type=float, default=5.0,
                        help="--parameters tracks: objective per unit of per-measurement IDF1 lost")
    parser.add_argument("--tracking-frame", choices=["world", "vehicle"], default="world")
    parser.add_argument("--displacement-oracle", action="store_true",
                        help="score with `primm eval --displacement-oracle`: PR gets the true displacement "
                             "(a diagnostic: what a perfect learned predictor could reach; never for shipped values)")
    parser.add_argument("--displacement-oracle-noise-m", type=float, default=None,
                        help="with --displacement-oracle: noise added to the true displacement, m per axis")
    parser.add_argument("--parameters", choices=sorted(PARAMETER_SETS), default="physics",
                        help="which parameters to tune")
    parser.add_argument("--method", default=None,
                        help="the method scored (imm, pr-imm, ...); default: pr-imm for --parameters imm and "
                             "pr-noise, else imm")
    parser.add_argument("--modes", type=parse_modes, nargs="+", default=None,
                        help="--parameters imm: candidate mode sets, e.g. pr,cv,ca,ct pr,cv,ct (default: the "
                             "configuration's)")
    args = parser.parse_args(argv)
    if args.method is None:
        args.method = "pr-imm" if args.parameters in WIDE_SETS else "imm"
    if args.factors is None:
        args.factors = [0.25, 0.5, 2.0, 4.0] if args.parameters in WIDE_SETS else [0.5, 0.7, 1.4, 2.0]
    if any(factor <= 0.0 for factor in args.factors):
        parser.error("--factors must be positive")
    if args.modes is not None and args.parameters != "imm":
        parser.error("--modes goes with --parameters imm")
    if args.parameters == "imm-class" and args.method != "pr-imm":
        parser.error("--parameters imm-class scores the IMM with the PR mode: --method pr-imm")
    if args.parameters == "pr-noise" and args.method not in ("pr-imm", "pr"):
        parser.error("--parameters pr-noise scores a method with the PR mode: --method pr-imm (or pr)")
    return args


def get_value(config: dict, section: str, key: str) -> float:
    node = config
    for part in section.split("."):
        node = node[part]
    return float(node[key])


def substitute(text: str, section: str, key: str, value: float) -> str:
    """``text`` (TOML) with ``key`` of ``[section]`` set to ``value``; comments are kept."""
    return substitute_raw(text, section, key, repr(value))


def substitute_raw(text: str, section: str, key: str, value: str) -> str:
    """``text`` (TOML) with ``key`` of ``[section]`` set to the TOML text ``value`` (which may span
    lines); an array value may span lines too (up to its closing bracket). The comment lines
    around it are kept, and so is a comment at the end of a one-line value."""
    lines = text.splitlines(keepends=True)
    current = None
    for index, line in enumerate(lines):
        header = re.match(r"\s*\[([^\[\]]+)\]\s*(#.*)?$", line)
        if header:
            current = header.group(1).strip()
            continue
        if current == section and re.match(rf"\s*{re.escape(key)}\s*=", line):
            end, depth = index, 0
            while True:
                code = lines[end].split("#", 1)[0]
                if end == index:
                    code = code.split("=", 1)[1]
                depth += code.count("[") - code.count("]")
                if depth <= 0 or end + 1 == len(lines):
                    break
                end += 1
            comment = line[line.index("#"):].rstrip("\n") if end == index and "#" in line else ""
            lines[index:end + 1] = [f"{key} = {value}" + (f" {comment}" if comment else "") + "\n"]
            return "".join(lines)
    raise KeyError(f"[{section}] {key} not found")


def get_matrix(config: dict, section: str, key: str) -> list:
    """The 2x2 matrix ``key`` of ``[section]`` as floats."""
    node = config
    for part in section.split("."):
        node = node[part]
    matrix = [[float(value) for value in row] for row in node[key]]
    if len(matrix) != 2 or any(len(row) != 2 for row in matrix):
        raise ValueError(f"[{section}] {key} is not a 2x2 matrix: {node[key]}")
    return matrix


def scaled_matrix(matrix: list, scale: float) -> list:
    """``matrix`` times ``scale``, entries rounded to 4 significant digits (zeros stay 0.0)."""
    if not scale > 0.0:
        raise ValueError(f"scale {scale} must be positive")
    return [[float(f"{value * scale:.4g}") for value in row] for row in matrix]


def format_covariance(matrix: list) -> str:
    """A 2x2 matrix as one-line TOML, as config/primm.toml writes it."""
    return "[" + ", ".join("[" + ", ".join(repr(value) for value in row) + "]" for row in matrix) + "]"


def pr_noise_text(text: str, matrices: dict, scales: dict) -> str:
    """``text`` (TOML) with every matrix of ``matrices`` ({(section, key): starting 2x2 matrix})
    set to itself times ``scales[(section, key)]`` (1.0 where missing)."""
    for (section, key), matrix in matrices.items():
        scale = scales.get((section, key), 1.0)
        text = substitute_raw(text, section, key, format_covariance(scaled_matrix(matrix, scale)))
    return text


def track_parameters(config: dict) -> list:
    """The knobs of the ``tracks`` set for a configuration: the likelihood cost's gate and spreads
    replace the paper cost's gates when the configuration uses it."""
    if config.get("association", {}).get("cost") == "likelihood":
        return [parameter for parameter in TRACK_PARAMETERS if parameter[1] != "paper_gate_m"] + LIKELIHOOD_PARAMETERS
    return list(TRACK_PARAMETERS)


def scaled_value(key: str, base: float, factor: float) -> float:
    """``base`` times ``factor``, through its odds for a probability (which stays in (0, 1)); 4
    significant digits."""
    if key in PROBABILITY_KEYS:
        odds = factor * base / (1.0 - base)
        return float(f"{odds / (1.0 + odds):.4g}")
    return float(f"{base * factor:.4g}")


def track_objective(args, result: dict, start: dict) -> float:
    """The ``tracks`` objective (module docstring), averaged over the directories."""
    terms = [
        (1.0 - confirmed) + args.false_track_weight * false_rate
        + args.idf1_guard_weight * max(0.0, idf1_start - idf1)
        for confirmed, false_rate, idf1, idf1_start in zip(
            result["confirmed_idf1"], result["false_tracks_per_minute"], result["idf1"], start["idf1"])
    ]
    return sum(terms) / len(terms)


def score(args, text: str) -> dict:
    """The method's RMSE_xy and IDF1 on every data directory for the configuration ``text`` (and
    the confirmed-track IDF1 and false-track rate)."""
    with tempfile.TemporaryDirectory() as tmp:
        config = os.path.join(tmp, "config.toml")
        with open(config, "w") as handle:
            handle.write(text)
        result = {"rmse_xy": [], "idf1": [], "velocity_rmse_mps": []}
        for data in args.data:
            report = os.path.join(tmp, "report.json")
            subprocess.run(
                [args.primm, "eval", "--data", data, "--methods", args.method, "--config", config,
                 "--tracking-frame", args.tracking_frame, "--json", report]
                + oracle_arguments(args),
                check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            )
            with open(report) as handle:
                scored = json.load(handle)["methods"][args.method.replace("-", "_")]
            result["rmse_xy"].append(scored["rmse_xy"])
            result["idf1"].append(scored["idf1"])
            result["velocity_rmse_mps"].append((scored.get("velocity") or {}).get("rmse_mps") or 0.0)
            if args.parameters == "tracks":
                confirmed = scored.get("confirmed_tracks") or {}
                result.setdefault("confirmed_idf1", []).append(confirmed.get("idf1") or 0.0)
                result.setdefault("false_tracks_per_minute", []).append(
                    confirmed.get("false_tracks_per_minute") or 0.0)
            pr_probability = scored_pr_probability(report, args.method)
            if pr_probability is not None:
                result.setdefault("pr_probability", []).append(pr_probability)
    return result


def oracle_arguments(args) -> list:
    """The `primm eval` options of the displacement oracle, if asked for."""
    if not args.displacement_oracle:
        return []
    noise = args.displacement_oracle_noise_m
    return ["--displacement-oracle"] + ([] if noise is None else ["--displacement-oracle-noise-m", repr(noise)])


def scored_pr_probability(report: str, method: str):
    """PR's mean mode probability in a ``primm eval`` report, where the method has one."""
    with open(report) as handle:
        probabilities = json.load(handle).get("mode_probabilities") or {}
    if probabilities.get("method") == method.replace("-", "_") and "pr" in probabilities:
        return probabilities["pr"]
    return None


def objective(args, result: dict, start: dict) -> float:
    if args.parameters == "tracks":
        return track_objective(args, result, start)
    velocities = result.get("velocity_rmse_mps") or [0.0] * len(result["rmse_xy"])
    terms = [
        rmse + args.velocity_weight_s * velocity + args.idf1_weight * max(0.0, idf1_start - idf1)
        for rmse, velocity, idf1, idf1_start in zip(result["rmse_xy"], velocities, result["idf1"], start["idf1"])
    ]
    return sum(terms) / len(terms)


def main(argv=None) -> int:
    args = parse_args(argv)
    for data in args.data:
        if os.path.basename(os.path.normpath(data)) == "evaluation":
            sys.exit(f"tune_physics: {data} is an evaluation split; tune on validation data only")
    with open(args.config) as handle:
        text = handle.read()
    if args.parameters == "imm":
        return tune_imm(args, text)
    if args.parameters == "pr-noise":
        return tune_pr_noise(args, text)
    if args.parameters == "imm-class":
        return tune_class_imm(args, text)
    config = tomllib.loads(text)
    start = score(args, text)
    if args.parameters == "tracks" and args.guard_config is not None:
        with open(args.guard_config) as handle:
            start["idf1"] = score(args, handle.read())["idf1"]
    best = objective(args, start, start)
    log = [{"parameter": None, "value": None, "result": start, "objective": best}]
    print(f"start: objective {best:.4f}  {start}", flush=True)
    parameters = track_parameters(config) if args.parameters == "tracks" else PARAMETER_SETS[args.parameters]
    for round_index in range(args.rounds):
        for section, key in parameters:
            base = get_value(config, section, key)
            for factor in args.factors:
                value = scaled_value(key, base, factor)
                candidate = substitute(text, section, key, value)
                try:
                    result = score(args, candidate)
                except subprocess.CalledProcessError:
                    # primm refused the candidate (e.g. a deletion threshold above confirmation).
                    log.append({"parameter": f"{section}.{key}", "value": value, "result": None})
                    continue
                value_objective = objective(args, result, start)
                log.append({"parameter": f"{section}.{key}", "value": value, "result": result,
                            "objective": value_objective})
                if value_objective < best - 1e-6:
                    best, text = value_objective, candidate
                    config = tomllib.loads(text)
                    print(f"round {round_index + 1}: {section}.{key} = {value}  objective {best:.4f}  {result}",
                          flush=True)
    return write_result(args, text, log, best)


def write_result(args, text: str, log: list, best: float) -> int:
    with open(args.out, "w") as handle:
        handle.write(text)
    with open(os.path.splitext(args.out)[0] + ".log.json", "w") as handle:
        json.dump(log, handle, indent=1)
    print(f"wrote {args.out} (objective {log[0]['objective']:.4f} -> {best:.4f}, {len(log)} runs)")
    return 0


def tune_imm(args, text: str) -> int:
    """Coordinate descent over the knobs of IMM_PARAMETERS and, once per round, the mode set."""
    original = text
    knobs, modes = imm_knobs(tomllib.loads(text))
    start = score(args, text)  # the configuration as given, unchanged
    best = objective(args, start, start)
    log = [{"parameter": None, "value": None, "knobs": dict(knobs), "modes": list(modes), "result": start,
            "objective": best}]
    print(f"start: {list(modes)} {knobs}  objective {best:.4f}  {start}", flush=True)

    def trial(name, value, candidate_knobs, candidate_modes):
        nonlocal best, knobs, modes, text
        candidate = imm_text(original, candidate_knobs, candidate_modes)
        result = score(args, candidate)
        value_objective = objective(args, result, start)
        log.append({"parameter": name, "value": value, "knobs": dict(candidate_knobs),
                    "modes": list(candidate_modes), "result": result, "objective": value_objective})
        print(f"  {name} = {value}: objective {value_objective:.4f}  {result}", flush=True)
        if value_objective < best - 1e-6:
            best, knobs, modes, text = value_objective, dict(candidate_knobs), candidate_modes, candidate
            print(f"  -> kept {name} = {value}  objective {best:.4f}", flush=True)

    for round_index in range(args.rounds):
        print(f"round {round_index + 1}", flush=True)
        for candidate_modes in args.modes or []:
            if candidate_modes != modes:
                trial("modes", ",".join(candidate_modes), knobs, candidate_modes)
        for _, key in IMM_PARAMETERS:
            if key == "physics_switch" and len(modes) < 3:
                continue  # a single physics mode has nothing to switch to
            base = knobs[key]
            for factor in args.factors:
                value = scaled_knob(key, base, factor)
                if value is None or value == base:
                    continue
                candidate_knobs = dict(knobs, **{key: value})
                if candidate_knobs["into_pr"] + candidate_knobs["physics_switch"] > MAX_LEAVE:
                    continue
                trial(key, value, candidate_knobs, modes)
        print(f"after round {round_index + 1}: {list(modes)} {knobs}  objective {best:.4f}", flush=True)
    log.append({"parameter": "chosen", "value": None, "knobs": knobs, "modes": list(modes), "objective": best})
    return write_result(args, text, log, best)


def tune_pr_noise(args, text: str) -> int:
    """Coordinate descent over the scales of PR_NOISE_PARAMETERS (Q_PR and R_PR of cars and
    pedestrians), each a factor on its starting matrix."""
    original = text
    config = tomllib.loads(text)
    if config.get("predictor", {}).get("process_noise", "constant") != "constant":
        print('note: predictor.process_noise is not "constant": the constant Q_PR is used only where the '
              "model gives no covariance", flush=True)
    matrices = {parameter: get_matrix(config, *parameter) for parameter in PR_NOISE_PARAMETERS}
    scales = {parameter: 1.0 for parameter in PR_NOISE_PARAMETERS}
    name = lambda parameter: f"{parameter[0]}.{parameter[1]}"  # noqa: E731

    def described(candidate_scales):
        return {name(p): {"scale": scale, "matrix": scaled_matrix(matrices[p], scale)}
                for p, scale in candidate_scales.items()}

    start = score(args, text)  # the configuration as given, unchanged
    best = objective(args, start, start)
    log = [{"parameter": None, "value": None, "scales": described(scales), "result": start, "objective": best}]
    print(f"start: objective {best:.4f}  {start}", flush=True)
    for round_index in range(args.rounds):
        print(f"round {round_index + 1}", flush=True)
        for parameter in PR_NOISE_PARAMETERS:
            base = scales[parameter]
            for factor in args.factors:
                value = float(f"{base * factor:.4g}")
                if value == base:
                    continue
                candidate_scales = {**scales, parameter: value}
                candidate = pr_noise_text(original, matrices, candidate_scales)
                result = score(args, candidate)
                value_objective = objective(args, result, start)
                log.append({"parameter": name(parameter), "value": value, "scales": described(candidate_scales),
                            "result": result, "objective": value_objective})
                print(f"  {name(parameter)} x{value} = {format_covariance(scaled_matrix(matrices[parameter], value))}"
                      f": objective {value_objective:.4f}  {result}", flush=True)
                if value_objective < best - 1e-6:
                    best, scales, text = value_objective, candidate_scales, candidate
                    print(f"  -> kept {name(parameter)} x{value}  objective {best:.4f}", flush=True)
        print(f"after round {round_index + 1}: {[(name(p), s) for p, s in scales.items()]}  objective {best:.4f}",
              flush=True)
    log.append({"parameter": "chosen", "value": None, "scales": described(scales), "objective": best})
    return write_result(args, text, log, best)


def tune_class_imm(args, text: str) -> int:
    """Coordinate descent over the per-class knobs of CLASS_IMM_PARAMETERS (cars first)."""
    original = text
    config = tomllib.loads(text)
    modes = tuple(mode for mode in MODES if mode in config["imm"]["modes"])
    if "pr" not in modes:
        sys.exit("tune_physics: --parameters imm-class needs pr among imm.modes")
    transition, initial = config["imm"]["transition"], config["imm"]["initial_mode_probabilities"]
    knobs = class_imm_knobs(config)
    start_knobs = {cls: dict(class_knobs) for cls, class_knobs in knobs.items()}
    start = score(args, text)  # the configuration as given, unchanged
    best = objective(args, start, start)
    log = [{"parameter": None, "value": None, "knobs": knobs, "result": start, "objective": best}]
    print(f"start: {knobs}  objective {best:.4f}  {start}", flush=True)
    for round_index in range(args.rounds):
        print(f"round {round_index + 1}", flush=True)
        for section, key in CLASS_IMM_PARAMETERS:
            cls = section.split(".")[1]
            base = knobs[cls][key]
            for factor in args.factors:
                value = scaled_knob(key, base, factor)
                if value is None or value == base:
                    continue
                candidate_knobs = {c: dict(k) for c, k in knobs.items()}
                candidate_knobs[cls][key] = value
                # Only classes moved off their starting knobs are written (the others keep their text).
                moved = {c: k for c, k in candidate_knobs.items() if k != start_knobs[c]}
                candidate = class_imm_full_text(original, moved, modes, transition, initial)
                result = score(args, candidate)
                value_objective = objective(args, result, start)
                log.append({"parameter": f"{section}.{key}", "value": value, "knobs": candidate_knobs,
                            "result": result, "objective": value_objective})
                print(f"  {section}.{key} = {value}: objective {value_objective:.4f}  {result}", flush=True)
                if value_objective < best - 1e-6:
                    best, knobs, text = value_objective, candidate_knobs, candidate
                    print(f"  -> kept {section}.{key} = {value}  objective {best:.4f}", flush=True)
        print(f"after round {round_index + 1}: {knobs}  objective {best:.4f}", flush=True)
    log.append({"parameter": "chosen", "value": None, "knobs": knobs, "objective": best})
    return write_result(args, text, log, best)


if __name__ == "__main__":
    sys.exit(main())
