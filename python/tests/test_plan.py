"""``platen.plan``: the drive and the summary of ``platen plan --json`` from arrays; bad input
raises ScenarioError (a ValueError) with the CLI's message."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import platen

from conftest import read_csv

RATE_HZ = 1024.0

SCENARIO = {
    "name": "LHPOST closed loop",
    "model": {"preset": "lhpost-2008"},
    "table_system": {"preset": "lhpost-2008"},
}


def quake(t: np.ndarray) -> np.ndarray:
    """An earthquake-like acceleration: five sines under a rise–hold–decay envelope, 0.3 g."""
    env = np.where(t < 0.5, 0.0, np.where(t < 2.0, ((t - 0.5) / 1.5) ** 2, np.exp(-(t - 2.0) / 2.0)))
    s = sum(
        a * np.sin(2 * math.pi * f * t + p)
        for f, a, p in [(0.7, 0.3, 0.0), (1.9, 1.0, 1.1), (3.3, 0.8, 2.3), (6.1, 0.6, 0.4), (11.0, 0.4, 5.0)]
    )
    return 0.3 * 9.80665 * env * s / 2.0


def target(seconds: float = 6.0):
    t = np.arange(int(seconds * RATE_HZ) + 1) / RATE_HZ
    return t, quake(t)


def test_plan_returns_the_drive_and_the_summary():
    t, a = target()
    p = platen.plan(SCENARIO, t, target_a_m_s2=a, iterations=3, max_scale=False)
    assert set(p) == {"drive_t_s", "drive_u_m", "summary"}
    assert p["drive_t_s"].dtype == np.float64 and p["drive_u_m"].dtype == np.float64
    assert len(p["drive_t_s"]) == len(t) == len(p["drive_u_m"])
    s = p["summary"]
    assert s["feasible"] is True
    assert s["max_scale"] is None
    records = s["iterations"]
    assert 2 <= len(records) <= 4
    assert s["drive"]["achieved"]["acceleration_nrmse"] < 0.5 * records[0]["acceleration_nrmse"]
    assert s["drive"]["out"] is None


def test_plan_agrees_with_the_cli(cli, tmp_path):
    t, a = target()
    scenario = tmp_path / "lhpost.json"
    scenario.write_text(json.dumps(SCENARIO))
    target_csv = tmp_path / "target.csv"
    with open(target_csv, "w") as f:
        f.write("t_s,a_m_s2\n")
        for ti, ai in zip(t, a):
            f.write(f"{float(ti)!r},{float(ai)!r}\n")
    drive_csv = tmp_path / "drive.csv"
    run = cli(
        "plan", scenario, "--target", target_csv, "--out", drive_csv, "--iterations", "3", "--json"
    )
    expected = json.loads(run.stdout)
    p = platen.plan(scenario, t, target_a_m_s2=a, iterations=3)
    got = p["summary"]
    for key in ("feasible", "max_scale", "iterations", "best_iteration", "stop", "margins", "limits"):
        assert got[key] == expected[key], key
    assert got["drive"]["achieved"] == expected["drive"]["achieved"]
    written = read_csv(drive_csv)
    np.testing.assert_array_equal(p["drive_t_s"], written["t_s"])
    np.testing.assert_array_equal(p["drive_u_m"], written["u_m"])


def test_a_displacement_target_and_no_iterations():
    t = np.arange(2049) / RATE_HZ
    u = 0.01 * np.sin(2 * math.pi * 1.0 * t) * np.sin(math.pi * t / t[-1]) ** 2
    p = platen.plan(SCENARIO, t, target_u_m=u, iterations=0, max_scale=False)
    s = p["summary"]
    assert s["target"]["kind"] == "displacement"
    assert len(s["iterations"]) == 1


@pytest.mark.parametrize(
    "kwargs, words",
    [
        ({}, "exactly one of"),
        ({"target_a_m_s2": "x", "target_u_m": [0.0]}, "exactly one of"),
        ({"target_a_m_s2": np.zeros(5)}, "samples"),
        ({"target_a_m_s2": None, "target_u_m": None, "gain": 3.0}, "exactly one of"),
    ],
)
def test_bad_targets_raise_scenario_error(kwargs, words):
    t, _ = target(1.0)
    with pytest.raises(platen.ScenarioError, match=words):
        platen.plan(SCENARIO, t, **kwargs)


def test_bad_settings_and_scenarios_raise_scenario_error():
    t, a = target(1.0)
    with pytest.raises(platen.ScenarioError, match="gain"):
        platen.plan(SCENARIO, t, target_a_m_s2=a, gain=2.5)
    with pytest.raises(platen.ScenarioError, match="iterations"):
        platen.plan(SCENARIO, t, target_a_m_s2=a, iterations=-1)
    with pytest.raises(platen.ScenarioError, match="frf"):
        platen.plan(SCENARIO, t, target_a_m_s2=a, frf="guessed")
    with pytest.raises(platen.ScenarioError, match="table_system"):
        platen.plan({"name": "bare", "model": {"preset": "lhpost-2008"}}, t, target_a_m_s2=a)
    # A target faster than the controller is not refused: it is put on the controller's
    # rate, anti-aliased, and the summary says so.
    fast = np.arange(2 * 2048 + 1) / 2048.0
    p = platen.plan(SCENARIO, fast, target_a_m_s2=quake(fast), iterations=0, max_scale=False)
    assert any("resampled to 1024 Hz" in w for w in p["summary"]["warnings"])
    assert p["summary"]["target"]["sample_rate_hz"] == 2048.0
    with pytest.raises(platen.ScenarioError, match="zero"):
        platen.plan(SCENARIO, t, target_a_m_s2=np.zeros_like(t))


def _three_component_target():
    """1 s at 256 Hz: a 4 Hz sine on x and a 6 Hz one on z, each under half-cosine ramps of
    0.3 s (so that it starts and ends at rest); y held at zero."""
    t = np.arange(257) / 256.0
    ramp = lambda x: 0.5 - 0.5 * np.cos(np.pi * np.clip(x / 0.3, 0.0, 1.0))  # noqa: E731
    r = ramp(t) * ramp(1.0 - t)
    return t, {"x": 2.0 * r * np.sin(2 * np.pi * 4 * t), "z": 1.0 * r * np.sin(2 * np.pi * 6 * t)}


def test_a_three_component_plan_on_the_lhpost6_replays_through_simulate(tmp_path):
    """Per-axis targets on a multi-axis scenario: the three-component plan. Its drive (six
    columns) written as a ``motion_csv`` and replayed through ``platen.simulate`` is the run
    the plan reports for its best iteration: each axis's signed peak acceleration is the
    plan's, to the bit (the CSV carries every digit)."""
    t, a = _three_component_target()
    scenario = {"table": {"preset": "lhpost6"}}
    p = platen.plan(scenario, t, target_a_m_s2=a, iterations=1, max_scale=False)
    s = p["summary"]
    assert set(p["drive"]) == {"x_m", "y_m", "z_m", "roll_rad", "pitch_rad", "yaw_rad"}
    assert len(s["iterations"]) == 2 and set(s["iterations"][0]["axes"]) == {"x", "y", "z"}
    assert s["iterations"][0]["axes"]["y"]["acceleration_nrmse"] is None
    assert s["feasible"] is True and s["max_scale"] is None and s["stall_reason"] is None
    best = s["iterations"][s["best_iteration"]]
    assert best["acceleration_nrmse"] < s["iterations"][0]["acceleration_nrmse"]
    drive = tmp_path / "drive.csv"
    names = ["x_m", "y_m", "z_m", "roll_rad", "pitch_rad", "yaw_rad"]
    with open(drive, "w") as f:
        f.write("t_s," + ",".join(names) + "\n")
        for j in range(len(p["drive_t_s"])):
            row = [p["drive_t_s"][j]] + [p["drive"][n][j] for n in names]
            f.write(",".join(repr(float(v)) for v in row) + "\n")
    run = platen.simulate({"table": {"preset": "lhpost6"}, "excitation": {"motion_csv": str(drive)}})
    for axis in ["x", "y", "z"]:
        achieved = run[f"{axis}_m_s2"]
        peak = achieved[np.argmax(np.abs(achieved))]
        assert peak == best["axes"][axis]["peak_a_m_s2"], axis


def test_bad_three_component_targets_raise_scenario_error():
    t, a = _three_component_target()
    scenario = {"table": {"preset": "lhpost6"}}
    with pytest.raises(platen.ScenarioError, match="expected an axis among x, y, z"):
        platen.plan(scenario, t, target_a_m_s2={"roll": a["x"]})
    with pytest.raises(platen.ScenarioError, match="linearised"):
        platen.plan(scenario, t, target_a_m_s2=a, frf="measured")
    with pytest.raises(platen.ScenarioError, match="same number"):
        platen.plan(scenario, t[:-1], target_a_m_s2=a)
    with pytest.raises(platen.ScenarioError, match="table"):
        platen.plan({"model": {"preset": "lhpost-2008"}}, t, target_a_m_s2=a)


def test_a_required_spectrum_csv_is_the_acceptance_reference(tmp_path):
    """``rrs``: the drive's run is judged against a required response spectrum CSV (here in
    g against frequency, far below anything achieved: every point is outside), as
    ``platen plan --rrs`` does; a bad file raises naming it."""
    t, a = target(4.0)
    rrs = tmp_path / "rrs.csv"
    rrs.write_text("frequency_hz,psa_g\n1,1e-6\n2,1e-6\n5,1e-6\n")
    p = platen.plan(SCENARIO, t, target_a_m_s2=a, iterations=0, max_scale=False, rrs=rrs)
    acc = p["summary"]["drive"]["spectrum_acceptance"]
    assert acc["rrs"] == str(rrs) and acc["count"] == 3 and acc["within"] is False
    assert [m["period_s"] for m in acc["outside"]] == [0.2, 0.5, 1.0]
    own = platen.plan(SCENARIO, t, target_a_m_s2=a, iterations=0, max_scale=False)
    assert own["summary"]["drive"]["spectrum_acceptance"]["rrs"] is None
    bad = tmp_path / "bad.csv"
    bad.write_text("period_s,psa_g\n0.5,0\n")
    with pytest.raises(platen.ScenarioError, match="bad.csv"):
        platen.plan(SCENARIO, t, target_a_m_s2=a, iterations=0, max_scale=False, rrs=bad)
    with pytest.raises(platen.ScenarioError, match="rrs_damping"):
        platen.plan(SCENARIO, t, target_a_m_s2=a, rrs=rrs, rrs_damping=5)


def test_a_fast_three_component_target_is_resampled_with_a_notice():
    """A three-component target faster than the LHPOST6's 2048 Hz controller is put on its
    rate with a notice, as a uniaxial one (it was refused)."""
    t = np.arange(2049) / 4096.0
    ramp = lambda x: 0.5 - 0.5 * np.cos(np.pi * np.clip(x / 0.15, 0.0, 1.0))  # noqa: E731
    x = 1.5 * ramp(t) * ramp(0.5 - t) * np.sin(2 * np.pi * 3 * t)
    p = platen.plan({"table": {"preset": "lhpost6"}}, t, target_a_m_s2={"x": x},
                    iterations=0, max_scale=False)
    s = p["summary"]
    assert any("resampled to 2048 Hz" in w for w in s["warnings"])
    assert s["target"]["sample_rate_hz"] == 4096.0 and len(p["drive_t_s"]) == 1025
    assert set(s["drive"]["spectrum_acceptance"]) == {"x"}


def test_iterate_at_a_low_level_returns_the_scaled_up_drive_and_its_full_level_run():
    """``iterate_at=0.5``: the drive is iterated at half the target and doubled; the drive
    returned is the doubled one (exactly: a power of two), and the summary reports both the
    level's error and the full-level run's."""
    t, a = target(4.0)
    p = platen.plan(SCENARIO, t, target_a_m_s2=a, iterations=1, max_scale=False, iterate_at=0.5)
    s = p["summary"]
    assert s["iterate_at"] == 0.5
    low = s["drive"]["at_iteration_level"]
    assert low == s["iterations"][s["best_iteration"]]
    assert np.max(np.abs(p["drive_u_m"])) == 2.0 * low["peak_drive_u_m"]
    assert s["drive"]["achieved"]["peak_drive_u_m"] == 2.0 * low["peak_drive_u_m"]
    with pytest.raises(platen.ScenarioError, match="iterate_at"):
        platen.plan(SCENARIO, t, target_a_m_s2=a, iterate_at=0.0)
