#!/usr/bin/env python3
"""Closed-loop records of a SMALL displacement-controlled uniaxial shake table carrying a
two-storey frame, exported as a lab's data system would export them, for
`platen identify --system` (identification of the whole loop from what labs record).

An independent reference: numpy only, no platen code, fixed seeds, deterministic. The
physics is that of tools/reference/system_ident_records.py (copied and adapted, not
re-invented), i.e. the model class of docs/table-system.md:

  digital controller at the record rate (zero-order hold; d = K_p (u_ref - u_meas) + K_vf v_ref,
  saturated at +-1, sent through a 16-bit +-10 V converter) -> pure valve delay -> second-order
  spool -> four-way critically-centred valve (orifice flow per land, K = Q_r / sqrt(dp_r / 2),
  laminar below 1e-4 of the rated drop, opening clamped to +-1) -> compressible chambers
  V_a = V_a0 + A_a u, V_b = V_b0 - A_b u with cross-port leakage C_L (p_a - p_b) and the
  cavitation floor at 0 Pa -> a platen with elastic, viscous and exact Coulomb friction
  (stick-slip: it sticks while |F_A - K u - B| <= F_mu; the v = 0 crossing and the breakaway
  are located inside the substep) -> a two-storey shear frame on the platen whose base shear
  B = sum m_i (absolute storey acceleration) loads the platen.

The valve delay is exact: every controller period is cut at the instant the held drive reaches
the spool (tau after the sample), as platen's own RK4 grid cuts it.

Run (from the repository root):

    python3 tools/reference/small_table_records.py tests/data/small_table
"""
import json
import math
import os
import sys
import time

import numpy as np

G = 9.80665                 # m/s^2 per g
FS = 204.8                  # controller and record rate, Hz
H = 1.0 / FS                # sample period, s (exactly 5/1024 s)
SUB = 16                    # nominal RK4 substeps per controller sample (see substep_grid)

# ----------------------------------------------------------------------------------------
# The truth (SI)
# ----------------------------------------------------------------------------------------
AREA = 0.0125
P = {
    "mass_kg": 2500.0,
    "stiffness_n_per_m": 20.0e3,
    "viscous_n_s_per_m": 1500.0,
    "coulomb_n": 600.0,
    "actuator_count": 1,
    "cap_area_m2": AREA,
    "rod_area_m2": AREA,
    "cap_volume_m3": 1.6e-3,
    "rod_volume_m3": 1.6e-3,
    "leakage_m3_s_per_pa": 2e-12,
    "bulk_modulus_pa": 1.4e9,
    "supply_pressure_pa": 20.7e6,
    "return_pressure_pa": 0.3e6,
    "valve_count": 1,
    "rated_pressure_drop_pa": 7e6,
    "no_load_velocity_full_drive_m_s": 1.95,
    "spool_natural_frequency_hz": 120.0,
    "spool_damping_ratio": 0.7,
    "valve_delay_s": 0.6e-3,
}
# K sqrt((Ps - Pr)/2) = 1.95 A: the no-load velocity at full drive (null pressures: each land
# drops (Ps - Pr)/2).
K_LAND = (P["no_load_velocity_full_drive_m_s"] * AREA
          / math.sqrt((P["supply_pressure_pa"] - P["return_pressure_pa"]) / 2))
P["rated_flow_m3_s"] = K_LAND * math.sqrt(P["rated_pressure_drop_pa"] / 2)
LIN = 1e-4 * P["rated_pressure_drop_pa"]          # laminar below this land drop, Pa
SQRT_LIN = math.sqrt(LIN)
W_SPOOL = 2 * math.pi * P["spool_natural_frequency_hz"]
Z_SPOOL = P["spool_damping_ratio"]

GAINS = {
    "sample_rate_hz": FS,
    "displacement_gain_per_m": 9.6,
    "velocity_feedforward_s_per_m": 0.5,
}
DRIVE_FULL_V = 10.0                     # the drive d = 1 is +10 V
V_QUANTUM = 20.0 / 65536                # 16-bit converter over +-10 V

# Two storeys, bottom first; equal storey stiffness with the first fixed-base mode at 6.5 Hz;
# storey dampers with both classical modal damping ratios (phi_n^T C phi_n / (2 w_n m_n)) 2 %.
M1, M2 = 1200.0, 900.0
F1_TARGET_HZ = 6.5
ZETA_TARGET = 0.02


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
    return float(c[0]), float(c[1])


K1 = K2 = float(storey_stiffness())
C1, C2 = storey_dampers(K1, K2)
SPECIMEN = [
    {"mass_kg": M1, "stiffness_n_per_m": K1, "damping_n_s_per_m": C1},
    {"mass_kg": M2, "stiffness_n_per_m": K2, "damping_n_s_per_m": C2},
]

NOISE = {
    "displacement_rms_m": 5e-6,
    "acceleration_rms_g": 0.002,
    "delta_p_rms_bar": 0.05,
}
HF_SHARE = 0.14                 # of each acceleration channel's total recorded power
HF_BAND_HZ = (30.0, 50.0)
SKEW = {"acceleration_samples": 2, "delta_p_samples": 1}


def specimen_modes():
    """Fixed-base modes of the specimen: complex eigenvalues (frequency, damping ratio) and
    the classical modal damping of the undamped modes, lowest first."""
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
            "damping_ratio": float(-e.real / abs(e)),
            "undamped_frequency_hz": float(w[n] / (2 * math.pi)),
            "classical_damping_ratio": float((phi[:, n] @ c @ phi[:, n]) / (2 * w[n] * mn)),
            "shape_top_normalised": [float(x) for x in shape],
        })
    w0, w1 = w
    n0, n1 = (phi[:, i] / math.sqrt(phi[:, i] @ m @ phi[:, i]) for i in range(2))
    coupling = (n0 @ c @ n1) / (2 * math.sqrt(w0 * w1))
    return out, float(coupling)


def oil_column_hz(mass):
    """(1/2pi) sqrt(n beta (A_a^2/V_a0 + A_b^2/V_b0) / M) at mid-stroke."""
    k = P["actuator_count"] * P["bulk_modulus_pa"] * (
        P["cap_area_m2"] ** 2 / P["cap_volume_m3"] + P["rod_area_m2"] ** 2 / P["rod_volume_m3"])
    return math.sqrt(k / mass) / (2 * math.pi)


# ----------------------------------------------------------------------------------------
# The plant (copied from system_ident_records.py, adapted)
# ----------------------------------------------------------------------------------------
PS, PR = P["supply_pressure_pa"], P["return_pressure_pa"]
AA, AB = P["cap_area_m2"], P["rod_area_m2"]
VA0, VB0 = P["cap_volume_m3"], P["rod_volume_m3"]
BETA, CL = P["bulk_modulus_pa"], P["leakage_m3_s_per_pa"]
MASS, KE, CE, FMU = P["mass_kg"], P["stiffness_n_per_m"], P["viscous_n_s_per_m"], P["coulomb_n"]
WS2 = W_SPOOL * W_SPOOL
ZW2 = 2 * Z_SPOOL * W_SPOOL


def root(dp):
    """sqrt(|dp|) with its sign; linear below LIN Pa (laminar) so the slope stays finite."""
    if dp >= LIN:
        return math.sqrt(dp)
    if dp <= -LIN:
        return -math.sqrt(-dp)
    return dp / SQRT_LIN


def parts(s, d, mode):
    """Rates of the state s = [u, v, pa, pb, x, xd, z1, z1d, z2, z2d] with valve input d.

    mode: +1 / -1 slipping with the friction's sign fixed, 0 stuck (v = 0, a = 0).
    Returns (rates, platen acceleration, net force N = F_A - K u - B)."""
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
    shear = -(K1 * z1 + C1 * z1d)          # base shear B = sum m_i (a + z_i'')
    net = fa - KE * u - shear
    if mode == 0:
        a = 0.0
    else:
        a = (net - CE * v - FMU * mode) / MASS
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
    """One substep of length dt with exact stick-slip; returns (state, mode, events)."""
    left = dt
    events = 0
    for _ in range(8):
        if left <= 0:
            break
        if mode == 0:
            new = rk4(s, d, 0, left)
            _, _, n_end = parts(new, d, 0)
            if abs(n_end) <= FMU:
                return new, 0, events
            sign = 1.0 if n_end > 0 else -1.0
            th = locate(lambda f: abs(parts(rk4(s, d, 0, f * left), d, 0)[2]) - FMU)
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
        if abs(n) <= FMU:
            mode = 0
        else:
            mode = 1.0 if n > 0 else -1.0
    return s, mode, events


def substep_grid(sub):
    """Substeps of one controller period: n1 steps up to the instant tau the new drive reaches
    the spool, n2 after it, none longer than H/sub."""
    tau = P["valve_delay_s"]
    n1 = max(1, math.ceil(tau * sub / H - 1e-12))
    n2 = max(1, math.ceil((H - tau) * sub / H - 1e-12))
    return [(tau / n1, True)] * n1 + [((H - tau) / n2, False)] * n2


def derivatives(u, h):
    """Central differences, one-sided (second order) at the ends."""
    v = np.empty_like(u)
    v[1:-1] = (u[2:] - u[:-2]) / (2 * h)
    v[0] = (-3 * u[0] + 4 * u[1] - u[2]) / (2 * h)
    v[-1] = (3 * u[-1] - 4 * u[-2] + u[-3]) / (2 * h)
    return v


def sig7(x):
    """x rounded to the 7 significant digits the export writes."""
    return float(f"{x:.7g}")


def null_pressures():
    """Equal land drops (pa + pb = Ps + Pr), no net force (Aa pa = Ab pb)."""
    return (PS + PR) * AB / (AA + AB), (PS + PR) * AA / (AA + AB)


def simulate(cmd, noise_u_m, sub=SUB):
    """The closed loop on the command cmd (m, at the record times).

    noise_u_m: the feedback sensor's noise per sample (the controller reads u + noise, as
    exported to 7 significant digits in mm). Returns the true state at the sample instants,
    what the controller read and sent, and diagnostics."""
    n = len(cmd)
    vref = derivatives(cmd, H)
    kp = GAINS["displacement_gain_per_m"]
    kvf = GAINS["velocity_feedforward_s_per_m"]
    pa0, pb0 = null_pressures()
    s = [0.0, 0.0, pa0, pb0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    mode = 0
    grid = substep_grid(sub)
    keys = ("u", "v", "a", "a1", "a2", "dp", "pa", "pb", "spool", "u_meas", "volts", "drive",
            "stuck")
    out = {k: np.zeros(n) for k in keys}
    diag = {"min_pressure_pa": float("inf"), "max_abs_spool": 0.0, "saturated_samples": 0,
            "min_land_drop_pa": float("inf"), "max_orifice_rate_times_step": 0.0,
            "stick_slip_events": 0}
    hmax = max(dt for dt, _ in grid)
    d_old = 0.0
    for i in range(n):
        rates, a_now, _ = parts(s, d_old, mode)
        u, v, pa, pb, x = s[0], s[1], s[2], s[3], s[4]
        # what the controller reads: the feedback, exported in mm to 7 significant digits
        um = sig7((u + noise_u_m[i]) * 1e3) * 1e-3
        raw = kp * (cmd[i] - um) + kvf * vref[i]
        if abs(raw) >= 1.0:
            diag["saturated_samples"] += 1
        d = min(max(raw, -1.0), 1.0)
        volts = round(d * DRIVE_FULL_V / V_QUANTUM) * V_QUANTUM
        volts = min(max(volts, -DRIVE_FULL_V), DRIVE_FULL_V)
        d = volts / DRIVE_FULL_V
        for k, val in zip(keys, (u, v, a_now, a_now + rates[7], a_now + rates[9], pa - pb,
                                 pa, pb, x, um, volts, d, 1.0 if mode == 0 else 0.0)):
            out[k][i] = val
        # diagnostics at the sample: cavitation margin, land drops, the orifice's stiffness
        diag["min_pressure_pa"] = min(diag["min_pressure_pa"], pa, pb)
        diag["max_abs_spool"] = max(diag["max_abs_spool"], abs(x))
        xo = min(abs(x), 1.0)
        lands = (PS - pa, pb - PR) if x >= 0 else (pa - PR, PS - pb)
        diag["min_land_drop_pa"] = min(diag["min_land_drop_pa"], *lands)
        for land, vol in zip(lands, (VA0 + AA * u, VB0 - AB * u)):
            slope = 1.0 / SQRT_LIN if abs(land) < LIN else 0.5 / math.sqrt(abs(land))
            diag["max_orifice_rate_times_step"] = max(
                diag["max_orifice_rate_times_step"], BETA / vol * K_LAND * xo * slope * hmax)
        for dt, before in grid:
            s, mode, ev = step(s, mode, d_old if before else d, dt)
            diag["stick_slip_events"] += ev
        d_old = d
        if not all(math.isfinite(z) for z in s):
            raise SystemExit("the reference loop diverged")
    out["vref"] = vref
    return out, diag


# ----------------------------------------------------------------------------------------
# Commands
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


def white_noise_cmd(dur_s, seed, rms_m, f_lo, f_hi):
    n = int(round(dur_s * FS)) + 1
    rng = np.random.default_rng(seed)
    spec = np.fft.rfft(rng.standard_normal(n))
    f = np.fft.rfftfreq(n, H)
    spec[(f < f_lo) | (f > f_hi)] = 0.0
    u = np.fft.irfft(spec, n) * cosine_taper(n, 1.0)
    u -= np.linspace(u[0], u[-1], n)         # exactly 0 at both ends (already ~0)
    return u * rms_m / np.sqrt(np.mean(u ** 2))


def white_noise_acc_cmd(dur_s, seed, acc_rms_m_s2, f_lo, f_hi):
    """Band-limited white-noise *acceleration* (as labs run white-noise tests), integrated
    twice in the frequency domain to the displacement command, 1 s cosine tapers, scaled so
    that the command's acceleration (central second difference) has the given RMS."""
    n = int(round(dur_s * FS)) + 1
    rng = np.random.default_rng(seed)
    spec = np.fft.rfft(rng.standard_normal(n))
    f = np.fft.rfftfreq(n, H)
    spec[(f < f_lo) | (f > f_hi)] = 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        spec = np.where(f > 0, -spec / (2 * np.pi * f) ** 2, 0.0)
    u = np.fft.irfft(spec, n) * cosine_taper(n, 1.0)
    u -= np.linspace(u[0], u[-1], n)
    a = (u[2:] - 2 * u[1:-1] + u[:-2]) / H ** 2
    return u * acc_rms_m_s2 / np.sqrt(np.mean(a ** 2))


def sweep_cmd(dur_s, f0, f1, acc_m_s2, cap_m):
    """Exponential sine sweep, amplitude min(cap, acc/(2 pi f)^2), 1 s cosine tapers."""
    n = int(round(dur_s * FS)) + 1
    t = np.arange(n) / FS
    dur = t[-1]
    r = f1 / f0
    f = f0 * r ** (t / dur)
    phase = 2 * np.pi * f0 * dur / math.log(r) * (r ** (t / dur) - 1)
    amp = np.minimum(cap_m, acc_m_s2 / (2 * np.pi * f) ** 2)
    return amp * cosine_taper(n, 1.0) * np.sin(phase)


def earthquake_cmd(dur_s, seed, fg_hz, zg, peak_m, hp_hz=0.2):
    """Earthquake-like displacement: white noise through a Kanai-Tajimi filter (ground
    frequency fg, damping zg) under a strong-motion envelope (t^2 rise to 15 % of the
    duration, strong part to 45 %, exponential decay to 5 % at the end) is the acceleration;
    it is integrated twice in the frequency domain (zero-padded to 4x) with a zero-phase
    4th-order high-pass at hp_hz on the displacement (the baseline treatment), then 1 s
    cosine tapers at both ends put it at rest at 0 at the start and the end, and it is scaled
    to the peak."""
    n = int(round(dur_s * FS)) + 1
    rng = np.random.default_rng(seed)
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
    return u * peak_m / np.max(np.abs(u))


# ----------------------------------------------------------------------------------------
# The data system
# ----------------------------------------------------------------------------------------
HEADER = ["Time (s)", "Command (mm)", "Actuator displacement (mm)", "Table displacement (mm)",
          "Voltage command (V)", "Delta P (bar)", "Table acceleration (g)",
          "Storey 1 acceleration (g)", "Storey 2 acceleration (g)"]
CLEAN_HEADER = ["t_s", "u_m", "a_m_s2", "storey1_a_m_s2", "storey2_a_m_s2"]
# platen's column map for the exported files (crates/platen-io/src/columns.rs)
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


def late(x, k):
    """x recorded k samples late: row i holds x[i - k]; the first k rows repeat x[0]."""
    if k == 0:
        return x.copy()
    return np.concatenate([np.full(k, x[0]), x[:-k]])


def band_noise(n, rng, f_lo, f_hi):
    spec = np.fft.rfft(rng.standard_normal(n))
    f = np.fft.rfftfreq(n, H)
    spec[(f < f_lo) | (f > f_hi)] = 0.0
    x = np.fft.irfft(spec, n)
    return x / np.sqrt(np.mean(x ** 2))


def time_text(i):
    """t = i/204.8 = 5 i / 1024 s written exactly (at most 10 decimals)."""
    return f"{i * 5 / 1024:.10f}".rstrip("0").rstrip(".") if i else "0"


def write_csv(path, header, cols, n):
    times = [time_text(i) for i in range(n)]
    with open(path, "w", newline="\n") as fh:
        fh.write(",".join(header) + "\n")
        cells = [[f"{x + 0.0:.7g}" for x in c] for c in cols]   # + 0.0: no "-0"
        for i in range(n):
            fh.write(times[i] + "," + ",".join(c[i] for c in cells) + "\n")


def export(sim, cmd, rec_seed):
    """The exported channels (file units) from the clean state, with noise, HF, skew."""
    n = len(cmd)
    rng = np.random.default_rng([rec_seed, 7])
    table_u_mm = (sim["u"] + NOISE["displacement_rms_m"] * rng.standard_normal(n)) * 1e3
    dp_bar = (late(sim["dp"], SKEW["delta_p_samples"]) * 1e-5
              + NOISE["delta_p_rms_bar"] * rng.standard_normal(n))
    accs, hf_rms = [], []
    for ch, key in enumerate(("a", "a1", "a2")):
        clean_g = late(sim[key], SKEW["acceleration_samples"]) / G
        crng = np.random.default_rng([rec_seed, 100 + ch])
        p_clean = float(np.mean(clean_g ** 2))
        hf = band_noise(n, crng, *HF_BAND_HZ) * math.sqrt(HF_SHARE / (1 - HF_SHARE) * p_clean)
        white = NOISE["acceleration_rms_g"] * crng.standard_normal(n)
        accs.append(clean_g + hf + white)
        hf_rms.append(math.sqrt(HF_SHARE / (1 - HF_SHARE) * p_clean) * G)
    cols = [cmd * 1e3, sim["u_meas"] * 1e3, table_u_mm, sim["volts"], dp_bar] + accs
    return cols, hf_rms


# ----------------------------------------------------------------------------------------
def records():
    """name -> (command in m rounded to what the file holds, seed, what it is)."""
    recs = {
        "wn.csv": (white_noise_acc_cmd(40.0, 11, 0.05 * G, 0.5, 20.0), 11,
                   "white-noise acceleration, 0.5-20 Hz, 0.05 g RMS, 40 s, 1 s cosine "
                   "tapers, seed 11"),
        "sweep.csv": (sweep_cmd(40.0, 0.5, 20.0, 0.1 * G, 0.025), 12,
                      "exponential sine sweep 0.5-20 Hz, 0.1 g (at most 25 mm), 40 s, 1 s "
                      "cosine tapers"),
        "eq1.csv": (earthquake_cmd(35.0, 101, 2.0, 0.6, 0.040), 101,
                    "earthquake-like, Kanai-Tajimi 2.0 Hz / 0.6, 35 s, peak 40 mm, seed 101"),
        "eq2.csv": (earthquake_cmd(40.0, 202, 3.0, 0.6, 0.035), 202,
                    "earthquake-like, Kanai-Tajimi 3.0 Hz / 0.6, 40 s, peak 35 mm, seed 202"),
        "eq3.csv": (earthquake_cmd(30.0, 303, 4.0, 0.6, 0.030), 303,
                    "earthquake-like, Kanai-Tajimi 4.0 Hz / 0.6, 30 s, peak 30 mm, seed 303 "
                    "(held out)"),
        "eq4.csv": (earthquake_cmd(45.0, 404, 1.5, 0.6, 0.050), 404,
                    "earthquake-like, Kanai-Tajimi 1.5 Hz / 0.6, 45 s, peak 50 mm, seed 404 "
                    "(held out)"),
        "constant-command.csv": (np.zeros(int(round(10.0 * FS)) + 1), 505,
                                 "command held at 0 for 10 s: the table at rest, only noise "
                                 "(bad input)"),
    }
    # the command the controller gets is the one the file holds (mm, 7 significant digits)
    return {k: (np.array([sig7(x * 1e3) * 1e-3 for x in c]), s, what)
            for k, (c, s, what) in recs.items()}


def main():
    outdir = sys.argv[1] if len(sys.argv) > 1 else "tests/data/small_table"
    os.makedirs(outdir, exist_ok=True)
    t_start = time.time()
    modes, coupling = specimen_modes()
    print(f"storey stiffness {K1:.6g} N/m, dampers {C1:.6g} / {C2:.6g} N s/m")
    for m in modes:
        print("specimen mode:", m)
    print(f"oil column {oil_column_hz(MASS):.4g} Hz bare, "
          f"{oil_column_hz(MASS + M1 + M2):.4g} Hz with the specimen rigid")
    print(f"K_land {K_LAND:.6g} m^3/s/sqrt(Pa), rated flow {P['rated_flow_m3_s']:.6g} m^3/s; "
          f"substeps per sample {len(substep_grid(SUB))}: "
          f"{[round(dt * 1e6, 3) for dt, _ in substep_grid(SUB)][:3]}... us")
    summary = {}
    for name, (cmd, seed, what) in records().items():
        t0 = time.time()
        n = len(cmd)
        noise_u = NOISE["displacement_rms_m"] * np.random.default_rng([seed, 1]).standard_normal(n)
        sim, diag = simulate(cmd, noise_u)
        cols, hf_rms = export(sim, cmd, seed)
        write_csv(os.path.join(outdir, name), HEADER, cols, n)
        if name == "eq1.csv":
            m = int(round(10.0 * FS)) + 1          # rows with t <= 10 s
            keep = [c[:m] for j, c in enumerate(cols) if HEADER[j + 1] != "Voltage command (V)"]
            write_csv(os.path.join(outdir, "no-drive.csv"),
                      [h for h in HEADER if h != "Voltage command (V)"], keep, m)
        if name in ("eq3.csv", "eq4.csv"):
            write_csv(os.path.join(outdir, name.replace(".csv", "-clean.csv")), CLEAN_HEADER,
                      [sim["u"], sim["a"], sim["a1"], sim["a2"]], n)
        rms_cmd = float(np.sqrt(np.mean(cmd ** 2)))
        err = sim["u"] - cmd
        rec = {
            "what": what,
            "seed": seed,
            "samples": n,
            "duration_s": (n - 1) / FS,
            "peak_command_m": float(np.max(np.abs(cmd))),
            "rms_command_m": rms_cmd,
            "peak_command_velocity_m_s": float(np.max(np.abs(sim["vref"]))),
            "tracking_nrmse": float(np.sqrt(np.mean(err ** 2)) / rms_cmd) if rms_cmd > 0 else None,
            "rms_tracking_error_m": float(np.sqrt(np.mean(err ** 2))),
            "peak_abs_drive": float(np.max(np.abs(sim["drive"]))),
            "saturated_fraction": diag["saturated_samples"] / n,
            "stuck_fraction": float(np.mean(sim["stuck"])),
            "stick_slip_events": diag["stick_slip_events"],
            "rms_table_acceleration_m_s2": float(np.sqrt(np.mean(sim["a"] ** 2))),
            "peak_table_acceleration_m_s2": float(np.max(np.abs(sim["a"]))),
            "rms_storey1_acceleration_m_s2": float(np.sqrt(np.mean(sim["a1"] ** 2))),
            "rms_storey2_acceleration_m_s2": float(np.sqrt(np.mean(sim["a2"] ** 2))),
            "peak_storey2_acceleration_m_s2": float(np.max(np.abs(sim["a2"]))),
            "peak_table_velocity_m_s": float(np.max(np.abs(sim["v"]))),
            "peak_abs_delta_p_pa": float(np.max(np.abs(sim["dp"]))),
            "hf_rms_m_s2": dict(zip(("table", "storey1", "storey2"), hf_rms)),
            "min_chamber_pressure_pa": diag["min_pressure_pa"],
            "min_land_drop_pa": diag["min_land_drop_pa"],
            "peak_abs_spool": diag["max_abs_spool"],
            "max_orifice_rate_times_step": diag["max_orifice_rate_times_step"],
        }
        summary[name] = rec
        print(name, json.dumps({k: v for k, v in rec.items() if k != "what"}),
              f"({time.time() - t0:.1f} s)", flush=True)

    pa0, pb0 = null_pressures()
    beta = P["bulk_modulus_pa"]
    truth = {
        "made_by": "tools/reference/small_table_records.py (numpy only, no platen code)",
        "regenerate": "python3 tools/reference/small_table_records.py tests/data/small_table",
        "numpy_version": np.__version__,
        "integration": {
            "method": "RK4, fixed step, each controller period cut at the valve delay",
            "substeps_per_sample": len(substep_grid(SUB)),
            "substeps_s": [dt for dt, _ in substep_grid(SUB)],
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
            "rated_flow_l_min": P["rated_flow_m3_s"] * 60e3,
            "land_coefficient_m3_s_per_sqrt_pa": K_LAND,
            "no_load_velocity_full_drive_m_s": P["no_load_velocity_full_drive_m_s"],
            "flow_gain_m_s_per_v": P["no_load_velocity_full_drive_m_s"] / DRIVE_FULL_V,
            "laminar_below_pa": LIN,
            "natural_frequency_hz": P["spool_natural_frequency_hz"],
            "damping_ratio": Z_SPOOL,
            "delay_s": P["valve_delay_s"],
            "critically_centred": True,
        },
        "oil_bulk_modulus_pa": beta,
        "supply_pressure_pa": PS,
        "return_pressure_pa": PR,
        "null_pressures_pa": [pa0, pb0],
        "force_capacity_n": AA * (PS - PR),
        "platen": {"mass_kg": MASS, "stiffness_n_per_m": KE, "viscous_n_s_per_m": CE,
                   "coulomb_n": FMU, "static_friction_n": FMU,
                   "identified_equivalent": {"effective_mass_kg": MASS,
                                             "stiffness_n_per_m": KE,
                                             "coulomb_force_n": FMU,
                                             "viscous_coefficient": CE,
                                             "viscous_exponent": 1.0,
                                             "low_velocity_force_n": 0.0,
                                             "low_velocity_decay_s_per_m": 0.0}},
        "specimen": {"storeys": SPECIMEN, "modes": modes,
                     "modal_damping_coupling_off_diagonal": coupling,
                     "design": "equal storey stiffness for a 6.5 Hz first fixed-base mode; "
                               "storey dampers with both classical modal damping ratios "
                               "phi_n^T C phi_n / (2 w_n m_n) = 0.02 (C of storey-damper "
                               "form is not exactly classical; the complex modes' ratios are "
                               "listed as damping_ratio)"},
        "controller": dict(GAINS, **{
            "law": "d = K_p (u_ref - u_meas) + K_vf v_ref, saturated at +-1, zero-order hold",
            "v_ref": "central difference of the command, one-sided second order at the ends",
            "u_meas": "the exported 'Actuator displacement (mm)' (true + noise), as read",
            "drive_output": "10 V x d quantised to 20 V/65536 (the drive the valve gets is "
                            "the quantised one, exported as 'Voltage command (V)')",
            "timing": "sample i reads the state at t_i and sends d_i, which reaches the spool "
                      "at t_i + delay and is held until t_(i+1) + delay; d = 0 before the "
                      "first",
        }),
        "initial_state": "at rest at u = 0, spool centred, null pressures, specimen at rest",
        "oil_column_frequency_hz": oil_column_hz(MASS),
        "oil_column_frequency_with_specimen_hz": oil_column_hz(MASS + M1 + M2),
        "ratios_to_actuator_area": {
            "area_m2": AREA,
            "mass_kg_per_m2": MASS / AREA,
            "stiffness_n_per_m_per_m2": KE / AREA,
            "viscous_n_s_per_m_per_m2": CE / AREA,
            "coulomb_n_per_m2": FMU / AREA,
            "storey_masses_kg_per_m2": [M1 / AREA, M2 / AREA],
            "storey_stiffness_n_per_m_per_m2": [K1 / AREA, K2 / AREA],
            "storey_dampers_n_s_per_m_per_m2": [C1 / AREA, C2 / AREA],
            "land_coefficient_per_m2": K_LAND / AREA,
            "leakage_per_m2": CL / AREA,
            "cap_volume_over_beta_area_m_per_pa": VA0 / (beta * AREA),
            "rod_volume_over_beta_area_m_per_pa": VB0 / (beta * AREA),
        },
        "record": {
            "rate_hz": FS,
            "times": "t = i/204.8 s exactly",
            "float_format": "7 significant digits (time exact)",
            "columns": HEADER,
        },
        "noise": dict(NOISE, **{"displacement_rms_mm": NOISE["displacement_rms_m"] * 1e3,
                                "acceleration_rms_m_s2": NOISE["acceleration_rms_g"] * G,
                                "delta_p_rms_pa": NOISE["delta_p_rms_bar"] * 1e5,
                                "drive_quantum_v": V_QUANTUM,
                                "white": "independent per channel and record; actuator and "
                                         "table displacements have independent noise"}),
        "high_frequency_content": {
            "channels": ["Table acceleration (g)", "Storey 1 acceleration (g)",
                         "Storey 2 acceleration (g)"],
            "band_hz": list(HF_BAND_HZ),
            "share_of_total_power": HF_SHARE,
            "power_relative_to_clean": HF_SHARE / (1 - HF_SHARE),
            "definition": "Gaussian, FFT band-limited; its mean square is 0.14/0.86 of the "
                          "clean (skewed) channel's mean square over the record, so it is 14 % "
                          "of clean + HF (the white sensor noise comes on top); independent per "
                          "channel and record",
        },
        "skew": {
            "acceleration_samples": SKEW["acceleration_samples"],
            "acceleration_s": SKEW["acceleration_samples"] / FS,
            "delta_p_samples": SKEW["delta_p_samples"],
            "delta_p_s": SKEW["delta_p_samples"] / FS,
            "on_time": ["Command (mm)", "Actuator displacement (mm)",
                        "Table displacement (mm)", "Voltage command (V)"],
            "definition": "row i holds the true value at row i - k; the first k rows repeat "
                          "the value at row 0; noise and HF content are added after the skew",
        },
        "training": ["wn.csv", "sweep.csv", "eq1.csv", "eq2.csv"],
        "held_out": ["eq3.csv", "eq4.csv"],
        "bad_inputs": {"no-drive.csv": "the rows t <= 10 s (2049) of eq1.csv without "
                                       "'Voltage command (V)'",
                       "constant-command.csv": "command held at 0 for 10 s"},
        "clean": {"eq3-clean.csv": "true, noise-free, un-skewed state of eq3.csv (SI)",
                  "eq4-clean.csv": "true, noise-free, un-skewed state of eq4.csv (SI)"},
        "records": summary,
    }
    with open(os.path.join(outdir, "truth.json"), "w") as fh:
        json.dump(truth, fh, indent=2)
        fh.write("\n")
    with open(os.path.join(outdir, "columns.json"), "w") as fh:
        fh.write("{\n" + ",\n".join(f"  {json.dumps(k)}: {json.dumps(v)}"
                                     for k, v in COLUMN_MAP.items()) + "\n}\n")
    print(f"total {time.time() - t_start:.1f} s")


if __name__ == "__main__":
    main()
