#!/usr/bin/env python3
"""Independent reference: closed-loop poles of a multi-axis shake table (NumPy).

Builds the CLOSED-LOOP STATE-SPACE MATRIX (command r = 0) of the small-signal model of
tools/reference/multi_axis_loop.py, in the time domain, and takes its eigenvalues with
numpy.linalg.eigvals. The model parts (mechanics A_q, A_v, B by numerical linearisation of the
nonlinear Newton-Euler model, the stroke Jacobian G, static forces, null pressures, mean flow
gains, G+ and the controller's gains) come from multi_axis_loop.py (imported, not copied); the
state-space assembly, the delay's Pade realisation and the verdicts are written here from the
equations below, not from the platen (Rust) code.

Usage (from the repository root):
    D=tests/data/multi_axis_poles
    python3 tools/reference/multi_axis_poles.py $D/swivel-stable.json \
        $D/swivel-roll-pitch-unstable.json $D/lhpost6.json --out $D/reference.json [--check]
Each file is a scenario with an explicit `table` (no preset, no specimen); the results are
keyed by file stem. numpy only at run time (multi_axis_loop imports scipy.signal).

STATE (the order is fixed; eigenvalues do not depend on it, the count does):
  [q (n_free), qdot (n_free)],
  per actuator i: P_a, P_b (only when double-acting, rod-side area > 0), x, xdot, and
                  PADE_ORDER = 6 states of the Pade approximant of its drive's delay,
  per free DOF k: xi_k (only if K_i != 0), eta_k (only if K_dp != 0 and f_hp > 0).

EQUATIONS (deviations from the static state at neutral; c = V0/beta):
  qddot = A_q q + A_v qdot + B f,      f_i = A_a P_a - A_b P_b
  c P_a' = -C_L (P_a - P_b) + K_qa x - A_a (G qdot)_i
  c P_b' =  C_L (P_a - P_b) - K_qb x + A_b (G qdot)_i
  single-acting: c P_a' = -C_L P_a + K_qa x - A_a (G qdot)_i
  xddot = w_v^2 (D_delayed - x) - 2 zeta w_v xdot
  D_delayed = Pade[6/6] of e^{-s theta} applied to D_i, theta = tau + T/2
              (valve delay plus the zero-order hold taken as its phase, a delay of T/2),
              N(-s theta)/N(s theta), N(x) = sum_k c_k x^k,
              c_k = (2m-k)! m! / ((2m)! k! (m-k)!), realised as a cascade of second-order
              all-pass sections in sigma = s theta (one per complex pole pair of N).
  d_k = -K_p qhat_k + K_i xi_k - K_vb qhatdot_k - K_ab qddot_k - K_dp h_k
  xi_k' = -qhat_k ;  eta_k' = -w_hp eta_k + dphat_k, h_k = dphat_k - w_hp eta_k
          (HP(s) = s/(s + w_hp); h_k = dphat_k when f_hp = 0)
  qhat = G+ G q ; dphat = G+ dp ; dp_i = P_a - P_b (single-acting: P_a)
  D = G d - K_fb (I - G G+) f                (G_c = G, G_c^+ = pinv(G) of multi_axis_loop)
  qddot_k in d_k is the free coordinate's own acceleration (row k of the mechanics).

VERDICTS
  stable  <=>  every eigenvalue has real part < MARGINAL = 1e-3 1/s. Eigenvalues with
  |Re| <= 1e-3 are "marginal" (mean-pressure modes of double-acting actuators, unclosed
  integrators, ...). unstable_poles: eigenvalues with Re > 1e-3 and Im >= 0, as
  [Re (1/s), Im/(2 pi) (Hz)], largest real part first. open_loop_unstable_poles[dof]:
  eigenvalues with Re > 1e-3 of the same matrix with that DOF's loop opened (its d_k forced
  to 0; its integrator/high-pass states kept, now driving nothing).

SELF-CHECKS (--check): the Pade realisation against the rational function and
e^{-j w theta}; the state space's command->pose response C (sI-A)^-1 B(s) (the command put
back in through the same law, d_k += (K_p + K_vf s + K_af s^2) r_k, xi_k' += r_k) against
multi_axis_loop.Loop.system with its valve's delay*hold replaced by the same Pade[6/6] of
e^{-s theta} (must agree to round-off), by the exact e^{-s theta}, and as written (exact
delay and exact hold (1-e^{-sT})/(sT)); each pole checked as a zero of multi_axis_loop's
(row-scaled) T(s); eigenvalues invariant under a diagonal rescaling of the state; the same
transfer check on a copy of each table with K_i, K_vb, K_af and an unfiltered K_dp added
(paths the given tables may not exercise).
"""

import argparse
import json
import math
import os
import sys
from fractions import Fraction

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import multi_axis_loop as mal  # noqa: E402

PADE_ORDER = 6
MARGINAL = 1e-3
DOFS = mal.DOFS


# ---------------------------------------------------------------- Pade of e^{-s theta}

def pade_coefficients(m):
    """c_k, k = 0..m, of N(x) = sum c_k x^k (exact fractions, then float)."""
    f = math.factorial
    return [float(Fraction(f(2 * m - k) * f(m), f(2 * m) * f(k) * f(m - k))) for k in range(m + 1)]


def pade_value(s, theta, m=PADE_ORDER):
    """N(-s theta)/N(s theta) evaluated directly (Horner)."""
    c = pade_coefficients(m)
    x = s * theta
    num = 0.0
    den = 0.0
    for ck in reversed(c):
        num = num * (-x) + ck
        den = den * x + ck
    return num / den


def delay_realisation(theta, m=PADE_ORDER):
    """(A, B, C, D) with C (sI - A)^-1 B + D = N(-s theta)/N(s theta), m states.

    N(sigma) = c_m prod (sigma - r_i); N(-sigma)/N(sigma) = (-1)^m prod (sigma + r_i)/(sigma - r_i).
    A complex pair r, conj(r) gives (sigma^2 - b sigma + k)/(sigma^2 + b sigma + k), b = -2 Re r,
    k = |r|^2, = 1 - 2 b sigma/(sigma^2 + b sigma + k):  x1' = x2, x2' = -k x1 - b x2 + u,
    y = u - 2 b x2. A real root r (odd m): (sigma - a)/(sigma + a), a = -r: x' = -a x + u,
    y = u - 2 a x. Sections in series; then sigma = s theta: A = A_sigma/theta, B = B_sigma/theta.
    """
    if theta <= 0.0:
        raise ValueError("the delay theta must be > 0")
    c = pade_coefficients(m)
    roots = np.roots(c[::-1])                      # roots of N(sigma), highest power first
    sections = []
    pairs = sorted([r for r in roots if r.imag > 1e-9 * abs(r)], key=lambda r: (abs(r), r.real))
    reals = sorted([r.real for r in roots if abs(r.imag) <= 1e-9 * abs(r)])
    if 2 * len(pairs) + len(reals) != m:
        raise ValueError("unexpected Pade root structure")
    for r in pairs:
        b, k = -2.0 * r.real, abs(r) ** 2
        sections.append((np.array([[0.0, 1.0], [-k, -b]]), np.array([[0.0], [1.0]]),
                         np.array([[0.0, -2.0 * b]]), np.array([[1.0]])))
    for r in reals:
        a = -r
        sections.append((np.array([[-a]]), np.array([[1.0]]), np.array([[-2.0 * a]]),
                         np.array([[1.0]])))
    A, B, C, D = sections[0]
    for A2, B2, C2, D2 in sections[1:]:
        n1, n2 = A.shape[0], A2.shape[0]
        An = np.zeros((n1 + n2, n1 + n2))
        An[:n1, :n1] = A
        An[n1:, :n1] = B2 @ C
        An[n1:, n1:] = A2
        B = np.vstack([B, B2 @ D])
        C = np.hstack([D2 @ C, C2])
        D = D2 @ D
        A = An
    sign = (-1.0) ** m
    return A / theta, B / theta, sign * C, sign * D


def ss_value(A, B, C, D, s):
    n = A.shape[0]
    return (C @ np.linalg.solve(s * np.eye(n) - A, B) + D)[0, 0]


# ---------------------------------------------------------------- the closed loop

class PoleModel:
    """Closed-loop state space (r = 0) of multi_axis_loop's linear model, Pade delays."""

    def __init__(self, table_dict):
        self.table_dict = table_dict
        lp = mal.Loop(table_dict)         # refuses presets, tables without controller, ...
        self.lp = lp
        self.nf, self.n = lp.nf, lp.n
        self.free_names = [DOFS[k] for k in lp.free]
        self.G = lp.G                     # G_c
        self.Gp = lp.Gp                   # G_c^+
        g = lp.gain
        nf, n = self.nf, self.n
        # --- layout
        idx = 2 * nf
        self.slots = []
        for h in lp.hyd:
            sl = {"pa": idx}
            idx += 1
            if h["ib"] is not None:
                sl["pb"] = idx
                idx += 1
            else:
                sl["pb"] = None
            sl["x"], sl["xd"] = idx, idx + 1
            idx += 2
            sl["delay"] = idx
            idx += PADE_ORDER
            self.slots.append(sl)
        self.xi = [None] * nf
        self.eta = [None] * nf
        for k in range(nf):
            if g["ki"][k] != 0.0:
                self.xi[k] = idx
                idx += 1
            if g["kdp"][k] != 0.0 and g["fhp"][k] > 0.0:
                self.eta[k] = idx
                idx += 1
        self.ns = ns = idx
        self.theta = [h["tau"] + lp.T / 2.0 for h in lp.hyd]
        # --- linear functions of the state (rows)
        F = np.zeros((n, ns))             # actuator forces f
        DP = np.zeros((n, ns))            # pressure differences dp
        for i, (h, sl) in enumerate(zip(lp.hyd, self.slots)):
            F[i, sl["pa"]] = h["Aa"]
            DP[i, sl["pa"]] = 1.0
            if sl["pb"] is not None:
                F[i, sl["pb"]] = -h["Ab"]
                DP[i, sl["pb"]] = -1.0
        QDD = np.zeros((nf, ns))          # qddot
        QDD[:, 0:nf] = lp.Aq
        QDD[:, nf:2 * nf] = lp.Av
        QDD += lp.B @ F
        GpG = self.Gp @ self.G
        QH = np.zeros((nf, ns))           # qhat
        QH[:, 0:nf] = GpG
        QHD = np.zeros((nf, ns))          # qhatdot
        QHD[:, nf:2 * nf] = GpG
        DPH = self.Gp @ DP                # dphat
        # --- plant + controller-state dynamics (everything but the drive's effect)
        A0 = np.zeros((ns, ns))
        A0[0:nf, nf:2 * nf] = np.eye(nf)
        A0[nf:2 * nf, :] = QDD
        MD = np.zeros((ns, n))            # d(state')/d(drive D_i)
        for i, (h, sl) in enumerate(zip(lp.hyd, self.slots)):
            cc = h["V0"] / lp.tab.beta
            Gi = self.G[i]
            pa, pb, x, xd, dl = sl["pa"], sl["pb"], sl["x"], sl["xd"], sl["delay"]
            if pb is not None:
                A0[pa, pa] += -h["CL"] / cc
                A0[pa, pb] += h["CL"] / cc
                A0[pb, pa] += h["CL"] / cc
                A0[pb, pb] += -h["CL"] / cc
                A0[pb, x] += -h["Kqb"] / cc
                A0[pb, nf:2 * nf] += h["Ab"] * Gi / cc
            else:
                A0[pa, pa] += -h["CL"] / cc
            A0[pa, x] += h["Kqa"] / cc
            A0[pa, nf:2 * nf] += -h["Aa"] * Gi / cc
            Ad, Bd, Cd, Dd = delay_realisation(self.theta[i])
            wv, zv = h["wv"], h["zv"]
            ds = slice(dl, dl + PADE_ORDER)
            A0[ds, ds] = Ad
            MD[ds, i] = Bd[:, 0]
            A0[x, xd] = 1.0
            A0[xd, x] = -wv * wv
            A0[xd, xd] = -2.0 * zv * wv
            A0[xd, ds] += wv * wv * Cd[0]
            MD[xd, i] = wv * wv * Dd[0, 0]
        H = np.zeros((nf, ns))            # h_k (high-passed dphat)
        for k in range(nf):
            H[k] = DPH[k]
            if self.xi[k] is not None:
                A0[self.xi[k]] = -QH[k]
            if self.eta[k] is not None:
                w = 2.0 * math.pi * g["fhp"][k]
                A0[self.eta[k]] = DPH[k]
                A0[self.eta[k], self.eta[k]] += -w
                H[k, self.eta[k]] += -w
        Dr = np.zeros((nf, ns))           # d = Dr x
        for k in range(nf):
            Dr[k] = -g["kp"][k] * QH[k] - g["kvb"][k] * QHD[k] - g["kab"][k] * QDD[k] \
                - g["kdp"][k] * H[k]
            if self.xi[k] is not None:
                Dr[k, self.xi[k]] += g["ki"][k]
        self.A0, self.MD, self.Dr, self.F = A0, MD, Dr, F
        self.proj = np.eye(n) - self.G @ self.Gp
        self.kfb = lp.kfb

    def matrix(self, open_dof=None):
        """Closed-loop A (r = 0); open_dof = k: DOF k's d_k forced to 0."""
        Dr = self.Dr.copy()
        if open_dof is not None:
            Dr[open_dof] = 0.0
        Drive = self.G @ Dr - self.kfb * self.proj @ self.F
        return self.A0 + self.MD @ Drive

    def input_matrix(self, s):
        """B(s) of the command r: d_k += (K_p + K_vf s + K_af s^2) r_k, xi_k' += r_k."""
        g = self.lp.gain
        B = (self.MD @ self.G) @ np.diag(g["kp"] + g["kvf"] * s + g["kaf"] * s * s)
        B = B.astype(complex)
        for k in range(self.nf):
            if self.xi[k] is not None:
                B[self.xi[k], k] += 1.0
        return B

    def transfer(self, f_hz):
        """Command -> pose (free DOFs) of this state space at j 2 pi f."""
        s = 2j * math.pi * f_hz
        A = self.matrix()
        Z = np.linalg.solve(s * np.eye(self.ns) - A, self.input_matrix(s))
        return Z[0:self.nf]


def sort_poles(p):
    return sorted(p, key=lambda z: (-z.real, z.imag))


def analyse(model):
    A = model.matrix()
    ev = np.linalg.eigvals(A)
    unst = [z for z in ev if z.real > MARGINAL and z.imag >= 0.0]
    unst = sorted(unst, key=lambda z: (-z.real, z.imag))
    marginal = int(np.sum(np.abs(ev.real) <= MARGINAL))
    beyond = ev[np.abs(ev.real) > MARGINAL]
    out = {
        "stable": bool(np.all(ev.real < MARGINAL)),
        "largest_real_part_1_s": float(np.max(ev.real)),
        "unstable_poles": [[float(z.real), float(z.imag / (2.0 * math.pi))] for z in unst],
        "states": int(model.ns),
        "open_loop_unstable_poles": {},
        "marginal_poles": marginal,
        "largest_real_part_beyond_marginal_1_s": float(np.max(beyond.real)) if beyond.size else None,
    }
    for k, name in enumerate(model.free_names):
        evk = np.linalg.eigvals(model.matrix(open_dof=k))
        out["open_loop_unstable_poles"][name] = int(np.sum(evk.real > MARGINAL))
    out["unstable_modes"] = unstable_modes(model, A, ev)
    return out, ev


def unstable_modes(model, A, ev):
    """Per distinct unstable pole (upper half-plane): the free DOFs' share of the mode.

    Share_k = w_k^2 P_kk / sum, P the orthogonal projector onto the span of the eigenvectors
    of the (possibly repeated) pole, restricted to q; w_k = 1 for translations and the
    platen's radius of gyration sqrt(I_kk/m) for rotations. Basis-independent for a
    repeated pole (a symmetric table's roll/pitch pair).
    """
    lp = model.lp
    w, V = np.linalg.eig(A)
    rho = np.sqrt(np.diag(lp.tab.Ic) / lp.tab.m)
    wq = np.array([1.0 if k < 3 else rho[k - 3] for k in lp.free])
    done = []
    out = []
    for z in sort_poles([z for z in w if z.real > MARGINAL and z.imag >= 0.0]):
        if any(abs(z - d) <= 1e-6 * abs(d) for d in done):
            continue
        done.append(z)
        cols = [j for j in range(len(w)) if abs(w[j] - z) <= 1e-6 * abs(z)]
        # projector onto the eigenvectors' span, the q rows weighted by w
        S = np.ones(model.ns)
        S[0:model.nf] = wq
        Q, _ = np.linalg.qr(V[:, cols] * S[:, None])
        diagp = np.sum(np.abs(Q[0:model.nf]) ** 2, axis=1)
        share = diagp / np.sum(diagp)
        out.append({"pole": [float(z.real), float(z.imag / (2.0 * math.pi))],
                    "multiplicity": len(cols),
                    "dof_share": {model.free_names[k]: float(share[k]) for k in range(model.nf)}})
    return out


# ---------------------------------------------------------------- self-checks

def check_delay(theta):
    Ad, Bd, Cd, Dd = delay_realisation(theta)
    num, den = mal.pade(theta, PADE_ORDER)     # multi_axis_loop's own Pade, for comparison
    rows = []
    for f in [1.0, 10.0, 100.0, 246.0, 1000.0, 1.0 / (2.0 * math.pi * theta)]:
        s = 2j * math.pi * f
        vs = ss_value(Ad, Bd, Cd, Dd, s)
        vr = pade_value(s, theta)
        vm = np.polyval(num, s) / np.polyval(den, s)
        ve = np.exp(-s * theta)
        rows.append((f, abs(vs - vr), abs(vr - vm), abs(vs - ve)))
    return rows


def rel(Ha, Hb):
    return float(np.max(np.abs(Ha - Hb)) / np.max(np.abs(Hb)))


def check_transfer(model, freqs):
    """max |H_ss - H_loop| / max |H_loop| per frequency for three valve variants of the loop."""
    lp = model.lp
    orig_valve = lp.valve
    sec = {}

    def patched(kind):
        def valve(s, i):
            h = lp.hyd[i]
            wv, zv = h["wv"], h["zv"]
            base = wv * wv / (s * s + 2.0 * zv * wv * s + wv * wv)
            th = model.theta[i]
            if kind == "pade":
                return base * pade_value(s, th)
            if kind == "exact_delay":
                return base * np.exp(-s * th)
            return orig_valve(s, i)
        return valve

    for kind in ["pade", "exact_delay", "as_written"]:
        lp.valve = patched(kind)
        errs = []
        for f in freqs:
            Hs = model.transfer(f)
            Hl = lp.transfer(f)[np.ix_(lp.free, lp.free)]
            errs.append(rel(Hs, Hl))
        sec[kind] = errs
    lp.valve = orig_valve
    return sec


def check_poles_are_zeros(model, ev, count=8):
    """For the least-damped/most unstable poles: sigma_min/sigma_max of the row-scaled T(s) of
    multi_axis_loop (valve with the same Pade delay) at the pole and 1% off it."""
    lp = model.lp
    orig_valve = lp.valve

    def valve(s, i):
        h = lp.hyd[i]
        wv, zv = h["wv"], h["zv"]
        return wv * wv / (s * s + 2.0 * zv * wv * s + wv * wv) * pade_value(s, model.theta[i])

    lp.valve = valve

    def ratio(s):
        T, _ = lp.system(s)
        T = T / np.max(np.abs(T), axis=1, keepdims=True)
        sv = np.linalg.svd(T, compute_uv=False)
        return float(sv[-1] / sv[0])

    cand = [z for z in ev if z.imag > 1e-6 and abs(z.real) > MARGINAL
            and abs(z) < 2.0 * math.pi * 60.0]
    cand = sorted(cand, key=lambda z: -z.real / abs(z))[:count]
    rows = [(z, ratio(z), ratio(z * (1.0 + 0.01j))) for z in cand]
    lp.valve = orig_valve
    return rows


def check_scaling(model):
    """Eigenvalues of S A S^-1 with pressures in MPa (and the rest unscaled)."""
    A = model.matrix()
    S = np.ones(model.ns)
    for sl in model.slots:
        S[sl["pa"]] = 1e-6
        if sl["pb"] is not None:
            S[sl["pb"]] = 1e-6
    As = (S[:, None] * A) / S[None, :]
    e1 = np.linalg.eigvals(A)
    e2 = np.linalg.eigvals(As)
    return float(np.max(e1.real)), float(np.max(e2.real)), \
        float(np.max(np.sort(e1.real)[-20:] - np.sort(e2.real)[-20:]))


def check_variant(table_dict, freqs):
    """The paths the given tables may not exercise: K_i (integrator states), K_vb, K_af and
    a K_dp without high-pass, added to a copy of the table; H_ss against multi_axis_loop with
    the same Pade delay. Returns (states, marginal poles, errors per frequency)."""
    t = json.loads(json.dumps(table_dict))
    dof = t["controller"].setdefault("dof", {})
    for j, name in enumerate(DOFS):
        g = dof.setdefault(name, {})
        g["integral_gain_per_m_s"] = 1.5 + 0.1 * j
        g["velocity_feedback_s_per_m"] = 0.02
        g["acceleration_feedforward_s2_per_m"] = 0.001
        if j % 2 == 0:
            g["delta_p_highpass_hz"] = 0.0
            g["delta_p_gain_per_pa"] = g.get("delta_p_gain_per_pa", 0.0) or 1e-9
    model = PoleModel(t)
    ev = np.linalg.eigvals(model.matrix())
    errs = check_transfer(model, freqs)["pade"]
    return model.ns, int(np.sum(np.abs(ev.real) <= MARGINAL)), errs


# ---------------------------------------------------------------- CLI

def load_table(path):
    with open(path) as f:
        sc = json.load(f)
    if "table" not in sc:
        raise SystemExit(f"{path}: no `table` key")
    if sc.get("specimen") is not None:
        raise SystemExit(f"{path}: a specimen is not supported")
    return sc["table"]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scenarios", nargs="+")
    ap.add_argument("--out")
    ap.add_argument("--check", action="store_true")
    args = ap.parse_args(argv)
    result = {}
    for path in sorted(args.scenarios):
        name = os.path.splitext(os.path.basename(path))[0]
        model = PoleModel(load_table(path))
        res, ev = analyse(model)
        result[name] = res
        print(f"== {name}: {model.ns} states, free {' '.join(model.free_names)}, "
              f"theta = {', '.join(sorted({f'{t * 1e3:.6g} ms' for t in model.theta}))}")
        print(f"   stable {res['stable']}, largest Re {res['largest_real_part_1_s']:.6g} 1/s, "
              f"{res['marginal_poles']} marginal, largest beyond marginal "
              f"{res['largest_real_part_beyond_marginal_1_s']:.6g} 1/s")
        for p in res["unstable_poles"]:
            print(f"   unstable pole {p[0]:.6g} 1/s at {p[1]:.6g} Hz")
        for m in res["unstable_modes"]:
            top = sorted(m["dof_share"].items(), key=lambda kv: -kv[1])[:3]
            print(f"   mode {m['pole'][0]:.4g} 1/s / {m['pole'][1]:.4g} Hz x{m['multiplicity']}: "
                  + ", ".join(f"{k} {v:.3f}" for k, v in top))
        print(f"   open-loop unstable poles per DOF: {res['open_loop_unstable_poles']}")
        osc = sorted([z for z in ev if z.imag > 1e-6], key=lambda z: -z.real / abs(z))[:6]
        print("   least damped: " + ", ".join(f"{z.imag / 2 / math.pi:.3f} Hz (zeta "
                                             f"{-z.real / abs(z):.4f})" for z in osc))
        if args.check:
            st, maxre, nzero, _ = model.lp.stability()
            print(f"   multi_axis_loop.stability() (its Pade 4 of tau and of the hold): stable "
                  f"{st}, max Re beyond its s=0 poles {maxre:.6g}, {nzero} at s = 0")
            th = model.theta[0]
            print(f"   delay realisation, theta {th:.6g} s: f, |ss - rational|, "
                  f"|rational - mal.pade|, |ss - exp(-j w theta)|")
            for f, a, b, c in check_delay(th):
                print(f"     {f:10.4g} Hz  {a:.2e}  {b:.2e}  {c:.2e}")
            freqs = [0.5, 2.0, 10.0, 30.0, 100.0]
            tc = check_transfer(model, freqs)
            print("   H_ss vs multi_axis_loop H, max|dH|/max|H| at " + ", ".join(f"{f:g}" for f in freqs)
                  + " Hz:")
            for kind, errs in tc.items():
                print(f"     {kind:12s} " + "  ".join(f"{e:.2e}" for e in errs))
            print("   poles as zeros of mal's row-scaled T(s): sigma_min/sigma_max at the pole | 1% off")
            for z, r0, r1 in check_poles_are_zeros(model, ev):
                print(f"     {z.real:10.4f} {z.imag / 2 / math.pi:8.3f} Hz  {r0:.2e} | {r1:.2e}")
            ns, nm, errs = check_variant(model.table_dict, freqs)
            print(f"   variant with K_i, K_vb, K_af, unfiltered K_dp: {ns} states, {nm} marginal; "
                  "pade H error " + "  ".join(f"{e:.2e}" for e in errs))
            a, b, c = check_scaling(model)
            print(f"   pressure-rescaled matrix: max Re {a:.6g} vs {b:.6g}; "
                  f"top-20 Re max diff {c:.2e}")
    if args.out:
        with open(args.out, "w") as f:
            f.write(json.dumps(result, indent=1, sort_keys=True) + "\n")


if __name__ == "__main__":
    main()
