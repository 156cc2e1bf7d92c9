"""tools/tune_physics.py: TOML substitution and the refusal to tune on evaluation data."""

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
        for section, key in parameters:
            value = tune_physics.get_value(config, section, key)
            changed = tomllib.loads(tune_physics.substitute(text, section, key, value * 2.0))
            assert tune_physics.get_value(changed, section, key) == value * 2.0, (name, section, key)
