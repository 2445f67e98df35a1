"""Scenarios from Python: loading, text, dotted values, and errors as the command line gives."""

import pytest

import omniloop
from conftest import SCENARIOS


def test_load_gives_the_files_scenario(smoke):
    assert smoke.name == "smoke"
    assert smoke.seed == 7
    assert smoke.path == SCENARIOS / "smoke.toml"
    assert smoke.max_cycles == round(smoke.duration_s / smoke.control_period_s)
    robot = smoke.robot
    assert robot["start"] == (-1000.0, -300.0, 0.0)
    assert robot["goal"]["x_mm"] == 1000.0 and robot["goal"]["y_mm"] == 100.0
    assert robot["differential"] is None


def test_from_toml_reads_text_and_names_it():
    s = omniloop.Scenario.from_toml(
        "[robot]\nstart = { x_mm = 0.0, y_mm = 0.0 }\n", name="tiny"
    )
    assert s.name == "tiny"
    assert s.path is None
    assert "start" in s.to_toml()


def test_a_bad_text_raises_scenario_error_located_as_the_cli_locates_it():
    with pytest.raises(omniloop.ScenarioError) as e:
        omniloop.Scenario.from_toml(
            "[robot]\nstart = { x_mm = 0.0, y_mm = 0.0 }\nmax_speed_mm_s = -3\n"
        )
    assert str(e.value) == (
        "<string>:3:1: field `robot.max_speed_mm_s`: must be a finite number > 0 (got -3)"
    )
    assert isinstance(e.value, ValueError)


def test_a_bad_file_names_file_line_column_and_field(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(
        (SCENARIOS / "smoke.toml").read_text().replace("duration_s = 20.0", "duration_s = -1")
    )
    with pytest.raises(omniloop.ScenarioError) as e:
        omniloop.Scenario.load(bad)
    line = next(
        i for i, t in enumerate(bad.read_text().splitlines(), 1) if "duration_s" in t
    )
    assert str(e.value).startswith(f"{bad}:{line}:1: field `run.duration_s`: ")


def test_a_toml_syntax_error_is_located():
    with pytest.raises(omniloop.ScenarioError, match=r"^<string>:2:\d+: "):
        omniloop.Scenario.from_toml("[robot]\nstart = {\n")


def test_a_missing_file_is_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError):
        omniloop.Scenario.load(tmp_path / "nowhere.toml")


def test_with_values_sets_dotted_keys_and_keeps_the_name(corner):
    fast = corner.with_values(
        {"robot.max_speed_mm_s": 800.0, "seed": 3, "robot.sensors[0].noise_sigma": 2}
    )
    assert fast.robot["max_speed_mm_s"] == 800.0
    assert fast.seed == 3
    assert fast.name == corner.name
    assert corner.robot["max_speed_mm_s"] != 800.0, "the original is left as it was"
    assert "noise_sigma = 2" in fast.to_toml()


def test_with_values_validates_as_sweep_set_does(corner):
    with pytest.raises(omniloop.ScenarioError) as e:
        corner.with_values({"robot.max_speed_mm_s": -1.0})
    assert "field `robot.max_speed_mm_s`: must be a finite number > 0" in str(e.value)
    assert str(e.value).startswith("--set robot.max_speed_mm_s=-1.0:1:")
    with pytest.raises(omniloop.ScenarioError, match="robot.sensors"):
        corner.with_values({"robot.sensors[5].noise_sigma": 1.0})
    with pytest.raises(ValueError, match="cannot be written in a scenario"):
        corner.with_values({"robot.max_speed_mm_s": object()})


def test_the_default_scenario_is_a_valid_scenario():
    text = omniloop.default_scenario()
    assert "[robot]" in text
    omniloop.Scenario.from_toml(text)
