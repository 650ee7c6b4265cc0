#!/usr/bin/env python3
"""Writes scenarios/paper-tests/: the periodic test program of Ozcelik et al. (2008), Tables I
and II, as inverse scenarios (prescribed motion -> actuator force), at the three hold-down
pressures the paper used (0, 6.9, 13.8 MPa).

Run from the repository root: python3 tools/make_paper_scenarios.py
The output is deterministic; the JSON files are committed. manifest.json lists the 72 tests for
`platen identify --manifest scenarios/paper-tests/manifest.json` (the paper's identification).

Choices where the paper is silent (stated in each description):
* S1-S3 (low-velocity sines, 1.0, 1.5, 2.5 cm/s peak) are at 0.1 Hz, which keeps their peak
  accelerations below the paper's "< 0.2 % g".
* Sines run 5 cycles (the paper analyses the second-to-last cycle); triangles 3 cycles
  ("only a few (2-3) cycles").
* Triangles keep Table I's amplitude and velocity; the rounded reversals are
  constant-acceleration arcs taking 20 % of a quarter period, A_r = 5 V^2 / U, so the period is
  4U/V + 2V/A_r = 4.4 U/V (10 % longer than a sharp triangle's). Table I's frequency for T7
  (0.10 Hz) does not match its U and V (4Uf = 15 cm/s, not 25 cm/s); U and V are kept.
"""
import json
import os

# (name, frequency Hz, amplitude m)  -- Table II, plus S1-S3 from the text (peak velocity)
SINES = [
    ("S1", 0.1, 0.010 / (2 * 3.141592653589793 * 0.1)),
    ("S2", 0.1, 0.015 / (2 * 3.141592653589793 * 0.1)),
    ("S3", 0.1, 0.025 / (2 * 3.141592653589793 * 0.1)),
    ("S4", 0.40, 0.04),
    ("S5", 1.00, 0.04),
    ("S6", 0.40, 0.10),
    ("S7", 0.80, 0.10),
    ("S8", 1.20, 0.10),
    ("S9", 0.60, 0.20),
    ("S10", 0.80, 0.20),
    ("S11", 1.20, 0.20),
    ("S12", 1.43, 0.20),
]
# (name, Table I frequency Hz, amplitude m, velocity m/s) -- Table I
TRIANGLES = [
    ("T1", 0.05, 0.05, 0.01),
    ("T2", 0.05, 0.075, 0.015),
    ("T3", 0.05, 0.125, 0.025),
    ("T4", 0.05, 0.50, 0.10),
    ("T5", 0.10, 0.25, 0.10),
    ("T6", 0.10, 0.625, 0.25),
    ("T7", 0.10, 0.375, 0.25),
    ("T8", 0.17, 0.75, 0.50),
    ("T9", 0.40, 0.4688, 0.75),
    ("T10", 0.40, 0.625, 1.00),
    ("T11", 0.50, 0.75, 1.50),
    ("T12", 0.67, 0.675, 1.80),
]
PRESSURES = [("13.8MPa", 13.8), ("6.9MPa", 6.9), ("0MPa", 0.0)]


def write(path, doc):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        json.dump(doc, f, indent=2)
        f.write("\n")


def main():
    root = os.path.join("scenarios", "paper-tests")
    for folder, p in PRESSURES:
        for name, f, u in SINES:
            v = u * 2 * 3.141592653589793 * f
            a_g = v * 2 * 3.141592653589793 * f / 9.80665
            cycles = 5
            write(os.path.join(root, folder, f"{name}.json"), {
                "name": f"{name} sine test at {p} MPa",
                "description": (
                    f"Paper test {name} (Table II / text): sine, u_max = {u * 100:.4g} cm at {f} Hz "
                    f"(peak {v * 100:.4g} cm/s, {a_g:.3g} g), {cycles} cycles, hold-down pressure {p} MPa. "
                    "Inverse run: the actuator force the identified model needs."
                ),
                "model": {"preset": "lhpost-2008", "hold_down_pressure_mpa": p},
                "excitation": {"sine_motion": {"amplitude_m": round(u, 9), "frequency_hz": f, "sample_rate_hz": 1024}},
                "duration_s": round(cycles / f, 9),
            })
        for name, f_table, u, v in TRIANGLES:
            a_r = 5 * v * v / u
            period = 4 * u / v + 2 * v / a_r
            cycles = 3
            write(os.path.join(root, folder, f"{name}.json"), {
                "name": f"{name} triangle test at {p} MPa",
                "description": (
                    f"Paper test {name} (Table I): triangle, u_max = {u * 100:.4g} cm, constant velocity "
                    f"{v * 100:.4g} cm/s (Table I frequency {f_table} Hz), rounded reversals at "
                    f"{a_r:.4g} m/s^2 (20 % of a quarter period), period {period:.4g} s, {cycles} cycles, "
                    f"hold-down pressure {p} MPa. Inverse run."
                ),
                "model": {"preset": "lhpost-2008", "hold_down_pressure_mpa": p},
                "excitation": {"triangle_motion": {
                    "amplitude_m": u, "velocity_m_s": v,
                    "reversal_acceleration_m_s2": round(a_r, 9), "sample_rate_hz": 1024,
                }},
                "duration_s": round(cycles * period, 9),
            })
    write_manifest(root)


def write_manifest(root):
    """scenarios/paper-tests/manifest.json: the whole programme for `platen identify --manifest`.
    Each entry names a scenario whose recorded-like data identify makes in memory (as
    `platen generate recorded --seed N` would write them), each test with its own noise seed;
    the hold-down pressure is the scenario's."""
    entries = []
    for folder, _ in PRESSURES:
        for name in [s[0] for s in SINES] + [t[0] for t in TRIANGLES]:
            entries.append(json.dumps({
                "scenario": f"{folder}/{name}.json", "seed": len(entries) + 1, "name": f"{name}@{folder}",
            }))
    with open(os.path.join(root, "manifest.json"), "w") as f:
        f.write('{\n  "tests": [\n    ' + ",\n    ".join(entries) + "\n  ]\n}\n")


if __name__ == "__main__":
    main()
