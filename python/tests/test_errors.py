"""Bad input raises platen.ScenarioError (a ValueError) with the CLI's located message; a
numerical failure raises platen.SimulationError; nothing unwinds across the boundary."""

from __future__ import annotations

import json

import numpy as np
import pytest

import platen
from conftest import REFERENCE, SCENARIOS

FORCE = str(REFERENCE / "identified_nonpaper_force.csv")


def cli_message(cli, *args):
    """The CLI's message (stderr without `error: `) and its exit code."""
    p = cli(*args, check=False)
    assert p.stderr.startswith("error: "), p.stderr
    return p.stderr[len("error: "):].rstrip("\n"), p.returncode


def bad_scenarios(tmp_path):
    """Malformed scenarios and records, each a (file name, scenario, extra files)."""
    base = {"model": {"preset": "lhpost-2008"}, "excitation": {"force_csv": FORCE}}
    yield "unknown-key", {**base, "integrater": {}}, {}
    yield "negative-mass", {**base, "model": {"preset": "lhpost-2008", "identified": {"effective_mass_kg": -5}}}, {}
    yield "both-forms", {**base, "model": {"preset": "lhpost-2008", "identified": {}, "full": {}}}, {}
    yield "missing-record", {**base, "excitation": {"force_csv": "nowhere.csv"}}, {}
    yield "bad-step", {**base, "integrator": {"method": "rk4", "step_s": 0.0003}}, {}
    yield "unsorted", {**base, "excitation": {"force_csv": "unsorted.csv"}}, {
        "unsorted.csv": "t_s,force_n\n0,0\n0.1,1\n0.1,2\n0.3,3\n"
    }
    yield "non-numeric", {**base, "excitation": {"force_csv": "cell.csv"}}, {
        "cell.csv": "t_s,force_n\n0,0\n0.1,abc\n0.2,2\n"
    }
    yield "missing-column", {**base, "excitation": {"force_csv": "cols.csv"}}, {"cols.csv": "t_s,f\n0,0\n0.1,1\n"}
    yield "too-long", {**base, "duration_s": 100}, {}
    yield "unknown-preset", {**base, "model": {"preset": "lhpost-2099"}}, {}
    # Unit slips (issue 38): refused with what the value looks like, the CLI's message.
    loop = {"model": {"preset": "lhpost-2008"}, "duration_s": 0.5,
            "excitation": {"sine_motion": {"amplitude_m": 0.02, "frequency_hz": 1.0}}}
    yield "bulk-modulus-in-gpa", {**loop, "table_system": {"preset": "lhpost-2008", "oil_bulk_modulus_pa": 1.5}}, {}
    yield "supply-in-mpa", {**loop, "table_system": {"preset": "lhpost-2008", "supply_pressure_pa": 20.7}}, {}
    yield "area-in-cm2", {**loop, "table_system": {"preset": "lhpost-2008", "actuator": {
        "cap_side_area_m2": 2051, "rod_side_area_m2": 0.1291}}}, {}
    yield "time-in-ms", {**base, "excitation": {"force_csv": "ms.csv"}}, {
        "ms.csv": "t_s,force_n\n" + "".join(f"{k * 1000 / 1024!r},{1e4 * (k % 7)}\n" for k in range(2049))
    }


@pytest.mark.parametrize("case", [c[0] for c in bad_scenarios(None)])
def test_a_bad_scenario_file_raises_scenario_error_with_the_clis_message(case, cli, tmp_path):
    name, scenario, files = next(c for c in bad_scenarios(tmp_path) if c[0] == case)
    for file, text in files.items():
        (tmp_path / file).write_text(text)
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(scenario))
    expected, code = cli_message(cli, "simulate", path)
    with pytest.raises(platen.ScenarioError) as raised:
        platen.simulate(path)
    assert str(raised.value) == expected
    assert code == raised.value.exit_code == 3
    assert isinstance(raised.value, ValueError) and isinstance(raised.value, platen.PlatenError)
    says = {"bulk-modulus-in-gpa": "looks like GPa", "supply-in-mpa": "looks like MPa",
            "area-in-cm2": "looks like cm²", "time-in-ms": '"t_s": {"unit": "ms"}'}
    assert says.get(case, "") in expected


def test_a_numerical_failure_raises_simulation_error_with_the_clis_message(cli, tmp_path):
    scenario = {
        "model": {"preset": "lhpost-2008", "identified": {"effective_mass_kg": 1e-300}},
        "excitation": {"sine_force": {"amplitude_n": 1e9, "frequency_hz": 0.5}},
        "duration_s": 1,
    }
    path = tmp_path / "tiny-mass.json"
    path.write_text(json.dumps(scenario))
    expected, code = cli_message(cli, "simulate", path)
    with pytest.raises(platen.SimulationError) as raised:
        platen.simulate(path)
    assert str(raised.value) == expected
    assert "numerical failure at t = " in expected
    assert code == raised.value.exit_code == 4
    with pytest.raises(platen.SimulationError):
        platen.simulate(scenario)


def test_dict_scenarios_are_reported_with_their_json_path():
    with pytest.raises(platen.ScenarioError, match=r"^`scenario dict`: model\.identified\.effective_mass_kg = -5: expected"):
        platen.simulate({"model": {"preset": "lhpost-2008", "identified": {"effective_mass_kg": -5}},
                         "excitation": {"force_csv": FORCE}})
    with pytest.raises(platen.ScenarioError, match=r"^`scenario dict`: integrater.*unknown field `integrater`"):
        platen.simulate({"model": {"preset": "lhpost-2008"}, "excitation": {"force_csv": FORCE}, "integrater": {}})
    with pytest.raises(platen.ScenarioError, match=r"^`scenario dict`: excitation\.lowpass_hz = nan: expected a finite number$"):
        platen.simulate({"model": {"preset": "lhpost-2008"}, "excitation": {"force_csv": FORCE, "lowpass_hz": float("nan")}})
    with pytest.raises(platen.ScenarioError, match=r"^`scenario dict`: excitation\.force_csv = object: expected a number"):
        platen.simulate({"model": {"preset": "lhpost-2008"}, "excitation": {"force_csv": object()}})
    with pytest.raises(platen.ScenarioError, match="expected a path to a scenario JSON file or a dict"):
        platen.simulate(42)
    # NumPy scalars and arrays are plain JSON values.
    run = platen.simulate({
        "model": {"preset": "lhpost-2008", "identified": {"coulomb_force_n": np.float32(2e4)}},
        "excitation": {"white_noise_motion": {"rms_acceleration_g": np.float64(0.05), "band_hz": np.array([0.5, 10]),
                                              "seed": np.int64(2)}},
        "duration_s": np.int32(4),
    })
    assert len(run) == 4 * 1024 + 1


def test_bad_arrays_name_the_array_and_the_index():
    t = np.arange(0, 100) / 100
    f = np.sin(t)
    cases = [
        ((t, np.where(t == t[3], np.nan, f)), "`platen.forward()`: force_n[3] = NaN is not finite"),
        ((np.where(t == t[5], t[4], t), f), "`platen.forward()`: time is not strictly increasing at sample 5"),
        ((t, f[:-1]), "`platen.forward()`: record columns differ in length: force_n has 99 values, expected 100"),
        ((t[:1], f[:1]), "`platen.forward()`: record has 1 samples; at least 2 are needed"),
        ((np.r_[t[:50], t[50:] + 0.003], f), "`platen.forward()`: record is not uniformly sampled: the interval before sample 50"),
        ((t.reshape(10, 10), f), "`platen.forward()`: t_s: expected a 1-D array, got shape (10, 10)"),
        ((t, f + 1j), "`platen.forward()`: force_n: expected real numbers (a float or integer array), got dtype complex128"),
        ((t, f > 0), "`platen.forward()`: force_n: expected real numbers (a float or integer array), got dtype bool"),
        ((t, ["a"] * 100), "`platen.forward()`: force_n: expected real numbers (a float or integer array), got dtype <U1"),
        ((t, [1.0, None] * 50), "`platen.forward()`: force_n: expected real numbers (a float or integer array), got dtype object"),
    ]
    for args, expected in cases:
        with pytest.raises(platen.ScenarioError) as raised:
            platen.forward(*args)
        assert str(raised.value).startswith(expected), (str(raised.value), expected)
    with pytest.raises(platen.ScenarioError, match=r"^`platen.inverse\(\)`: record columns differ in length: a_m_s2 has 3 values, expected 100"):
        platen.inverse(t, f, a_m_s2=[0.0, 0.0, 0.0])
    with pytest.raises(platen.ScenarioError, match=r"^`platen.inverse\(\)`: u_m\[7\] = inf is not finite"):
        platen.inverse(t, np.where(t == t[7], np.inf, f))


def test_settings_errors_name_the_argument():
    t = np.arange(0, 1025) / 1024
    f = 1e4 * np.sin(t)
    with pytest.raises(platen.ScenarioError, match=r"^`platen.forward\(\)`: model.identified.viscous_exponent = 2: expected"):
        platen.forward(t, f, model={"identified": {"viscous_exponent": 2}})
    with pytest.raises(platen.ScenarioError, match=r"^`platen.forward\(\)`: integrator.step_s = 0.0003: expected"):
        platen.forward(t, f, integrator={"method": "rk4", "step_s": 0.0003})
    with pytest.raises(platen.ScenarioError, match=r"^`platen.forward\(\)`: initial.*unknown field `u`"):
        platen.forward(t, f, initial={"u": 0.1})
    with pytest.raises(platen.ScenarioError, match=r"^`platen.inverse\(\)`: model.preset = \"nope\""):
        platen.inverse(t, f, model="nope")
    with pytest.raises(platen.ScenarioError, match=r"^`platen.forward\(\)`: model = int: expected None, a preset name or a dict"):
        platen.forward(t, f, model=3)


def test_a_bad_specimen_is_refused_naming_the_storey():
    t = np.arange(0, 1025) / 1024
    with pytest.raises(platen.ScenarioError, match=r"specimen = int: expected None"):
        platen.forward(t, np.sin(t), specimen=3)
    storeys = [{"mass_kg": -30e3, "stiffness_n_per_m": 5e7, "damping_n_s_per_m": 1e5}]
    with pytest.raises(platen.ScenarioError, match=r"specimen.storeys\[0\].mass_kg = -30000"):
        platen.forward(t, 1e4 * np.sin(t), specimen=storeys)
    with pytest.raises(platen.ScenarioError, match=r"specimen.storeys\[0\].mass_kg"):
        platen.inverse(t, 0.01 * np.sin(t), specimen={"storeys": storeys})


def test_model_errors(cli):
    expected, code = cli_message(cli, "model", "--preset", "lhpost-2099")
    with pytest.raises(platen.ScenarioError) as raised:
        platen.model("lhpost-2099")
    assert str(raised.value) == expected and code == 3
    with pytest.raises(platen.ScenarioError, match=r"pressure_mpa = -1: expected a pressure >= 0 MPa"):
        platen.model(pressure_mpa=-1)
    with pytest.raises(platen.ScenarioError, match=r"13.8e6 looks like Pa \(13.8 MPa\)"):
        platen.model(pressure_mpa=13.8e6)
    with pytest.raises(platen.ScenarioError, match="form = 'fll': expected 'identified' or 'full'"):
        platen.model(form="fll")


def test_compare_errors_carry_the_clis_message(cli, tmp_path):
    scenario = SCENARIOS / "sr9" / "sr9-forward.json"
    short = tmp_path / "short.csv"
    lines = (SCENARIOS / "sr9" / "sr9-recorded.csv").read_text().splitlines()
    short.write_text("\n".join(lines[:2000]) + "\n")
    expected, code = cli_message(cli, "compare", scenario, "--recorded", short)
    with pytest.raises(platen.ScenarioError) as raised:
        platen.compare(scenario, short)
    assert str(raised.value) == expected and code == 3
    with pytest.raises(platen.ScenarioError, match=r"^`columns=`: columns.u_m.unit = "):
        platen.compare(scenario, SCENARIOS / "sr9" / "sr9-recorded.csv", columns={"u_m": {"unit": "furlong"}})
    with pytest.raises(platen.ScenarioError, match=r"window = \(5, 2\): expected finite times with t0_s < t1_s"):
        platen.compare(scenario, SCENARIOS / "sr9" / "sr9-recorded.csv", window=(5, 2))


def test_identify_errors(cli, tmp_path):
    # A record that never moves: no identification method has anything to fit.
    t = np.arange(0, 10 * 512 + 1) / 512
    u = np.full_like(t, 0.01)
    record = tmp_path / "at-rest.csv"
    columns = {"t_s": t, "u_m": u, "a_m_s2": np.zeros_like(t), "force_n": 1e3 * np.sin(t)}
    lines = [",".join(columns)] + [",".join(repr(float(c[i])) for c in columns.values()) for i in range(len(t))]
    record.write_text("\n".join(lines) + "\n")
    p = cli("identify", record, check=False)
    with pytest.raises(platen.IdentificationError) as raised:
        platen.identify(record)
    assert "error: " + str(raised.value) == p.stderr.rstrip("\n")
    assert isinstance(raised.value, ValueError) and p.returncode == 3
    with pytest.raises(platen.ScenarioError, match="pressure_mpa has 2 values for 1 files"):
        platen.identify([record], pressure_mpa=[13.8, 6.9])
    with pytest.raises(platen.ScenarioError, match="no test files"):
        platen.identify([])
    # A manifest's mistake: the CLI's message, naming the manifest and the JSON path.
    manifest = tmp_path / "manifest.json"
    manifest.write_text(json.dumps({"floors": [{"column": "Acc", "mass_kg": -1}], "tests": [{"file": "at-rest.csv"}]}))
    p = cli("identify", "--manifest", manifest, check=False)
    with pytest.raises(platen.ScenarioError) as raised:
        platen.identify(manifest=manifest)
    assert "error: " + str(raised.value) == p.stderr.rstrip("\n") and p.returncode == 3
    assert "at `floors[0].mass_kg` (tests[0]): -1: expected a mass > 0 kg" in str(raised.value)


def test_sweep_errors():
    scenario = SCENARIOS / "sr9-like-sine-force.json"
    with pytest.raises(platen.ScenarioError, match=r"set: `full.platen_mass_kg`: the scenario runs the identified model"):
        platen.sweep(scenario, set={"full.platen_mass_kg": [130e3]})
    with pytest.raises(platen.ScenarioError, match=r"set: `identified.mass`: unknown"):
        platen.sweep(scenario, set={"identified.mass": [130e3]})
    with pytest.raises(platen.ScenarioError, match=r"case 1 \(scale 1, 13.8 MPa, identified.effective_mass_kg = -1\): the model cannot be built"):
        platen.sweep(scenario, set={"identified.effective_mass_kg": [144e3, -1]})
    with pytest.raises(platen.ScenarioError, match=r"pressure_mpa: -1.0 MPa: expected a pressure >= 0"):
        platen.sweep(scenario, pressure_mpa=[-1])
