#!/usr/bin/env python3
"""An independent test record whose acceleration channel lags the displacement by exactly two
samples (9.765625 ms at 204.8 Hz), for platen's channel-skew correction (NumPy/SciPy only).

The platen, its stick-slip and the earthquake-like target motion are those of
tools/record_reference/make_records.py (imported from there: SciPy's DOP853 with exact
stick-slip; nothing of platen), with a table that is neither the paper's nor that script's:

    Me 80 t, Ke 0.9 MN/m, Fmu 20 kN, Ce 35 kN/(m/s)^0.6, alpha 0.6, A 6 kN, B 40 s/m

The data system's skew: the accelerometer's sample written at t_j is the platen's
acceleration at t_(j-2) (the platen is at rest before t = 0, so the first two are 0). Sensor
noise (u 0.02 mm, a 0.03 m/s^2, force 0.8 kN white + 1 kN AR(1) with rho 0.97) and offsets
(u +2.5 mm, a +0.012 m/s^2, force +3 kN) are added after the skew, as a sensor's are. The
file is in platen's own SI columns (t_s, u_m, a_m_s2, force_n), time stamps k/204.8 printed
exactly (Python's shortest round-trip repr).

Outputs (tests/data/skew/):
  skewed-eq.csv   30 s at 204.8 Hz, earthquake-like, peak speed 0.40 m/s
  truth.json      the parameters, the delay, noise, offsets, and the record's peaks

Usage (from the repository root):  python3 tools/skew_reference/make_skewed_record.py
Deterministic: fixed seeds; the same NumPy/SciPy give the same bytes (about 2 minutes).
"""

import json
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "record_reference"))
import make_records as mr  # noqa: E402  (the independent plant and target motions)

OUT = os.path.join(HERE, "..", "..", "tests", "data", "skew")
FS_HZ = mr.FS_HZ
DELAY_SAMPLES = 2

TABLE = dict(Me=80e3, Ke=0.9e6, Fmu=20e3, Ce=35e3, alpha=0.6, A=6e3, B=40.0)
NOISE = dict(u_m=2e-5, a_m_s2=0.03, force_white_n=800.0, force_ar_n=1000.0, force_ar_rho=0.97)
OFFSETS = dict(u_m=2.5e-3, a_m_s2=0.012, force_n=3.0e3)


def main():
    os.makedirs(OUT, exist_ok=True)
    t, u_t, v_t, a_t = mr.target_motion("eq", 30.0, 31, 0.40)
    force = mr.target_force(TABLE, [], u_t, v_t, a_t)
    plant = mr.Plant(TABLE, [], force)
    Y, MODE, events = plant.simulate(len(t))
    a, _ = plant.outputs(Y, MODE)
    n = len(t)
    # The skew: the sample written at t_j holds a(t_(j-2)); at rest before t = 0.
    a_late = np.concatenate([np.zeros(DELAY_SAMPLES), a[:-DELAY_SAMPLES]])
    rng = np.random.default_rng(301)
    u_rec = Y[:, 0] + OFFSETS["u_m"] + rng.standard_normal(n) * NOISE["u_m"]
    a_rec = a_late + OFFSETS["a_m_s2"] + rng.standard_normal(n) * NOISE["a_m_s2"]
    f_rec = (force + OFFSETS["force_n"] + rng.standard_normal(n) * NOISE["force_white_n"]
             + mr.ar1(n, rng, NOISE["force_ar_n"], NOISE["force_ar_rho"]))
    lines = ["t_s,u_m,a_m_s2,force_n"]
    for j in range(n):
        lines.append(f"{repr(j / FS_HZ)},{u_rec[j]:.7e},{a_rec[j]:.6e},{f_rec[j]:.6e}")
    with open(os.path.join(OUT, "skewed-eq.csv"), "w") as fh:
        fh.write("\n".join(lines) + "\n")
    rec = dict(t=t, u=Y[:, 0], v=Y[:, 1], a=a, stuck=MODE == 0, events=events)
    truth = dict(
        sample_rate_hz=FS_HZ,
        identified=dict(effective_mass_kg=TABLE["Me"], stiffness_n_per_m=TABLE["Ke"],
                        coulomb_force_n=TABLE["Fmu"], viscous_coefficient=TABLE["Ce"],
                        viscous_exponent=TABLE["alpha"], low_velocity_force_n=TABLE["A"],
                        low_velocity_decay_s_per_m=TABLE["B"]),
        channel_delay_samples=dict(a_m_s2=DELAY_SAMPLES, force_n=0),
        channel_delay_s=dict(a_m_s2=DELAY_SAMPLES / FS_HZ, force_n=0.0),
        noise_si=NOISE,
        offsets_si=OFFSETS,
        record=mr.summary(rec),
    )
    with open(os.path.join(OUT, "truth.json"), "w") as fh:
        json.dump(truth, fh, indent=2, sort_keys=True)
        fh.write("\n")
    print(truth["record"])


if __name__ == "__main__":
    main()
