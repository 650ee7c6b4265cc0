#!/usr/bin/env python3
"""Closed-loop records of a servo-hydraulic table carrying a specimen, for
`platen identify --system`.

An independent reference: numpy only, no platen code. It simulates the loop of
docs/table-system.md with parameters that are NOT the lhpost-2008 preset's:

  digital controller (zero-order hold) -> valve delay -> second-order spool -> four-way
  critically-centred valve (orifice flow per land, laminar below 1e-4 of the rated drop) ->
  compressible single-ended actuator chambers with cross-port leakage -> a platen with
  elastic, viscous and exact Coulomb friction (stick-slip: the platen sticks while
  |F_A - K u - B| <= F_mu; the v = 0 crossing and the breakaway are located inside the
  substep) -> a two-storey shear frame on the platen (base shear B = sum m_i * absolute
  storey acceleration, B = -(k1 z1 + c1 z1') with z the storey displacements relative to
  the platen).

The hydraulics start as platen's closed loop starts them: centred spool, the null pressures
(equal land drops, no net force), the platen and the specimen at rest at u = 0.

It writes what the controller and the lab's sensors read (with sensor noise) and the drive
the controller sent:

    t_s, command_u_m, u_m, drive, delta_p_pa, cap_pressure_pa, rod_pressure_pa, a_m_s2,
    storey1_a_m_s2, storey2_a_m_s2

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
# Two storeys, bottom first: relative to the platen, storey i feels k_i, c_i to the one below.
SPECIMEN = [
    {"mass_kg": 3000.0, "stiffness_n_per_m": 3.0e6, "damping_n_s_per_m": 3000.0},
    {"mass_kg": 2000.0, "stiffness_n_per_m": 3.0e6, "damping_n_s_per_m": 2500.0},
]
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
NOISE = {"u_m": 2e-6, "a_m_s2": 0.02, "storey_a_m_s2": 0.02, "pressure_pa": 5e3,
         "drive_quantum": 1.0 / 32768}

M1, M2 = SPECIMEN[0]["mass_kg"], SPECIMEN[1]["mass_kg"]
K1, K2 = SPECIMEN[0]["stiffness_n_per_m"], SPECIMEN[1]["stiffness_n_per_m"]
C1, C2 = SPECIMEN[0]["damping_n_s_per_m"], SPECIMEN[1]["damping_n_s_per_m"]


def oil_column_hz(p, mass):
    """Oil column at the chambers' initial volumes: (1/2pi) sqrt(b(Aa^2/Va + Ab^2/Vb)/M)."""
    k = p["bulk_modulus_pa"] * (p["cap_area_m2"] ** 2 / p["cap_volume_m3"]
                                + p["rod_area_m2"] ** 2 / p["rod_volume_m3"])
    return math.sqrt(k / mass) / (2 * math.pi)


def specimen_modes():
    """Fixed-base modes of the specimen: (frequency Hz, damping ratio), lowest first."""
    m = np.diag([M1, M2])
    k = np.array([[K1 + K2, -K2], [-K2, K2]])
    c = np.array([[C1 + C2, -C2], [-C2, C2]])
    a = np.block([[np.zeros((2, 2)), np.eye(2)],
                  [-np.linalg.solve(m, k), -np.linalg.solve(m, c)]])
    ev = [e for e in np.linalg.eigvals(a) if e.imag > 0]
    modes = sorted((abs(e) / (2 * math.pi), -e.real / abs(e)) for e in ev)
    return [{"frequency_hz": f, "damping_ratio": z} for f, z in modes]


K_LAND = P["rated_flow_m3_s"] / math.sqrt(P["rated_pressure_drop_pa"] / 2)
LIN = 1e-4 * P["rated_pressure_drop_pa"]
W_SPOOL = 2 * math.pi * P["spool_natural_frequency_hz"]


def root(dp):
    """sqrt(|dp|) with its sign; linear below LIN Pa (laminar) so the slope stays finite."""
    a = abs(dp)
    if a >= LIN:
        return math.copysign(math.sqrt(a), dp)
    return dp / math.sqrt(LIN)


def parts(s, d, mode):
    """Rates of the state s = [u, v, pa, pb, x, xd, z1, z1d, z2, z2d] with valve input d.

    mode: +1 / -1 slipping with the friction's sign fixed, 0 stuck (v = 0, a = 0).
    Returns (rates, platen acceleration, net force N = F_A - K u - B)."""
    u, v, pa, pb, x, xd, z1, z1d, z2, z2d = s
    p = P
    pa_r, pb_r = max(pa, 0.0), max(pb, 0.0)
    ps, pr = p["supply_pressure_pa"], p["return_pressure_pa"]
    xo = min(max(x, -1.0), 1.0)
    if xo >= 0:
        qa = K_LAND * xo * root(ps - pa_r)
        qb = K_LAND * xo * root(pb_r - pr)
    else:
        qa = K_LAND * xo * root(pa_r - pr)
        qb = K_LAND * xo * root(ps - pb_r)
    aa, ab = p["cap_area_m2"], p["rod_area_m2"]
    va = p["cap_volume_m3"] + aa * u
    vb = p["rod_volume_m3"] - ab * u
    b, cl = p["bulk_modulus_pa"], p["leakage_m3_s_per_pa"]
    leak = cl * (pa_r - pb_r)
    dpa = b / va * (qa - aa * v - leak)
    dpb = b / vb * (-qb + ab * v + leak)
    if pa <= 0 and dpa < 0:
        dpa = 0.0
    if pb <= 0 and dpb < 0:
        dpb = 0.0
    fa = aa * pa_r - ab * pb_r
    shear = -(K1 * z1 + C1 * z1d)          # base shear B = sum m_i (a + z_i'')
    net = fa - p["stiffness_n_per_m"] * u - shear
    if mode == 0:
        a = 0.0
    else:
        a = (net - p["viscous_n_s_per_m"] * v - p["coulomb_n"] * mode) / p["mass_kg"]
    f1 = -K1 * z1 - C1 * z1d + K2 * (z2 - z1) + C2 * (z2d - z1d)
    f2 = -K2 * (z2 - z1) - C2 * (z2d - z1d)
    xdd = W_SPOOL * W_SPOOL * (d - x) - 2 * p["spool_damping_ratio"] * W_SPOOL * xd
    rates = [v if mode != 0 else 0.0, a, dpa, dpb, xd, xdd,
             z1d, f1 / M1 - a, z2d, f2 / M2 - a]
    return rates, a, net


def rk4(s, d, mode, dt):
    k1, _, _ = parts(s, d, mode)
    k2, _, _ = parts([a + 0.5 * dt * b for a, b in zip(s, k1)], d, mode)
    k3, _, _ = parts([a + 0.5 * dt * b for a, b in zip(s, k2)], d, mode)
    k4, _, _ = parts([a + dt * b for a, b in zip(s, k3)], d, mode)
    out = [a + dt / 6 * (b + 2 * c + 2 * e + f) for a, b, c, e, f in zip(s, k1, k2, k3, k4)]
    if mode == 0:
        out[1] = 0.0
    return out


def locate(g, lo=0.0, hi=1.0):
    """The root of g on (lo, hi) (g(lo) and g(hi) of opposite signs): Illinois."""
    glo, ghi = g(lo), g(hi)
    side = 0
    for _ in range(60):
        m = (lo * ghi - hi * glo) / (ghi - glo)
        gm = g(m)
        if gm == 0 or hi - lo < 1e-13:
            return m
        if (gm > 0) == (ghi > 0):
            hi, ghi = m, gm
            if side == -1:
                glo *= 0.5
            side = -1
        else:
            lo, glo = m, gm
            if side == 1:
                ghi *= 0.5
            side = 1
    return 0.5 * (lo + hi)


def step(s, mode, d, dt):
    """One substep of length dt with exact stick-slip; returns (state, mode)."""
    fmu = P["coulomb_n"]
    left = dt
    for _ in range(8):
        if left <= 0:
            break
        if mode == 0:
            new = rk4(s, d, 0, left)
            _, _, n_end = parts(new, d, 0)
            if abs(n_end) <= fmu:
                return new, 0
            sign = 1.0 if n_end > 0 else -1.0
            th = locate(lambda f: abs(parts(rk4(s, d, 0, f * left), d, 0)[2]) - fmu)
            s = rk4(s, d, 0, th * left)
            left -= th * left
            mode = sign
            continue
        new = rk4(s, d, mode, left)
        if new[1] * mode > 0:
            return new, mode
        th = locate(lambda f: rk4(s, d, mode, f * left)[1] * mode)
        s = rk4(s, d, mode, th * left)
        s[1] = 0.0
        left -= th * left
        _, _, n = parts(s, d, 0)
        if abs(n) <= fmu:
            mode = 0
        else:
            mode = 1.0 if n > 0 else -1.0
    return s, mode


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


COLUMNS = ("u_m", "drive", "delta_p_pa", "cap_pressure_pa", "rod_pressure_pa", "a_m_s2",
           "storey1_a_m_s2", "storey2_a_m_s2", "true_a_m_s2")


def simulate(cmd, g, rng):
    n = len(cmd)
    h = 1.0 / FS
    dt = h / SUB
    vref, aref = derivatives(cmd, h)
    ps, pr = P["supply_pressure_pa"], P["return_pressure_pa"]
    aa, ab = P["cap_area_m2"], P["rod_area_m2"]
    # platen's null state: equal land drops (pa + pb = Ps + Pr), no net force (Aa pa = Ab pb).
    pa0 = (ps + pr) * ab / (aa + ab)
    pb0 = (ps + pr) * aa / (aa + ab)
    s = [0.0, 0.0, pa0, pb0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    mode = 0
    w = 2 * math.pi * g["delta_p_highpass_hz"]
    c = 2.0 / h
    out = {k: np.zeros(n) for k in COLUMNS}
    d_old = 0.0
    hp = 0.0
    dp_prev = None
    u_prev = None
    for i in range(n):
        rates, a_now, _ = parts(s, d_old, mode)
        um = s[0] + NOISE["u_m"] * rng.standard_normal()
        am = a_now + NOISE["a_m_s2"] * rng.standard_normal()
        pam = s[2] + NOISE["pressure_pa"] * rng.standard_normal()
        pbm = s[3] + NOISE["pressure_pa"] * rng.standard_normal()
        a1 = a_now + rates[7] + NOISE["storey_a_m_s2"] * rng.standard_normal()
        a2 = a_now + rates[9] + NOISE["storey_a_m_s2"] * rng.standard_normal()
        dpm = pam - pbm
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
        for k, x in zip(COLUMNS, (um, d, dpm, pam, pbm, am, a1, a2, a_now)):
            out[k][i] = x
        for j in range(SUB):
            s, mode = step(s, mode, d_old if j < DELAY_SUB else d, dt)
        d_old = d
        if not all(math.isfinite(x) for x in s):
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
        "wn-a.csv": white_noise(n, 11, 0.0015, 0.2, 20.0),
        "chirp.csv": chirp(n, 0.5, 30.0, 4.0, 0.01),
        "wn-b.csv": white_noise(n, 23, 0.0015, 0.2, 20.0),
    }
    rng = np.random.default_rng(2026)
    summary = {}
    header = ("t_s,command_u_m,u_m,drive,delta_p_pa,cap_pressure_pa,rod_pressure_pa,a_m_s2,"
              "storey1_a_m_s2,storey2_a_m_s2\n")
    for name, cmd in records.items():
        out = simulate(cmd, GAINS, rng)
        t = np.arange(n) / FS
        rows = []
        for i in range(n):
            rows.append(f"{t[i]:.9g},{cmd[i]:.9e},{out['u_m'][i]:.9e},{out['drive'][i]:.9e},"
                        f"{out['delta_p_pa'][i]:.1f},{out['cap_pressure_pa'][i]:.1f},"
                        f"{out['rod_pressure_pa'][i]:.1f},{out['a_m_s2'][i]:.6g},"
                        f"{out['storey1_a_m_s2'][i]:.6g},{out['storey2_a_m_s2'][i]:.6g}\n")
        with open(os.path.join(outdir, name), "w") as fh:
            fh.write(header)
            fh.writelines(rows)
        if name == "wn-a.csv":
            with open(os.path.join(outdir, "missing-command.csv"), "w") as fh:
                fh.write(header.replace("command_u_m,", ""))
                for r in rows[:49]:
                    cells = r.split(",")
                    fh.write(",".join(cells[:1] + cells[2:]))
        true_a = out["true_a_m_s2"]
        summary[name] = {
            "peak_drive": float(np.max(np.abs(out["drive"]))),
            "rms_tracking_error_m": float(np.sqrt(np.mean((cmd - out["u_m"]) ** 2))),
            "rms_table_acceleration_m_s2": float(np.sqrt(np.mean(true_a ** 2))),
            "peak_table_acceleration_m_s2": float(np.max(np.abs(true_a))),
            "stuck_fraction": float(np.mean(true_a == 0.0)),
        }
        print(name, summary[name], flush=True)
    total = P["mass_kg"] + M1 + M2
    truth = {
        "made_by": "tools/reference/system_ident_records.py",
        "controller": GAINS,
        "plant": P,
        "specimen": {"storeys": SPECIMEN, "modes": specimen_modes()},
        "oil_column_frequency_hz": oil_column_hz(P, P["mass_kg"]),
        "oil_column_frequency_with_specimen_hz": oil_column_hz(P, total),
        "noise": NOISE,
        "records": summary,
    }
    with open(os.path.join(outdir, "truth.json"), "w") as fh:
        json.dump(truth, fh, indent=2)
        fh.write("\n")
    print(json.dumps(truth, indent=2))


if __name__ == "__main__":
    main()
