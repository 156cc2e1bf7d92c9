"""tools/tune_physics.py: TOML substitution, the [imm] knobs, the PR noise scales and the refusal to tune on
evaluation data."""

import os
import sys
import tomllib

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))

import tune_physics  # noqa: E402

ROOT = os.path.join(os.path.dirname(__file__), "..", "..")


def test_a_substituted_value_lands_in_its_own_section_and_keeps_the_comments():
    with open(os.path.join(ROOT, "config", "primm.toml")) as handle:
        text = handle.read()
    changed = tune_physics.substitute(text, "classes.pedestrian.coordinated_turn", "acceleration_psd_m2_per_s3", 0.25)
    before, after = tomllib.loads(text), tomllib.loads(changed)
    assert after["classes"]["pedestrian"]["coordinated_turn"]["acceleration_psd_m2_per_s3"] == 0.25
    # The same key of other sections is untouched, and so is everything else.
    after["classes"]["pedestrian"]["coordinated_turn"]["acceleration_psd_m2_per_s3"] = (
        before["classes"]["pedestrian"]["coordinated_turn"]["acceleration_psd_m2_per_s3"]
    )
    assert after == before
    assert changed.count("#") == text.count("#")


def test_an_unknown_key_is_an_error():
    with pytest.raises(KeyError):
        tune_physics.substitute("[a]\nb = 1\n", "a", "c", 2.0)


def test_tuning_on_an_evaluation_split_is_refused(tmp_path):
    evaluation = tmp_path / "evaluation"
    evaluation.mkdir()
    with pytest.raises(SystemExit, match="evaluation split"):
        tune_physics.main(["--data", str(evaluation), "--out", str(tmp_path / "out.toml")])


def test_every_parameter_of_both_sets_exists_in_the_shipped_configuration_and_can_be_set():
    with open(os.path.join(ROOT, "config", "primm.toml")) as handle:
        text = handle.read()
    config = tomllib.loads(text)
    for name, parameters in tune_physics.PARAMETER_SETS.items():
        assert parameters, name
        if name in ("imm", "pr-noise", "imm-class"):
            continue  # knobs that generate [imm] arrays (also per class), and matrix scales (tested below)
        for section, key in parameters:
            value = tune_physics.get_value(config, section, key)
            changed = tomllib.loads(tune_physics.substitute(text, section, key, value * 2.0))
            assert tune_physics.get_value(changed, section, key) == value * 2.0, (name, section, key)


def shipped_text():
    with open(os.path.join(ROOT, "config", "primm.toml")) as handle:
        return handle.read()


without_class_imm = tune_physics.without_class_imm


def test_the_shipped_class_sections_read_back_as_the_knobs_that_made_them():
    text = shipped_text()
    config = tomllib.loads(text)
    knobs = tune_physics.class_imm_knobs(config)
    assert knobs["car"] == {"pr_leave": 0.48, "into_pr": 0.000625, "initial_pr": 0.005182}
    assert knobs["pedestrian"] == {"pr_leave": 0.015, "into_pr": 0.01, "initial_pr": 0.04}
    base = tomllib.loads(without_class_imm(text))
    assert "imm" not in base["classes"]["car"] and "imm" not in base["classes"]["pedestrian"]
    # Regenerated from those knobs around [imm], the sections are the shipped ones.
    imm = base["imm"]
    for cls in ("car", "pedestrian"):
        matrix, start = tune_physics.class_imm_arrays(knobs[cls], tune_physics.MODES, imm["transition"],
                                                      imm["initial_mode_probabilities"])
        shipped = config["classes"][cls]["imm"]
        for row, shipped_row in zip(matrix, shipped["transition"], strict=True):
            assert row == pytest.approx(shipped_row, abs=1e-6)
        assert start == pytest.approx(shipped["initial_mode_probabilities"], abs=1e-6)


KNOBS = {"pr_leave": 0.06, "into_pr": 0.004, "physics_switch": 0.03, "initial_pr": 0.6,
         "likelihood_temperature": 0.2}


@pytest.mark.parametrize("modes", [("pr", "cv", "ca", "ct"), ("pr", "cv", "ct"), ("pr", "cv"), ("pr", "ct")])
def test_generated_matrices_are_stochastic_and_follow_the_knobs(modes):
    matrix, initial = tune_physics.imm_arrays(KNOBS, modes)
    index = {mode: i for i, mode in enumerate(tune_physics.MODES)}
    physics = [mode for mode in modes if mode != "pr"]
    assert len(matrix) == 4 and all(len(row) == 4 for row in matrix)
    for row in matrix:
        assert all(0.0 <= value <= 1.0 for value in row)
        assert abs(sum(row) - 1.0) <= 1e-9  # primm's own tolerance
    assert abs(sum(initial) - 1.0) <= 1e-9
    # Nothing flows into, or starts in, an inactive mode.
    for mode in tune_physics.MODES:
        if mode not in modes:
            assert all(row[index[mode]] == 0.0 for row in matrix)
            assert initial[index[mode]] == 0.0
    pr = matrix[index["pr"]]
    assert pr[index["pr"]] == pytest.approx(1.0 - KNOBS["pr_leave"])
    for mode in physics:
        assert pr[index[mode]] == pytest.approx(KNOBS["pr_leave"] / len(physics))
        row = matrix[index[mode]]
        assert row[index["pr"]] == pytest.approx(KNOBS["into_pr"])
        switch = KNOBS["physics_switch"] if len(physics) > 1 else 0.0
        assert row[index[mode]] == pytest.approx(1.0 - KNOBS["into_pr"] - switch)
        for other in physics:
            if other != mode:
                assert row[index[other]] == pytest.approx(switch / (len(physics) - 1))
        assert initial[index[mode]] == pytest.approx((1.0 - KNOBS["initial_pr"]) / len(physics))
    assert initial[index["pr"]] == pytest.approx(KNOBS["initial_pr"])


def test_imm_text_round_trips_through_the_knobs_and_touches_only_the_imm_keys():
    text = shipped_text()
    knobs, modes = tune_physics.imm_knobs(tomllib.loads(text))
    assert modes == tune_physics.MODES
    # The shipped [imm] section is of the generated form: rewriting it changes nothing.
    assert tomllib.loads(tune_physics.imm_text(text, knobs, modes)) == tomllib.loads(text)
    changed_text = tune_physics.imm_text(text, KNOBS, ("pr", "cv", "ct"))
    changed, before = tomllib.loads(changed_text), tomllib.loads(text)
    assert changed["imm"]["modes"] == ["pr", "cv", "ct"]
    assert changed["imm"]["likelihood_temperature"] == 0.2
    assert tune_physics.imm_knobs(changed) == (dict(KNOBS, likelihood_temperature=0.2), ("pr", "cv", "ct"))
    for key in ("modes", "transition", "initial_mode_probabilities", "likelihood_temperature"):
        del changed["imm"][key], before["imm"][key]
    assert changed == before
    assert changed_text.count("#") == text.count("#")


def test_a_multi_line_array_is_replaced_whole():
    text = "[a]\n# m\nb = [\n  [1, 2],\n  [3, 4],\n]\nc = 1 # n\n"
    changed = tune_physics.substitute_raw(text, "a", "b", "[[5.0]]")
    assert changed == "[a]\n# m\nb = [[5.0]]\nc = 1 # n\n"


def test_probability_knobs_stay_probabilities():
    assert tune_physics.scaled_knob("initial_pr", 0.5, 4.0) == pytest.approx(0.8)
    assert tune_physics.scaled_knob("initial_pr", 0.25, 0.25) == pytest.approx(1 / 13, rel=1e-3)
    assert tune_physics.scaled_knob("pr_leave", 0.3, 4.0) is None
    assert tune_physics.scaled_knob("likelihood_temperature", 0.1, 4.0) == 0.4
    with pytest.raises(ValueError):
        tune_physics.imm_arrays(dict(KNOBS, into_pr=0.6, physics_switch=0.5), tune_physics.MODES)


def test_a_mode_set_needs_pr():
    assert tune_physics.parse_modes("ct,pr") == ("pr", "ct")
    with pytest.raises(Exception):
        tune_physics.parse_modes("cv,ca")


PR_NOISE = tune_physics.PR_NOISE_PARAMETERS
CAR_Q = ("classes.car.learned", "process_noise_covariance_m2")
CAR_R = ("classes.car.learned", "measurement_noise_covariance_m2")
PEDESTRIAN_Q = ("classes.pedestrian.learned", "process_noise_covariance_m2")
PEDESTRIAN_R = ("classes.pedestrian.learned", "measurement_noise_covariance_m2")


def shipped_matrices(text):
    config = tomllib.loads(text)
    return {parameter: tune_physics.get_matrix(config, *parameter) for parameter in PR_NOISE}


def learned_section(config, cls):
    return config["classes"][cls]["learned"]


def test_the_pr_noise_set_is_q_and_r_of_cars_and_pedestrians():
    assert sorted(PR_NOISE) == sorted([CAR_Q, CAR_R, PEDESTRIAN_Q, PEDESTRIAN_R])
    assert tune_physics.PARAMETER_SETS["pr-noise"] is PR_NOISE
    for matrix in shipped_matrices(shipped_text()).values():
        # Isotropic and diagonal in the shipped configuration, which scaling keeps.
        assert matrix[0][1] == matrix[1][0] == 0.0 and matrix[0][0] == matrix[1][1] > 0.0


def test_a_scaled_matrix_is_scaled_whole_and_rounded():
    assert tune_physics.scaled_matrix([[0.011, 0.0], [0.0, 0.011]], 4.0) == [[0.044, 0.0], [0.0, 0.044]]
    assert tune_physics.scaled_matrix([[0.0006, 0.0], [0.0, 0.0006]], 0.25) == [[0.00015, 0.0], [0.0, 0.00015]]
    assert tune_physics.scaled_matrix([[0.36, 0.01], [0.01, 0.25]], 1 / 3) == [[0.12, 0.003333], [0.003333, 0.08333]]
    assert tune_physics.format_covariance([[0.044, 0.0], [0.0, 0.044]]) == "[[0.044, 0.0], [0.0, 0.044]]"
    for scale in (0.0, -1.0):
        with pytest.raises(ValueError):
            tune_physics.scaled_matrix([[1.0, 0.0], [0.0, 1.0]], scale)
    with pytest.raises(ValueError):
        tune_physics.get_matrix({"a": {"b": [[1.0, 0.0, 0.0]]}}, "a", "b")


def test_pr_noise_text_scales_only_the_chosen_matrices_of_their_own_class():
    text = shipped_text()
    matrices = shipped_matrices(text)
    # Unit scales rewrite nothing that matters.
    assert tomllib.loads(tune_physics.pr_noise_text(text, matrices, {})) == tomllib.loads(text)
    changed_text = tune_physics.pr_noise_text(text, matrices, {CAR_Q: 4.0, PEDESTRIAN_R: 0.5})
    changed, before = tomllib.loads(changed_text), tomllib.loads(text)
    car_q = before["classes"]["car"]["learned"]["process_noise_covariance_m2"][0][0]
    pedestrian_r = before["classes"]["pedestrian"]["learned"]["measurement_noise_covariance_m2"][0][0]
    assert learned_section(changed, "car")["process_noise_covariance_m2"] == [
        [float(f"{car_q * 4:.4g}"), 0.0], [0.0, float(f"{car_q * 4:.4g}")]]
    assert learned_section(changed, "pedestrian")["measurement_noise_covariance_m2"] == [
        [pedestrian_r / 2, 0.0], [0.0, pedestrian_r / 2]]
    # The other class's matrices, the physics modes' R of the same classes (same key name, other
    # section), the two-wheelers' PR matrices and everything else are untouched.
    learned_section(changed, "car")["process_noise_covariance_m2"] = learned_section(
        before, "car")["process_noise_covariance_m2"]
    learned_section(changed, "pedestrian")["measurement_noise_covariance_m2"] = learned_section(
        before, "pedestrian")["measurement_noise_covariance_m2"]
    assert changed == before
    assert changed_text.count("#") == text.count("#")


def test_pr_noise_defaults_to_pr_imm_and_wide_factors_and_needs_the_pr_mode():
    args = tune_physics.parse_args(["--data", "d", "--out", "o", "--parameters", "pr-noise"])
    assert args.method == "pr-imm" and args.factors == [0.25, 0.5, 2.0, 4.0]
    args = tune_physics.parse_args(["--data", "d", "--out", "o", "--parameters", "pr-noise", "--factors", "0.5", "3"])
    assert args.factors == [0.5, 3.0]
    assert tune_physics.parse_args(["--data", "d", "--out", "o"]).method == "imm"
    for bad in (["--method", "imm"], ["--method", "cv"], ["--factors", "0", "2"]):
        with pytest.raises(SystemExit):
            tune_physics.parse_args(["--data", "d", "--out", "o", "--parameters", "pr-noise", *bad])


def test_pr_noise_tuning_on_an_evaluation_split_is_refused(tmp_path, monkeypatch):
    validation, evaluation = tmp_path / "validation", tmp_path / "evaluation"
    validation.mkdir(), evaluation.mkdir()
    monkeypatch.setattr(tune_physics, "score", lambda args, text: pytest.fail("scored evaluation data"))
    with pytest.raises(SystemExit, match="evaluation split"):
        tune_physics.main(["--data", str(validation), str(evaluation) + "/", "--parameters", "pr-noise",
                           "--config", os.path.join(ROOT, "config", "primm.toml"), "--out", str(tmp_path / "o.toml")])
    assert not (tmp_path / "o.toml").exists()


def test_pr_noise_descent_finds_the_best_scales_and_writes_them(tmp_path, monkeypatch):
    """A synthetic objective, lowest at car Q_PR x4 and pedestrian R_PR x0.5 with the other two
    at x1, read back from the candidate configuration primm would get."""
    text = shipped_text()
    start = {p: m[0][0] for p, m in shipped_matrices(text).items()}
    target = {CAR_Q: 4.0, CAR_R: 1.0, PEDESTRIAN_Q: 1.0, PEDESTRIAN_R: 0.5}
    calls = []

    def fake_score(args, candidate):
        config = tomllib.loads(candidate)
        error = 0.0
        for parameter in PR_NOISE:
            matrix = tune_physics.get_matrix(config, *parameter)
            assert matrix[0][1] == matrix[1][0] == 0.0 and matrix[0][0] == matrix[1][1]
            ratio = matrix[0][0] / start[parameter] / target[parameter]
            error += abs(ratio - 1.0)
        calls.append(error)
        # Two data directories; IDF1 unaffected.
        return {"rmse_xy": [1.0 + error, 1.2 + error], "idf1": [0.9, 0.8]}

    monkeypatch.setattr(tune_physics, "score", fake_score)
    out = tmp_path / "pr_noise.toml"
    assert tune_physics.main(["--data", "a/validation", "b/validation", "--parameters", "pr-noise", "--rounds", "1",
                              "--config", os.path.join(ROOT, "config", "primm.toml"), "--out", str(out)]) == 0
    assert len(calls) == 1 + 4 * 4  # the start, then four factors on each of the four knobs
    chosen = tomllib.loads(out.read_text())
    for parameter in PR_NOISE:
        value = tune_physics.get_matrix(chosen, *parameter)[0][0]
        assert value == pytest.approx(start[parameter] * target[parameter], rel=1e-3), parameter
    # Nothing outside the four matrices changed.
    assert tune_physics.pr_noise_text(out.read_text(), shipped_matrices(out.read_text()), {}) == out.read_text()
    before = tomllib.loads(text)
    for parameter in PR_NOISE:
        section, key = parameter
        cls = section.split(".")[1]
        learned_section(chosen, cls)[key] = learned_section(before, cls)[key]
    assert chosen == before
    import json
    log = json.loads((tmp_path / "pr_noise.log.json").read_text())
    assert log[0]["objective"] == pytest.approx(1.1 + calls[0])
    assert log[-1]["parameter"] == "chosen" and log[-1]["objective"] == pytest.approx(1.1)
    assert log[-1]["scales"]["classes.car.learned.process_noise_covariance_m2"]["scale"] == 4.0
    assert log[-1]["scales"]["classes.pedestrian.learned.measurement_noise_covariance_m2"]["scale"] == 0.5


def test_an_idf1_loss_outweighs_a_small_rmse_gain(tmp_path, monkeypatch):
    """pr-noise uses the same objective: a candidate that lowers RMSE_xy by 0.01 m but loses 0.001
    of IDF1 (x20 = 0.02 m) is not kept."""
    def fake_score(args, candidate):
        scale = tune_physics.get_matrix(tomllib.loads(candidate), *CAR_R)[0][0] / 0.36
        if scale == 1.0:
            return {"rmse_xy": [1.0], "idf1": [0.9]}
        return {"rmse_xy": [0.99], "idf1": [0.899]}

    monkeypatch.setattr(tune_physics, "score", fake_score)
    out = tmp_path / "o.toml"
    tune_physics.main(["--data", "a/validation", "--parameters", "pr-noise", "--rounds", "1", "--factors", "2",
                       "--config", os.path.join(ROOT, "config", "primm.toml"), "--out", str(out)])
    assert tomllib.loads(out.read_text()) == tomllib.loads(shipped_text())


def test_the_velocity_weight_prices_velocity_rmse_in_metres_per_metre_per_second(tmp_path):
    """--velocity-weight-s adds that many metres of objective per m/s of velocity RMSE; without it
    velocities do not count."""
    out = str(tmp_path / "o.toml")
    start = {"rmse_xy": [1.0, 2.0], "idf1": [0.9, 0.8], "velocity_rmse_mps": [1.5, 2.5]}
    positions_only = tune_physics.parse_args(["--data", "a/validation", "--out", out])
    assert abs(tune_physics.objective(positions_only, start, start) - 1.5) < 1e-12
    weighted = tune_physics.parse_args(["--data", "a/validation", "--out", out, "--velocity-weight-s", "0.5"])
    assert abs(tune_physics.objective(weighted, start, start) - (1.5 + 0.5 * 2.0)) < 1e-12
    # A truer velocity is worth a little position error, but not lost identity.
    truer_velocity = dict(start, rmse_xy=[1.01, 2.01], velocity_rmse_mps=[1.3, 2.3])
    assert tune_physics.objective(weighted, truer_velocity, start) < tune_physics.objective(weighted, start, start)
    assert tune_physics.objective(positions_only, truer_velocity, start) > 1.5
    lost_identity = dict(truer_velocity, idf1=[0.89, 0.8])
    assert tune_physics.objective(weighted, lost_identity, start) > tune_physics.objective(weighted, start, start)


# --- imm-class: the PR mode's weight per class, in [classes.<class>.imm] ---

def shipped_imm():
    config = tomllib.loads(shipped_text())
    return config["imm"]["transition"], config["imm"]["initial_mode_probabilities"]


def test_the_imm_class_set_is_three_knobs_of_cars_and_pedestrians_scored_with_pr_imm():
    assert tune_physics.PARAMETER_SETS["imm-class"] == [
        (f"classes.{cls}.imm", key) for cls in ("car", "pedestrian") for key in ("pr_leave", "into_pr", "initial_pr")]
    args = tune_physics.parse_args(["--data", "d", "--out", "o", "--parameters", "imm-class"])
    assert args.method == "pr-imm" and args.factors == [0.25, 0.5, 2.0, 4.0]
    with pytest.raises(SystemExit):
        tune_physics.parse_args(["--data", "d", "--out", "o", "--parameters", "imm-class", "--method", "imm"])


@pytest.mark.parametrize("modes", [("pr", "cv", "ca", "ct"), ("pr", "cv", "ct"), ("pr", "cv")])
def test_class_arrays_follow_the_knobs_and_keep_the_physics_block_of_imm(modes):
    transition, initial = shipped_imm()
    knobs = {"pr_leave": 0.12, "into_pr": 0.04, "initial_pr": 0.3}
    matrix, start = tune_physics.class_imm_arrays(knobs, modes, transition, initial)
    for row in matrix:
        assert sum(row) == pytest.approx(1.0, abs=1e-12) and all(0.0 <= p <= 1.0 for p in row)
    assert sum(start) == pytest.approx(1.0, abs=1e-12)
    physics = [i for i, mode in enumerate(tune_physics.MODES) if mode in modes and mode != "pr"]
    assert matrix[0][0] == pytest.approx(0.88)
    for j in range(1, 4):
        assert matrix[0][j] == pytest.approx(0.12 / len(physics) if j in physics else 0.0)
    assert start[0] == pytest.approx(0.3)
    for i in range(1, 4):
        assert matrix[i][0] == pytest.approx(0.04)
    # --method imm renormalises over the active physics modes: the same as [imm]'s, to rounding.
    for i in physics:
        ours = sum(matrix[i][j] for j in physics)
        theirs = sum(transition[i][j] for j in physics)
        for j in physics:
            assert matrix[i][j] / ours == pytest.approx(transition[i][j] / theirs, abs=1e-7)
    ours, theirs = sum(start[j] for j in physics), sum(initial[j] for j in physics)
    for j in physics:
        assert start[j] / ours == pytest.approx(initial[j] / theirs, abs=1e-7)


def test_class_arrays_at_the_starting_knobs_are_imm_itself():
    transition, initial = shipped_imm()
    knobs = tune_physics.class_imm_knobs(tomllib.loads(without_class_imm(shipped_text())))
    assert knobs["car"] == knobs["pedestrian"] == {"pr_leave": 0.03, "into_pr": 0.01, "initial_pr": 0.07692}
    matrix, start = tune_physics.class_imm_arrays(knobs["car"], tune_physics.MODES, transition, initial)
    assert matrix == transition
    assert start == pytest.approx(initial, abs=1e-7)


def test_class_imm_text_adds_a_section_to_its_class_only_and_round_trips():
    text = without_class_imm(shipped_text())
    transition, initial = shipped_imm()
    knobs = {"car": {"pr_leave": 0.12, "into_pr": 0.0025, "initial_pr": 0.02}}
    changed = tune_physics.class_imm_full_text(text, knobs, tune_physics.MODES, transition, initial)
    before, after = tomllib.loads(text), tomllib.loads(changed)
    car = after["classes"]["car"].pop("imm")
    assert set(car) == {"transition", "initial_mode_probabilities"}
    assert after == before  # nothing else changed: not [imm], not the pedestrians
    assert "[classes.car.imm]" in changed and "[classes.pedestrian.imm]" not in changed
    # The section sits in the car block, before the pedestrians', and comments are kept.
    assert changed.index("[classes.car.imm]") < changed.index("[classes.pedestrian]")
    assert changed.count("#") == text.count("#") + 1
    read = tune_physics.class_imm_knobs(tomllib.loads(changed))
    assert read["car"] == knobs["car"]
    assert read["pedestrian"] == {"pr_leave": 0.03, "into_pr": 0.01, "initial_pr": 0.07692}
    # Written again (another value): the section is substituted, not duplicated.
    knobs["car"]["pr_leave"] = 0.06
    again = tune_physics.class_imm_full_text(changed, knobs, tune_physics.MODES, transition, initial)
    assert again.count("[classes.car.imm]") == 1
    assert tune_physics.class_imm_knobs(tomllib.loads(again))["car"]["pr_leave"] == 0.06
    # A section with only one key gets the other added under its header.
    partial = text + "\n[classes.pedestrian.imm]\ninitial_mode_probabilities = [0.5, 0.5, 0.0, 0.0]\n"
    filled = tune_physics.class_imm_full_text(
        partial, {"pedestrian": {"pr_leave": 0.01, "into_pr": 0.01, "initial_pr": 0.2}},
        tune_physics.MODES, transition, initial)
    pedestrian = tomllib.loads(filled)["classes"]["pedestrian"]["imm"]
    assert pedestrian["transition"][0][0] == pytest.approx(0.99)
    assert pedestrian["initial_mode_probabilities"][0] == pytest.approx(0.2)


def test_imm_class_descent_writes_only_the_classes_it_moved(tmp_path, monkeypatch):
    """A synthetic objective, lowest at a car pr_leave of 0.12 with everything else as it was."""
    calls = []

    def fake_score(args, candidate):
        knobs = tune_physics.class_imm_knobs(tomllib.loads(candidate))
        error = abs(knobs["car"]["pr_leave"] - 0.12) + abs(knobs["pedestrian"]["initial_pr"] - 0.07692)
        calls.append(error)
        return {"rmse_xy": [1.0 + error], "idf1": [0.9]}

    monkeypatch.setattr(tune_physics, "score", fake_score)
    base = tmp_path / "one_imm.toml"
    base.write_text(without_class_imm(shipped_text()))
    out = tmp_path / "imm_class.toml"
    assert tune_physics.main(["--data", "a/validation", "--parameters", "imm-class", "--rounds", "1",
                              "--config", str(base), "--out", str(out)]) == 0
    chosen = tomllib.loads(out.read_text())
    assert tune_physics.class_imm_knobs(chosen)["car"]["pr_leave"] == 0.12
    assert "imm" in chosen["classes"]["car"] and "imm" not in chosen["classes"]["pedestrian"]
    chosen["classes"]["car"].pop("imm")
    assert chosen == tomllib.loads(base.read_text())


def test_the_oracle_flag_reaches_every_primm_eval_call(tmp_path, monkeypatch):
    commands = []

    def fake_run(command, **_):
        commands.append(command)
        report = command[command.index("--json") + 1]
        with open(report, "w") as handle:
            handle.write('{"methods": {"pr_imm": {"rmse_xy": 1.0, "idf1": 0.9}}, "mode_probabilities": {}}')

    monkeypatch.setattr(tune_physics.subprocess, "run", fake_run)
    for flag, expected in (([], False), (["--displacement-oracle"], True),
                           (["--displacement-oracle", "--displacement-oracle-noise-m", "0.1"], True)):
        args = tune_physics.parse_args(["--data", "a/validation", "b/validation", "--out", str(tmp_path / "o.toml"),
                                        "--parameters", "imm", "--method", "pr-imm"] + flag)
        commands.clear()
        assert tune_physics.score(args, shipped_text()) == {"rmse_xy": [1.0, 1.0], "idf1": [0.9, 0.9],
                                                            "velocity_rmse_mps": [0.0, 0.0]}
        assert len(commands) == 2
        assert all(("--displacement-oracle" in command) == expected for command in commands)
        noise = "0.1" in flag
        assert all((command[-2:] == ["--displacement-oracle-noise-m", "0.1"]) == noise for command in commands)


def test_the_tracks_set_moves_probabilities_through_their_odds_and_other_knobs_by_factor():
    assert tune_physics.scaled_value("detection_probability", 0.5, 3.0) == 0.75
    assert 0.0 < tune_physics.scaled_value("deletion_existence_probability", 0.9, 100.0) < 1.0
    assert tune_physics.scaled_value("paper_gate_m", 4.0, 0.5) == 2.0
    config = tomllib.loads(shipped_text())
    for section, key in tune_physics.TRACK_PARAMETERS + tune_physics.LIKELIHOOD_PARAMETERS:
        tune_physics.get_value(config, section, key)  # every knob exists in the shipped file
    config["association"]["cost"] = "likelihood"
    likelihood = tune_physics.track_parameters(config)
    assert ("association", "likelihood_gate_chi2") in likelihood
    assert all(key != "paper_gate_m" for _, key in likelihood)
    config["association"]["cost"] = "paper"
    assert ("classes.car", "paper_gate_m") in tune_physics.track_parameters(config)


def test_the_tracks_objective_rewards_confirmed_identity_and_punishes_false_tracks_and_idf1_lost(tmp_path):
    args = tune_physics.parse_args(["--data", "a/validation", "--out", str(tmp_path / "o.toml"),
                                    "--parameters", "tracks"])
    start = {"idf1": [0.95], "confirmed_idf1": [0.9], "false_tracks_per_minute": [100.0]}
    base = tune_physics.objective(args, start, start)
    assert abs(base - (0.1 + 0.1)) < 1e-12
    fewer_false = dict(start, false_tracks_per_minute=[10.0])
    assert tune_physics.objective(args, fewer_false, start) < base
    # A confirmed-IDF1 gain bought with per-measurement IDF1 costs five times that loss.
    traded = dict(start, confirmed_idf1=[0.92], idf1=[0.94])
    assert tune_physics.objective(args, traded, start) > base
