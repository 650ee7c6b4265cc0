#!/usr/bin/env python3
"""Closed-loop records of a servo-hydraulic table for `platen identify --system`.

An independent reference: numpy only, no platen code. It simulates the loop of
docs/table-system.md (digital controller with zero-order hold, valve delay, second-order
spool, four-way critically-centred valve with orifice flow, compressible single-ended
actuator chambers with leakage, a platen with elastic, viscous and smoothed Coulomb forces)
with parameters that are NOT the lhpost-2008 preset's, and writes what the controller read
(with sensor noise) and the drive it sent:

    t_s, command_u_m, u_m, drive, delta_p_pa, a_m_s2

Conventions the controller uses (and `platen identify --system` assumes):
  v_ref, a_ref: central differences of the command (one-sided at the ends, as platen does);
  v:            backward difference of the measured displacement (0 at the first sample);
  a:            the measured acceleration;
  HP(dp):       first-order Tustin high-pass of the measured dp, output 0 at the first sample.

Run:  python3 tools/reference/system_ident_records.py tests/data/system_ident
"""
import json
import math
import os
import sys

import numpy as np

FS = 1024.0          # controller and record rate, Hz
SUB = 16             # integration substeps per controller sample (RK4)
DELAY_SUB = 8        # valve delay in substeps (8/16384 s = 0.488 ms)

P = {
    "mass_kg": 20000.0,
    "stiffness_n_per_m": 2.0e5,
    "viscous_n_s_per_m": 5.0e3,
    "coulomb_n": 2000.0,
    "coulomb_smoothing_m_s": 0.002,
    "cap_area_m2": 0.05,
    "rod_area_m2": 0.035,
    "cap_volume_m3": 0.03,
    "rod_volume_m3": 0.025,
    "bulk_modulus_pa": 1.2e9,
    "leakage_m3_s_per_pa": 1e-11,
    "supply_pressure_pa": 21e6,
    "return_pressure_pa": 0.3e6,
    "rated_flow_m3_s": 0.05,
    "rated_pressure_drop_pa": 7e6,
    "spool_natural_frequency_hz": 150.0,
    "spool_damping_ratio": 0.7,
    "valve_delay_s": DELAY_SUB / (FS * SUB),
}
GAINS = {
    "sample_rate_hz": FS,
    "displacement_gain_per_m": 20.0,
    "velocity_feedforward_s_per_m": 0.5,
    "acceleration_feedforward_s2_per_m": 0.003,
    "velocity_feedback_s_per_m": 0.05,
    "acceleration_feedback_s2_per_m": 0.001,
    "delta_p_gain_per_pa": 3e-8,
    "delta_p_highpass_hz": 0.5,
}
NOISE = {"u_m": 2e-6, "a_m_s2": 0.02, "delta_p_pa": 5e3, "drive_quantum": 1.0 / 32768}


def oil_column_hz(p):
    """Free oil column at the chambers' initial volumes: (1/2pi) sqrt(b(Aa^2/Va + Ab^2/Vb)/M)."""
    k = p["bulk_modulus_pa"] * (p["cap_area_m2"] ** 2 / p["cap_volume_m3"]
                                + p["rod_area_m2"] ** 2 / p["rod_volume_m3"])
    return math.sqrt(k / p["mass_kg"]) / (2 * math.pi)


def orifice(dp, k, lin):
    """Flow through one land: k*sqrt(dp), linear below `lin` Pa so the slope stays finite."""
    a = abs(dp)
    return np.where(a >= lin, k * np.sign(dp) * np.sqrt(a), k * dp / math.sqrt(lin))


def rhs(s, d, p):
    u, v, pa, pb, x, xd = s
    k = p["rated_flow_m3_s"] / math.sqrt(p["rated_pressure_drop_pa"] / 2)
    lin = 1e-4 * p["rated_pressure_drop_pa"]
    ps, pr = p["supply_pressure_pa"], p["return_pressure_pa"]
    xo = min(max(x, -1.0), 1.0)
    if xo >= 0:
        qa = xo * float(orifice(ps - pa, k, lin))
        qb = xo * float(orifice(pb - pr, k, lin))
    else:
        qa = xo * float(orifice(pa - pr, k, lin))
        qb = xo * float(orifice(ps - pb, k, lin))
    aa, ab = p["cap_area_m2"], p["rod_area_m2"]
    va = p["cap_volume_m3"] + aa * u
    vb = p["rod_volume_m3"] - ab * u
    b, cl = p["bulk_modulus_pa"], p["leakage_m3_s_per_pa"]
    dpa = b / va * (qa - aa * v - cl * (pa - pb))
    dpb = b / vb * (-qb + ab * v + cl * (pa - pb))
    f = (aa * pa - ab * pb - p["stiffness_n_per_m"] * u - p["viscous_n_s_per_m"] * v
         - p["coulomb_n"] * math.tanh(v / p["coulomb_smoothing_m_s"]))
    a = f / p["mass_kg"]
    w = 2 * math.pi * p["spool_natural_frequency_hz"]
    z = p["spool_damping_ratio"]
    xdd = w * w * (d - x) - 2 * z * w * xd
    return np.array([v, a, dpa, dpb, xd, xdd]), a


def derivatives(u, h):
    """Central differences, one-sided (second order) at the ends."""
    v = np.empty_like(u)
    a = np.empty_like(u)
    v[1:-1] = (u[2:] - u[:-2]) / (2 * h)
    v[0] = (-3 * u[0] + 4 * u[1] - u[2]) / (2 * h)
    v[-1] = (3 * u[-1] - 4 * u[-2] + u[-3]) / (2 * h)
    a[1:-1] = (u[2:] - 2 * u[1:-1] + u[:-2]) / h ** 2
    a[0] = a[1]
    a[-1] = a[-2]
    return v, a


def simulate(cmd, p, g, rng):
    n = len(cmd)
    h = 1.0 / FS
    dt = h / SUB
    vref, aref = derivatives(cmd, h)
    # Initial state: at rest, pressures balancing the areas (p_a A_a = p_b A_b).
    pb0 = 9e6
    pa0 = pb0 * p["rod_area_m2"] / p["cap_area_m2"]
    s = np.array([0.0, 0.0, pa0, pb0, 0.0, 0.0])
    w = 2 * math.pi * g["delta_p_highpass_hz"]
    c = 2.0 / h
    out = {k: np.zeros(n) for k in ("u_m", "a_m_s2", "delta_p_pa", "drive")}
    d_old = 0.0
    hp = 0.0
    dp_prev = None
    u_prev = None
    _, a_now = rhs(s, 0.0, p)
    for i in range(n):
        um = s[0] + NOISE["u_m"] * rng.standard_normal()
        am = a_now + NOISE["a_m_s2"] * rng.standard_normal()
        dpm = s[2] - s[3] + NOISE["delta_p_pa"] * rng.standard_normal()
        hp = 0.0 if dp_prev is None else (c * (dpm - dp_prev) + (c - w) * hp) / (c + w)
        dp_prev = dpm
        vm = 0.0 if u_prev is None else (um - u_prev) / h
        u_prev = um
        d = (g["displacement_gain_per_m"] * (cmd[i] - um)
             + g["velocity_feedforward_s_per_m"] * vref[i]
             + g["acceleration_feedforward_s2_per_m"] * aref[i]
             - g["velocity_feedback_s_per_m"] * vm
             - g["acceleration_feedback_s2_per_m"] * am
             - g["delta_p_gain_per_pa"] * hp)
        d = min(max(d, -1.0), 1.0)
        d = round(d / NOISE["drive_quantum"]) * NOISE["drive_quantum"]
        out["u_m"][i], out["a_m_s2"][i], out["delta_p_pa"][i], out["drive"][i] = um, am, dpm, d
        for j in range(SUB):
            dd = d_old if j < DELAY_SUB else d
            k1, _ = rhs(s, dd, p)
            k2, _ = rhs(s + 0.5 * dt * k1, dd, p)
            k3, _ = rhs(s + 0.5 * dt * k2, dd, p)
            k4, _ = rhs(s + dt * k3, dd, p)
            s = s + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        d_old = d
        _, a_now = rhs(s, d, p)
        if not np.all(np.isfinite(s)):
            raise SystemExit("the reference loop diverged")
    return out


def white_noise(n, seed, rms_m, f_lo, f_hi):
    rng = np.random.default_rng(seed)
    x = rng.standard_normal(n)
    f = np.fft.rfftfreq(n, 1.0 / FS)
    spec = np.fft.rfft(x)
    spec[(f < f_lo) | (f > f_hi)] = 0.0
    u = np.fft.irfft(spec, n)
    taper = np.minimum(1.0, np.minimum(np.arange(n), n - 1 - np.arange(n)) / (0.5 * FS))
    u *= taper
    return u * rms_m / np.sqrt(np.mean(u ** 2))


def chirp(n, f0, f1, acc_m_s2, cap_m):
    t = np.arange(n) / FS
    dur = t[-1]
    f = f0 * (f1 / f0) ** (t / dur)
    phase = 2 * np.pi * f0 * dur / math.log(f1 / f0) * ((f1 / f0) ** (t / dur) - 1)
    amp = np.minimum(cap_m, acc_m_s2 / (2 * np.pi * f) ** 2)
    taper = np.minimum(1.0, np.minimum(t, dur - t) / 0.5)
    return amp * taper * np.sin(phase)


def main():
    outdir = sys.argv[1] if len(sys.argv) > 1 else "tests/data/system_ident"
    os.makedirs(outdir, exist_ok=True)
    n = int(6 * FS)
    records = {
        "wn-a.csv": white_noise(n, 11, 0.004, 0.2, 25.0),
        "chirp.csv": chirp(n, 0.5, 30.0, 4.0, 0.01),
        "wn-b.csv": white_noise(n, 23, 0.004, 0.2, 25.0),
    }
    rng = np.random.default_rng(2026)
    summary = {}
    for name, cmd in records.items():
        out = simulate(cmd, P, GAINS, rng)
        t = np.arange(n) / FS
        with open(os.path.join(outdir, name), "w") as fh:
            fh.write("t_s,command_u_m,u_m,drive,delta_p_pa,a_m_s2\n")
            for i in range(n):
                fh.write(f"{t[i]:.9g},{cmd[i]:.9e},{out['u_m'][i]:.9e},{out['drive'][i]:.9e},"
                         f"{out['delta_p_pa'][i]:.6f},{out['a_m_s2'][i]:.6e}\n")
        summary[name] = {
            "peak_drive": float(np.max(np.abs(out["drive"]))),
            "rms_tracking_error_m": float(np.sqrt(np.mean((cmd - out["u_m"]) ** 2))),
        }
    truth = {
        "made_by": "tools/reference/system_ident_records.py",
        "controller": GAINS,
        "plant": P,
        "oil_column_frequency_hz": oil_column_hz(P),
        "noise": NOISE,
        "records": summary,
    }
    with open(os.path.join(outdir, "truth.json"), "w") as fh:
        json.dump(truth, fh, indent=2)
        fh.write("\n")
    print(json.dumps(truth, indent=2))


if __name__ == "__main__":
    main()
