"""tools/tune_physics.py: TOML substitution, the [imm] knobs and the refusal to tune on evaluation data."""

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
        if name == "imm":
            continue  # knobs that generate [imm] arrays, not keys (tested below)
        for section, key in parameters:
            value = tune_physics.get_value(config, section, key)
            changed = tomllib.loads(tune_physics.substitute(text, section, key, value * 2.0))
            assert tune_physics.get_value(changed, section, key) == value * 2.0, (name, section, key)


def shipped_text():
    with open(os.path.join(ROOT, "config", "primm.toml")) as handle:
        return handle.read()


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
