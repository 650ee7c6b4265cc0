#!/usr/bin/env python3
"""Writes the shipped multi-axis scenarios (scenarios/multi-axis/): an LHPOST6-like table
(not the lhpost6 preset, which comes with the multi-axis closed loop) and a synthetic
three-component table motion, with its exact velocity and acceleration.

The motion: per axis a sum of sines (fixed frequencies 0.3-6 Hz and phases below) under a
Tukey envelope (2 s cosine ramps), sampled at 200 Hz for 20 s; x and y peak near 0.25 m and
0.2 m, z near 2 cm. The rates and accelerations are the analytic derivatives of the enveloped
sum, so the inverse needs no finite differences.

The specimen: a two-level tower, 60 t per level at 6 m and 12 m above the platen's top
surface, its centre of mass off the platen's centre by (0.9, -0.6) m, with x, y and z DOFs per
level relative to the platen (a shear frame in x and y, 2 Hz and 1.8 Hz first modes; axial
columns, about 20 Hz), Rayleigh damping of 2 % at 2 and 10 Hz.

The forward scenario's forces are platen's own: its inverse of the first 10 s of the motion on
the table (pads with friction) carrying the tower (run with the binary named by PLATEN, default
target/release/platen: build it first), kept to t_s and the actuator force columns.

Usage (from the repository root, Python 3 only): python3 tools/make_multi_axis_scenarios.py
The output is deterministic.
"""

import csv
import json
import math
import os
import subprocess
import sys
import tempfile

OUT = "scenarios/multi-axis"
RATE_HZ = 200
DURATION_S = 20.0
RAMP_S = 2.0

# (amplitude m, frequency Hz, phase rad) per axis.
SINES = {
    "x": [(0.10, 0.31, 0.2), (0.08, 0.53, 1.9), (0.04, 0.87, 4.1), (0.015, 1.4, 2.7),
          (0.006, 2.3, 0.5), (0.002, 3.7, 5.5), (0.0006, 5.9, 3.3)],
    "y": [(0.08, 0.37, 3.0), (0.07, 0.61, 0.4), (0.03, 0.95, 5.0), (0.012, 1.6, 1.1),
          (0.005, 2.6, 3.9), (0.0015, 4.1, 0.8), (0.0006, 6.0, 2.2)],
    "z": [(0.004, 0.9, 1.3), (0.003, 1.7, 4.4), (0.0015, 2.9, 0.1), (0.0006, 4.6, 2.8),
          (0.0003, 6.2, 5.1)],
}


def envelope(t):
    """Tukey window and its first two derivatives."""
    if t < RAMP_S:
        s = t / RAMP_S
    elif t > DURATION_S - RAMP_S:
        s = (DURATION_S - t) / RAMP_S
    else:
        return 1.0, 0.0, 0.0
    sign = 1.0 if t < RAMP_S else -1.0
    w = 0.5 - 0.5 * math.cos(math.pi * s)
    dw = sign * 0.5 * math.pi / RAMP_S * math.sin(math.pi * s)
    ddw = 0.5 * (math.pi / RAMP_S) ** 2 * math.cos(math.pi * s)
    return w, dw, ddw


def axis(t, sines):
    f = df = ddf = 0.0
    for a, hz, ph in sines:
        w = 2.0 * math.pi * hz
        f += a * math.sin(w * t + ph)
        df += a * w * math.cos(w * t + ph)
        ddf -= a * w * w * math.sin(w * t + ph)
    e, de, dde = envelope(t)
    return e * f, de * f + e * df, dde * f + 2.0 * de * df + e * ddf


def write_motion(path):
    n = int(round(DURATION_S * RATE_HZ)) + 1
    names = ["t_s"]
    for a, unit in (("x", "m"), ("y", "m"), ("z", "m")):
        names += [f"{a}_{unit}", f"{a}_{unit}_s", f"{a}_{unit}_s2"]
    with open(path, "w", newline="\n") as f:
        f.write(",".join(names) + "\n")
        for i in range(n):
            t = i / RATE_HZ
            row = [t]
            for a in ("x", "y", "z"):
                row += axis(t, SINES[a])
            f.write(",".join(format(float(x), ".12g") for x in row) + "\n")


def table():
    m = 180e3
    dims = (12.2, 7.6, 1.5)
    ixx = m / 12 * (dims[1] ** 2 + dims[2] ** 2)
    iyy = m / 12 * (dims[0] ** 2 + dims[2] ** 2)
    izz = m / 12 * (dims[0] ** 2 + dims[1] ** 2)
    horizontal = []
    c30, s30 = math.cos(math.radians(30)), math.sin(math.radians(30))
    for name, x, y in (("h1", 6.1, 1.5), ("h2", 6.1, -1.5), ("h3", -6.1, 1.5), ("h4", -6.1, -1.5)):
        sx = 1.0 if x > 0 else -1.0
        sy = 1.0 if y > 0 else -1.0
        base = [round(x + sx * 3.0 * c30, 6), round(y + sy * 3.0 * s30, 6), -0.6]
        horizontal.append({
            "name": name, "base_m": base, "platen_m": [x, y, -0.6],
            "cap_side_area_m2": 0.2, "rod_side_area_m2": 0.12,
            "chamber_volume_m3": 0.25, "stroke_m": 0.9,
        })
    vertical = []
    k = 0
    for x in (-4.0, 0.0, 4.0):
        for y in (-2.4, 2.4):
            k += 1
            vertical.append({
                "name": f"v{k}", "base_m": [x, y, -3.0],
                "pad": {"axis": [0.0, 0.0, 1.0], "contact_m": [x, y, -1.2],
                        "friction_coefficient": 0.0044},
                "cap_side_area_m2": 0.5, "rod_side_area_m2": 0.0,
                "chamber_volume_m3": 0.15, "stroke_m": 0.13,
            })
    struts = [{
        "name": name, "base_m": [x, y, -4.5], "platen_m": [x, y, -1.2],
        "area_m2": 0.15, "pressure_pa": 13.8e6, "gas_volume_m3": 0.315,
        "polytropic_exponent": 1.44,
    } for name, x, y in (("s1", -5.0, 0.0), ("s2", 5.0, 0.0), ("s3", 0.0, -3.0), ("s4", 0.0, 3.0))]
    return {
        "platen": {
            "mass_kg": m,
            "inertia_kg_m2": [[round(ixx, 3), 0.0, 0.0], [0.0, round(iyy, 3), 0.0],
                              [0.0, 0.0, round(izz, 3)]],
            "centre_of_mass_m": [0.0, 0.0, -0.6],
        },
        "actuators": horizontal + vertical,
        "hold_down_struts": struts,
        "oil_bulk_modulus_pa": 1.5e9,
        "supply_pressure_pa": 20.7e6,
        "return_pressure_pa": 0.5e6,
    }


def tower():
    """Two levels with x, y, z DOFs each (order x1, y1, z1, x2, y2, z2)."""
    m, ex, ey, heights = 60e3, 0.9, -0.6, (6.0, 12.0)

    def shear(f_hz):
        # Equal storeys whose first mode is f_hz: k from the 2-DOF shear frame,
        # w1^2 = k/m * (3 - sqrt(5))/2.
        return m * (2 * math.pi * f_hz) ** 2 / ((3 - math.sqrt(5)) / 2)

    kx, ky, kz = shear(2.0), shear(1.8), shear(20.0)
    n = 6
    M = [[0.0] * n for _ in range(n)]
    K = [[0.0] * n for _ in range(n)]
    for d, kd in enumerate((kx, ky, kz)):
        i, j = d, 3 + d
        M[i][i] = M[j][j] = m
        K[i][i] = 2 * kd
        K[i][j] = K[j][i] = -kd
        K[j][j] = kd
    # Rayleigh damping, 2 % at 2 Hz and 10 Hz: C = a M + b K.
    w1, w2, z = 2 * math.pi * 2.0, 2 * math.pi * 10.0, 0.02
    a = 2 * z * w1 * w2 / (w1 + w2)
    b = 2 * z / (w1 + w2)
    C = [[a * M[r][c] + b * K[r][c] for c in range(n)] for r in range(n)]
    influence = []
    for h in heights:
        influence.append([1.0, 0.0, 0.0, 0.0, h, -ey])
        influence.append([0.0, 1.0, 0.0, -h, 0.0, ex])
        influence.append([0.0, 0.0, 1.0, ey, -ex, 0.0])
    r = lambda mat: [[round(x, 6) for x in row] for row in mat]
    return {"mass_matrix": r(M), "stiffness_matrix": r(K), "damping_matrix": r(C),
            "influence": influence}


def main():
    os.makedirs(OUT, exist_ok=True)
    write_motion(os.path.join(OUT, "three-component-motion.csv"))
    scenario = {
        "name": "multi-axis inverse: three-component motion, tall eccentric tower",
        "description": "The actuator forces an LHPOST6-like table (4 horizontal actuators in a V, "
                       "6 vertical bearing actuators, 4 hold-down struts) needs to move a 120 t, "
                       "12 m tower with an eccentric centre of mass through a synthetic "
                       "three-component motion (tools/make_multi_axis_scenarios.py).",
        "table": table(),
        "specimen": tower(),
        "excitation": {"motion_csv": "three-component-motion.csv"},
    }
    with open(os.path.join(OUT, "tower-inverse.json"), "w", newline="\n") as f:
        json.dump(scenario, f, indent=2)
        f.write("\n")
    bare = {
        "name": "multi-axis inverse: three-component motion, bare table",
        "description": "The same LHPOST6-like table and motion without a specimen.",
        "table": table(),
        "excitation": {"motion_csv": "three-component-motion.csv"},
    }
    with open(os.path.join(OUT, "bare-inverse.json"), "w", newline="\n") as f:
        json.dump(bare, f, indent=2)
        f.write("\n")
    northridge = {
        "name": "LHPOST6 closed loop: Northridge, Tarzana, three components, tall eccentric tower",
        "description": "The LHPOST6 preset (docs/lhpost6.md) in closed loop under the three "
                       "components of Northridge 1994 at Tarzana (090 along x, 360 along y, UP "
                       "along z, 50 %: at 100 % the vertical record integrates to 0.19 m, beyond the verticals' ±0.127 m), carrying the 120 t, 12 m tower with its centre of mass "
                       "off-centre: will the vertical actuators hold its overturning moment, how "
                       "far does it pitch, how much of x leaks into pitch and z? Needs the PEER "
                       "records (PLATEN_RECORDS_DIR).",
        "table": {"preset": "lhpost6"},
        "specimen": tower(),
        "excitation": {"ground_motion": {
            "x": {"record": "RSN1087_NORTHR_TAR090.AT2", "scale": 0.5},
            "y": {"record": "RSN1087_NORTHR_TAR360.AT2", "scale": 0.5},
            "z": {"record": "RSN1087_NORTHR_TAR-UP.AT2", "scale": 0.5},
        }},
    }
    with open(os.path.join(OUT, "lhpost6-northridge.json"), "w", newline="\n") as f:
        json.dump(northridge, f, indent=2)
        f.write("\n")


def write_forward(platen):
    """The forward scenario: the table (pads with friction) carrying the tower, under the
    actuator forces that platen's inverse finds for the first 10 s of the motion (its own
    output, kept to t_s and the force columns), so that its run retraces that motion open
    loop: friction, stick at the start and the specimen included."""
    with tempfile.TemporaryDirectory() as tmp:
        inverse = {
            "name": "inverse (makes the forward scenario's forces)",
            "table": table(),
            "specimen": tower(),
            "excitation": {"motion_csv": os.path.abspath(os.path.join(OUT, "three-component-motion.csv"))},
        }
        path = os.path.join(tmp, "inverse.json")
        with open(path, "w") as f:
            json.dump(inverse, f)
        out = os.path.join(tmp, "out.csv")
        subprocess.run([platen, "simulate", path, "--out", out], check=True, stdout=subprocess.DEVNULL)
        with open(out, newline="") as f:
            rows = list(csv.reader(f))
    header = rows[0]
    names = [a["name"] + "_force_n" for a in table()["actuators"]]
    keep = [0] + [header.index(n) for n in names]
    end = int(round(10.0 * RATE_HZ)) + 1
    with open(os.path.join(OUT, "forward-forces.csv"), "w", newline="\n") as f:
        f.write(",".join(header[i] for i in keep) + "\n")
        for r in rows[1:end + 1]:
            f.write(",".join(format(float(r[i]), ".15g") for i in keep) + "\n")
    forward = {
        "name": "multi-axis forward: actuator forces, the tower on the table with friction",
        "description": "The LHPOST6-like table (pads with the paper's friction) carrying the 12 m "
                       "eccentric tower, under the actuator forces platen's inverse finds for the "
                       "first 10 s of the three-component motion "
                       "(tools/make_multi_axis_scenarios.py): open loop, it retraces that motion "
                       "until the force's interpolation error drifts it off.",
        "table": table(),
        "specimen": tower(),
        "excitation": {"force_csv": "forward-forces.csv"},
        "integrator": {"method": "rk4", "step_s": 1.0 / (4 * RATE_HZ)},
    }
    with open(os.path.join(OUT, "forward.json"), "w", newline="\n") as f:
        json.dump(forward, f, indent=2)
        f.write("\n")


if __name__ == "__main__":
    main()
    write_forward(os.environ.get("PLATEN", "target/release/platen"))
