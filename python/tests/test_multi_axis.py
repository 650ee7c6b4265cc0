"""A multi-axis (six-DOF) table from Python: ``platen.simulate`` runs a scenario with a
``table``; its columns (pose, rates, accelerations, per actuator stroke and force, per strut
force, the specimen's base forces and overturning moments) are float64 arrays equal to the
CSV that ``platen simulate --out`` writes; a bad table raises a ValueError naming its path."""

from __future__ import annotations

import json

import numpy as np
import pytest

import platen
from conftest import SCENARIOS, read_csv

POSE = ["x_m", "y_m", "z_m", "roll_rad", "pitch_rad", "yaw_rad"]


def test_the_tower_scenario_runs_with_the_contract_columns():
    run = platen.simulate(str(SCENARIOS / "multi-axis" / "tower-inverse.json"))
    columns = list(run.columns)
    assert columns[:7] == ["t_s"] + POSE
    for name in ["x_m_s", "yaw_rad_s2", "h1_stroke_m", "v6_force_n", "s1_force_n",
                 "base_force_x_n", "overturning_moment_y_n_m"]:
        assert name in columns
    assert run["x_m"].dtype == np.float64 and run["x_m"].shape == (4001,)
    assert run.summary["within_limits"] is True
    assert run.summary["samples"] == 4001
    # The pads carry the platen, the tower and the struts' pull: their forces sum to more
    # than the weight at rest.
    pads = sum(run[f"v{i}_force_n"] for i in range(1, 7))
    assert pads[0] > (180e3 + 120e3) * 9.80665


def same_as_cli(cli, tmp_path, name):
    """``platen.simulate`` of a shipped multi-axis scenario, checked column by column against
    the CSV that ``platen simulate --out`` writes for it."""
    scenario = str(SCENARIOS / "multi-axis" / name)
    out = tmp_path / "out.csv"
    cli("simulate", scenario, "--out", str(out))
    expected = read_csv(out)
    run = platen.simulate(scenario)
    assert list(run.columns) == list(expected)
    for column, values in expected.items():
        np.testing.assert_array_equal(run[column], values, err_msg=column)
    return run


def test_the_columns_equal_the_cli_output(cli, tmp_path):
    same_as_cli(cli, tmp_path, "bare-inverse.json")


def test_a_bad_table_raises_a_value_error_naming_its_path():
    with open(SCENARIOS / "multi-axis" / "bare-inverse.json") as f:
        doc = json.load(f)
    doc["excitation"]["motion_csv"] = str(SCENARIOS / "multi-axis" / "three-component-motion.csv")
    doc["table"]["platen"]["inertia_kg_m2"][0][1] = 1e6
    with pytest.raises(ValueError, match=r"table\.platen\.inertia_kg_m2"):
        platen.simulate(doc)


def test_the_forward_scenario_equals_the_cli_output(cli, tmp_path):
    """A forward run (friction, the tower): the same columns and values as the CLI's CSV,
    the platen at rest at the first sample and the friction dissipating."""
    run = same_as_cli(cli, tmp_path, "forward.json")
    assert run["stuck"][0] == 1.0
    assert run["dissipated_j"][-1] > 0.0


def test_the_lhpost6_closed_loop_equals_the_cli_output(cli, tmp_path):
    """The closed loop on the ``lhpost6`` preset (its DOF controller, valves and chambers),
    commanded with the shipped three-component motion for 0.5 s: the same columns and values
    as the CLI's CSV, and the summary's tracking and loop figures."""
    doc = {
        "name": "lhpost6 closed loop, 0.5 s",
        "table": {"preset": "lhpost6"},
        "duration_s": 0.5,
        "excitation": {
            "motion_csv": str(SCENARIOS / "multi-axis" / "three-component-motion.csv")
        },
    }
    path = tmp_path / "loop.json"
    path.write_text(json.dumps(doc))
    out = tmp_path / "out.csv"
    cli("simulate", str(path), "--out", str(out))
    expected = read_csv(out)
    run = platen.simulate(str(path))
    assert list(run.columns) == list(expected)
    for column, values in expected.items():
        np.testing.assert_array_equal(run[column], values, err_msg=column)
    for name in ["command_x_m", "h1_drive", "v1_spool_opening", "v1_delta_p_pa",
                 "h2_flow_m3_s", "supply_pressure_pa", "warping_force_n"]:
        assert name in run.columns
    assert run.summary["kind"] == "closed_loop"
    assert set(run.summary["tracking"]) == {"x", "y", "z", "roll", "pitch", "yaw"}
    assert run.summary["loop"]["controller_samples"] == 1025


def test_generated_motions_per_axis_from_python():
    """A sine per axis (x and z) as the prescribed motion of the bare table, given as a
    dict: each axis is its closed form ``A·sin(2πft)`` (to 1e-12 of its amplitude), y and
    the rotations still; a rotation among the axes raises a ValueError naming the path."""
    with open(SCENARIOS / "multi-axis" / "bare-inverse.json") as f:
        doc = json.load(f)
    doc["duration_s"] = 1.0
    doc["excitation"] = {"sine_motion": {
        "x": {"amplitude_m": 0.02, "frequency_hz": 1.5, "sample_rate_hz": 256.0},
        "z": {"amplitude_m": 0.003, "frequency_hz": 4.0, "sample_rate_hz": 256.0},
    }}
    run = platen.simulate(doc)
    t = run["t_s"]
    assert t.shape == (257,)
    np.testing.assert_allclose(run["x_m"], 0.02 * np.sin(2 * np.pi * 1.5 * t), rtol=0, atol=2e-14)
    np.testing.assert_allclose(run["z_m"], 0.003 * np.sin(2 * np.pi * 4.0 * t), rtol=0, atol=3e-15)
    for still in ["y_m", "roll_rad", "pitch_rad", "yaw_rad"]:
        assert not run[still].any(), still
    doc["excitation"]["sine_motion"]["yaw"] = {"amplitude_m": 0.01, "frequency_hz": 1.0}
    with pytest.raises(ValueError, match=r"excitation\.sine_motion.*motion_csv"):
        platen.simulate(doc)
