#!/usr/bin/env python3
"""Independent references for a platen carrying a specimen (Python/SciPy, not platen).

The platen (identified form, parameters not the paper's: model "a07" of stick_slip_cases.py)
carries a 2-storey linear shear building, storeys bottom to top with mass m_i, storey
stiffness k_i and storey damping c_i; z_i is floor i's displacement relative to the platen.

    floor i:   m_i (a + z_i'') = V_{i+1} - V_i,   V_i = k_i (z_i - z_{i-1}) + c_i (z_i' - z_{i-1}'),
               z_0 = 0, V_{n+1} = 0
    base shear B = sum m_i (a + z_i'') = -(k_1 z_1 + c_1 z_1')   (force of the platen on it)
    platen:    Me a = F(t) - Ke u - s D(|v|) - B,   D(w) = Fmu + Ce w^alpha + A exp(-B_s w)

Exact (non-regularised) stick-slip with the specimen:
  * slip (s = +1 or -1): the full state (u, v, z, z') is integrated with s frozen and v = 0
    located as a terminal event;
  * at v = 0 the net force N = F - Ke u - B is compared with Fs = Fmu + A: |N| <= Fs -> stick,
    otherwise immediate reversal with s = sign(N);
  * stick: the platen is at rest (a = 0) and the specimen keeps vibrating on it; N(t) is no
    longer linear in t, so the breakaway |N(t)| = Fs is located as a terminal event on the
    integrated specimen state (two events, N - Fs and N + Fs); slip then starts with s = sign(N).

Every sample interval of the 1024 Hz force record is integrated separately with DOP853
(rtol 1e-12, atol 1e-14 on displacements and velocities, max_step 1/16384 s); F is the linear
interpolant of the printed samples (repr round trip).

Two cases are written to tests/data/reference/:

1. specimen_force.csv / specimen_reference.csv: forward, a force with stick phases (a slow
   sine near the threshold plus a tone that excites the frame), with u, v, z1, z2, z1', z2' at
   every sample, and specimen_sticks.csv (every stick interval).
2. specimen_inverse.csv: inverse. A prescribed platen motion u(t) (a sum of sines), sampled at
   1024 Hz with its exact velocity and acceleration; the specimen is driven by the base
   acceleration linear between samples (what platen's inverse assumes) and solved EXACTLY per
   interval with the matrix exponential of the augmented linear system (scipy.linalg.expm), from
   rest relative to the platen. Written: t, u, v, a, the base shear and the actuator force
   F = Me a + Ke u + sign(v) D(|v|) + B (Eq. 23 plus the base shear).

Usage (from the repository root, with numpy and scipy installed):
    python3 tools/reference/specimen_cases.py
The output is deterministic (same inputs, same SciPy/NumPy/libm -> same bytes).
"""

import math
import os

import numpy as np
from scipy.integrate import solve_ivp
from scipy.linalg import expm

FS_HZ = 1024
MAX_STEP = 1.0 / (16 * FS_HZ)
OUT_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                       "tests", "data", "reference")

# The platen: model "a07" of stick_slip_cases.py (not the paper's).
P = dict(Me=95000.0, Ke=2.1e6, Fmu=18000.0, Ce=30000.0, alpha=0.7, A=8000.0, B=50.0)
# The specimen: 20 t and 15 t floors; fixed-base modes near 2.6 and 6.8 Hz, a few % damping.
M_ST = [20000.0, 15000.0]
K_ST = [1.6e7, 1.2e7]
C_ST = [4.0e4, 3.0e4]

DURATION_S = 6.0
# (amplitude N, frequency Hz, phase rad): a slow sine whose peaks pass the 26 kN threshold,
# and a tone near the first mode that keeps the frame ringing through the stick phases.
FORCE = [(40e3, 0.5, 0.0), (6e3, 2.9, 0.7)]

# The inverse's motion: (amplitude m, frequency Hz, phase rad).
MOTION = [(0.02, 0.8, 0.0), (0.002, 3.3, 0.4), (0.0004, 7.5, 1.1)]
INVERSE_DURATION_S = 4.0


def fmt(x):
    return repr(float(x))


def fs():
    return P["Fmu"] + P["A"]


def damping(w):
    d = P["Fmu"] + P["A"] * math.exp(-P["B"] * w)
    if w > 0.0:
        d += P["Ce"] * w ** P["alpha"]
    return d


def base_shear(z1, zd1):
    return -(K_ST[0] * z1 + C_ST[0] * zd1)


def storey_acc(a, z, zd):
    """Relative floor accelerations z'' under platen acceleration a."""
    z1, z2 = z
    zd1, zd2 = zd
    v1 = K_ST[0] * z1 + C_ST[0] * zd1
    v2 = K_ST[1] * (z2 - z1) + C_ST[1] * (zd2 - zd1)
    return [(v2 - v1) / M_ST[0] - a, -v2 / M_ST[1] - a]


def force_samples():
    n = int(round(DURATION_S * FS_HZ))
    out = []
    for k in range(n + 1):
        t = k / FS_HZ
        ramp = min(1.0, t / 1.0)
        f = sum(amp * math.sin(2.0 * math.pi * fr * t + ph) for amp, fr, ph in FORCE)
        out.append(float(repr(ramp * f)))
    return out


def forward(F):
    """(rows of t,u,v,z1,z2,zd1,zd2 at every sample, stick intervals)."""
    atol = 1e-14
    n = len(F) - 1
    y = [0.0] * 6                      # u, v, z1, z2, zd1, zd2
    rows = [(0.0, *y)]
    mode = 0
    n0 = F[0] - P["Ke"] * y[0] - base_shear(y[2], y[4])
    if abs(n0) > fs():
        mode = 1 if n0 > 0 else -1
    sticks = []
    stick_start = 0.0 if mode == 0 else None
    t = 0.0
    for k in range(n):
        tk, tk1 = k / FS_HZ, (k + 1) / FS_HZ
        Fk, dF = F[k], (F[k + 1] - F[k]) * FS_HZ

        def Fat(tt):
            return Fk + dF * (tt - tk)

        guard = 0
        while t < tk1:
            guard += 1
            if guard > 50:
                raise RuntimeError(f"no progress in interval {k} at t={t!r}")
            if mode == 0:
                u = y[0]

                def rhs_stick(tt, yy):
                    z, zd = yy[0:2], yy[2:4]
                    return [zd[0], zd[1], *storey_acc(0.0, z, zd)]

                def net(tt, yy):
                    return Fat(tt) - P["Ke"] * u - base_shear(yy[0], yy[2])

                def up(tt, yy):
                    return net(tt, yy) - fs()

                def down(tt, yy):
                    return net(tt, yy) + fs()
                up.terminal = True
                up.direction = 1
                down.terminal = True
                down.direction = -1
                sol = solve_ivp(rhs_stick, (t, tk1), y[2:6], method="DOP853", rtol=1e-12,
                                atol=atol, max_step=MAX_STEP, events=[up, down])
                if sol.status < 0:
                    raise RuntimeError(sol.message)
                if sol.status == 1:
                    which = 0 if len(sol.t_events[0]) else 1
                    te = float(sol.t_events[which][0])
                    ye = [float(x) for x in sol.y_events[which][0]]
                    y = [u, 0.0, *ye]
                    sticks.append((stick_start, te))
                    stick_start = None
                    t = te
                    mode = 1 if which == 0 else -1
                    continue
                y = [u, 0.0, *[float(x) for x in sol.y[:, -1]]]
                t = tk1
                break

            s = mode

            def rhs(tt, yy, s=s):
                u, v = yy[0], yy[1]
                z, zd = yy[2:4], yy[4:6]
                w = max(s * v, 0.0)
                bs = base_shear(z[0], zd[0])
                a = (Fat(tt) - P["Ke"] * u - s * damping(w) - bs) / P["Me"]
                return [v, a, zd[0], zd[1], *storey_acc(a, z, zd)]

            def ev(tt, yy, s=s):
                return s * yy[1]
            ev.terminal = True
            ev.direction = -1
            sol = solve_ivp(rhs, (t, tk1), y, method="DOP853", rtol=1e-12, atol=atol,
                            max_step=MAX_STEP, events=ev)
            if sol.status < 0:
                raise RuntimeError(sol.message)
            if sol.status == 1:
                te = float(sol.t_events[0][0])
                ye = [float(x) for x in sol.y_events[0][0]]
                t = te
                y = [ye[0], 0.0, *ye[2:6]]
                N = Fat(t) - P["Ke"] * y[0] - base_shear(y[2], y[4])
                if abs(N) <= fs():
                    mode = 0
                    stick_start = t
                else:
                    mode = 1 if N > 0 else -1
            else:
                t = tk1
                y = [float(x) for x in sol.y[:, -1]]
        t = tk1
        if mode == 0:
            y[1] = 0.0
        rows.append((tk1, *y))
    if mode == 0:
        sticks.append((stick_start, None))
    return rows, sticks


def inverse():
    """Rows t,u,v,a,base_shear_n,force_n with the specimen solved exactly per interval."""
    n = int(round(INVERSE_DURATION_S * FS_HZ))
    ts = [k / FS_HZ for k in range(n + 1)]

    def motion(t):
        u = v = a = 0.0
        for amp, fr, ph in MOTION:
            w = 2.0 * math.pi * fr
            u += amp * math.sin(w * t + ph)
            v += amp * w * math.cos(w * t + ph)
            a -= amp * w * w * math.sin(w * t + ph)
        return u, v, a

    samples = [tuple(float(repr(x)) for x in motion(t)) for t in ts]
    # x' = A x + b (a0 + (a1 - a0) s/h): x = (z1, z2, zd1, zd2). Augment with the forcing's
    # constant and ramp: X = (x, p, q), p' = 0 (p = a0), q' = p_rate (q = a at time s).
    K = np.array([[K_ST[0] + K_ST[1], -K_ST[1]], [-K_ST[1], K_ST[1]]])
    C = np.array([[C_ST[0] + C_ST[1], -C_ST[1]], [-C_ST[1], C_ST[1]]])
    Minv = np.diag([1.0 / M_ST[0], 1.0 / M_ST[1]])
    A = np.zeros((4, 4))
    A[0:2, 2:4] = np.eye(2)
    A[2:4, 0:2] = -Minv @ K
    A[2:4, 2:4] = -Minv @ C
    rows = []
    x = np.zeros(4)
    for k, t in enumerate(ts):
        if k > 0:
            h = ts[k] - ts[k - 1]
            a0, a1 = samples[k - 1][2], samples[k][2]
            # X = (x, q, r): q = base acceleration (q' = r), r = its constant rate.
            big = np.zeros((6, 6))
            big[0:4, 0:4] = A
            big[2:4, 4] = -1.0           # floors feel -a (relative coordinates)
            big[4, 5] = 1.0
            X0 = np.concatenate([x, [a0, (a1 - a0) / h]])
            x = (expm(big * h) @ X0)[0:4]
        u, v, a = samples[k]
        bs = base_shear(x[0], x[2])
        s = 1.0 if v > 0 else (-1.0 if v < 0 else 0.0)
        force = P["Me"] * a + P["Ke"] * u + s * damping(abs(v)) + bs
        rows.append((t, u, v, a, bs, force))
    return rows


def main():
    os.makedirs(OUT_DIR, exist_ok=True)
    F = force_samples()
    with open(os.path.join(OUT_DIR, "specimen_force.csv"), "w") as f:
        f.write("t_s,force_n\n")
        for k, x in enumerate(F):
            f.write(f"{fmt(k / FS_HZ)},{fmt(x)}\n")
    rows, sticks = forward(F)
    with open(os.path.join(OUT_DIR, "specimen_reference.csv"), "w") as f:
        f.write("t_s,u_m,v_m_s,storey1_u_m,storey2_u_m,storey1_v_m_s,storey2_v_m_s\n")
        for r in rows:
            f.write(",".join(fmt(x) for x in r) + "\n")
    with open(os.path.join(OUT_DIR, "specimen_sticks.csv"), "w") as f:
        f.write("start_s,end_s\n")
        for a, b in sticks:
            f.write(f"{fmt(a)},{'' if b is None else fmt(b)}\n")
    inv = inverse()
    with open(os.path.join(OUT_DIR, "specimen_inverse.csv"), "w") as f:
        f.write("t_s,u_m,v_m_s,a_m_s2,base_shear_n,force_n\n")
        for r in inv:
            f.write(",".join(fmt(x) for x in r) + "\n")
    short = sum(1 for a, b in sticks if b is not None and b - a < 1.0 / FS_HZ)
    print(f"forward: {len(rows)} samples, {len(sticks)} stick intervals ({short} shorter than a "
          f"sample), peak |u| {max(abs(r[1]) for r in rows):.4g} m, peak |z2| "
          f"{max(abs(r[4]) for r in rows):.4g} m")
    print(f"inverse: {len(inv)} samples, peak |B| {max(abs(r[4]) for r in inv):.4g} N, "
          f"peak |F| {max(abs(r[5]) for r in inv):.4g} N")


if __name__ == "__main__":
    main()
