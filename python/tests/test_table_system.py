"""A closed-loop run from Python: a scenario dict with a ``table_system`` gives a run whose
columns include the loop's (``command_u_m``, ``drive``, …) and whose summary has the oil-column
frequency; a bad ``table_system`` raises a ValueError naming its JSON path."""

from __future__ import annotations

import json

import numpy as np
import pytest

import platen
from conftest import read_csv

CONTRACT = [
    "t_s",
    "u_m",
    "v_m_s",
    "a_m_s2",
    "force_n",
    "inertial_force_n",
    "elastic_force_n",
    "dissipative_force_n",
]
SYSTEM = ["command_u_m", "drive", "spool_opening", "delta_p_pa", "flow_m3_s", "supply_pressure_pa"]


def closed_loop(table_system=None, duration_s=0.5):
    """The LHPOST preset's loop commanded by a 2 cm, 1 Hz sine (1024 Hz samples)."""
    return {
        "name": "closed-loop sine",
        "model": {"preset": "lhpost-2008"},
        "table_system": table_system if table_system is not None else {"preset": "lhpost-2008"},
        "excitation": {"sine_motion": {"amplitude_m": 0.02, "frequency_hz": 1.0}},
        "duration_s": duration_s,
    }


def test_a_closed_loop_run_has_the_system_columns_and_the_oil_column_frequency():
    run = platen.simulate(closed_loop())
    assert list(run.columns[:8]) == CONTRACT
    assert list(run.columns[8:14]) == SYSTEM
    n = len(run)
    assert n == 513 == run.summary["samples"]
    for name in run.columns:
        column = run[name]
        assert isinstance(column, np.ndarray), name
        assert column.dtype == np.float64 and column.shape == (n,), name
        assert np.all(np.isfinite(column)), name
    drive = run["drive"]
    assert np.all(np.abs(drive) <= 1.0)
    assert np.max(np.abs(drive)) > 0.0
    np.testing.assert_allclose(run["command_u_m"], 0.02 * np.sin(2 * np.pi * run["t_s"]), rtol=0, atol=1e-12)
    assert run.summary["oil_column_frequency_hz"] == pytest.approx(10.66, abs=0.02)
    assert run.summary["direction"] == "forward"
    tracking = run.summary["table_system"]["tracking_displacement_rms_m"]
    assert 0.0 <= tracking < 0.02
    assert run.summary["table_system"]["loop_margins"]["stable"] is True
    # Every column is in the dict and the DataFrame-ready mapping.
    assert set(run.to_dict()) == set(run.columns)


def test_a_run_without_a_table_system_has_no_system_columns():
    scenario = closed_loop()
    del scenario["table_system"]
    run = platen.simulate(scenario)
    assert list(run.columns) == CONTRACT
    # The keys of a closed loop are there, None, as in every summary: a key that does not
    # apply is null, never absent.
    assert run.summary["oil_column_frequency_hz"] is None
    assert run.summary["table_system"] is None
    with pytest.raises(KeyError):
        run["drive"]


@pytest.mark.parametrize(
    "table_system, path",
    [
        ({"preset": "lhpost-2008", "actuator": {"area_m2": 0}}, "table_system.actuator.cap_side_area_m2"),
        ({"preset": "lhpost-2008", "return_pressure_pa": 3e7}, "table_system.return_pressure_pa"),
        ({"preset": "lhpost-2008", "servo_valve": {"natural_frequency_hz": 0}}, "table_system.servo_valve.natural_frequency_hz"),
        ({"preset": "lhpost-2008", "controller": {"sample_rate_hz": 0}}, "table_system.controller.sample_rate_hz"),
        ({"preset": "lhpost-2008", "actuator": {"chamber_volume_m3": 0.1}}, "table_system.actuator.chamber_volume_m3"),
        ({"preset": "lhpost-2008", "controller": {"kp": 1}}, "table_system.controller"),
        ({"preset": "lhpost-2099"}, "table_system.preset"),
        ({"actuator": {"count": 1}}, "table_system.actuator.cap_side_area_m2"),
    ],
)
def test_a_bad_table_system_raises_a_value_error_naming_its_path(table_system, path):
    with pytest.raises(ValueError) as raised:
        platen.simulate(closed_loop(table_system))
    assert isinstance(raised.value, platen.ScenarioError)
    assert path in str(raised.value), str(raised.value)
    assert raised.value.exit_code == 3


def test_the_system_columns_equal_the_clis_csv(cli, tmp_path):
    path = tmp_path / "loop.json"
    path.write_text(json.dumps(closed_loop(duration_s=0.25)))
    out = tmp_path / "loop.csv"
    cli("simulate", path, "--out", out)
    expected = read_csv(out)
    run = platen.simulate(path)
    assert list(run.columns) == list(expected)
    for name, column in expected.items():
        np.testing.assert_array_equal(run[name], column, err_msg=name)
