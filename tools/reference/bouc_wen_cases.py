#!/usr/bin/env python3
"""Independent reference for Bouc-Wen storeys on a prescribed platen motion (SciPy, not platen).

A two-storey shear building, storeys bottom to top, floor i of mass m_i, relative displacement
z_i (to the platen), storey drift d_i = z_i - z_{i-1} (z_0 = 0). Each storey's shear is

    V_i = a_i k_i d_i + q_i + c_i d_i',
    q_i' = (1 - a_i) k_i d_i' (1 - |q_i / q_yi|^n_i (b_i sgn(d_i' q_i) + 1 - b_i)),
    q_yi = (1 - a_i) Fy_i,

and floor i obeys m_i (a + z_i'') = V_{i+1} - V_i (V_{n+1} = 0). This is OpenSees'
uniaxialMaterial BoucWen with alpha = a, ko = k, beta = b/dy^n, gamma = (1 - b)/dy^n, Ao = 1 and
no degradation, written in the hysteretic force q = (1 - a) k z. The energy dissipated in
hysteresis is carried as its own state, independently of how platen computes it:

    E_i' = q_i (d_i' - q_i' / ((1 - a_i) k_i)).

The base acceleration is the platen's acceleration sampled at 512 Hz and linear between
samples (what platen's inverse run assumes): a 1.3 Hz sine of 4 m/s^2 plus a 3.1 Hz one of
1.5 m/s^2, over 6 s, from rest. Every sample interval is integrated separately with RK45 at
rtol 1e-10 (atol 1e-14 m, m/s, N, J scaled per state). Written to
tests/data/reference/bouc_wen_inverse.csv: t_s, a_m_s2 (the samples, repr round trip), and
per storey drift, hysteretic force and hysteretic energy at every sample.

Usage (from the repository root, with numpy and scipy installed):
    python3 tools/reference/bouc_wen_cases.py
"""
import math
import os

import numpy as np
from scipy.integrate import solve_ivp

RATE_HZ = 512.0
SECONDS = 6.0

# Storeys: mass kg, stiffness N/m, damping N s/m, yield force N, post-yield ratio, n, b.
STOREYS = [
    (30e3, 27_083_177.88, 86_208.43, 160e3, 0.05, 2.0, 0.5),
    (25e3, 19_345_127.06, 61_577.45, 90e3, 0.10, 4.0, 0.7),
]


def base_acceleration(t):
    return 4.0 * math.sin(2.0 * math.pi * 1.3 * t) + 1.5 * math.sin(2.0 * math.pi * 3.1 * t)


def rhs(acc):
    n = len(STOREYS)

    def f(t, y):
        z, zd, q, e = y[0:n], y[n:2 * n], y[2 * n:3 * n], y[3 * n:4 * n]
        a = acc(t)
        shear = np.zeros(n)
        qd = np.zeros(n)
        ed = np.zeros(n)
        for i, (m, k, c, fy, r, expo, b) in enumerate(STOREYS):
            d = z[i] - (z[i - 1] if i > 0 else 0.0)
            dd = zd[i] - (zd[i - 1] if i > 0 else 0.0)
            qy = (1.0 - r) * fy
            sgn = np.sign(dd * q[i])
            qd[i] = (1.0 - r) * k * dd * (1.0 - abs(q[i] / qy) ** expo * (b * sgn + 1.0 - b))
            ed[i] = q[i] * (dd - qd[i] / ((1.0 - r) * k))
            shear[i] = r * k * d + q[i] + c * dd
        zdd = np.zeros(n)
        for i, (m, *_rest) in enumerate(STOREYS):
            above = shear[i + 1] if i + 1 < n else 0.0
            zdd[i] = (above - shear[i]) / m - a
        return np.concatenate([zd, zdd, qd, ed])

    return f


def main():
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    out = os.path.join(root, "tests", "data", "reference", "bouc_wen_inverse.csv")
    count = int(SECONDS * RATE_HZ) + 1
    t = [i / RATE_HZ for i in range(count)]
    a = [base_acceleration(x) for x in t]
    n = len(STOREYS)
    y = np.zeros(4 * n)
    atol = np.concatenate([np.full(2 * n, 1e-14), np.full(n, 1e-8), np.full(n, 1e-10)])
    rows = []

    def row(i, y):
        cells = [repr(t[i]), repr(a[i])]
        for s in range(n):
            d = y[s] - (y[s - 1] if s > 0 else 0.0)
            cells += [repr(float(d)), repr(float(y[2 * n + s])), repr(float(y[3 * n + s]))]
        return ",".join(cells)

    rows.append(row(0, y))
    for i in range(1, count):
        t0, t1, a0, a1 = t[i - 1], t[i], a[i - 1], a[i]
        acc = lambda s, t0=t0, t1=t1, a0=a0, a1=a1: a0 + (a1 - a0) * (s - t0) / (t1 - t0)
        sol = solve_ivp(rhs(acc), (t0, t1), y, method="RK45", rtol=1e-10, atol=atol)
        if not sol.success:
            raise SystemExit(f"interval {i}: {sol.message}")
        y = sol.y[:, -1]
        rows.append(row(i, y))
    header = ["t_s", "a_m_s2"]
    for s in range(1, n + 1):
        header += [f"storey{s}_drift_m", f"storey{s}_hysteretic_force_n", f"storey{s}_hysteretic_j"]
    with open(out, "w") as fh:
        fh.write(",".join(header) + "\n")
        fh.write("\n".join(rows) + "\n")
    print(f"wrote {out}: {len(rows)} rows")


if __name__ == "__main__":
    main()
