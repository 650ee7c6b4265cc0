"""The Python API gives what the command-line tool gives: the same samples to the last bit,
the same --json objects, the same sweep rows."""

from __future__ import annotations

import json

import numpy as np
import pytest

import platen
from conftest import SCENARIOS, read_csv

SHIPPED = [
    "sr9-like-sine-force.json",
    "paper-forward-force-dopri5.json",
    "full-model-large-stroke.json",
    "s9-sine-motion.json",
    "sr9/sr9-forward.json",
    "specimen/frame-forward.json",
    "specimen/frame-inverse.json",
    "specimen/frame-yielding-inverse.json",
]


@pytest.mark.parametrize("name", SHIPPED)
def test_simulate_gives_the_clis_csv_to_the_last_bit_and_its_json(name, cli_json, tmp_path):
    path = SCENARIOS / name
    out = tmp_path / "out.csv"
    expected_summary = cli_json("simulate", path, "--out", out)
    expected = read_csv(out)
    run = platen.simulate(path)
    assert run.columns == tuple(expected), "columns in CSV order"
    for column in run.columns:
        a = run[column]
        assert a.dtype == np.float64 and a.ndim == 1 and a.flags.c_contiguous
        assert np.array_equal(a, expected[column]), f"{column} differs from the CLI's CSV"
    assert run.summary.pop("out") is None
    assert expected_summary.pop("out") == str(out)
    assert run.summary == expected_summary


def test_a_scenario_dict_runs_as_its_file():
    path = SCENARIOS / "sr9" / "sr9-forward.json"
    scenario = json.loads(path.read_text())
    scenario["excitation"]["force_csv"] = str(path.parent / scenario["excitation"]["force_csv"])
    from_dict = platen.simulate(scenario)
    from_file = platen.simulate(str(path))
    for column in from_file.columns:
        assert np.array_equal(from_dict[column], from_file[column]), column
    assert from_dict.summary.pop("scenario") == "scenario dict"
    from_file.summary.pop("scenario")
    assert from_dict.summary == from_file.summary


def test_forward_on_arrays_gives_simulate_of_the_same_record():
    """A force CSV read in Python and given as arrays runs exactly as the scenario that
    names it (the SR9 record with its 0.6 Hz low-pass and recorded initial state)."""
    path = SCENARIOS / "sr9" / "sr9-forward.json"
    rec = read_csv(path.parent / "sr9-recorded.csv")
    run = platen.forward(
        rec["t_s"],
        rec["force_n"],
        integrator={"method": "rk4", "step_s": 1 / 1024},
        initial={"u_m": rec["u_m"][0], "v_m_s": rec["v_m_s"][0]},
        duration_s=20.0,
        lowpass_hz=0.6,
        lowpass_filter="brickwall",
    )
    expected = platen.simulate(path)
    for column in expected.columns:
        assert np.array_equal(run[column], expected[column]), column


def test_compare_gives_the_clis_json_and_the_readmes_sr9_numbers(cli_json):
    scenario = SCENARIOS / "sr9" / "sr9-forward.json"
    recorded = SCENARIOS / "sr9" / "sr9-recorded.csv"
    result = platen.compare(scenario, recorded)
    assert result == cli_json("compare", scenario, "--recorded", recorded)
    # The README's SR9 check: displacement NRMSE 0.694 %, velocity 1.454 %, peak ratios
    # 0.9992 and 0.9991, correlation 0.99998 and 0.99990, lag +1.0 ms.
    u, v = result["u_m"], result["v_m_s"]
    assert round(100 * u["nrmse"], 3) == 0.694 and round(100 * v["nrmse"], 3) == 1.454
    assert round(u["peak_ratio"], 4) == 0.9992 and round(v["peak_ratio"], 4) == 0.9991
    assert round(u["correlation"], 5) == 0.99998 and round(v["correlation"], 5) == 0.99990
    assert round(1e3 * u["lag_s"], 1) == 1.0


def test_compare_nrmse_is_numpys_on_the_simulated_and_recorded_columns():
    """NRMSE = RMS(simulated − recorded) / RMS(recorded), computed here in NumPy from the run's
    columns and the recorded CSV (they share their time stamps): the README's 14 digits."""
    scenario = SCENARIOS / "sr9" / "sr9-forward.json"
    recorded = read_csv(SCENARIOS / "sr9" / "sr9-recorded.csv")
    run = platen.simulate(scenario)
    n = len(run)
    assert np.array_equal(run["t_s"], recorded["t_s"][:n])
    result = platen.compare(scenario, SCENARIOS / "sr9" / "sr9-recorded.csv")
    for column, readme in [("u_m", 0.6942888859e-2), ("v_m_s", 1.4537857852e-2)]:
        rec = recorded[column][:n]
        nrmse = np.sqrt(np.mean((run[column] - rec) ** 2)) / np.sqrt(np.mean(rec**2))
        # Summation order differs between NumPy and the library: 1e-12 relative.
        assert abs(result[column]["nrmse"] / nrmse - 1) < 1e-12, (column, result[column]["nrmse"], nrmse)
        assert abs(nrmse - readme) < 1e-12, (column, nrmse)


@pytest.mark.parametrize(
    "kwargs, args",
    [
        ({}, []),
        ({"pressure_mpa": 6.9, "form": "full"}, ["--pressure-mpa", "6.9", "--form", "full"]),
        ({"pressure_mpa": None}, []),
    ],
)
def test_model_gives_the_clis_json(kwargs, args, cli_json):
    assert platen.model(**kwargs) == cli_json("model", *args)


def test_sweep_rows_are_the_clis_csv(cli, tmp_path):
    scenario = SCENARIOS / "sr9-like-sine-force.json"
    out = tmp_path / "cases.csv"
    cli(
        "sweep", scenario, "--scale", "0.5,1,1.5", "--pressure-mpa", "6.9,13.8",
        "--set", "identified.coulomb_force_n=20e3,25e3", "--out", out,
    )
    rows = platen.sweep(
        scenario,
        scale=[0.5, 1, 1.5],
        pressure_mpa=[6.9, 13.8],
        set={"identified.coulomb_force_n": [20e3, 25e3]},
        as_frame=False,
    )
    expected = out.read_text().splitlines()
    header = expected[0].split(",")
    assert len(rows) == 12 == len(expected) - 1
    assert list(rows[0]) == header
    for row, line in zip(rows, expected[1:]):
        cells = line.split(",")
        for name, cell in zip(header, cells):
            value = row[name]
            if cell == "":
                assert value is None, (name, value)
            elif name in ("limits_exceeded", "status"):
                assert value == cell, (name, cell, value)
            else:
                # Shortest round-trip text: the same double.
                assert float(cell) == value and type(value) is (int if name in ("case", "events") else float)
    assert all(r["status"] == "ok" for r in rows)


def test_sweep_with_no_axis_is_the_scenario_itself():
    scenario = SCENARIOS / "sr9-like-sine-force.json"
    [row] = platen.sweep(scenario, as_frame=False)
    s = platen.simulate(scenario).summary
    assert (row["peak_u_m"], row["peak_force_n"], row["stick_time_s"]) == (
        s["peak_u_m"],
        s["peak_force_n"],
        s["stick_time_s"],
    )


def test_sweep_returns_a_dataframe_when_pandas_is_installed():
    pd = pytest.importorskip("pandas", reason="SKIPPED: pandas is not installed")
    frame = platen.sweep(SCENARIOS / "sr9-like-sine-force.json", scale=[0.5, 1])
    assert isinstance(frame, pd.DataFrame)
    assert list(frame["scale"]) == [0.5, 1.0]
    assert frame["peak_u_m"].dtype == np.float64


def test_identify_gives_the_clis_json(cli, cli_json, tmp_path):
    """Recorded-like tests made by the CLI (two sines, two triangles at 13.8 MPa)."""
    files = []
    for name in ["S9", "S11", "T7", "T9"]:
        out = tmp_path / f"{name}.csv"
        cli("generate", "recorded", SCENARIOS / "paper-tests" / "13.8MPa" / f"{name}.json", "--seed", "3", "--out", out)
        files.append(out)
    expected = cli_json("identify", *files, "--pressure-mpa", "13.8")
    result = platen.identify(files, pressure_mpa=13.8)
    assert result == expected
    assert abs(result["effective_mass_kg"] / 144e3 - 1) < 0.01
    assert abs(result["stiffness_n_per_m"] / 1.266e6 - 1) < 0.01
    assert [r["method"] for r in result["records"]] == ["periodic"] * 4


def test_identify_routes_an_earthquake_record_as_the_cli_does(cli_json):
    """A lab's earthquake record goes to the any-record method, in Python as in the CLI."""
    data = SCENARIOS.parent / "tests" / "data" / "any-record"
    record, columns = data / "eq-lab.csv", data / "columns.json"
    expected = cli_json("identify", record, "--columns", columns)
    result = platen.identify(record, columns=columns)
    assert result == expected
    assert result["method"] == "record"
    assert [(r["method"], r["used"]) for r in result["records"]] == [("record", True)]


def test_identify_applies_a_column_maps_delay_as_the_cli_does(cli_json, tmp_path):
    """A column map's ``delay_s`` (a channel's known skew) reaches identification through the
    reading the CLI uses: the same object, with the delay given."""
    data = SCENARIOS.parent / "tests" / "data" / "any-record"
    columns = json.loads((data / "columns.json").read_text())
    columns["a_m_s2"]["delay_s"] = 0.004
    path = tmp_path / "columns-delay.json"
    path.write_text(json.dumps(columns))
    record = data / "eq-lab.csv"
    expected = cli_json("identify", record, "--columns", path)
    assert platen.identify(record, columns=path) == expected
    result = platen.identify(record, columns=columns)
    assert result == expected
    assert result["records"][0]["channel_delay_s"] == {"a_m_s2": 0.004}


def test_identify_reads_a_manifest_with_floors_as_the_cli_does(cli_json):
    """``manifest=`` with a specimen's floors (their base shear taken off the force) gives
    ``platen identify --manifest … --json``."""
    manifest = SCENARIOS.parent / "tests" / "data" / "any-record" / "two-storey-manifest.json"
    expected = cli_json("identify", "--manifest", manifest)
    result = platen.identify(manifest=manifest)
    assert result == expected
    (entry,) = result["records"]
    assert entry["floor_masses_kg"] == [14000.0, 11000.0]
    assert entry["peak_base_shear_n"] > 0


def test_identify_reads_a_mixed_days_manifest_as_the_cli_does(cli_json):
    """A manifest with a column map, a declared kind and scenario entries (recorded-like
    data made in memory): the CLI's object, every record accounted for."""
    manifest = SCENARIOS.parent / "tests" / "data" / "any-record" / "mixed-day-manifest.json"
    expected = cli_json("identify", "--manifest", manifest)
    result = platen.identify(manifest=manifest)
    assert result == expected
    assert [r["name"] for r in result["records"]] == [
        "eq-lab", "wn-lab", "wn-low-lab", "S9@13.8MPa", "T4@13.8MPa"
    ]


def test_forward_and_inverse_with_a_specimen_give_the_scenarios_run():
    """``specimen=`` on arrays runs exactly as the shipped specimen scenarios, with the
    specimen's columns after the contract's."""
    path = SCENARIOS / "specimen" / "frame-forward.json"
    scenario = json.loads(path.read_text())
    from_file = platen.simulate(path)
    assert from_file.columns[8:] == (
        "base_shear_n", "storey1_u_m", "storey2_u_m", "storey1_a_m_s2", "storey2_a_m_s2"
    )
    exc = scenario["excitation"]["sine_force"]
    t = from_file["t_s"]
    force = from_file["force_n"]
    run = platen.forward(
        t, force, integrator=scenario["integrator"], specimen=scenario["specimen"]["storeys"]
    )
    assert run.columns == from_file.columns
    for column in run.columns:
        assert np.array_equal(run[column], from_file[column]), column
    assert exc["amplitude_n"] == pytest.approx(np.max(np.abs(force)))
    inv = platen.inverse(
        run["t_s"], run["u_m"], run["v_m_s"], run["a_m_s2"], specimen=scenario["specimen"]
    )
    # The inverse's force is Eq. 23 plus the base shear of the specimen it drives.
    parts = inv["inertial_force_n"] + inv["elastic_force_n"] + inv["dissipative_force_n"]
    assert np.allclose(inv["force_n"], parts + inv["base_shear_n"], rtol=0, atol=1e-6)


def test_a_yielding_specimen_from_python_gives_its_hysteresis():
    """``specimen=`` with a storey's ``hysteresis`` (issue 52): the forward and inverse runs
    give each storey's drift, restoring force, hysteretic force and energy, and the summary
    its ductility."""
    storeys = [
        {"mass_kg": 12e3, "stiffness_n_per_m": 6e6, "damping_n_s_per_m": 2e4,
         "hysteresis": {"bilinear": {"yield_force_n": 6e3, "post_yield_stiffness_ratio": 0.05}}},
        {"mass_kg": 8e3, "stiffness_n_per_m": 4e6, "damping_n_s_per_m": 1.2e4,
         "hysteresis": {"bouc_wen": {"yield_force_n": 4e3, "exponent": 3}}},
    ]
    t = np.arange(0, 4 * 1024 + 1) / 1024
    force = 2e6 * np.sin(2 * np.pi * 1.5 * t)
    run = platen.forward(t, force, specimen=storeys)
    for name in ("storey1_drift_m", "storey2_force_n", "storey1_hysteretic_force_n",
                 "storey2_hysteretic_j"):
        assert name in run.columns, name
    assert run["storey1_hysteretic_j"][-1] > 0 and run["storey2_hysteretic_j"][-1] > 0
    # Elastic-plastic with 5 % hardening: the restoring force stays within its envelope.
    k, fy = 6e6, 6e3
    dy = fy / k
    envelope = fy + 0.05 * k * np.maximum(np.abs(run["storey1_drift_m"]) - dy, 0.0)
    assert np.all(np.abs(run["storey1_force_n"]) <= envelope * (1 + 1e-9))
    summary = run.summary["specimen"]["storeys"]
    assert summary[0]["ductility"] > 1 and summary[1]["ductility"] > 1
    assert summary[0]["ductility"] == pytest.approx(
        np.max(np.abs(run["storey1_drift_m"])) / dy, rel=1e-12)
