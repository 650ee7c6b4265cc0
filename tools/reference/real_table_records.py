#!/usr/bin/env python3
"""Stand-ins for REAL lab records of a small displacement-controlled uniaxial shake table
carrying a two-storey frame (issue 51), exported as its data system would export them, for
`platen identify --system` and the any-record method `platen identify`.

An independent reference: numpy only, no platen code, fixed seeds, deterministic (two runs
give byte-identical files). The physics is that of tools/reference/small_table_records.py
(copied and adapted, not re-invented): a digital controller at the record rate (zero-order
hold, 16-bit +-10 V drive) -> pure valve delay -> second-order spool -> four-way
critically-centred valve (orifice flow per land, laminar below 1e-4 of the rated drop) ->
compressible chambers with cross-port leakage -> the platen with exact stick-slip -> a
two-storey shear frame whose base shear loads the platen. What differs from the small
table's records is what the issue measured on the real ones:

  * the controller is P + velocity feed-forward + delta-p feedback:
    d = K_p (u_ref - u_meas) + K_vf v_ref - K_dp dp_meas (K_p 14.3 /m, K_vf 0.44 s/m,
    K_dp 2.4e-9 /Pa; the drive on +-10 V mapped to +-1);
  * the storeys weigh 0.8 of the platen each; the frame's first fixed-base mode is 7.5 Hz
    with 0.3 % damping (both classical modal damping ratios 0.3 %);
  * the platen's friction is a Coulomb force with a Stribeck term and a viscous law of
    exponent 0.85: F = sgn(v) [F_mu + a exp(-b |v|) + C |v|^alpha], about 0.1 g of the
    platen's mass at 2 mm/s and a fifth less at 7 mm/s; it sticks while
    |F_A - K u - B| <= F_mu + a (the breakaway force; exact stick-slip as in the small
    table's reference, the v = 0 crossing and the breakaway located inside the substep);
  * per-record accelerometer skew 2.2-2.6 samples (the three accelerometers within 0.15
    samples of each other), delta-p skew about 0.64 samples, fractional (band-limited); each
    accelerometer holds the mean acceleration over the sample interval (anti-aliasing: the
    platen's acceleration jumps at every stick and slip);
  * 13-15 % of each accelerometer's power in 30-50 Hz, uncorrelated with the command; a
    quiet white sensor noise (0.0005 g); sensor offsets: each accelerometer's within
    +-0.72 mg per record (what is left after zeroing), delta-p's within +-1 bar per record (a
    table at rest holds its friction, so delta-p cannot be zeroed at rest);
  * unequal record lengths (6 152 to 32 567 samples), quiet stretches at rest before and
    after the motion, table accelerations of about 0.12-0.29 m/s^2 RMS.

Run (from the repository root):

    python3 tools/reference/real_table_records.py out/real-standins            # 34 records
    python3 tools/reference/real_table_records.py tests/data/real_table --small  # 5 short

Options: --count N (records of the full set; the first N of the same sequence, 34 by
default), --small (the small committed set), --sub K (RK4 substeps per sample, default 16),
--readme-only (rewrite README.md from the folder's truth.json). It writes the records, the
held-out record's clean state (small set), truth.json, columns.json (for --system),
columns-anyrecord.json (force = delta-p x area, for the any-record method) and README.md.

Why the offsets and the quiet white noise: on the real records the issue reports the storey
fit's first mode 11 % low while a plain fit with the drifts integrated over 1-40 Hz gets
7.44 Hz; broadband accelerometer noise large enough to bias platen's fit that much would
bias the 1-40 Hz fit more (its 1/w^4 weighting at 1-2 Hz), so what the real records carry
is content below 1 Hz: offsets. A delta-p offset is what makes the force balance fit to
35 % and hides delta-p's skew, as reported.

The integration is vectorised over the records (one RK4 step of every record at once);
a record whose platen sticks or slips within a substep is integrated alone through that
substep, with the event located exactly (Illinois), as in the small table's reference.
"""
import argparse
import json
import math
import os
import time

import numpy as np

G = 9.80665                 # m/s^2 per g
FS = 204.8                  # controller and record rate, Hz
H = 1.0 / FS                # sample period, s (exactly 5/1024 s)

# ----------------------------------------------------------------------------------------
# The truth (SI)
# ----------------------------------------------------------------------------------------
AREA = 0.002                # one double-ended actuator, m^2 (about a 50 mm bore)
MASS = 400.0                # platen, kg
P = {
    "mass_kg": MASS,
    "stiffness_n_per_m": 0.0,
    "actuator_count": 1,
    "cap_area_m2": AREA,
    "rod_area_m2": AREA,
    "cap_volume_m3": 2.5e-4,
    "rod_volume_m3": 2.5e-4,
    "leakage_m3_s_per_pa": 1.2e-11,
    "bulk_modulus_pa": 1.4e9,
    "supply_pressure_pa": 20.7e6,
    "return_pressure_pa": 0.3e6,
    "valve_count": 1,
    "rated_pressure_drop_pa": 7e6,
    "no_load_velocity_full_drive_m_s": 2.2,
    "spool_natural_frequency_hz": 120.0,
    "spool_damping_ratio": 0.7,
    "valve_delay_s": 0.6e-3,
}
K_LAND = (P["no_load_velocity_full_drive_m_s"] * AREA
          / math.sqrt((P["supply_pressure_pa"] - P["return_pressure_pa"]) / 2))
P["rated_flow_m3_s"] = K_LAND * math.sqrt(P["rated_pressure_drop_pa"] / 2)
LIN = 1e-4 * P["rated_pressure_drop_pa"]          # laminar below this land drop, Pa
SQRT_LIN = math.sqrt(LIN)
W_SPOOL = 2 * math.pi * P["spool_natural_frequency_hz"]
Z_SPOOL = P["spool_damping_ratio"]

GAINS = {
    "sample_rate_hz": FS,
    "displacement_gain_per_m": 14.3,
    "velocity_feedforward_s_per_m": 0.44,
    "delta_p_gain_per_pa": 2.4e-9,
    "delta_p_highpass_hz": 0.0,
}
DRIVE_FULL_V = 10.0                     # the drive d = 1 is +10 V
V_QUANTUM = 20.0 / 65536                # 16-bit converter over +-10 V

# Friction: F(|v|) = F_mu + a exp(-b |v|) + C |v|^alpha while slipping.
STRIBECK_B = 200.0                      # s/m: the Stribeck term falls e-fold in 5 mm/s
ALPHA = 0.9
F_AT_2MM = 0.10 * MASS * G              # about 0.1 g of the platen's mass at 2 mm/s
F_AT_7MM = 0.8 * F_AT_2MM               # a fifth less at 7 mm/s
VISCOUS_AT_50MM = 40.0                  # N at 50 mm/s
CV = VISCOUS_AT_50MM / 0.05 ** ALPHA


def _friction_law():
    e2, e7 = math.exp(-STRIBECK_B * 0.002), math.exp(-STRIBECK_B * 0.007)
    v2, v7 = CV * 0.002 ** ALPHA, CV * 0.007 ** ALPHA
    a = ((F_AT_2MM - v2) - (F_AT_7MM - v7)) / (e2 - e7)
    fmu = F_AT_2MM - v2 - a * e2
    return fmu, a


FMU, A_ST = _friction_law()
F_BREAK = FMU + A_ST                    # the breakaway (static) force, N
KE = P["stiffness_n_per_m"]


def friction(w):
    """F(|v|) >= 0 at speed w >= 0 (scalar or array)."""
    return FMU + A_ST * np.exp(-STRIBECK_B * w) + CV * np.power(w, ALPHA)


# Two storeys, bottom first, 0.8 of the platen each; equal storey stiffness for a 7.5 Hz
# first fixed-base mode; storey dampers with both classical modal damping ratios 0.3 %.
M1, M2 = 0.8 * MASS, 0.8 * MASS
F1_TARGET_HZ = 7.5
ZETA_TARGET = 0.003


def storey_stiffness():
    lam = np.sort(np.linalg.eigvals(np.linalg.solve(np.diag([M1, M2]),
                                                    np.array([[2.0, -1.0], [-1.0, 1.0]]))).real)
    return (2 * math.pi * F1_TARGET_HZ) ** 2 / lam[0]


def undamped_modes(k1, k2):
    m = np.diag([M1, M2])
    k = np.array([[k1 + k2, -k2], [-k2, k2]])
    w2, phi = np.linalg.eig(np.linalg.solve(m, k))
    order = np.argsort(w2.real)
    return np.sqrt(w2.real[order]), phi.real[:, order], m


def storey_dampers(k1, k2):
    w, phi, m = undamped_modes(k1, k2)
    rows, rhs = [], []
    for n in range(2):
        rows.append([phi[0, n] ** 2, (phi[1, n] - phi[0, n]) ** 2])
        rhs.append(ZETA_TARGET * 2 * w[n] * (phi[:, n] @ m @ phi[:, n]))
    c = np.linalg.solve(np.array(rows), np.array(rhs))
    c[np.abs(c) < 1e-9 * np.max(np.abs(c))] = 0.0     # rounding of an exact 0
    return float(c[0]), float(c[1])


K1 = K2 = float(storey_stiffness())
C1, C2 = storey_dampers(K1, K2)
SPECIMEN = [
    {"mass_kg": M1, "stiffness_n_per_m": K1, "damping_n_s_per_m": C1},
    {"mass_kg": M2, "stiffness_n_per_m": K2, "damping_n_s_per_m": C2},
]

NOISE = {
    "displacement_rms_m": 5e-6,
    "acceleration_rms_g": 0.0005,
    "delta_p_rms_bar": 0.05,
    "controller_delta_p_rms_pa": 5e3,
}
# Each accelerometer's offset (what is left after a lab zeroes its channels), per channel and
# record, uniform in +-this, g; and the delta-p transducer's, bar, per record (a table at rest
# holds its friction, so delta-p cannot be zeroed at rest), in what the controller reads too.
ACC_OFFSET_G = 0.00072
DP_OFFSET_BAR = 1.0
HF_SHARE_RANGE = (0.13, 0.15)   # of each acceleration channel's total recorded power
HF_BAND_HZ = (30.0, 50.0)
ACC_SKEW_RANGE = (2.2, 2.6)     # samples, per record (the table accelerometer's)
ACC_CHANNEL_SPREAD = 0.07       # each storey accelerometer within +-this of the table's
DP_SKEW = (0.64, 0.02)          # samples: centre, +- per record


def specimen_modes():
    """Fixed-base modes: complex eigenvalues and classical modal damping, lowest first."""
    m = np.diag([M1, M2])
    k = np.array([[K1 + K2, -K2], [-K2, K2]])
    c = np.array([[C1 + C2, -C2], [-C2, C2]])
    a = np.block([[np.zeros((2, 2)), np.eye(2)],
                  [-np.linalg.solve(m, k), -np.linalg.solve(m, c)]])
    ev = sorted((e for e in np.linalg.eigvals(a) if e.imag > 0), key=abs)
    w, phi, _ = undamped_modes(K1, K2)
    out = []
    for n, e in enumerate(ev):
        mn = phi[:, n] @ m @ phi[:, n]
        shape = phi[:, n] / phi[1, n]
        out.append({
            "frequency_hz": float(abs(e) / (2 * math.pi)),
            "damped_frequency_hz": float(e.imag / (2 * math.pi)),
            "damping_ratio": float(-e.real / abs(e)),
            "undamped_frequency_hz": float(w[n] / (2 * math.pi)),
            "classical_damping_ratio": float((phi[:, n] @ c @ phi[:, n]) / (2 * w[n] * mn)),
            "shape_top_normalised": [float(x) for x in shape],
        })
    return out


def transmissibility_peak_hz():
    """Peak of |roof absolute acceleration / base acceleration| of the fixed-base frame."""
    f = np.arange(5.0, 10.0, 1e-4)
    w = 2 * np.pi * f
    m = np.diag([M1, M2])
    k = np.array([[K1 + K2, -K2], [-K2, K2]])
    c = np.array([[C1 + C2, -C2], [-C2, C2]])
    mag = []
    for wi in w:
        z = np.linalg.solve(-wi ** 2 * m + 1j * wi * c + k, -m @ np.ones(2))
        mag.append(abs(1 - wi ** 2 * z[1]))
    return float(f[int(np.argmax(mag))])


def oil_column_hz(mass):
    k = P["actuator_count"] * P["bulk_modulus_pa"] * (
        P["cap_area_m2"] ** 2 / P["cap_volume_m3"] + P["rod_area_m2"] ** 2 / P["rod_volume_m3"])
    return math.sqrt(k / mass) / (2 * math.pi)


# ----------------------------------------------------------------------------------------
# The plant, scalar (copied from small_table_records.py, friction law extended)
# ----------------------------------------------------------------------------------------
PS, PR = P["supply_pressure_pa"], P["return_pressure_pa"]
AA, AB = P["cap_area_m2"], P["rod_area_m2"]
VA0, VB0 = P["cap_volume_m3"], P["rod_volume_m3"]
BETA, CL = P["bulk_modulus_pa"], P["leakage_m3_s_per_pa"]
WS2 = W_SPOOL * W_SPOOL
ZW2 = 2 * Z_SPOOL * W_SPOOL


def root(dp):
    if dp >= LIN:
        return math.sqrt(dp)
    if dp <= -LIN:
        return -math.sqrt(-dp)
    return dp / SQRT_LIN


def parts(s, d, mode):
    """Rates of s = [u, v, pa, pb, x, xd, z1, z1d, z2, z2d] with valve input d; mode +1/-1
    slipping (friction's sign fixed), 0 stuck. Returns (rates, platen acceleration, net
    force N = F_A - K u - B)."""
    u, v, pa, pb, x, xd, z1, z1d, z2, z2d = s
    pa_r = pa if pa > 0.0 else 0.0
    pb_r = pb if pb > 0.0 else 0.0
    xo = 1.0 if x > 1.0 else (-1.0 if x < -1.0 else x)
    if xo >= 0:
        qa = K_LAND * xo * root(PS - pa_r)
        qb = K_LAND * xo * root(pb_r - PR)
    else:
        qa = K_LAND * xo * root(pa_r - PR)
        qb = K_LAND * xo * root(PS - pb_r)
    va = VA0 + AA * u
    vb = VB0 - AB * u
    leak = CL * (pa_r - pb_r)
    dpa = BETA / va * (qa - AA * v - leak)
    dpb = BETA / vb * (-qb + AB * v + leak)
    if pa <= 0 and dpa < 0:
        dpa = 0.0
    if pb <= 0 and dpb < 0:
        dpb = 0.0
    fa = AA * pa_r - AB * pb_r
    shear = -(K1 * z1 + C1 * z1d)
    net = fa - KE * u - shear
    if mode == 0:
        a = 0.0
    else:
        w = abs(v)
        a = (net - mode * (FMU + A_ST * math.exp(-STRIBECK_B * w) + CV * w ** ALPHA)) / MASS
    r21 = K2 * (z2 - z1) + C2 * (z2d - z1d)
    f1 = -K1 * z1 - C1 * z1d + r21
    f2 = -r21
    xdd = WS2 * (d - x) - ZW2 * xd
    rates = (v if mode != 0 else 0.0, a, dpa, dpb, xd, xdd,
             z1d, f1 / M1 - a, z2d, f2 / M2 - a)
    return rates, a, net


def rk4(s, d, mode, dt):
    k1, _, _ = parts(s, d, mode)
    h2 = 0.5 * dt
    k2, _, _ = parts([a + h2 * b for a, b in zip(s, k1)], d, mode)
    k3, _, _ = parts([a + h2 * b for a, b in zip(s, k2)], d, mode)
    k4, _, _ = parts([a + dt * b for a, b in zip(s, k3)], d, mode)
    h6 = dt / 6
    out = [a + h6 * (b + 2 * c + 2 * e + f) for a, b, c, e, f in zip(s, k1, k2, k3, k4)]
    if mode == 0:
        out[1] = 0.0
    return out


def locate(g, lo=0.0, hi=1.0):
    """The root of g on (lo, hi) (g(lo), g(hi) of opposite signs): Illinois."""
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
        if abs(gm) < 1e-12 * (1.0 + abs(glo) + abs(ghi)):
            return m
    return 0.5 * (lo + hi)


def step(s, mode, d, dt):
    """One substep of length dt with exact stick-slip; returns (state, mode, events)."""
    left = dt
    events = 0
    for _ in range(8):
        if left <= 0:
            break
        if mode == 0:
            new = rk4(s, d, 0, left)
            _, _, n_end = parts(new, d, 0)
            if abs(n_end) <= F_BREAK:
                return new, 0, events
            sign = 1.0 if n_end > 0 else -1.0
            th = locate(lambda f: abs(parts(rk4(s, d, 0, f * left), d, 0)[2]) - F_BREAK)
            s = rk4(s, d, 0, th * left)
            left -= th * left
            mode = sign
            events += 1
            continue
        new = rk4(s, d, mode, left)
        if new[1] * mode > 0:
            return new, mode, events
        th = locate(lambda f: rk4(s, d, mode, f * left)[1] * mode)
        s = rk4(s, d, mode, th * left)
        s[1] = 0.0
        left -= th * left
        _, _, n = parts(s, d, 0)
        events += 1
        if abs(n) <= F_BREAK:
            mode = 0
        else:
            mode = 1.0 if n > 0 else -1.0
    return s, mode, events


# ----------------------------------------------------------------------------------------
# The plant, vectorised over records (the same equations as `parts`, element-wise)
# ----------------------------------------------------------------------------------------
def vroot(dp):
    ad = np.abs(dp)
    return np.where(ad >= LIN, np.sign(dp) * np.sqrt(ad), dp / SQRT_LIN)


def vparts(s, d, mode):
    """`parts` for every column of s (10 x N), d and mode of length N."""
    u, v, pa, pb, x, xd, z1, z1d, z2, z2d = s
    pa_r = np.maximum(pa, 0.0)
    pb_r = np.maximum(pb, 0.0)
    xo = np.clip(x, -1.0, 1.0)
    pos = xo >= 0
    qa = K_LAND * xo * vroot(np.where(pos, PS - pa_r, pa_r - PR))
    qb = K_LAND * xo * vroot(np.where(pos, pb_r - PR, PS - pb_r))
    leak = CL * (pa_r - pb_r)
    dpa = BETA / (VA0 + AA * u) * (qa - AA * v - leak)
    dpb = BETA / (VB0 - AB * u) * (-qb + AB * v + leak)
    dpa = np.where((pa <= 0) & (dpa < 0), 0.0, dpa)
    dpb = np.where((pb <= 0) & (dpb < 0), 0.0, dpb)
    net = AA * pa_r - AB * pb_r - KE * u + K1 * z1 + C1 * z1d
    w = np.abs(v)
    slip = mode != 0
    a = np.where(slip, (net - mode * (FMU + A_ST * np.exp(-STRIBECK_B * w)
                                      + CV * np.power(w, ALPHA))) / MASS, 0.0)
    r21 = K2 * (z2 - z1) + C2 * (z2d - z1d)
    f1 = -K1 * z1 - C1 * z1d + r21
    rates = np.array([np.where(slip, v, 0.0), a, dpa, dpb, xd, WS2 * (d - x) - ZW2 * xd,
                      z1d, f1 / M1 - a, z2d, -r21 / M2 - a])
    return rates, a, net


def vnet(s):
    u, pa, pb, z1, z1d = s[0], s[2], s[3], s[6], s[7]
    return AA * np.maximum(pa, 0.0) - AB * np.maximum(pb, 0.0) - KE * u + K1 * z1 + C1 * z1d


def vrk4(s, d, mode, dt):
    k1, _, _ = vparts(s, d, mode)
    k2, _, _ = vparts(s + 0.5 * dt * k1, d, mode)
    k3, _, _ = vparts(s + 0.5 * dt * k2, d, mode)
    k4, _, _ = vparts(s + dt * k3, d, mode)
    out = s + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    out[1] = np.where(mode == 0, 0.0, out[1])
    return out


def substep_grid(sub):
    tau = P["valve_delay_s"]
    n1 = max(1, math.ceil(tau * sub / H - 1e-12))
    n2 = max(1, math.ceil((H - tau) * sub / H - 1e-12))
    return [(tau / n1, True)] * n1 + [((H - tau) / n2, False)] * n2


def derivatives(u, h):
    v = np.empty_like(u)
    v[1:-1] = (u[2:] - u[:-2]) / (2 * h)
    v[0] = (-3 * u[0] + 4 * u[1] - u[2]) / (2 * h)
    v[-1] = (3 * u[-1] - 4 * u[-2] + u[-3]) / (2 * h)
    return v


def sig7(x):
    return float(f"{x:.7g}")


def null_pressures():
    return (PS + PR) * AB / (AA + AB), (PS + PR) * AA / (AA + AB)


def simulate(cmds, noise_u, noise_dp, sub):
    """The closed loops of every record at once. cmds: commands (m, rounded as exported),
    noise_u / noise_dp: the controller's feedback noise per sample; lists of equal-length
    arrays per record. Returns per record the true state at the sample instants, what the
    controller read and sent, and diagnostics."""
    nrec = len(cmds)
    lens = [len(c) for c in cmds]
    n = max(lens)
    pad = lambda x: np.concatenate([x, np.zeros(n - len(x))])
    cmd = np.array([pad(c) for c in cmds])
    vref = np.array([pad(derivatives(c, H)) for c in cmds])
    nu = np.array([pad(x) for x in noise_u])
    ndp = np.array([pad(x) for x in noise_dp])
    kp = GAINS["displacement_gain_per_m"]
    kvf = GAINS["velocity_feedforward_s_per_m"]
    kdp = GAINS["delta_p_gain_per_pa"]
    pa0, pb0 = null_pressures()
    s = np.zeros((10, nrec))
    s[2], s[3] = pa0, pb0
    mode = np.zeros(nrec)
    grid = substep_grid(sub)
    keys = ("u", "v", "a", "a1", "a2", "v1", "v2", "dp", "spool", "u_meas", "dp_meas", "volts",
            "drive", "stuck")
    out = {k: np.zeros((nrec, n)) for k in keys}
    events = np.zeros(nrec, dtype=int)
    sat = np.zeros(nrec, dtype=int)
    minp = np.full(nrec, np.inf)
    d_old = np.zeros(nrec)
    t0 = time.time()
    for i in range(n):
        rates, a_now, _ = vparts(s, d_old, mode)
        um = np.array([sig7(x * 1e3) * 1e-3 for x in s[0] + nu[:, i]])
        dpm = s[2] - s[3] + ndp[:, i]
        raw = kp * (cmd[:, i] - um) + kvf * vref[:, i] - kdp * dpm
        sat += np.abs(raw) >= 1.0
        d = np.clip(raw, -1.0, 1.0)
        volts = np.clip(np.round(d * DRIVE_FULL_V / V_QUANTUM) * V_QUANTUM,
                        -DRIVE_FULL_V, DRIVE_FULL_V)
        d = volts / DRIVE_FULL_V
        for k, val in zip(keys, (s[0], s[1], a_now, a_now + rates[7], a_now + rates[9],
                                 s[1] + s[7], s[1] + s[9], s[2] - s[3], s[4], um, dpm,
                                 volts, d,
                                 (mode == 0).astype(float))):
            out[k][:, i] = val
        minp = np.minimum(minp, np.minimum(s[2], s[3]))
        for dt, before in grid:
            dd = d_old if before else d
            new = vrk4(s, dd, mode, dt)
            stuck = mode == 0
            ev = np.where(stuck, np.abs(vnet(new)) > F_BREAK, new[1] * mode <= 0)
            if ev.any():
                for j in np.nonzero(ev)[0]:
                    sj, mj, e = step(list(s[:, j]), mode[j], dd[j], dt)
                    new[:, j] = sj
                    mode[j] = mj
                    events[j] += e
            s = new
        d_old = d
        if not np.all(np.isfinite(s)):
            raise SystemExit("the reference loop diverged")
        if i and i % 4096 == 0:
            print(f"  sample {i}/{n} ({time.time() - t0:.0f} s)", flush=True)
    sims = []
    for r in range(nrec):
        m = lens[r]
        sim = {k: out[k][r, :m].copy() for k in keys}
        sim["vref"] = vref[r, :m].copy()
        diag = {"stick_slip_events": int(events[r]), "saturated_samples": int(sat[r]),
                "min_pressure_pa": float(minp[r])}
        sims.append((sim, diag))
    return sims


# ----------------------------------------------------------------------------------------
# Commands (copied from small_table_records.py; quiet stretches added)
# ----------------------------------------------------------------------------------------
def cosine_taper(n, ramp_s):
    t = np.arange(n) / FS
    dur = (n - 1) / FS
    w = np.ones(n)
    r = t < ramp_s
    w[r] = 0.5 * (1 - np.cos(np.pi * t[r] / ramp_s))
    r = t > dur - ramp_s
    w[r] = 0.5 * (1 - np.cos(np.pi * (dur - t[r]) / ramp_s))
    return w


def white_noise_acc_cmd(n, rng, f_lo, f_hi):
    """Band-limited white-noise acceleration integrated twice in the frequency domain,
    1 s cosine tapers (unscaled)."""
    spec = np.fft.rfft(rng.standard_normal(n))
    f = np.fft.rfftfreq(n, H)
    spec[(f < f_lo) | (f > f_hi)] = 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        spec = np.where(f > 0, -spec / (2 * np.pi * f) ** 2, 0.0)
    u = np.fft.irfft(spec, n) * cosine_taper(n, 1.0)
    u -= np.linspace(u[0], u[-1], n)
    return u


def earthquake_cmd(n, rng, fg_hz, zg, hp_hz=0.2):
    """Earthquake-like displacement (Kanai-Tajimi white noise under a strong-motion envelope,
    integrated twice in the frequency domain with a zero-phase 4th-order high-pass at hp_hz,
    1 s cosine tapers; unscaled)."""
    dur_s = (n - 1) / FS
    t = np.arange(n) / FS
    t1, t2 = 0.15 * dur_s, 0.45 * dur_s
    decay = -math.log(0.05) / (dur_s - t2)
    env = np.where(t < t1, (t / t1) ** 2, np.where(t < t2, 1.0, np.exp(-decay * (t - t2))))
    nf = 4 * n
    w = 2 * np.pi * np.fft.rfftfreq(nf, H)
    wg = 2 * np.pi * fg_hz
    kt = (wg ** 2 + 2j * zg * wg * w) / (wg ** 2 - w ** 2 + 2j * zg * wg * w)
    noise = np.fft.rfft(rng.standard_normal(n), nf)
    acc = np.fft.irfft(noise * kt, nf)[:n] * env
    a_spec = np.fft.rfft(acc, nf)
    wc = 2 * np.pi * hp_hz
    with np.errstate(divide="ignore", invalid="ignore"):
        hp = (w / wc) ** 4 / (1 + (w / wc) ** 4)
        u_spec = np.where(w > 0, -a_spec * hp / w ** 2, 0.0)
    u = np.fft.irfft(u_spec, nf)[:n] * cosine_taper(n, 1.0)
    u -= np.linspace(u[0], u[-1], n)
    return u


def second_difference_rms(u):
    a = (u[2:] - 2 * u[1:-1] + u[:-2]) / H ** 2
    return float(np.sqrt(np.mean(a ** 2)))


def make_command(spec):
    """The command of one record: quiet (at rest at 0), the motion, quiet; scaled so that
    the command's acceleration has the RMS asked for over the whole record."""
    n = spec["samples"]
    rng = np.random.default_rng([spec["seed"], 3])
    q0 = int(round(spec["quiet_before_s"] * FS))
    q1 = int(round(spec["quiet_after_s"] * FS))
    nm = n - q0 - q1
    if spec["kind"] == "wn":
        motion = white_noise_acc_cmd(nm, rng, *spec["band_hz"])
    else:
        motion = earthquake_cmd(nm, rng, spec["ground_hz"], 0.6)
    u = np.concatenate([np.zeros(q0), motion, np.zeros(q1)])
    u *= spec["command_acc_rms_m_s2"] / second_difference_rms(u)
    return np.array([sig7(x * 1e3) * 1e-3 for x in u])


# ----------------------------------------------------------------------------------------
# The set of records
# ----------------------------------------------------------------------------------------
FULL_COUNT = 34
SHORTEST, LONGEST = 6152, 32567
FULL_TOTAL = 673_000            # samples over the 34 records (about 55 minutes)


def full_lengths(count):
    """Record lengths: the 34 of the default set (6 152 to 32 567 samples, 673 000 in all,
    the shortest 3rd and the longest 6th), then uniform draws for more."""
    rng = np.random.default_rng(5134)
    mid = rng.uniform(SHORTEST, LONGEST, FULL_COUNT - 2)
    rest = FULL_TOTAL - SHORTEST - LONGEST
    mid = mid * rest / mid.sum()
    mid = np.clip(np.round(mid), SHORTEST + 1, LONGEST - 1).astype(int)
    mid[-1] += rest - int(mid.sum())
    lens = list(mid[:2]) + [SHORTEST] + list(mid[2:4]) + [LONGEST] + list(mid[4:])
    lens = [int(x) for x in lens]
    for k in range(FULL_COUNT, count):
        lens.append(int(np.random.default_rng([5134, k]).integers(SHORTEST, LONGEST + 1)))
    return lens[:count]


def record_specs(count, small):
    """name -> the record's specification (command kind, length, seed, levels, skews)."""
    specs = []
    if small:
        lengths = [3600, 3900, 3300, 4100, 3700]
        base_seed = 9000
    else:
        lengths = full_lengths(count)
        base_seed = 1000
    for r, n in enumerate(lengths):
        seed = base_seed + r
        rng = np.random.default_rng([seed, 0])
        kind = "wn" if r % 2 == 0 else "eq"
        dur = n / FS
        quiet = min(0.12 * dur, 10.0)
        spec = {
            "seed": seed,
            "samples": n,
            "kind": kind,
            "quiet_before_s": round(float(rng.uniform(0.3, 1.0) * quiet), 3),
            "quiet_after_s": round(float(rng.uniform(0.3, 1.0) * quiet), 3),
            "command_acc_rms_m_s2": round(float(rng.uniform(0.085, 0.21)), 4),
            "acc_skew_samples": float(rng.uniform(*ACC_SKEW_RANGE)),
            "storey_skew_offsets_samples": [float(x) for x in
                                            rng.uniform(-ACC_CHANNEL_SPREAD, ACC_CHANNEL_SPREAD,
                                                        2)],
            "delta_p_skew_samples": float(DP_SKEW[0] + rng.uniform(-1, 1) * DP_SKEW[1]),
            "hf_shares": [float(x) for x in rng.uniform(*HF_SHARE_RANGE, 3)],
            "acc_offsets_g": [float(x) for x in rng.uniform(-ACC_OFFSET_G, ACC_OFFSET_G, 3)],
            "delta_p_offset_bar": float(rng.uniform(-1, 1) * DP_OFFSET_BAR),
        }
        if kind == "wn":
            spec["band_hz"] = [0.3, 15.0]
        else:
            spec["ground_hz"] = round(float(rng.uniform(1.5, 5.0)), 3)
        name = f"r{r + 1:02d}-{kind}.csv"
        specs.append((name, spec))
    return specs


# ----------------------------------------------------------------------------------------
# The data system
# ----------------------------------------------------------------------------------------
HEADER = ["Time (s)", "Command (mm)", "Actuator displacement (mm)", "Table displacement (mm)",
          "Voltage command (V)", "Delta P (bar)", "Table acceleration (g)",
          "Storey 1 acceleration (g)", "Storey 2 acceleration (g)"]
CLEAN_HEADER = ["t_s", "u_m", "a_m_s2", "storey1_a_m_s2", "storey2_a_m_s2", "delta_p_pa",
                "a_mean_m_s2", "storey1_a_mean_m_s2", "storey2_a_mean_m_s2"]
COLUMN_MAP = {
    "t_s": {"name": "Time (s)", "unit": "s"},
    "command_u_m": {"name": "Command (mm)", "unit": "mm"},
    "u_m": {"name": "Actuator displacement (mm)", "unit": "mm"},
    "drive": {"name": "Voltage command (V)", "unit": "V", "scale": 0.1},
    "delta_p_pa": {"name": "Delta P (bar)", "unit": "bar"},
    "a_m_s2": {"name": "Table acceleration (g)", "unit": "g"},
    "storey1_a_m_s2": {"name": "Storey 1 acceleration (g)", "unit": "g"},
    "storey2_a_m_s2": {"name": "Storey 2 acceleration (g)", "unit": "g"},
}
# For the any-record method (`platen identify <files>`): the force from delta-p on the
# actuator's area; the storeys' base shear stays in it (no storey masses are known).
COLUMN_MAP_ANY = {
    "t_s": {"name": "Time (s)", "unit": "s"},
    "u_m": {"name": "Actuator displacement (mm)", "unit": "mm"},
    "a_m_s2": {"name": "Table acceleration (g)", "unit": "g"},
    "force_n": {"name": "Delta P (bar)", "unit": "bar", "times_area_m2": AREA},
}


def late(x, k):
    """x recorded k samples late (k fractional: band-limited): row i holds x(t_i - k h).
    The line through the end values is taken off, the rest zero-padded and delayed in the
    frequency domain, the line (delayed) put back; before the record the signal is at rest
    at its first value."""
    n = len(x)
    line = x[0] + (x[-1] - x[0]) * np.arange(n) / (n - 1)
    r = x - line
    nf = 2 * n
    f = np.fft.rfftfreq(nf)
    y = np.fft.irfft(np.fft.rfft(r, nf) * np.exp(-2j * np.pi * f * k), nf)[:n]
    i = np.arange(n) - k
    line_late = np.where(i < 0, x[0], x[0] + (x[-1] - x[0]) * i / (n - 1))
    return y + line_late


def interval_means(vel, a0):
    """The accelerometer channel before skew and noise: the mean acceleration over each sample
    interval, (V(t_i) - V(t_(i-1)))/h from the absolute velocity V (row 0: the acceleration
    at t_0). A data system's anti-aliasing: the platen's acceleration jumps at every stick
    and slip, and point samples of it would alias; the mean over the interval stands for
    the value at t_i - h/2 (half a sample of the skew)."""
    out = np.empty_like(vel)
    out[0] = a0
    out[1:] = np.diff(vel) / H
    return out


def band_noise(n, rng, f_lo, f_hi):
    spec = np.fft.rfft(rng.standard_normal(n))
    f = np.fft.rfftfreq(n, H)
    spec[(f < f_lo) | (f > f_hi)] = 0.0
    x = np.fft.irfft(spec, n)
    return x / np.sqrt(np.mean(x ** 2))


def time_text(i):
    return f"{i * 5 / 1024:.10f}".rstrip("0").rstrip(".") if i else "0"


def write_csv(path, header, cols, n):
    times = [time_text(i) for i in range(n)]
    with open(path, "w", newline="\n") as fh:
        fh.write(",".join(header) + "\n")
        cells = [[f"{x + 0.0:.7g}" for x in c] for c in cols]
        for i in range(n):
            fh.write(times[i] + "," + ",".join(c[i] for c in cells) + "\n")


def export(sim, cmd, spec):
    """The exported channels (file units): noise, HF content, skews."""
    n = len(cmd)
    seed = spec["seed"]
    rng = np.random.default_rng([seed, 7])
    table_u_mm = (sim["u"] + NOISE["displacement_rms_m"] * rng.standard_normal(n)) * 1e3
    dp_bar = (late(sim["dp"], spec["delta_p_skew_samples"]) * 1e-5
              + NOISE["delta_p_rms_bar"] * rng.standard_normal(n) + spec["delta_p_offset_bar"])
    accs, hf_rms = [], []
    skews = [spec["acc_skew_samples"]] + [spec["acc_skew_samples"] + o
                                          for o in spec["storey_skew_offsets_samples"]]
    for ch, (key, vkey) in enumerate((("a", "v"), ("a1", "v1"), ("a2", "v2"))):
        mean = interval_means(sim[vkey], sim[key][0])
        clean_g = late(mean, skews[ch] - 0.5) / G
        crng = np.random.default_rng([seed, 100 + ch])
        share = spec["hf_shares"][ch]
        p_clean = float(np.mean(clean_g ** 2))
        hf_amp = math.sqrt(share / (1 - share) * p_clean)
        hf = band_noise(n, crng, *HF_BAND_HZ) * hf_amp
        white = NOISE["acceleration_rms_g"] * crng.standard_normal(n)
        accs.append(clean_g + hf + white + spec["acc_offsets_g"][ch])
        hf_rms.append(hf_amp * G)
    cols = [cmd * 1e3, sim["u_meas"] * 1e3, table_u_mm, sim["volts"], dp_bar] + accs
    return cols, hf_rms, skews


# ----------------------------------------------------------------------------------------
def welch_peak(a_base, a_top, nperseg=8192):
    """Peak of |H1| = |P_xy / P_xx| (Welch, Hann, half overlap), Hz, numpy only."""
    n = len(a_base)
    nperseg = min(nperseg, n)
    step_ = nperseg // 2
    win = np.hanning(nperseg)
    pxx = 0.0
    pxy = 0.0
    for s0 in range(0, n - nperseg + 1, step_):
        x = np.fft.rfft(win * (a_base[s0:s0 + nperseg] - a_base[s0:s0 + nperseg].mean()))
        y = np.fft.rfft(win * (a_top[s0:s0 + nperseg] - a_top[s0:s0 + nperseg].mean()))
        pxx = pxx + np.abs(x) ** 2
        pxy = pxy + np.conj(x) * y
    f = np.fft.rfftfreq(nperseg, H)
    band = (f > 3.0) & (f < 12.0)
    h = np.abs(pxy / pxx)
    return float(f[band][np.argmax(h[band])])


def write_readme(outdir, truth):
    """README.md of the folder, from its truth.json."""
    t = truth
    pl, sp, ctl, rat = t["platen"], t["specimen"], t["controller"], t["ratios_to_actuator_area"]
    recs = t["records"]
    small = t["held_out"] is not None
    m1, m2 = (s["mass_kg"] for s in sp["storeys"])
    k1 = sp["storeys"][0]["stiffness_n_per_m"]
    c1, c2 = (s["damping_n_s_per_m"] for s in sp["storeys"])
    md = sp["modes"]
    lens = [r["samples"] for r in recs.values()]
    acc = [r["rms_table_acceleration_m_s2"] for r in recs.values()]
    trk = [r["tracking_nrmse"] for r in recs.values()]
    low = [r["below_2mm_s_fraction"] for r in recs.values()]
    stuck = [r["stuck_fraction"] for r in recs.values()]
    peaks = [r["transmissibility_peak_hz_clean"] for r in recs.values()]
    L = []
    w = L.append
    w("# Stand-ins for real records of a small table carrying a two-storey frame (issue 51)")
    w("")
    w("Made by an independent reference that uses no platen code (numpy only, fixed seeds, "
      "deterministic: two runs give byte-identical files). They have what the issue measured "
      "on real records of a small displacement-controlled uniaxial table (the real records "
      "stay outside the project):")
    w("")
    w("```sh")
    w(t["regenerate"])
    w("```")
    w("")
    w(f"{len(recs)} records, {t['total_samples']} samples ({t['total_minutes']:.1f} min) at "
      f"204.8 Hz, {min(lens)} to {max(lens)} samples each. The physics is copied from "
      "`tools/reference/small_table_records.py` (RK4, exact stick-slip located inside the "
      "substep, orifice law with its laminar transition, zero-order-hold controller), with the "
      "friction law, controller, frame and data system below. Every file here is written by the "
      "script, this README too (from `truth.json`).")
    w("")
    w("## The truth (SI)")
    w("")
    w("| part | value |")
    w("|---|---|")
    w(f"| actuator | 1, double-ended, A = {t['actuator']['cap_area_m2']} m², V_a0 = V_b0 = "
      f"{t['actuator']['cap_volume_m3']} m³, leakage {t['actuator']['leakage_m3_s_per_pa']:g} "
      "m³/s/Pa |")
    w(f"| oil, supply / return | β = {t['oil_bulk_modulus_pa']:g} Pa; "
      f"{t['supply_pressure_pa'] / 1e6:g} / {t['return_pressure_pa'] / 1e6:g} MPa |")
    sv = t["servo_valve"]
    w(f"| servo-valve | four-way, critically centred, no-load velocity "
      f"{sv['no_load_velocity_full_drive_m_s']} m/s at full drive (K = "
      f"{sv['land_coefficient_m3_s_per_sqrt_pa']:.6g} m³/s/√Pa); delay {sv['delay_s'] * 1e3} ms, "
      f"then 2nd order {sv['natural_frequency_hz']:g} Hz, ζ {sv['damping_ratio']} |")
    w(f"| platen | M = {pl['mass_kg']:g} kg, K = {pl['stiffness_n_per_m']:g}; friction "
      f"sgn(v)·[F_μ + a·e^(−b|v|) + C·|v|^α] with F_μ = {pl['coulomb_n']:.2f} N, a = "
      f"{pl['low_velocity_force_n']:.2f} N, b = {pl['low_velocity_decay_s_per_m']:g} s/m, "
      f"C = {pl['viscous_coefficient']:.2f} N/(m/s)^α, α = {pl['viscous_exponent']}: "
      f"{pl['friction_at_2mm_s_n']:.1f} N at 2 mm/s ({pl['friction_at_2mm_s_over_mg']:.3f}·M·g), "
      f"{pl['friction_at_7mm_s_n']:.1f} N at 7 mm/s (a fifth less); sticks while "
      f"|F_A − K u − B| ≤ F_μ + a = {pl['breakaway_force_n']:.1f} N |")
    w(f"| specimen (bottom first) | m = {m1:g}, {m2:g} kg (0.8 of the platen each); "
      f"k₁ = k₂ = **{k1:.6g} N/m**; c₁ = **{c1:.6g}**, c₂ = {c2:.3g} N·s/m |")
    w(f"| specimen modes (fixed base) | **{md[0]['frequency_hz']:.4f} Hz, ζ "
      f"{md[0]['damping_ratio'] * 100:.4f} %** and **{md[1]['frequency_hz']:.4f} Hz, ζ "
      f"{md[1]['damping_ratio'] * 100:.4f} %** (complex eigenvalues; classical ratios "
      f"{md[0]['classical_damping_ratio'] * 100:.3f} % both; shapes "
      f"[{md[0]['shape_top_normalised'][0]:.3f}, 1], [{md[1]['shape_top_normalised'][0]:.3f}, 1]); "
      f"roof/base transmissibility peak {sp['transmissibility_peak_hz']:.4f} Hz |")
    w(f"| oil column | {t['oil_column_frequency_hz']:.2f} Hz bare, "
      f"{t['oil_column_frequency_with_specimen_hz']:.2f} Hz with the specimen rigid |")
    w(f"| controller | 204.8 Hz, zero-order hold: d = K_p (u_ref − u_meas) + K_vf·v_ref − "
      f"K_Δp·Δp_meas, K_p = {ctl['displacement_gain_per_m']} /m, K_vf = "
      f"{ctl['velocity_feedforward_s_per_m']} s/m, K_Δp = {ctl['delta_p_gain_per_pa']:g} /Pa "
      "(Δp unfiltered), saturated at ±1, 16 bits over ±10 V |")
    w("")
    w(f"Ratios to the actuator area (all the records show): M/A = {rat['mass_kg_per_m2']:g} "
      f"kg/m², storey masses/A {rat['storey_masses_kg_per_m2'][0]:g}, k/A = "
      f"{rat['storey_stiffness_n_per_m_per_m2'][0]:.6g}, F_μ/A = {rat['coulomb_n_per_m2']:.6g} Pa.")
    w("")
    w("## What the data system records")
    w("")
    w("Every record: a header row, comma separated, the small table's columns and units "
      "(`columns.json` maps them for `platen identify --system`):")
    w("")
    w("| column | what | noise | skew (samples late) |")
    w("|---|---|---|---|")
    nz = t["noise"]
    w("| `Time (s)` | t = i/204.8 exactly | | |")
    w("| `Command (mm)` | u_ref | none | on time |")
    w(f"| `Actuator displacement (mm)` | the feedback the controller read | "
      f"{nz['displacement_rms_m'] * 1e6:g} µm RMS white | on time |")
    w(f"| `Table displacement (mm)` | its own sensor | {nz['displacement_rms_m'] * 1e6:g} µm RMS "
      "white, independent | on time |")
    w("| `Voltage command (V)` | the drive × 10 V, quantised to 20 V/65536 | | on time |")
    w(f"| `Delta P (bar)` | p_a − p_b | {nz['delta_p_rms_bar']} bar RMS white + a per-record "
      f"offset, uniform in ±{t['delta_p_offset_bar']} bar | "
      f"{t['skew']['delta_p_samples'][0]} ± {t['skew']['delta_p_samples'][1]} per record |")
    w(f"| `Table acceleration (g)` | platen, absolute: the mean over the sample interval | "
      f"{nz['acceleration_rms_g']} g RMS white + 30–50 Hz content + offset | "
      f"{t['skew']['acceleration_samples_range'][0]}–{t['skew']['acceleration_samples_range'][1]}, "
      "per record |")
    w(f"| `Storey 1 acceleration (g)`, `Storey 2 acceleration (g)` | absolute, likewise | "
      f"likewise, independent | the table's ± up to {t['skew']['storey_offsets_within_samples']} |")
    w("")
    w("* Skew: row i holds the true value at t_i − k·h, k fractional (band-limited delay). An "
      "accelerometer holds the mean acceleration over the sample interval (a data system's "
      "anti-aliasing; the platen's acceleration jumps at every stick and slip and point samples "
      "would alias), which is half a sample of its k. Noise, the 30–50 Hz content and the "
      "offsets come after the skew.")
    w(f"* 30–50 Hz content: Gaussian, FFT band-limited, independent per channel and record, "
      f"{t['high_frequency_content']['share_of_total_power_range'][0] * 100:g}–"
      f"{t['high_frequency_content']['share_of_total_power_range'][1] * 100:g} % of the "
      "channel's power (clean + content; per record in `truth.json`), uncorrelated with the "
      "command.")
    w(f"* Offsets: each accelerometer's, per channel and record, uniform in "
      f"±{t['acceleration_offset_g']} g (what is left after zeroing: gravity on a tilt of 1 mrad "
      "is 1 mg); Δp's per record (a table at rest holds its friction, so Δp cannot be zeroed at "
      "rest; the controller reads the same transducer).")
    w("* The command and the feedback are written exactly as the controller used them (7 "
      "significant digits); the drive the valve got is the quantised voltage / 10.")
    w("")
    w("`columns-anyrecord.json` maps the files for the any-record method (`platen identify "
      f"FILES --columns columns-anyrecord.json`): the force is Δp × {t['actuator']['cap_area_m2']} "
      "m² (the storeys' base shear stays in it: no storey masses are given).")
    w("")
    w("## Files")
    w("")
    w(f"Lengths {min(lens)}–{max(lens)} samples; table acceleration {min(acc):.3f}–{max(acc):.3f} "
      f"m/s² RMS; tracking NRMSE (RMS(u − u_ref)/RMS(u_ref)) {min(trk) * 100:.2f}–"
      f"{max(trk) * 100:.2f} %; {min(low) * 100:.0f}–{max(low) * 100:.0f} % of each record "
      f"below 2 mm/s ({min(stuck) * 100:.0f}–{max(stuck) * 100:.0f} % stuck); roof/table "
      f"transmissibility peak (noise-free, Welch) {min(peaks):.3f}–{max(peaks):.3f} Hz. "
      "Quiet stretches at rest before and after the motion. `wn`: band-limited white-noise "
      "acceleration (0.3–15 Hz); `eq`: earthquake-like (Kanai–Tajimi, ground frequency per "
      "record, strong-motion envelope), as in the small table's reference.")
    w("")
    w("| file | samples | command | table acc. RMS m/s² | roof acc. RMS | below 2 mm/s | "
      "acc. skew | Δp skew | Δp offset bar |")
    w("|---|---|---|---|---|---|---|---|---|")
    for name, r in recs.items():
        what = (f"white noise {r['band_hz'][0]}–{r['band_hz'][1]} Hz" if r["kind"] == "wn"
                else f"earthquake-like, {r['ground_hz']} Hz")
        tag = " (held out)" if name == t["held_out"] else ""
        w(f"| `{name}`{tag} | {r['samples']} | {what} | {r['rms_table_acceleration_m_s2']:.3f} | "
          f"{r['rms_storey2_acceleration_m_s2']:.3f} | {r['below_2mm_s_fraction'] * 100:.0f} % | "
          f"{r['acc_skew_samples']:.3f} | {r['delta_p_skew_samples']:.3f} | "
          f"{r['delta_p_offset_bar']:+.3f} |")
    if small:
        w(f"| `{t['held_out'].replace('.csv', '-clean.csv')}` | | the held-out record's true, "
          "noise-free, un-skewed state (SI): `t_s,u_m,a_m_s2,storey1_a_m_s2,storey2_a_m_s2,"
          "delta_p_pa` at the sample instants, then the three accelerations' interval means "
          "(`*_a_mean_m_s2`, what the accelerometers hold before skew, noise and offset) | | | | | | |")
    w("| `truth.json` | | every parameter, the derived ones, ratios to A, noise, skews, "
      "offsets, per-record figures | | | | | | |")
    w("")
    with open(os.path.join(outdir, "README.md"), "w") as fh:
        fh.write("\n".join(L) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("outdir")
    ap.add_argument("--count", type=int, default=FULL_COUNT)
    ap.add_argument("--small", action="store_true",
                    help="the small set (5 records of 3 300-4 100 samples) for the tests")
    ap.add_argument("--sub", type=int, default=16, help="nominal RK4 substeps per sample")
    ap.add_argument("--readme-only", action="store_true",
                    help="only (re)write README.md from the folder's truth.json")
    args = ap.parse_args()
    outdir = args.outdir
    if args.readme_only:
        with open(os.path.join(outdir, "truth.json")) as fh:
            write_readme(outdir, json.load(fh))
        return
    os.makedirs(outdir, exist_ok=True)
    t_start = time.time()
    modes = specimen_modes()
    print(f"storey stiffness {K1:.6g} N/m, dampers {C1:.6g} / {C2:.6g} N s/m")
    for m in modes:
        print("specimen mode:", m)
    print(f"friction: F_mu {FMU:.4g} N, Stribeck a {A_ST:.4g} N, b {STRIBECK_B} s/m, "
          f"C {CV:.4g} N/(m/s)^{ALPHA}; F(2 mm/s) {friction(0.002):.4g} N, "
          f"F(7 mm/s) {friction(0.007):.4g} N, breakaway {F_BREAK:.4g} N")
    print(f"oil column {oil_column_hz(MASS):.4g} Hz bare, "
          f"{oil_column_hz(MASS + M1 + M2):.4g} Hz with the specimen rigid")
    specs = record_specs(args.count, args.small)
    cmds = [make_command(s) for _, s in specs]
    noise_u = [NOISE["displacement_rms_m"]
               * np.random.default_rng([s["seed"], 1]).standard_normal(s["samples"])
               for _, s in specs]
    noise_dp = [NOISE["controller_delta_p_rms_pa"]
                * np.random.default_rng([s["seed"], 2]).standard_normal(s["samples"])
                + s["delta_p_offset_bar"] * 1e5 for _, s in specs]
    print(f"{len(specs)} records, {sum(s['samples'] for _, s in specs)} samples; simulating",
          flush=True)
    sims = simulate(cmds, noise_u, noise_dp, args.sub)
    summary = {}
    held_out = specs[-1][0] if args.small else None
    for (name, spec), cmd, (sim, diag) in zip(specs, cmds, sims):
        n = len(cmd)
        cols, hf_rms, skews = export(sim, cmd, spec)
        write_csv(os.path.join(outdir, name), HEADER, cols, n)
        if name == held_out:
            means = [interval_means(sim[v], sim[a][0])
                     for a, v in (("a", "v"), ("a1", "v1"), ("a2", "v2"))]
            write_csv(os.path.join(outdir, name.replace(".csv", "-clean.csv")), CLEAN_HEADER,
                      [sim["u"], sim["a"], sim["a1"], sim["a2"], sim["dp"]] + means, n)
        rms_cmd = float(np.sqrt(np.mean(cmd ** 2)))
        err = sim["u"] - cmd
        speed = np.abs(sim["v"])
        rec_acc = cols[5] * G
        rec = dict(spec)
        rec.update({
            "duration_s": (n - 1) / FS,
            "accelerometer_skews_samples": skews,
            "peak_command_m": float(np.max(np.abs(cmd))),
            "rms_command_m": rms_cmd,
            "tracking_nrmse": float(np.sqrt(np.mean(err ** 2)) / rms_cmd),
            "peak_abs_drive": float(np.max(np.abs(sim["drive"]))),
            "saturated_samples": diag["saturated_samples"],
            "stuck_fraction": float(np.mean(sim["stuck"])),
            "below_2mm_s_fraction": float(np.mean(speed < 0.002)),
            "stick_slip_events": diag["stick_slip_events"],
            "rms_table_acceleration_m_s2": float(np.sqrt(np.mean(sim["a"] ** 2))),
            "rms_recorded_table_acceleration_m_s2": float(np.sqrt(np.mean(rec_acc ** 2))),
            "rms_storey1_acceleration_m_s2": float(np.sqrt(np.mean(sim["a1"] ** 2))),
            "rms_storey2_acceleration_m_s2": float(np.sqrt(np.mean(sim["a2"] ** 2))),
            "peak_storey2_acceleration_m_s2": float(np.max(np.abs(sim["a2"]))),
            "peak_table_velocity_m_s": float(np.max(speed)),
            "rms_table_velocity_m_s": float(np.sqrt(np.mean(sim["v"] ** 2))),
            "peak_abs_delta_p_pa": float(np.max(np.abs(sim["dp"]))),
            "min_chamber_pressure_pa": diag["min_pressure_pa"],
            "hf_rms_m_s2": dict(zip(("table", "storey1", "storey2"), hf_rms)),
            "transmissibility_peak_hz_clean": welch_peak(sim["a"], sim["a2"]),
        })
        summary[name] = rec
        print(name, n, f"acc {rec['rms_table_acceleration_m_s2']:.3f} m/s2, roof "
              f"{rec['rms_storey2_acceleration_m_s2']:.3f}, stuck {rec['stuck_fraction']:.2f}, "
              f"<2mm/s {rec['below_2mm_s_fraction']:.2f}, track {rec['tracking_nrmse']:.4f}, "
              f"events {rec['stick_slip_events']}, peak T {rec['transmissibility_peak_hz_clean']}",
              flush=True)

    pa0, pb0 = null_pressures()
    regen = ("python3 tools/reference/real_table_records.py " + outdir
             + (" --small" if args.small else "")
             + (f" --count {args.count}" if args.count != FULL_COUNT and not args.small else "")
             + (f" --sub {args.sub}" if args.sub != 16 else ""))
    total = sum(s["samples"] for _, s in specs)
    truth = {
        "made_by": "tools/reference/real_table_records.py (numpy only, no platen code)",
        "regenerate": regen,
        "numpy_version": np.__version__,
        "integration": {
            "method": "RK4, fixed step, each controller period cut at the valve delay; "
                      "vectorised over the records, a record with a stick-slip event in a "
                      "substep integrated alone through it",
            "substeps_per_sample": len(substep_grid(args.sub)),
            "substeps_s": [dt for dt, _ in substep_grid(args.sub)],
            "stick_slip": "exact: v = 0 crossing and breakaway located inside the substep "
                          "(Illinois)",
        },
        "actuator": {"count": 1, "double_ended": True, "cap_area_m2": AA, "rod_area_m2": AB,
                     "cap_volume_m3": VA0, "rod_volume_m3": VB0,
                     "leakage_m3_s_per_pa": CL},
        "servo_valve": {
            "count": 1,
            "rated_pressure_drop_pa": P["rated_pressure_drop_pa"],
            "rated_flow_m3_s": P["rated_flow_m3_s"],
            "land_coefficient_m3_s_per_sqrt_pa": K_LAND,
            "no_load_velocity_full_drive_m_s": P["no_load_velocity_full_drive_m_s"],
            "laminar_below_pa": LIN,
            "natural_frequency_hz": P["spool_natural_frequency_hz"],
            "damping_ratio": Z_SPOOL,
            "delay_s": P["valve_delay_s"],
            "critically_centred": True,
        },
        "oil_bulk_modulus_pa": BETA,
        "supply_pressure_pa": PS,
        "return_pressure_pa": PR,
        "null_pressures_pa": [pa0, pb0],
        "platen": {
            "mass_kg": MASS, "stiffness_n_per_m": KE,
            "friction_law": "sgn(v) [F_mu + a exp(-b|v|) + C |v|^alpha] while slipping; "
                            "stuck while |F_A - K u - B| <= F_mu + a",
            "coulomb_n": FMU, "low_velocity_force_n": A_ST,
            "low_velocity_decay_s_per_m": STRIBECK_B,
            "viscous_coefficient": CV, "viscous_exponent": ALPHA,
            "breakaway_force_n": F_BREAK,
            "friction_at_2mm_s_n": float(friction(0.002)),
            "friction_at_7mm_s_n": float(friction(0.007)),
            "friction_at_2mm_s_over_mg": float(friction(0.002) / (MASS * G)),
            "identified_equivalent": {"effective_mass_kg": MASS, "stiffness_n_per_m": KE,
                                      "coulomb_force_n": FMU, "viscous_coefficient": CV,
                                      "viscous_exponent": ALPHA,
                                      "low_velocity_force_n": A_ST,
                                      "low_velocity_decay_s_per_m": STRIBECK_B},
        },
        "specimen": {"storeys": SPECIMEN, "modes": modes,
                     "transmissibility_peak_hz": transmissibility_peak_hz(),
                     "storey_mass_over_platen": [M1 / MASS, M2 / MASS],
                     "design": "equal storey stiffness for a 7.5 Hz first fixed-base mode; "
                               "storey dampers with both classical modal damping ratios "
                               "0.003"},
        "controller": dict(GAINS, **{
            "law": "d = K_p (u_ref - u_meas) + K_vf v_ref - K_dp dp_meas, saturated at +-1, "
                   "zero-order hold, quantised to 16 bits over +-10 V",
            "dp_meas": "the true p_a - p_b at the sample plus the transducer's offset "
                       "(records.*.delta_p_offset_bar) and the controller's own sensor noise "
                       "(white, controller_delta_p_rms_pa); the recorded 'Delta P' column is "
                       "another reading of the same transducer (same offset), skewed and with "
                       "its own noise",
            "u_meas": "the exported 'Actuator displacement (mm)' (true + noise), as read",
        }),
        "oil_column_frequency_hz": oil_column_hz(MASS),
        "oil_column_frequency_with_specimen_hz": oil_column_hz(MASS + M1 + M2),
        "ratios_to_actuator_area": {
            "area_m2": AREA,
            "mass_kg_per_m2": MASS / AREA,
            "coulomb_n_per_m2": FMU / AREA,
            "storey_masses_kg_per_m2": [M1 / AREA, M2 / AREA],
            "storey_stiffness_n_per_m_per_m2": [K1 / AREA, K2 / AREA],
            "storey_dampers_n_s_per_m_per_m2": [C1 / AREA, C2 / AREA],
            "land_coefficient_per_m2": K_LAND / AREA,
            "cap_volume_over_beta_area_m_per_pa": VA0 / (BETA * AREA),
        },
        "record": {"rate_hz": FS, "times": "t = i/204.8 s exactly",
                   "float_format": "7 significant digits (time exact)", "columns": HEADER},
        "noise": dict(NOISE, **{"acceleration_rms_m_s2": NOISE["acceleration_rms_g"] * G,
                                "delta_p_rms_pa": NOISE["delta_p_rms_bar"] * 1e5,
                               "offsets": "accelerometers: records.*.acc_offsets_g (g, table, "
                                          "storey 1, storey 2); delta-p: "
                                          "records.*.delta_p_offset_bar",
                                "drive_quantum_v": V_QUANTUM}),
        "high_frequency_content": {
            "band_hz": list(HF_BAND_HZ),
            "share_of_total_power_range": list(HF_SHARE_RANGE),
            "definition": "Gaussian, FFT band-limited, independent per channel and record; "
                          "its mean square is share/(1 - share) of the clean (skewed) "
                          "channel's over the record (shares per record in records.*.hf_shares)",
        },
        "skew": {
            "acceleration_samples_range": list(ACC_SKEW_RANGE),
            "storey_offsets_within_samples": ACC_CHANNEL_SPREAD,
            "delta_p_samples": list(DP_SKEW),
            "on_time": ["Command (mm)", "Actuator displacement (mm)",
                        "Table displacement (mm)", "Voltage command (V)"],
            "definition": "row i holds the true value at t_i - k h (k fractional, "
                          "band-limited delay); the accelerometers hold the mean acceleration "
                          "over the sample interval (anti-aliasing: the platen's acceleration "
                          "jumps at stick and slip), which counts as half a sample of k, "
                          "delayed by the other k - 1/2; noise and HF content added after the "
                          "skew",
        },
        "acceleration_offset_g": ACC_OFFSET_G,
        "delta_p_offset_bar": DP_OFFSET_BAR,
        "held_out": held_out,
        "fitted": [name for name, _ in specs if name != held_out] if held_out else None,
        "total_samples": total,
        "total_minutes": total / FS / 60,
        "records": summary,
    }
    with open(os.path.join(outdir, "truth.json"), "w") as fh:
        json.dump(truth, fh, indent=2)
        fh.write("\n")
    for fname, cmap in (("columns.json", COLUMN_MAP), ("columns-anyrecord.json", COLUMN_MAP_ANY)):
        with open(os.path.join(outdir, fname), "w") as fh:
            fh.write("{\n" + ",\n".join(f"  {json.dumps(k)}: {json.dumps(v)}"
                                         for k, v in cmap.items()) + "\n}\n")
    write_readme(outdir, truth)
    print(f"total {time.time() - t_start:.1f} s")


if __name__ == "__main__":
    main()
