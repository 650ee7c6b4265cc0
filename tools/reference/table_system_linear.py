#!/usr/bin/env python3
"""Independent NumPy reference: small-signal closed-loop FRF of a servo-hydraulic shake table.

Written from the equations below (not from any platen code). Reads
tests/data/reference/table_system_linear_params.json and writes
tests/data/reference/table_system_frf.csv.

Nonlinear model (SI units, pressures absolute):
  platen    M a = n (Aa pa - Ab pb) - Ke u - C v
  chambers  pa' = beta/Va ( Qa - Aa v - CL (pa - pb))
            pb' = beta/Vb (-Qb + Ab v + CL (pa - pb))            (Va, Vb at u = 0, constant)
  valve     critically centred 4-way, orifice law per land, K = m Qr / sqrt(dpr/2)
            xv > 0: Qa = K xv sqrt(Ps - pa), Qb = K xv sqrt(pb - PR)
            xv < 0: Qa = K xv sqrt(pa - PR), Qb = K xv sqrt(Ps - pb)
  spool     xv'' = wv^2 (w - xv) - 2 zv wv xv',  w(t) = drive after ZOH and pure delay tau
  control   d = Kp (r - u) + Kvf r' + Kaf r'' - Kvb v - Kab a - Kdp HP(pa - pb),
            HP(s) = s / (s + 2 pi f_hp);  W(jw) = ZOH(jw) exp(-jw tau) D(jw),
            ZOH(jw) = (1 - exp(-jw T)) / (jw T),  T = 1/fc

Linearisation: u = v = xv = 0, pa0 + pb0 = Ps + PR, Aa pa0 = Ab pb0, flows at xv = 0+:
  Qa = Kqa xv, Qb = Kqb xv, Kqa = K sqrt(Ps - pa0), Kqb = K sqrt(pb0 - PR)
  (flow-pressure coefficients are zero at xv = 0 for a critically centred valve; the leakage
  CL is kept).  The reference parameter set is a double-ended (symmetric) actuator, Aa = Ab and
  Va = Vb: then pa0 = pb0 = (Ps + PR)/2, the gains at xv = 0+ and 0- are the same (the
  linearisation holds on both sides of the null, which a small sine crosses every half cycle)
  and the null point is an exact equilibrium (no cross-port leakage flow at rest).

Plant state x = [u, v, dpa, dpb] (perturbations), input xv.

Usage (from the repository root, needs only numpy):
    python3 tools/reference/table_system_linear.py            # FRF csv + poles/margins
    python3 tools/reference/table_system_linear.py --check    # also the time-domain cross-check
    python3 tools/reference/table_system_linear.py --nonlinear  # nonlinear equations, small sines
    python3 tools/reference/table_system_linear.py --params P.json --out F.csv
"""

import argparse
import csv
import json
import math
import os

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REF_DIR = os.path.join(HERE, "..", "..", "tests", "data", "reference")
DEFAULT_PARAMS = os.path.join(REF_DIR, "table_system_linear_params.json")
DEFAULT_OUT = os.path.join(REF_DIR, "table_system_frf.csv")
FREQS_HZ = [0.5, 1.0, 2.0, 3.0, 5.0, 7.0, 10.0, 12.0, 15.0, 20.0, 25.0]


# --------------------------------------------------------------------------------------------
# Parameters and the linear plant
# --------------------------------------------------------------------------------------------
class Model:
    def __init__(self, params, side=+1):
        self.params = params
        mech = params["mechanics"]
        ts = params["table_system"]
        act, sv, ctl = ts["actuator"], ts["servo_valve"], ts["controller"]
        self.M = float(mech["mass_kg"])
        self.Ke = float(mech["stiffness_n_per_m"])
        self.C = float(mech["viscous_n_s_per_m"])
        self.n = float(act["count"])
        self.Aa = float(act["cap_side_area_m2"])
        self.Ab = float(act["rod_side_area_m2"])
        self.Va, self.Vb = (float(x) for x in act["chamber_volume_m3"])
        self.CL = float(act["leakage_m3_s_per_pa"])
        self.m = float(sv["count"])
        self.Qr = float(sv["rated_flow_m3_s"])
        self.dpr = float(sv["rated_pressure_drop_pa"])
        self.wv = 2.0 * math.pi * float(sv["natural_frequency_hz"])
        self.zv = float(sv["damping_ratio"])
        self.tau = float(sv["delay_s"])
        self.beta = float(ts["oil_bulk_modulus_pa"])
        self.Ps = float(ts["supply_pressure_pa"])
        self.PR = float(ts["return_pressure_pa"])
        self.fc = float(ctl["sample_rate_hz"])
        self.T = 1.0 / self.fc
        self.Kp = float(ctl["displacement_gain_per_m"])
        self.Kvf = float(ctl["velocity_feedforward_s_per_m"])
        self.Kaf = float(ctl["acceleration_feedforward_s2_per_m"])
        self.Kvb = float(ctl["velocity_feedback_s_per_m"])
        self.Kab = float(ctl["acceleration_feedback_s2_per_m"])
        self.Kdp = float(ctl["delta_p_gain_per_pa"])
        self.whp = 2.0 * math.pi * float(ctl["delta_p_highpass_hz"])

        # valve: per-land coefficient, rated flow at dpr/2 per land
        self.K = self.m * self.Qr / math.sqrt(self.dpr / 2.0)
        # null pressures
        self.pa0 = self.Ab * (self.Ps + self.PR) / (self.Aa + self.Ab)
        self.pb0 = self.Aa * (self.Ps + self.PR) / (self.Aa + self.Ab)
        self.side = side
        if side > 0:   # x_v = 0+ (the reference): supply -> A, B -> return
            self.Kqa = self.K * math.sqrt(self.Ps - self.pa0)
            self.Kqb = self.K * math.sqrt(self.pb0 - self.PR)
        else:          # x_v = 0- (only for comparison): A -> return, supply -> B
            self.Kqa = self.K * math.sqrt(self.pa0 - self.PR)
            self.Kqb = self.K * math.sqrt(self.Ps - self.pb0)

        M, n, b = self.M, self.n, self.beta
        Aa, Ab, Va, Vb, CL = self.Aa, self.Ab, self.Va, self.Vb, self.CL
        # plant x = [u, v, dpa, dpb], input xv
        self.Ap = np.array([
            [0.0, 1.0, 0.0, 0.0],
            [-self.Ke / M, -self.C / M, n * Aa / M, -n * Ab / M],
            [0.0, -b / Va * Aa, -b / Va * CL, b / Va * CL],
            [0.0, b / Vb * Ab, b / Vb * CL, -b / Vb * CL],
        ])
        self.Bp = np.array([0.0, 0.0, b / Va * self.Kqa, -b / Vb * self.Kqb])

    # --- closed forms -------------------------------------------------------------------------
    def oil_column_hz(self):
        k_h = self.n * self.beta * (self.Aa ** 2 / self.Va + self.Ab ** 2 / self.Vb)
        return math.sqrt(k_h / self.M) / (2.0 * math.pi)

    def velocity_gains(self):
        """Candidate 'no-load velocity per unit opening' values (m/s per unit xv)."""
        Aa, Ab, Va, Vb = self.Aa, self.Ab, self.Va, self.Vb
        # linear model, loop open, CL -> 0: constant v needs constant force, so
        # Aa dpa' = Ab dpb'; with the two chamber equations this gives
        lin = (Aa * self.Kqa / Va + Ab * self.Kqb / Vb) / (Aa ** 2 / Va + Ab ** 2 / Vb)
        # nonlinear steady no-load motion (pressures leave the null values)
        ext = self.K * math.sqrt((Aa * self.Ps - Ab * self.PR) / (Aa ** 3 + Ab ** 3))
        ret = self.K * math.sqrt((Ab * self.Ps - Aa * self.PR) / (Aa ** 3 + Ab ** 3))
        return dict(linear_null=lin, cap_side=self.Kqa / Aa, rod_side=self.Kqb / Ab,
                    nonlinear_extend=ext, nonlinear_retract=ret)

    # --- the nonlinear plant, for checking the linearisation -----------------------------------
    def nonlinear_rhs(self, x, xv):
        """d/dt [u, v, pa, pb] of the nonlinear equations (absolute pressures)."""
        u, v, pa, pb = x
        K = self.K
        if xv >= 0.0:
            Qa = K * xv * math.sqrt(max(self.Ps - pa, 0.0))
            Qb = K * xv * math.sqrt(max(pb - self.PR, 0.0))
        else:
            Qa = K * xv * math.sqrt(max(pa - self.PR, 0.0))
            Qb = K * xv * math.sqrt(max(self.Ps - pb, 0.0))
        leak = self.CL * (pa - pb)
        a = (self.n * (self.Aa * pa - self.Ab * pb) - self.Ke * u - self.C * v) / self.M
        return np.array([v, a,
                         self.beta / self.Va * (Qa - self.Aa * v - leak),
                         self.beta / self.Vb * (-Qb + self.Ab * v + leak)])

    def check_linearisation(self):
        """Max relative deviation of (Ap, Bp) from finite differences of nonlinear_rhs."""
        x0 = np.array([0.0, 0.0, self.pa0, self.pb0])
        steps = np.array([1e-6, 1e-6, 10.0, 10.0])
        J = np.zeros((4, 4))
        for j in range(4):
            e = np.zeros(4)
            e[j] = steps[j]
            J[:, j] = (self.nonlinear_rhs(x0 + e, 0.0) - self.nonlinear_rhs(x0 - e, 0.0)) / (2 * steps[j])
        dx = 1e-9 * self.side
        Bfd = (self.nonlinear_rhs(x0, dx) - self.nonlinear_rhs(x0, 0.0)) / dx
        scale = np.maximum(np.abs(self.Ap), 1e-300)
        errA = np.max(np.where(self.Ap != 0, np.abs(J - self.Ap) / scale, np.abs(J)))
        errB = np.max(np.abs(Bfd - self.Bp) / np.maximum(np.abs(self.Bp), 1e-300))
        return errA, errB, self.nonlinear_rhs(x0, 0.0)

    # --- frequency responses of the blocks ----------------------------------------------------
    def plant(self, s):
        """(U, A, dP) per unit xv at complex frequency s."""
        x = np.linalg.solve(s * np.eye(4) - self.Ap, self.Bp.astype(complex))
        u = x[0]
        return u, s * s * u, x[2] - x[3]

    def zoh(self, s):
        return (1.0 - np.exp(-s * self.T)) / (s * self.T)

    def spool(self, s):
        return self.wv ** 2 / (s * s + 2.0 * self.zv * self.wv * s + self.wv ** 2)

    def hp(self, s):
        return s / (s + self.whp)

    def valve_path(self, s):
        """xv per unit controller output d (ZOH, delay, spool)."""
        return self.zoh(s) * np.exp(-s * self.tau) * self.spool(s)

    def loop(self, s):
        """Loop transfer, broken at the controller output d (negative feedback: 1 + L)."""
        Gu, Ga, Gdp = self.plant(s)
        fb = (self.Kp + self.Kvb * s) * Gu + self.Kab * Ga + self.Kdp * self.hp(s) * Gdp
        return self.valve_path(s) * fb

    def closed_loop(self, s):
        """H_u = U/R, H_a = A/R by block algebra."""
        Gu, Ga, Gdp = self.plant(s)
        P = self.valve_path(s)
        L = self.loop(s)
        ff = self.Kp + self.Kvf * s + self.Kaf * s * s
        Hu = Gu * P * ff / (1.0 + L)
        return Hu, s * s * Hu


# --------------------------------------------------------------------------------------------
# Rational (Pade) closed-loop state space: poles and a second FRF evaluation
# --------------------------------------------------------------------------------------------
def pade_coeffs(order):
    """Coefficients c_k (ascending) with exp(-x) ~ sum c_k (-x)^k / sum c_k x^k."""
    n = order
    return [math.factorial(2 * n - k) * math.factorial(n)
            / (math.factorial(2 * n) * math.factorial(k) * math.factorial(n - k))
            for k in range(n + 1)]


def tf2ss(num, den, theta):
    """Controllable canonical realisation of num(x)/den(x), x = s*theta (ascending coeffs)."""
    num = np.array(num, float)
    den = np.array(den, float)
    num = num / den[-1]
    den = den / den[-1]
    nd = len(den) - 1
    num = np.concatenate([num, np.zeros(nd + 1 - len(num))])
    D = num[nd]
    b = num[:nd] - D * den[:nd]
    A = np.zeros((nd, nd))
    A[:-1, 1:] = np.eye(nd - 1)
    A[-1, :] = -den[:nd]
    B = np.zeros(nd)
    B[-1] = 1.0
    return A / theta, B / theta, b.copy(), D


def delay_ss(theta, order):
    c = pade_coeffs(order)
    den = c
    num = [ck * (-1) ** k for k, ck in enumerate(c)]
    return tf2ss(num, den, theta)


def zoh_ss(T, order):
    # (1 - exp(-x)) / x with exp(-x) ~ N(x)/D(x): (D - N) / (x D)
    c = pade_coeffs(order)
    den = np.array(c)
    num = np.array([ck * (-1) ** k for k, ck in enumerate(c)])
    dn = den - num
    assert abs(dn[0]) < 1e-15
    return tf2ss(dn[1:], den, T)          # (D - N)/x over D


def closed_loop_ss(md, order):
    """Closed loop with Pade(order) for exp(-s tau) and for exp(-sT) inside the ZOH.

    States: plant(4), spool (xv, xv'), HP filter z, ZOH states, delay states.
    Inputs: [r, r', r''].  Outputs: u, a.
    """
    Az, Bz, Cz, Dz = zoh_ss(md.T, order)
    Ad, Bd, Cd, Dd = delay_ss(md.tau, order)
    nz, nd = len(Bz), len(Bd)
    N = 4 + 2 + 1 + nz + nd
    ip, iv, ih, iz, idl = 0, 4, 6, 7, 7 + nz
    # controller output d = cd . X + dr . [r, r', r'']
    cd = np.zeros(N)
    cd[ip + 0] -= md.Kp
    cd[ip + 1] -= md.Kvb
    cd[ip:ip + 4] -= md.Kab * md.Ap[1, :]                 # a = Ap[1] x (Bp[1] = 0)
    dp_row = np.zeros(N)
    dp_row[ip + 2], dp_row[ip + 3] = 1.0, -1.0
    hp_out = dp_row.copy()
    hp_out[ih] -= md.whp                                   # HP = dp - whp z,  z' = -whp z + dp
    cd -= md.Kdp * hp_out
    dr = np.array([md.Kp, md.Kvf, md.Kaf])
    # ZOH output dz = Cz xz + Dz d; delay output w = Cd xd + Dd dz
    dz_row = np.zeros(N)
    dz_row[iz:iz + nz] = Cz
    dz_row += Dz * cd
    dz_r = Dz * dr
    w_row = np.zeros(N)
    w_row[idl:idl + nd] = Cd
    w_row += Dd * dz_row
    w_r = Dd * dz_r

    A = np.zeros((N, N))
    B = np.zeros((N, 3))
    A[ip:ip + 4, ip:ip + 4] = md.Ap
    A[ip:ip + 4, iv] = md.Bp
    A[iv, iv + 1] = 1.0
    A[iv + 1, iv] = -md.wv ** 2
    A[iv + 1, iv + 1] = -2.0 * md.zv * md.wv
    A[iv + 1, :] += md.wv ** 2 * w_row
    B[iv + 1, :] += md.wv ** 2 * w_r
    A[ih, :] += dp_row
    A[ih, ih] -= md.whp
    A[iz:iz + nz, iz:iz + nz] += Az
    A[iz:iz + nz, :] += np.outer(Bz, cd)
    B[iz:iz + nz, :] += np.outer(Bz, dr)
    A[idl:idl + nd, idl:idl + nd] += Ad
    A[idl:idl + nd, :] += np.outer(Bd, dz_row)
    B[idl:idl + nd, :] += np.outer(Bd, dz_r)
    Cu = np.zeros(N)
    Cu[ip] = 1.0
    Ca = np.zeros(N)
    Ca[ip:ip + 4] = md.Ap[1, :]
    return A, B, Cu, Ca


def ss_frf(A, B, Cu, Ca, f):
    s = 2j * math.pi * f
    x = np.linalg.solve(s * np.eye(len(A)) - A, B.astype(complex) @ np.array([1.0, s, s * s]))
    return Cu @ x, Ca @ x


# --------------------------------------------------------------------------------------------
# Margins (exact ZOH and delay)
# --------------------------------------------------------------------------------------------
def _bisect(fun, a, b, iters=80):
    fa = fun(a)
    for _ in range(iters):
        c = math.sqrt(a * b)
        fcv = fun(c)
        if (fcv > 0) == (fa > 0):
            a, fa = c, fcv
        else:
            b = c
    return math.sqrt(a * b)


def margins(md, fmin=1e-3, fmax=None, npts=40001):
    fmax = fmax or 0.45 * md.fc
    fs = np.logspace(math.log10(fmin), math.log10(fmax), npts)
    L = np.array([md.loop(2j * math.pi * f) for f in fs])
    mag = np.abs(L)
    ph = np.unwrap(np.angle(L)) * 180.0 / math.pi

    def phase_at(f):
        # unwrapped phase at f, continued from the nearest grid point
        i = int(np.clip(np.searchsorted(fs, f), 1, len(fs) - 1))
        p = np.angle(md.loop(2j * math.pi * f)) * 180.0 / math.pi
        return p + 360.0 * round((ph[i] - p) / 360.0)

    gcs = []
    for i in np.where(np.diff(np.sign(mag - 1.0)) != 0)[0]:
        f = _bisect(lambda x: abs(md.loop(2j * math.pi * x)) - 1.0, fs[i], fs[i + 1])
        p = phase_at(f)
        wrapped = (p + 180.0) % 360.0 - 180.0         # in [-180, 180)
        lag_margin = (p + 180.0) % 360.0              # extra phase lag that reaches -1
        gcs.append(dict(f=f, phase=p, distance=180.0 - abs(wrapped), lag_margin=lag_margin,
                        delay_margin=lag_margin / 360.0 / f))
    pcs = []
    k = np.floor((ph + 180.0) / 360.0)
    for i in np.where(np.diff(k) != 0)[0]:
        target = -180.0 + 360.0 * max(k[i], k[i + 1])
        f = _bisect(lambda x: phase_at(x) - target, fs[i], fs[i + 1])
        g = abs(md.loop(2j * math.pi * f))
        pcs.append(dict(f=f, phase=target, mag_db=20.0 * math.log10(g)))
    ret = 1.0 + L
    i = int(np.argmin(np.abs(ret)))
    # Nyquist: winding of 1 + L around 0 along the imaginary axis; L(-jw) = conj(L(jw)),
    # L(j inf) -> 0, so the (0, inf) part counts twice.  Poles of L at s = 0 (n0 of them,
    # L ~ k / s^n0; the displacement integrator when Ke = 0 and the plant is type 1) are
    # passed on a small half circle to their right, along which the phase of L changes by
    # -n0 * 180 deg.
    f0 = np.concatenate([[1e-9], fs, [1e5]])
    r0 = 1.0 + np.array([md.loop(2j * math.pi * f) for f in f0])
    n0 = max(0, int(round(math.log10(abs(md.loop(2j * math.pi * 1e-9))
                                     / abs(md.loop(2j * math.pi * 1e-8))))))
    wind = (2.0 * (np.unwrap(np.angle(r0))[-1] - np.angle(r0[0])) / (2.0 * math.pi)
            - 0.5 * n0)
    return dict(gain_crossovers=gcs, phase_crossovers=pcs, min_return=abs(ret[i]),
                min_return_f=fs[i], nyquist_winding_ccw=wind, loop_poles_at_zero=n0)


def open_loop_rhp_poles(md, order=6):
    """Open-loop poles of the Pade loop (plant, spool, HP, ZOH, delay) in Re s > 0."""
    poles = list(np.linalg.eigvals(md.Ap)) + list(np.roots([1.0, 2 * md.zv * md.wv, md.wv ** 2]))
    poles += [-md.whp]
    poles += list(np.linalg.eigvals(zoh_ss(md.T, order)[0]))
    poles += list(np.linalg.eigvals(delay_ss(md.tau, order)[0]))
    return [p for p in poles if p.real > 1e-9]


# --------------------------------------------------------------------------------------------
# Time-domain cross-check of the LINEAR model (delay-differential equation)
# --------------------------------------------------------------------------------------------
def expm(A):
    """Matrix exponential: scaling and squaring with a 24-term Taylor series."""
    nrm = np.linalg.norm(A, 1)
    s = max(0, int(math.ceil(math.log2(nrm / 0.25))) if nrm > 0 else 0)
    X = A / 2.0 ** s
    E = np.eye(len(A))
    term = np.eye(len(A))
    for k in range(1, 25):
        term = term @ X / k
        E = E + term
    for _ in range(s):
        E = E @ E
    return E


def simulate_sine(md, f, amp=1e-3, duration=None, fit_cycles=None):
    """Simulate the linear closed loop under r = amp sin(2 pi f t) and fit sines to u and a.

    The drive reaching the spool is w(t) = (1/T) int_{t-tau-T}^{t-tau} d(s) ds, which is the
    time-domain operator whose transfer function is ZOH(s) exp(-s tau).  A state I with
    I' = d is carried; w(t) = (I(t - tau) - I(t - tau - T)) / T.  The time step h divides both
    tau and T, so the delayed values sit on the grid.  Between grid points the linear system is
    advanced exactly (matrix exponential) with w first-order-hold (linear) inside the step; r is
    generated exactly by an oscillator state.  Pressures are carried in MPa for conditioning.
    """
    # common grid: h = T / q with tau / h integer
    q = None
    for cand in range(1, 4001):
        x = md.tau * md.fc * cand
        if abs(x - round(x)) < 1e-9 and round(x) >= 1:
            q = cand
            break
    if q is None:
        raise RuntimeError("no common grid for tau and T")
    while md.T / q > 1e-5:  # keep h small against the spool and the Pade-free delay grid
        q *= 2
    h = md.T / q
    n_tau = int(round(md.tau / h))
    n_T = q
    w = 2.0 * math.pi * f
    ps = 1e6  # pressure scale (MPa)

    # state: u, v, pa[MPa], pb[MPa], xv, xv', z[MPa], I, sr, cr   (r = amp sr, sr = sin wt)
    N = 10
    A = np.zeros((N, N))
    Bw = np.zeros(N)
    Ap = md.Ap.copy()
    A[0, 1] = 1.0
    A[1, 0], A[1, 1] = Ap[1, 0], Ap[1, 1]
    A[1, 2], A[1, 3] = Ap[1, 2] * ps, Ap[1, 3] * ps
    for i in (2, 3):
        A[i, 1] = Ap[i, 1] / ps
        A[i, 2], A[i, 3] = Ap[i, 2], Ap[i, 3]
        A[i, 4] = md.Bp[i] / ps
    A[4, 5] = 1.0
    A[5, 4] = -md.wv ** 2
    A[5, 5] = -2.0 * md.zv * md.wv
    Bw[5] = md.wv ** 2
    A[6, 2], A[6, 3], A[6, 6] = 1.0, -1.0, -md.whp
    # I' = d
    arow = A[1, :].copy()  # a = arow . x
    d = np.zeros(N)
    d[0] -= md.Kp
    d[1] -= md.Kvb
    d -= md.Kab * arow
    hp = np.zeros(N)
    hp[2], hp[3], hp[6] = ps, -ps, -md.whp * ps
    d -= md.Kdp * hp
    d[8] += amp * (md.Kp - md.Kaf * w * w)     # r = amp sr, r'' = -amp w^2 sr
    d[9] += amp * md.Kvf * w                   # r' = amp w cr
    A[7, :] = d
    A[8, 9], A[9, 8] = w, -w

    # exact step with FOH on w: expm of [[A h, Bw h, 0], [0, 0, 1], [0, 0, 0]]
    Mx = np.zeros((N + 2, N + 2))
    Mx[:N, :N] = A * h
    Mx[:N, N] = Bw * h
    Mx[N, N + 1] = 1.0
    E = expm(Mx)
    Phi = E[:N, :N]
    G1 = E[:N, N + 1]
    G0 = E[:N, N] - G1

    if duration is None:
        duration = max(6.0, 30.0 / f)
    nblk = int(math.ceil(duration / (n_tau * h)))
    nsteps = nblk * n_tau
    # block propagation: within n_tau steps every w is already known
    P = np.empty((n_tau + 1, N, N))
    P[0] = np.eye(N)
    for j in range(1, n_tau + 1):
        P[j] = Phi @ P[j - 1]
    H0 = np.array([P[m] @ G0 for m in range(n_tau)])  # (n_tau, N)
    H1 = np.array([P[m] @ G1 for m in range(n_tau)])
    jj = np.arange(n_tau)[:, None]
    mm = np.arange(n_tau)[None, :]
    mask = mm <= jj
    idx0 = np.where(mask, jj - mm, 0)       # w_{k + j - m}, for X[j+1] (j = 0..n_tau-1)
    idx1 = np.where(mask, jj - mm + 1, 0)
    Pstack = P[1:]                          # (n_tau, N, N)

    I_hist = np.zeros(nsteps + 1 + n_tau + n_T)  # offset so negative times read 0
    off = n_tau + n_T
    u_out = np.empty(nsteps + 1)
    a_out = np.empty(nsteps + 1)
    x = np.zeros(N)
    x[9] = 1.0  # cr(0) = 1, sr(0) = 0
    u_out[0] = x[0]
    a_out[0] = arow @ x
    for b in range(nblk):
        k = b * n_tau
        # w_{k..k+n_tau}
        jidx = np.arange(k, k + n_tau + 1)
        wblk = (I_hist[off + jidx - n_tau] - I_hist[off + jidx - n_tau - n_T]) / md.T
        W0 = np.where(mask, wblk[idx0], 0.0)
        W1 = np.where(mask, wblk[idx1], 0.0)
        X = Pstack @ x + W0 @ H0 + W1 @ H1   # states at k+1 .. k+n_tau
        I_hist[off + k + 1: off + k + n_tau + 1] = X[:, 7]
        u_out[k + 1: k + n_tau + 1] = X[:, 0]
        a_out[k + 1: k + n_tau + 1] = X @ arow
        x = X[-1]
    t = np.arange(nsteps + 1) * h
    if fit_cycles is None:
        fit_cycles = max(4, int(round(2.0 * f)))
    t0 = t[-1] - fit_cycles / f
    sel = t >= t0 - 1e-12
    res = {}
    for name, y in (("u", u_out), ("a", a_out)):
        G = np.column_stack([np.sin(w * t[sel]), np.cos(w * t[sel]), np.ones(sel.sum())])
        coef, *_ = np.linalg.lstsq(G, y[sel], rcond=None)
        resid = y[sel] - G @ coef
        res[name] = (complex(coef[0], coef[1]) / amp,   # y = Im(H amp e^{jwt}) = amp(Hr sin + Hi cos)
                     float(np.sqrt(np.mean(resid ** 2)) / (np.abs(complex(coef[0], coef[1])))))
    return res, h


# --------------------------------------------------------------------------------------------
# Time-domain run of the NONLINEAR equations (informative: how close a small sine gets)
# --------------------------------------------------------------------------------------------
def simulate_nonlinear_sines(md, freqs, amps, q=8, settle=4.0):
    """Nonlinear closed loop (orifice law, both valve sides) under r = amp sin(2 pi f t).

    One batch over all (f, amp) pairs; fixed-step RK4 with h = T/q.  The drive is the same
    operator as in the linear check, w(t) = (I(t - tau) - I(t - tau - T)) / T with I' = d, the
    past I read by cubic Lagrange interpolation on the step grid (the delayed points lie at
    least tau - h in the past, so the history is complete).  Start at rest at the null point;
    the last max(4, round(2 f)) cycles after `settle` seconds are fitted with the fundamental,
    2nd and 3rd harmonics and a constant.  Returns {(f, amp): (H_u, H_a, thd_u)}.
    """
    pairs = [(f, a) for f in freqs for a in amps]
    nb = len(pairs)
    fv = np.array([p[0] for p in pairs])
    av = np.array([p[1] for p in pairs])
    wv_ = 2.0 * math.pi * fv
    h = md.T / q
    cyc = np.maximum(4, np.round(2.0 * fv))
    t_end = settle + np.max(cyc / fv)
    nsteps = int(math.ceil(t_end / h))
    K, Ps, PR = md.K, md.Ps, md.PR

    # interpolation of I at (k + c) h - lag for the stage offsets c = 0, 1/2, 1
    def stencil(c, lag):
        x = c - lag / h                       # position relative to step k, in steps
        i0 = int(math.floor(x)) - 1           # points i0 .. i0 + 3
        nodes = np.arange(i0, i0 + 4, dtype=float)
        wts = np.array([np.prod([(x - nodes[m]) / (nodes[j] - nodes[m])
                                 for m in range(4) if m != j]) for j in range(4)])
        assert i0 + 3 <= 0, "delay shorter than the interpolation stencil"
        return i0, wts

    st = {c: (stencil(c, md.tau), stencil(c, md.tau + md.T)) for c in (0.0, 0.5, 1.0)}
    off = int(math.ceil((md.tau + md.T) / h)) + 8
    I_hist = np.zeros((nsteps + 1 + off, nb))   # I = 0 before t = 0 (at rest)

    def drive(k, c):
        (i1, w1), (i2, w2) = st[c]
        I1 = w1 @ I_hist[off + k + i1: off + k + i1 + 4]
        I2 = w2 @ I_hist[off + k + i2: off + k + i2 + 4]
        return (I1 - I2) / md.T

    def accel(X):
        return (md.n * (md.Aa * X[2] - md.Ab * X[3]) - md.Ke * X[0] - md.C * X[1]) / md.M

    def rhs(t, X, w):
        u, v, pa, pb, xv, xvd, z, _ = X
        pos = xv >= 0.0
        Qa = K * xv * np.sqrt(np.maximum(np.where(pos, Ps - pa, pa - PR), 0.0))
        Qb = K * xv * np.sqrt(np.maximum(np.where(pos, pb - PR, Ps - pb), 0.0))
        leak = md.CL * (pa - pb)
        a = accel(X)
        sn, cs = np.sin(wv_ * t), np.cos(wv_ * t)
        r, rd, rdd = av * sn, av * wv_ * cs, -av * wv_ ** 2 * sn
        dp = pa - pb
        d = (md.Kp * (r - u) + md.Kvf * rd + md.Kaf * rdd - md.Kvb * v - md.Kab * a
             - md.Kdp * (dp - md.whp * z))
        return np.array([v, a,
                         md.beta / md.Va * (Qa - md.Aa * v - leak),
                         md.beta / md.Vb * (-Qb + md.Ab * v + leak),
                         xvd, md.wv ** 2 * (w - xv) - 2.0 * md.zv * md.wv * xvd,
                         -md.whp * z + dp, d])

    X = np.zeros((8, nb))
    X[2], X[3] = md.pa0, md.pb0
    X[6] = (md.pa0 - md.pb0) / md.whp if md.whp > 0 else 0.0
    t_out = np.arange(nsteps + 1) * h
    u_out = np.empty((nsteps + 1, nb))
    a_out = np.empty((nsteps + 1, nb))
    u_out[0], a_out[0] = X[0], accel(X)
    for k in range(nsteps):
        t = k * h
        wm = drive(k, 0.5)
        k1 = rhs(t, X, drive(k, 0.0))
        k2 = rhs(t + 0.5 * h, X + 0.5 * h * k1, wm)
        k3 = rhs(t + 0.5 * h, X + 0.5 * h * k2, wm)
        k4 = rhs(t + h, X + h * k3, drive(k, 1.0))
        X = X + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        I_hist[off + k + 1] = X[7]
        u_out[k + 1], a_out[k + 1] = X[0], accel(X)
    out = {}
    for b, (f, amp) in enumerate(pairs):
        w = 2.0 * math.pi * f
        sel = t_out >= t_out[-1] - cyc[b] / f - 1e-12
        tt = t_out[sel]
        G = np.column_stack([np.sin(w * tt), np.cos(w * tt), np.sin(2 * w * tt),
                             np.cos(2 * w * tt), np.sin(3 * w * tt), np.cos(3 * w * tt),
                             np.ones(len(tt))])
        cu, *_ = np.linalg.lstsq(G, u_out[sel, b], rcond=None)
        ca, *_ = np.linalg.lstsq(G, a_out[sel, b], rcond=None)
        Hu = complex(cu[0], cu[1]) / amp
        Ha = complex(ca[0], ca[1]) / amp
        thd = math.sqrt(cu[2] ** 2 + cu[3] ** 2 + cu[4] ** 2 + cu[5] ** 2) / abs(Hu * amp)
        out[(f, amp)] = (Hu, Ha, thd)
    return out, h


# --------------------------------------------------------------------------------------------
def unwrapped_phases(md, freqs, which):
    """Phase (deg) at freqs, unwrapped along a dense grid starting at freqs[0]."""
    grid = np.unique(np.concatenate([np.linspace(freqs[0], freqs[-1], 4001), freqs]))
    H = np.array([md.closed_loop(2j * math.pi * f)[which] for f in grid])
    ph = np.unwrap(np.angle(H)) * 180.0 / math.pi
    return [float(ph[np.searchsorted(grid, f)]) for f in freqs]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--params", default=DEFAULT_PARAMS)
    ap.add_argument("--out", default=None, help="default: " + os.path.relpath(DEFAULT_OUT))
    ap.add_argument("--check", action="store_true", help="time-domain cross-check (~15 s)")
    ap.add_argument("--nonlinear", action="store_true",
                    help="informative run of the nonlinear equations with small sines (~1 min)")
    ap.add_argument("--side", choices=["plus", "minus"], default="plus",
                    help="linearise at x_v = 0+ (the reference) or 0- (comparison only; the"
                         " CSV is then written only if --out is given)")
    args = ap.parse_args()
    with open(args.params) as fh:
        md = Model(json.load(fh), side=+1 if args.side == "plus" else -1)
    write_csv = args.side == "plus" or args.out is not None
    if args.out is None:
        args.out = DEFAULT_OUT

    print("null pressures pa0 = %.6g Pa, pb0 = %.6g Pa" % (md.pa0, md.pb0))
    print("K_land = %.6g m^3/s/sqrt(Pa), Kqa = %.6g, Kqb = %.6g m^3/s" % (md.K, md.Kqa, md.Kqb))
    print("oil-column frequency (blocked valve) f = %.6f Hz" % md.oil_column_hz())
    vg = md.velocity_gains()
    print("velocity per unit opening [m/s]:")
    print("  linearised at the null point, loop open (used): %.6f  -> 1/. = %.6f s/m"
          % (vg["linear_null"], 1.0 / vg["linear_null"]))
    print("  Kqa/Aa = %.6f, Kqb/Ab = %.6f%s"
          % (vg["cap_side"], vg["rod_side"],
             "" if math.isclose(vg["cap_side"], vg["rod_side"], rel_tol=1e-12)
             else " (inconsistent for a single-ended actuator)"))
    print("  nonlinear steady no-load: extend %.6f, retract %.6f"
          % (vg["nonlinear_extend"], vg["nonlinear_retract"]))
    mo = Model(md.params, side=-md.side)
    print("flow gains at x_v = 0%s (other side of the null): Kqa = %.6g, Kqb = %.6g m^3/s"
          " (%.6f, %.6f times this side)" % ("-" if md.side > 0 else "+", mo.Kqa, mo.Kqb,
                                            mo.Kqa / md.Kqa, mo.Kqb / md.Kqb))
    eA, eB, f0 = md.check_linearisation()
    print("check: plant matrices vs finite differences of the nonlinear equations: "
          "max rel dev A %.1e, B %.1e" % (eA, eB))
    print("nonlinear rhs at the null point with x_v = 0: dpa/dt = %.4g Pa/s, dpb/dt = %.4g Pa/s%s"
          % (f0[2], f0[3], " (an exact equilibrium)" if f0[2] == 0.0 and f0[3] == 0.0
             else " (cross-port leakage; not an exact equilibrium)"))
    print("plant poles (u, v, pa, pb):", np.array2string(np.linalg.eigvals(md.Ap), precision=5))

    # margins
    mg = margins(md)
    print("loop broken at the controller output d (exact ZOH and delay):")
    for g in mg["gain_crossovers"]:
        print("  |L| = 1 at %8.4f Hz, phase %9.3f deg, distance from -1: %.3f deg, "
              "lag margin %.3f deg (delay margin %.4f s)"
              % (g["f"], g["phase"], g["distance"], g["lag_margin"], g["delay_margin"]))
    for p in mg["phase_crossovers"]:
        print("  phase %7.1f deg at %9.4f Hz, |L| = %8.3f dB -> gain margin %.3f dB"
              % (p["phase"], p["f"], p["mag_db"], -p["mag_db"]))
    print("  min |1 + L| = %.4f at %.3f Hz (peak sensitivity %.3f)"
          % (mg["min_return"], mg["min_return_f"], 1.0 / mg["min_return"]))
    rhp = open_loop_rhp_poles(md)
    print("  open-loop RHP poles: %d, poles of L at s = 0: %d (indented to the right); Nyquist:"
          " 1 + L winds %.3f times (ccw) about 0"
          % (len(rhp), mg["loop_poles_at_zero"], mg["nyquist_winding_ccw"]))

    # closed-loop poles with Pade approximations
    for order in (4, 8):
        A, B, Cu, Ca = closed_loop_ss(md, order)
        ev = np.linalg.eigvals(A)
        print("closed-loop poles, Pade order %d for exp(-s tau) and exp(-s T): max Re = %.6g"
              % (order, ev.real.max()))
    ev = ev[np.argsort(np.abs(ev))]
    print("  poles below 300 Hz (order 8):")
    for p in ev:
        if abs(p) < 2 * math.pi * 300 and p.imag >= 0:
            wn = abs(p)
            z = -p.real / wn if wn > 0 else float("nan")
            print("    %+.6e %+.6ej   fn = %9.4f Hz  zeta = %.4f" % (p.real, p.imag,
                                                                    wn / 2 / math.pi, z))
    print("  (the pole at 0 is the conserved combination (Va dpa + Vb dpb)/beta + (Aa - Ab) u,"
          " exact when Kqa = Kqb;\n   it is not excited from the command and is absent from"
          " H_u)")

    # FRF
    rows = []
    ph_u = unwrapped_phases(md, FREQS_HZ, 0)
    for f, pu in zip(FREQS_HZ, ph_u):
        Hu, Ha = md.closed_loop(2j * math.pi * f)
        rows.append((f, abs(Hu), pu, abs(Ha), pu + 180.0))
    if write_csv:
        with open(args.out, "w", newline="") as fh:
            wr = csv.writer(fh, lineterminator="\n")
            wr.writerow(["frequency_hz", "gain_u", "phase_u_deg", "gain_a_m_s2_per_m",
                         "phase_a_deg"])
            for r in rows:
                wr.writerow([repr(float(v)) for v in r])
        print("wrote", os.path.relpath(args.out))
    print("  f [Hz]    |Hu|       ph_u [deg]   |Ha| [1/s^2]   ph_a [deg]")
    for r in rows:
        print("  %5.1f  %10.6f  %11.4f  %12.4f  %11.4f" % r)

    # cross-check 1: closed-loop Pade state space vs block algebra
    A, B, Cu, Ca = closed_loop_ss(md, 8)
    worst = 0.0
    for f in FREQS_HZ:
        Hu, Ha = md.closed_loop(2j * math.pi * f)
        Su, Sa = ss_frf(A, B, Cu, Ca, f)
        worst = max(worst, abs(Su - Hu) / abs(Hu), abs(Sa - Ha) / abs(Ha))
    print("check: Pade(8) closed-loop state space vs block algebra, max |dH|/|H| = %.3e" % worst)

    if args.check:
        for f in (2.0, 10.0):
            res, h = simulate_sine(md, f)
            Hu, Ha = md.closed_loop(2j * math.pi * f)
            for name, H in (("u", Hu), ("a", Ha)):
                Hs, rr = res[name]
                dg = abs(Hs) / abs(H) - 1.0
                dph = (np.angle(Hs / H)) * 180.0 / math.pi
                print("check: time-domain %4.1f Hz %s: gain %.9f (FRF %.9f, rel %.2e), "
                      "phase diff %.2e deg, fit residual %.1e (h = %.3g s)"
                      % (f, name, abs(Hs), abs(H), dg, dph, rr, h))

    if args.nonlinear:
        amps = (1e-3, 1e-4, 1e-5)
        res, h = simulate_nonlinear_sines(md, (2.0, 5.0, 10.0), amps)
        print("nonlinear equations, RK4 h = %.3g s (informative; the deviation is the orifice"
              " nonlinearity, proportional to the amplitude):" % h)
        for (f, amp), (Hu_s, Ha_s, thd) in res.items():
            Hu, Ha = md.closed_loop(2j * math.pi * f)
            print("  %4.1f Hz, amp %.0e m: |H_u| %.9f (FRF %.9f, rel %+.2e), phase diff %+.2e deg;"
                  " a: rel %+.2e, %+.2e deg; harmonics/fundamental (u) %.1e"
                  % (f, amp, abs(Hu_s), abs(Hu), abs(Hu_s) / abs(Hu) - 1.0,
                     np.angle(Hu_s / Hu) * 180.0 / math.pi, abs(Ha_s) / abs(Ha) - 1.0,
                     np.angle(Ha_s / Ha) * 180.0 / math.pi, thd))


if __name__ == "__main__":
    main()
