#!/usr/bin/env python3
"""Independent references for the hard cases of exact stick-slip (Python/SciPy, not platen).

Three families, all on models whose parameters are not the paper's:

1. creep: a constant force F_s + delta from rest (F_s = Fmu + A, the static threshold).
   For delta > 0 the platen leaves rest and creeps at the speed w_c that solves
   D(w_c) = F_s + delta - Ke u: the sqrt-like law |v|^alpha makes the start singular and the
   creep stiff, which is exactly what an explicit integrator gets wrong.  The reference is
   SciPy's implicit Radau on (u, w) with tight tolerances, started at a tiny time t0 from the
   exact early-time solution of  M w' = delta - Ce w^alpha  (u = 0, the Stribeck and elastic
   terms are below 1e-12 of delta there), so the solver never sees the singular point.
   Written: creep_reference.csv (model, delta_n, t_s, u_m, v_m_s at 0.25 s intervals).

2. swing: slow slip, then a +-X force swing across one sample interval that reverses the
   platen twice inside that interval.  The swing sample is searched automatically (the first
   slow-slip sample whose swing gives two v = 0 events inside one interval, checked on the
   reference's own event list).  Reference: make_reference.simulate (DOP853, events).
   Written: swing_X_force.csv, swing_X_reference.csv, and swing_events.csv.

3. raw: an unfiltered recorded-like force of a slow small sine test: a 0.2 Hz sine whose peaks
   barely exceed the threshold, a 246 Hz servo-valve tone and white noise (numpy, fixed
   seed), at 1024 Hz.  It holds many stick intervals shorter than a sample.
   Written: raw_force.csv, raw_reference.csv, raw_sticks.csv (every stick interval).

Usage (from the repository root, with numpy and scipy installed):
    python3 tools/reference/stick_slip_cases.py
The output is deterministic (same inputs, same SciPy/NumPy/libm -> same bytes).
"""

import math
import os
import sys

import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_reference as ref  # noqa: E402  (the shared event-located DOP853 reference)

FS_HZ = ref.FS_HZ
OUT_DIR = ref.OUT_DIR

# Two models that are not the paper's: the identified_nonpaper one (alpha = 0.7) and a
# stiffer-creep variant with alpha = 0.5.
MODELS = {
    "a07": dict(Me=95000.0, Mp=0.0, h=3.3, Ke=2.1e6, Kp=0.0, Fmu=18000.0, Ce=30000.0,
                alpha=0.7, A=8000.0, B=50.0, cb=0.0, beta=0.5, MuIvFhd=0.0),
    "a05": dict(Me=120000.0, Mp=0.0, h=3.3, Ke=1.5e6, Kp=0.0, Fmu=20000.0, Ce=40000.0,
                alpha=0.5, A=10000.0, B=60.0, cb=0.0, beta=0.5, MuIvFhd=0.0),
}
CREEP_DELTAS = [0.0, "ulp", 1e-9, 1e-6, 1e-3, 1.0, 100.0]
CREEP_T_END = 2.0


def fmt(x):
    return repr(float(x))


# ---------------------------------------------------------------------------------------
# 1. creep
# ---------------------------------------------------------------------------------------
def creep_case(p, delta):
    """u(t), w(t) at 0.25 s steps for the constant force Fs + delta from rest."""
    fs = p["Fmu"] + p["A"]
    force = math.nextafter(fs, math.inf) if delta == "ulp" else fs + delta
    d = force - fs                          # the excess actually representable
    times = [0.25 * k for k in range(int(CREEP_T_END / 0.25) + 1)]
    if d <= 0.0:
        return force, [(t, 0.0, 0.0) for t in times]
    M, C, al, A, B, K = p["Me"], p["Ce"], p["alpha"], p["A"], p["B"], p["Ke"]

    # The law's excess over the threshold, D(w) - Fs = C w^al + A (exp(-B w) - 1), written
    # with expm1 so that an excess of 1e-12 N on 26 kN keeps its precision.
    def rhs(t, y):
        u, w = y
        w = max(w, 0.0)
        return [w, (d - K * u - (C * w ** al + A * math.expm1(-B * w))) / M]

    def jac(t, y):
        w = max(y[1], 1e-300)
        return [[0.0, 1.0], [-K / M, -(al * C * w ** (al - 1.0) - A * B * math.exp(-B * w)) / M]]

    # Early-time solution of M w' = d - C w^al (u = 0, exp(-B w) = 1 - B w ~ 1): start
    # where C w^al = 1e-6 d, i.e. the inertial phase w = d t / M to 1e-6 relative.
    w0 = (1e-6 * d / C) ** (1.0 / al)
    t0 = M * w0 / d
    u0 = 0.5 * d * t0 * t0 / M
    # Tolerances relative to the creep speed, which can be as small as 1e-23 m/s.
    wc = (d / C) ** (1.0 / al)
    atol = [1e-9 * wc * CREEP_T_END, 1e-9 * wc]
    # The elastic force grows with u; if it uses up the excess the platen stops (w = 0) and
    # friction holds it from then on (|N| <= Fs is checked there).
    def stop(t, y):
        return y[1]
    stop.terminal = True
    stop.direction = -1
    sol = solve_ivp(rhs, (t0, CREEP_T_END), [u0, w0], method="Radau", rtol=1e-10,
                    atol=atol, jac=jac, events=stop, dense_output=True)
    if sol.status < 0:
        raise RuntimeError(sol.message)
    rows = [(0.0, 0.0, 0.0)]
    if sol.status == 1:
        t_stop = float(sol.t_events[0][0])
        u_stop = float(sol.y_events[0][0][0])
        net = force - K * u_stop
        if abs(net) > fs:
            raise RuntimeError(f"stop at {t_stop} without friction holding: {net}")
        for t in times[1:]:
            if t <= t0:
                rows.append((t, 0.0, 0.0))
            elif t < t_stop:
                u, w = sol.sol(t)
                rows.append((t, float(u), float(w)))
            else:
                rows.append((t, u_stop, 0.0))
        return force, rows
    for t in times[1:]:
        if t <= t0:
            rows.append((t, 0.0, 0.0))
        else:
            u, w = sol.sol(t)
            rows.append((t, float(u), float(w)))
    return force, rows


def write_creep():
    path = os.path.join(OUT_DIR, "creep_reference.csv")
    with open(path, "w", newline="\n") as f:
        f.write("model,delta,force_n,t_s,u_m,v_m_s\n")
        for name, p in MODELS.items():
            for delta in CREEP_DELTAS:
                force, rows = creep_case(p, delta)
                for t, u, w in rows:
                    f.write(f"{name},{delta},{fmt(force)},{fmt(t)},{fmt(u)},{fmt(w)}\n")
                print(f"creep {name} delta={delta}: u(2 s) = {rows[-1][1]:.6e} m, "
                      f"v = {rows[-1][2]:.6e} m/s")


# ---------------------------------------------------------------------------------------
# 2. swing
# ---------------------------------------------------------------------------------------
def slow_slip_force(p, n):
    """A force that starts the platen slipping slowly in the + direction and keeps it
    slipping (a ramp that balances the growing elastic force at about 0.2 mm/s)."""
    fs = p["Fmu"] + p["A"]
    out = []
    for k in range(n + 1):
        t = k / FS_HZ
        out.append(fs + 150.0 + p["Ke"] * 2e-4 * t + 100.0 * math.sin(2 * math.pi * 1.5 * t))
    return out


def events_per_interval(events):
    per = {}
    for (t, *_rest) in events:
        k = int(math.floor(t * FS_HZ + 1e-9))
        per[k] = per.get(k, 0) + 1
    return per


def write_swing():
    p = MODELS["a07"]
    model = ref.Model(p)
    n = int(0.5 * FS_HZ)
    saved_n = ref.N_SAMPLES
    ref.N_SAMPLES = n
    base = slow_slip_force(p, n)
    _, v_base, *_ = ref.simulate(model, base)
    rows = []
    for x in (150e3, 200e3, 300e3):
        found = None
        for j in range(int(0.3 * FS_HZ), int(0.3 * FS_HZ) + 8):
            if not (0.0 < v_base[j] < 1e-3):
                continue
            for scale in [1.0 - 0.05 * i for i in range(20)]:
                force = list(base[: j + 64])
                force[j] -= scale * x
                force[j + 1] += x
                u, v, w_, ed, sticks, evs = ref.simulate(model, force)
                per = events_per_interval(evs)
                if per.get(j, 0) >= 2:
                    found = (j, scale, force, u, v, evs)
                    break
            if found:
                break
        if not found:
            print(f"X = {x}: no double reversal inside one interval found; skipped")
            continue
        j, scale, force, u, v, evs = found
        name = f"swing_{int(x / 1e3)}kN"
        ref.write_case(name, force, u, v)
        inside = [e for e in evs if int(math.floor(e[0] * FS_HZ + 1e-9)) == j]
        rows.append((name, j, scale, len(inside), len(evs)))
        print(f"{name}: swing at sample {j} (pre-drop {scale} X), {len(inside)} v=0 events "
              f"inside interval {j}, {len(evs)} in all")
    ref.N_SAMPLES = saved_n
    with open(os.path.join(OUT_DIR, "swing_events.csv"), "w", newline="\n") as f:
        f.write("case,interval,pre_drop_fraction,events_inside,events_total\n")
        for r in rows:
            f.write(",".join(str(c) for c in r) + "\n")


# ---------------------------------------------------------------------------------------
# 3. raw recorded-like force
# ---------------------------------------------------------------------------------------
def raw_force(p, n, seed=246):
    rng = np.random.default_rng(seed)
    fs = p["Fmu"] + p["A"]
    t = np.arange(n + 1) / FS_HZ
    ramp = np.minimum(t / 2.0, 1.0)
    sine = 1.15 * fs * np.sin(2 * np.pi * 0.2 * t)
    tone = 3000.0 * np.sin(2 * np.pi * 246.0 * t + 0.3)
    noise = 3500.0 * rng.standard_normal(n + 1)
    f = ramp * sine + tone + noise
    # Round to 0.1 N like a logged channel; the printed decimal is the record.
    return [float(repr(round(float(x), 1))) for x in f]


def write_raw():
    p = MODELS["a07"]
    model = ref.Model(p)
    n = int(10.0 * FS_HZ)
    saved_n = ref.N_SAMPLES
    ref.N_SAMPLES = n
    force = raw_force(p, n)
    u, v, w_, ed, sticks, evs = ref.simulate(model, force)
    ref.N_SAMPLES = saved_n
    ref.write_case("raw", force, u, v)
    dt = 1.0 / FS_HZ
    short = sum(1 for a, b in sticks if b is not None and b - a < dt)
    with open(os.path.join(OUT_DIR, "raw_sticks.csv"), "w", newline="\n") as f:
        f.write("start_s,end_s\n")
        for a, b in sticks:
            f.write(f"{fmt(a)},{'' if b is None else fmt(b)}\n")
    stops = sum(1 for e in evs if abs(e[2]) <= e[3])
    print(f"raw: {len(sticks)} stick intervals ({short} shorter than a sample), "
          f"{stops} stops, {len(evs) - stops} reversals, peak |u| {np.max(np.abs(u)):.4e} m")


def main():
    os.makedirs(OUT_DIR, exist_ok=True)
    which = sys.argv[1:] or ["creep", "swing", "raw"]
    if "creep" in which:
        write_creep()
    if "swing" in which:
        write_swing()
    if "raw" in which:
        write_raw()


if __name__ == "__main__":
    main()
