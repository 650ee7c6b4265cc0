#!/usr/bin/env python3
"""Independent reference: small-signal MIMO closed loop of a multi-axis shake table (NumPy/SciPy).

Command -> pose transfer matrix H(j w) (6 x 6 complex, H[i][j] = pose_i / command_j) of a
six-DOF rigid platen on servo-hydraulic actuators under DOF control, linearised about the
neutral pose. Written from the project's design brief and the equations below, not from any
platen (Rust) code. Kinematics and Newton-Euler conventions are those of
tools/reference/multi_axis_cases.py (its functions are copied here, marked "copied").

Usage (from the repository root):
    python3 tools/reference/multi_axis_loop.py TABLE.json --freqs 0.5,1,2,5,10,20 [--json OUT.json]
TABLE.json is a scenario with a "table" key (explicit, no "preset"); a "specimen" is refused.
Importable: transfer_matrix(table_dict, f_hz) -> 6 x 6 complex ndarray.

Units: SI. Pose q = (x, y, z, roll, pitch, yaw) in m and rad, so H[i][j] is m/m, rad/rad,
m/rad or rad/m. Held DOFs (table.held_dofs) are rows and columns of zeros. The CLI (not
transfer_matrix) sets entries below 1e-12 max|H| to 0: round-off of couplings that are exactly
zero by symmetry.

EQUATIONS (s = j w; a "d" prefix = deviation from neutral, dropped below where obvious)

1. Mechanics (exact nonlinear model, then linearised numerically).
   R = Rz(yaw) Ry(pitch) Rx(roll); platen point p at t + R p. Angular velocity
   w = vee(Rdot R^T), wdot = vee(Rddot R^T + Rdot Rdot^T) = E(theta) theta'' + wdot0(theta,
   theta'), E's columns = w(theta, e_k). Wrench about the current reference point t:
     swivel actuator i: force f_i along n_i = (t + R p_i - b_i)/|..| at t + R p_i;
       stroke s_i = |t + R p_i - b_i| - L_i0;
     pad actuator i: force f_i along the fixed axis a_i at X_i = c_i + s_i a_i, the point
       where the axis meets the underside (platen-frame plane p_z = c_i,z),
       s_i = (c_i,z - e3^T R^T (c_i - t)) / (e3^T R^T a_i);
     hold-down strut j: force p_j A_j along -n_j at t + R p_j, p_j = p0 (V0/V)^gamma,
       V = V0 - A (L_j - L_j0) (as multi_axis_cases.py: the pull grows when the strut
       lengthens);
     gravity m g_vec (g_vec = (0, 0, -9.80665)) at t + R c.
   Newton-Euler about the reference point, with the 6 x 6 mass matrix
     Mm = [[m I, -m [r_c]x], [m [r_c]x, I_w - m [r_c]x [r_c]x]],  r_c = R c, I_w = R I_c R^T:
     Mm [t''; wdot] = b = [F - m w x (w x r_c);  M - w x (I_w w) - m r_c x (w x (w x r_c))].
   Generalised coordinates: [t''; wdot] = J q'' + [0; wdot0], J = blockdiag(I3, E). Held DOFs
   are ideal constraints (q_held = 0): their reaction does no work on the free coordinates, so
     (J^T Mm J)_ff q''_f = (J^T (b - Mm [0; wdot0]))_f           -> q''_f = F(q_f, q'_f, f).
   Linearised by central differences about (q_f, q'_f, f) = (0, 0, f0):
     dq'' = A_q dq + A_v dq' + B df
   (includes the struts' geometric stiffness and pretension, gravity, the actuators' static
   forces turning with the platen and the pads' forces on fixed lines; frictionless).

2. Geometry. G (n_act x n_free), G_ik = d s_i / d q_k at neutral (central differences of the
   stroke functions). Force transmission Gamma (n_free x n_act) = d(generalised force)/d f_i
   = (J^T [u_i; r_i x u_i])_f at neutral. Gamma = G^T for swivels and for pads whose axis is
   normal to the underside (all the project's tables); for a tilted pad they differ
   (d s/d t = e3 / a_z, not a) - see the note at static_forces().

3. Static forces: Gamma f0 = -(J^T W_passive)_f at neutral (gravity + struts), minimum norm:
   f0 = pinv(Gamma) w. (The brief writes pinv(G^T); identical when Gamma = G^T.)

4. Hydraulics, actuator i (areas A_a, A_b; A_b = 0 is single-acting), chambers V0 each:
   K = m Q_r / sqrt(dp_r / 2)           (land coefficient, m valves, rated total drop dp_r)
   double-acting null pressures: p_a0 + p_b0 = P_s + P_R, A_a p_a0 - A_b p_b0 = f0_i;
   single-acting: p_a0 = f0_i / A_a.
   K_qa = K (sqrt(P_s - p_a0) + sqrt(p_a0 - P_R)) / 2,  K_qb = K (sqrt(P_s - p_b0) +
   sqrt(p_b0 - P_R)) / 2  (mean of the opening- and closing-side gains: a small sine's
   fundamental; the critically centred valve has no pressure-flow coefficient at null).
   (V0/beta) s P_a = K_qa X_i - A_a s S_i - C_L (P_a - P_b)
   (V0/beta) s P_b = -K_qb X_i + A_b s S_i + C_L (P_a - P_b)
   single-acting: (V0/beta) s P_a = K_qa X_i - A_a s S_i - C_L P_a
   S_i = G_i q, f_i = A_a P_a - A_b P_b.

5. Valve: X_i = W_i(s) D_i,  W_i = w_v^2/(s^2 + 2 z_v w_v s + w_v^2) e^{-s tau} Z(s),
   Z(s) = (1 - e^{-sT})/(sT), T = 1/f_c (the controller's zero-order hold).

6. Controller (per free DOF k, diagonal gains):
   qhat = G+ S = G+ G q (G+ = pinv(G)), dp_dof = G+ dP, dP_i = P_a - P_b (single: P_a),
   d_k = (K_p + K_i/s)(r_k - qhat_k) + (K_vf s + K_af s^2) r_k - K_vb s qhat_k
         - K_ab s^2 q_k - K_dp HP(s) dp_dof,k,      HP = s/(s + 2 pi f_hp) (1 if f_hp = 0)
   D = G d - K_fb N N^T f,   N = orthonormal basis of null(G^T) (SVD).

7. Assembled per frequency as one complex linear system T(s) z = b(s) r in
   z = [q_f, P (chambers), X (spools), d (DOF drives)] and solved for r = e_j.
   Per-DOF loop (others closed): break at d_k (d_k = injected v), L_k = -(controller's d_k)/v;
   gain and phase margins from L_k(j w) (advisory: L_k has resonances and anti-resonances,
   so single-loop margins can look fine while the loop is not; see margins()). Stability:
   eigenvalues of the closed loop in state space with Pade approximants of e^{-s tau} and of
   the hold (state_space(), stability()); the Pade model's frequency response agrees with
   the exact solve (test_multi_axis_loop.py).

NOTES
 * Each double-acting actuator gives the closed loop one pole at exactly s = 0: with these
   null pressures K_qa = K_qb, and the critically centred valve has no pressure-flow
   coefficient at null, so the mean pressure p_a + p_b integrates -(A_a - A_b) S' and no
   feedback or leakage (cross-port) reaches it. stability() counts these apart.
 * Hold-down strut gas volume: V = V0 - A (L - L0) as multi_axis_cases.py (and the paper's
   K'_e); DESIGN.md writes V0 + A (L - L0), which would make the struts destabilising.
 * Frictionless: pads' friction coefficients and `bearings` are ignored; so are `stroke_m`,
   `limits` and an `accumulator` (constant supply). Specimens and presets are refused.
"""

import argparse
import json
import math
import sys

import numpy as np
from scipy import signal

G_ACC = 9.80665
G_VEC = np.array([0.0, 0.0, -G_ACC])
DOFS = ["x", "y", "z", "roll", "pitch", "yaw"]
GAIN_NAMES = {
    "kp": "displacement_gain_per_m",
    "ki": "integral_gain_per_m_s",
    "kvf": "velocity_feedforward_s_per_m",
    "kaf": "acceleration_feedforward_s2_per_m",
    "kvb": "velocity_feedback_s_per_m",
    "kab": "acceleration_feedback_s2_per_m",
    "kdp": "delta_p_gain_per_pa",
    "fhp": "delta_p_highpass_hz",
}


# ---------------------------------------------------------------- rotations (copied)

def elem(axis, a):
    """(R, dR/da, d2R/da2) of an elementary rotation about x, y or z (copied)."""
    c, s = math.cos(a), math.sin(a)
    if axis == "x":
        return (np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]),
                np.array([[0.0, 0.0, 0.0], [0.0, -s, -c], [0.0, c, -s]]),
                np.array([[0.0, 0.0, 0.0], [0.0, -c, s], [0.0, -s, -c]]))
    if axis == "y":
        return (np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]),
                np.array([[-s, 0.0, c], [0.0, 0.0, 0.0], [-c, 0.0, -s]]),
                np.array([[-c, 0.0, -s], [0.0, 0.0, 0.0], [s, 0.0, -c]]))
    return (np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]),
            np.array([[-s, -c, 0.0], [c, -s, 0.0], [0.0, 0.0, 0.0]]),
            np.array([[-c, s, 0.0], [-s, -c, 0.0], [0.0, 0.0, 0.0]]))


def rot(ang):
    roll, pitch, yaw = ang
    return elem("z", yaw)[0] @ elem("y", pitch)[0] @ elem("x", roll)[0]


def rot_derivs(ang, rate, acc):
    """R, Rdot, Rddot by the product rule, R = Rz(yaw) Ry(pitch) Rx(roll) (copied)."""
    roll, pitch, yaw = ang
    droll, dpitch, dyaw = rate
    aroll, apitch, ayaw = acc
    A0, A1, A2 = elem("z", yaw)
    B0, B1, B2 = elem("y", pitch)
    C0, C1, C2 = elem("x", roll)
    Ad, Bd, Cd = dyaw * A1, dpitch * B1, droll * C1
    Add = ayaw * A1 + dyaw * dyaw * A2
    Bdd = apitch * B1 + dpitch * dpitch * B2
    Cdd = aroll * C1 + droll * droll * C2
    R = A0 @ B0 @ C0
    Rd = Ad @ B0 @ C0 + A0 @ Bd @ C0 + A0 @ B0 @ Cd
    Rdd = (Add @ B0 @ C0 + A0 @ Bdd @ C0 + A0 @ B0 @ Cdd
           + 2.0 * (Ad @ Bd @ C0 + Ad @ B0 @ Cd + A0 @ Bd @ Cd))
    return R, Rd, Rdd


def vee(W):
    return 0.5 * np.array([W[2, 1] - W[1, 2], W[0, 2] - W[2, 0], W[1, 0] - W[0, 1]])


def skew(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def omega_and_dot(ang, rate, acc):
    R, Rd, Rdd = rot_derivs(ang, rate, acc)
    return R, vee(Rd @ R.T), vee(Rdd @ R.T + Rd @ Rd.T)


def e_matrix_numeric(ang):
    """Columns w(theta, e_k) (copied)."""
    return np.column_stack([omega_and_dot(ang, np.eye(3)[k], np.zeros(3))[1] for k in range(3)])


# ---------------------------------------------------------------- table model

class Table:
    """Geometry, mechanics and hydraulic/controller parameters of an explicit `table`."""

    def __init__(self, d):
        if "preset" in d:
            raise ValueError("table presets are not supported: give the table explicitly")
        p = d["platen"]
        self.m = float(p["mass_kg"])
        self.Ic = np.array(p["inertia_kg_m2"], dtype=float)
        self.c = np.array(p["centre_of_mass_m"], dtype=float)
        self.act = d["actuators"]
        self.struts = d.get("hold_down_struts", [])
        self.names = [a["name"] for a in self.act]
        held = d.get("held_dofs", [])
        for h in held:
            if h not in DOFS:
                raise ValueError(f"unknown held DOF {h!r}")
        self.free = [k for k, n in enumerate(DOFS) if n not in held]
        self.beta = float(d["oil_bulk_modulus_pa"])
        self.ps = float(d["supply_pressure_pa"])
        self.pr = float(d.get("return_pressure_pa", 0.0))
        self.ctrl = d.get("controller")
        if self.ctrl is None:
            raise ValueError("the table has no controller: no closed loop to linearise")
        self.L0 = {}
        for a in self.act:
            if "platen_m" in a:
                self.L0[a["name"]] = float(np.linalg.norm(np.array(a["platen_m"], float)
                                                          - np.array(a["base_m"], float)))
            elif "pad" not in a:
                raise ValueError(f"actuator {a['name']}: neither platen_m nor pad")
            if "servo_valve" not in a:
                raise ValueError(f"actuator {a['name']}: no servo_valve")
        for s in self.struts:
            self.L0[s["name"]] = float(np.linalg.norm(np.array(s["platen_m"], float)
                                                      - np.array(s["base_m"], float)))

    # --- kinematics (as multi_axis_cases.Table, copied) ---
    def actuator_lines(self, t, R):
        """Per actuator: (stroke, unit vector of the force, world point of the force)."""
        out = []
        e3 = np.array([0.0, 0.0, 1.0])
        for a in self.act:
            if "platen_m" in a:
                x = t + R @ np.array(a["platen_m"], float)
                d = x - np.array(a["base_m"], float)
                L = float(np.linalg.norm(d))
                out.append((L - self.L0[a["name"]], d / L, x))
            else:
                ax = np.array(a["pad"].get("axis", [0.0, 0.0, 1.0]), float)
                ax = ax / np.linalg.norm(ax)
                c = np.array(a["pad"]["contact_m"], float)
                s = (c[2] - e3 @ (R.T @ (c - t))) / (e3 @ (R.T @ ax))
                out.append((float(s), ax, c + s * ax))
        return out

    def passive_wrench(self, t, R):
        """Wrench about t of gravity and the hold-down struts."""
        rc = R @ self.c
        F = self.m * G_VEC
        M = np.cross(rc, self.m * G_VEC)
        for s in self.struts:
            x = t + R @ np.array(s["platen_m"], float)
            d = x - np.array(s["base_m"], float)
            L = float(np.linalg.norm(d))
            A, V0 = s["area_m2"], s["gas_volume_m3"]
            V = V0 - A * (L - self.L0[s["name"]])
            p = s["pressure_pa"] * (V0 / V) ** s["polytropic_exponent"]
            f = -p * A * d / L
            F = F + f
            M = M + np.cross(x - t, f)
        return F, M

    def mass_matrix(self, R):
        rc = R @ self.c
        Iw = R @ self.Ic @ R.T
        S = skew(rc)
        M = np.zeros((6, 6))
        M[0:3, 0:3] = self.m * np.eye(3)
        M[0:3, 3:6] = -self.m * S
        M[3:6, 0:3] = self.m * S
        M[3:6, 3:6] = Iw - self.m * S @ S
        return M

    def full(self, qf):
        q = np.zeros(6)
        q[self.free] = qf
        return q

    def strokes(self, qf):
        q = self.full(qf)
        return np.array([s for s, _, _ in self.actuator_lines(q[0:3], rot(q[3:6]))])

    def generalised_forces(self, qf, qdf, f):
        """(J^T Mm J)_ff and (J^T (b - Mm [0; wdot0]))_f: the reduced Newton-Euler system."""
        q, qd = self.full(qf), self.full(qdf)
        t, ang, rate = q[0:3], q[3:6], qd[3:6]
        R, w, wd0 = omega_and_dot(ang, rate, np.zeros(3))
        F, M = self.passive_wrench(t, R)
        for fi, (_, u, x) in zip(f, self.actuator_lines(t, R)):
            F = F + fi * u
            M = M + np.cross(x - t, fi * u)
        rc = R @ self.c
        Iw = R @ self.Ic @ R.T
        b = np.concatenate([F - self.m * np.cross(w, np.cross(w, rc)),
                            M - np.cross(w, Iw @ w)
                            - self.m * np.cross(rc, np.cross(w, np.cross(w, rc)))])
        Mm = self.mass_matrix(R)
        J = np.eye(6)
        J[3:6, 3:6] = e_matrix_numeric(ang)
        Mg = J.T @ Mm @ J
        Qg = J.T @ (b - Mm @ np.concatenate([np.zeros(3), wd0]))
        fr = self.free
        return Mg[np.ix_(fr, fr)], Qg[fr]

    def accel(self, qf, qdf, f):
        """q''_f = F(q_f, q'_f, f): the nonlinear, frictionless, constrained platen."""
        Mg, Qg = self.generalised_forces(qf, qdf, f)
        return np.linalg.solve(Mg, Qg)


# ---------------------------------------------------------------- linearisation

def geometry_matrix(tab, h=1e-6):
    """G_ik = d stroke_i / d q_k at neutral over the free DOFs, central differences."""
    nf = len(tab.free)
    G = np.zeros((len(tab.act), nf))
    for k in range(nf):
        e = np.zeros(nf)
        e[k] = h
        G[:, k] = (tab.strokes(e) - tab.strokes(-e)) / (2.0 * h)
    return G


def static_forces(tab):
    """f0 (minimum norm) holding the platen at neutral, and the force transmission Gamma.

    Gamma[:, i] = d(generalised force)/d f_i (exactly linear in f). The brief's
    f0 = pinv(G^T) w uses the stroke Jacobian instead; the two agree when Gamma = G^T, which
    holds for swivels and for pads whose axis is normal to the platen's underside. For a
    tilted pad only Gamma gives an equilibrium (the linearisation point), so Gamma is used.
    """
    nf = len(tab.free)
    z = np.zeros(nf)
    n = len(tab.act)
    _, Q0 = tab.generalised_forces(z, z, np.zeros(n))      # gravity + struts
    Gam = np.zeros((nf, n))
    for i in range(n):
        f = np.zeros(n)
        f[i] = 1.0
        Gam[:, i] = tab.generalised_forces(z, z, f)[1] - Q0
    f0 = np.linalg.pinv(Gam) @ (-Q0)
    resid = Gam @ f0 + Q0
    if np.max(np.abs(resid)) > 1e-6 * max(1.0, np.max(np.abs(Q0))):
        raise ValueError(f"the actuators cannot hold the platen at neutral (residual {resid})")
    return f0, Gam


def linearise(tab, f0, hq=1e-5, hf=1e3):
    """A_q, A_v, B of dq'' = A_q dq + A_v dq' + B df about (0, 0, f0), central differences."""
    nf, n = len(tab.free), len(tab.act)
    z = np.zeros(nf)
    Aq = np.zeros((nf, nf))
    Av = np.zeros((nf, nf))
    B = np.zeros((nf, n))
    for k in range(nf):
        e = np.zeros(nf)
        e[k] = hq
        Aq[:, k] = (tab.accel(e, z, f0) - tab.accel(-e, z, f0)) / (2.0 * hq)
        Av[:, k] = (tab.accel(z, e, f0) - tab.accel(z, -e, f0)) / (2.0 * hq)
    for i in range(n):
        e = np.zeros(n)
        e[i] = hf
        B[:, i] = (tab.accel(z, z, f0 + e) - tab.accel(z, z, f0 - e)) / (2.0 * hf)
    return Aq, Av, B


# ---------------------------------------------------------------- the linear model

def pade(theta, order):
    """(num, den) polynomials in s (highest power first) of the Pade approximant of e^{-s theta}."""
    c = [math.factorial(2 * order - k) * math.factorial(order)
         / (math.factorial(2 * order) * math.factorial(k) * math.factorial(order - k))
         for k in range(order + 1)]
    num = [c[k] * (-theta) ** k for k in range(order, -1, -1)]
    den = [c[k] * theta ** k for k in range(order, -1, -1)]
    return np.array(num), np.array(den)


def scaled_ss(num, den, w0):
    """State space of num(s)/den(s) realised in the scaled variable sigma = s / w0."""
    num = np.trim_zeros(np.atleast_1d(np.asarray(num, float)), "f")
    den = np.atleast_1d(np.asarray(den, float))
    nn, nd = len(num) - 1, len(den) - 1
    num_s = np.array([num[k] * w0 ** (nn - k) for k in range(nn + 1)])
    den_s = np.array([den[k] * w0 ** (nd - k) for k in range(nd + 1)])
    A, B, C, D = signal.tf2ss(num_s / den_s[0], den_s / den_s[0])
    return w0 * A, w0 * B, C, D


def series(blocks):
    """Series connection u -> block 0 -> block 1 -> ... (SISO state spaces)."""
    A, B, C, D = blocks[0]
    for A2, B2, C2, D2 in blocks[1:]:
        n1, n2 = A.shape[0], A2.shape[0]
        An = np.zeros((n1 + n2, n1 + n2))
        An[:n1, :n1] = A
        An[n1:, :n1] = B2 @ C
        An[n1:, n1:] = A2
        B = np.vstack([B, B2 @ D])
        C = np.hstack([D2 @ C, C2])
        D = D2 @ D
        A = An
    return A, B, C, D


class Loop:
    """Everything frequency-independent of the linearised closed loop."""

    def __init__(self, table_dict):
        tab = Table(table_dict)
        self.tab = tab
        self.free = tab.free
        nf, n = len(tab.free), len(tab.act)
        self.nf, self.n = nf, n
        self.G = geometry_matrix(tab)
        self.f0, self.Gamma = static_forces(tab)
        self.Aq, self.Av, self.B = linearise(tab, self.f0)
        self.Gp = np.linalg.pinv(self.G)
        # null space of G^T (force combinations that move nothing), orthonormal, from the SVD
        U, sv, _ = np.linalg.svd(self.G)
        rank = int(np.sum(sv > 1e-9 * sv[0])) if sv.size else 0
        if rank < nf:
            raise ValueError(f"the actuators do not control every free DOF (rank {rank} < {nf})")
        self.N = U[:, rank:]
        # hydraulics per actuator
        self.chambers = []          # (actuator index, side 'a' or 'b')
        self.hyd = []
        for i, a in enumerate(tab.act):
            Aa = float(a["cap_side_area_m2"])
            Ab = float(a.get("rod_side_area_m2", 0.0))
            V0 = float(a["chamber_volume_m3"])
            CL = float(a.get("leakage_m3_s_per_pa", 0.0))
            sv_ = a["servo_valve"]
            K = sv_.get("count", 1) * sv_["rated_flow_m3_s"] / math.sqrt(
                sv_["rated_pressure_drop_pa"] / 2.0)
            if Ab > 0.0:
                pa0 = (self.f0[i] + Ab * (tab.ps + tab.pr)) / (Aa + Ab)
                pb0 = tab.ps + tab.pr - pa0
            else:
                pa0 = self.f0[i] / Aa
                pb0 = None
            for p in [pa0] + ([pb0] if pb0 is not None else []):
                if not (tab.pr < p < tab.ps):
                    raise ValueError(f"actuator {a['name']}: null pressure {p:.4g} Pa outside "
                                     f"(P_R, P_s) for its static force {self.f0[i]:.4g} N (an actuator whose load "
                                     f"the held DOFs' constraints carry has none: remove it)")
            Kqa = K * (math.sqrt(tab.ps - pa0) + math.sqrt(pa0 - tab.pr)) / 2.0
            Kqb = (K * (math.sqrt(tab.ps - pb0) + math.sqrt(pb0 - tab.pr)) / 2.0
                   if pb0 is not None else 0.0)
            h = {"Aa": Aa, "Ab": Ab, "V0": V0, "CL": CL, "K": K, "pa0": pa0, "pb0": pb0,
                 "Kqa": Kqa, "Kqb": Kqb, "wv": 2.0 * math.pi * sv_["natural_frequency_hz"],
                 "zv": sv_["damping_ratio"], "tau": sv_.get("delay_s", 0.0),
                 "ia": len(self.chambers), "ib": None}
            self.chambers.append((i, "a"))
            if Ab > 0.0:
                h["ib"] = len(self.chambers)
                self.chambers.append((i, "b"))
            self.hyd.append(h)
        nch = len(self.chambers)
        self.nch = nch
        # f = Ef P (actuator forces), dP = Edp P (pressure differences fed back)
        self.Ef = np.zeros((n, nch))
        self.Edp = np.zeros((n, nch))
        for i, h in enumerate(self.hyd):
            self.Ef[i, h["ia"]] = h["Aa"]
            self.Edp[i, h["ia"]] = 1.0
            if h["ib"] is not None:
                self.Ef[i, h["ib"]] = -h["Ab"]
                self.Edp[i, h["ib"]] = -1.0
        # controller
        c = tab.ctrl
        self.T = 1.0 / float(c["sample_rate_hz"])
        self.kfb = float(c.get("force_balance_gain", 0.0))
        self.gain = {key: np.zeros(nf) for key in GAIN_NAMES}
        dofg = c.get("dof", {})
        for kk, k in enumerate(tab.free):
            g = dofg.get(DOFS[k], {})
            for key, name in GAIN_NAMES.items():
                self.gain[key][kk] = float(g.get(name, 0.0))

    # --- frequency-dependent pieces ---
    def zoh(self, s):
        return 1.0 if s == 0 else (1.0 - np.exp(-s * self.T)) / (s * self.T)

    def valve(self, s, i):
        h = self.hyd[i]
        wv, zv = h["wv"], h["zv"]
        return wv * wv / (s * s + 2.0 * zv * wv * s + wv * wv) * np.exp(-s * h["tau"]) * self.zoh(s)

    def hp(self, s):
        fhp = self.gain["fhp"]
        return np.array([s / (s + 2.0 * math.pi * f) if f > 0.0 else 1.0 for f in fhp])

    def system(self, s, break_dof=None):
        """T(s), Br(s): T z = Br r (r over the free DOFs), z = [q, P, X, d].

        break_dof = k: the controller's row k is replaced by d_k = v (v the last column of Br,
        r = 0); returns also the row vector c with y_k = c z the controller's own d_k.
        """
        nf, n, nch = self.nf, self.n, self.nch
        iq, iP, iX, id_ = 0, nf, nf + nch, nf + nch + n
        N = nf + nch + n + nf
        T = np.zeros((N, N), dtype=complex)
        Br = np.zeros((N, nf), dtype=complex)
        # mechanics: (s^2 - s A_v - A_q) q - B Ef P = 0
        T[iq:iP, iq:iP] = s * s * np.eye(nf) - s * self.Av - self.Aq
        T[iq:iP, iP:iX] = -self.B @ self.Ef
        # chambers
        for i, h in enumerate(self.hyd):
            c = h["V0"] / self.tab.beta
            ra = iP + h["ia"]
            T[ra, ra] += c * s + h["CL"]
            T[ra, iX + i] = -h["Kqa"]
            T[ra, iq:iP] += h["Aa"] * s * self.G[i]
            if h["ib"] is not None:
                rb = iP + h["ib"]
                T[ra, rb] += -h["CL"]
                T[rb, rb] += c * s + h["CL"]
                T[rb, ra] += -h["CL"]
                T[rb, iX + i] = h["Kqb"]
                T[rb, iq:iP] += -h["Ab"] * s * self.G[i]
        # spools: X - W (G d - K_fb N N^T Ef P) = 0
        NN = self.N @ self.N.T
        for i in range(n):
            W = self.valve(s, i)
            T[iX + i, iX + i] = 1.0
            T[iX + i, id_:N] = -W * self.G[i]
            T[iX + i, iP:iX] = W * self.kfb * (NN[i] @ self.Ef)
        # controller: d - Cr r + Cq q + K_dp HP G+ Edp P = 0
        if s == 0:
            raise ValueError("the frequency must be > 0 (integrators, mean-pressure modes)")
        g = self.gain
        ki_s = g["ki"] / s
        GpG = self.Gp @ self.G
        Cq = ((g["kp"] + ki_s + g["kvb"] * s)[:, None] * GpG
              + np.diag(g["kab"] * s * s))
        Cp = (g["kdp"] * self.hp(s))[:, None] * (self.Gp @ self.Edp)
        rows = slice(id_, N)
        T[rows, id_:N] = np.eye(nf)
        T[rows, iq:iP] = Cq
        T[rows, iP:iX] = Cp
        Br[rows, :] = np.diag(g["kp"] + ki_s + g["kvf"] * s + g["kaf"] * s * s)
        if break_dof is None:
            return T, Br
        k = break_dof
        cvec = -T[id_ + k].copy()
        cvec[id_ + k] = 0.0
        T[id_ + k] = 0.0
        T[id_ + k, id_ + k] = 1.0
        v = np.zeros(N, dtype=complex)
        v[id_ + k] = 1.0
        return T, v, cvec

    def transfer(self, f_hz):
        """6 x 6 complex H(j 2 pi f): pose over command, held rows/cols zero."""
        s = 2j * math.pi * f_hz
        T, Br = self.system(s)
        Z = np.linalg.solve(T, Br)
        H = np.zeros((6, 6), dtype=complex)
        H[np.ix_(self.free, self.free)] = Z[0:self.nf, :]
        return H

    def loop_gain(self, f_hz, k):
        """L_k(j w): DOF k's loop broken at its drive d_k, every other loop closed."""
        s = 2j * math.pi * f_hz
        T, v, cvec = self.system(s, break_dof=k)
        z = np.linalg.solve(T, v)
        return -(cvec @ z)

    # --- margins ---
    def margins(self, k, fmin=0.01, fmax=2000.0, npts=3000):
        """Gain and phase margins of L_k (log grid, crossings refined by bisection).

        L_k has lightly damped poles and zeros (the other DOFs' and its own oil columns), so
        |L_k| may cross 1 several times: every crossing is listed with the angle of L_k
        there; the phase margin is the smallest angular distance of those points from -1
        (unsigned: which side of -1 a crossing passes is a matter for the Nyquist count,
        and stability is decided by the closed-loop poles). The gain margin is
        -20 log10 |L_k| at the crossing of the negative real axis nearest |L| = 1.
        """
        fs = np.logspace(math.log10(fmin), math.log10(fmax), npts)
        L = np.array([self.loop_gain(f, k) for f in fs])

        def refine(fun, a, b):
            fa = fun(a)
            for _ in range(50):
                m = math.sqrt(a * b)
                fm = fun(m)
                if (fm > 0) == (fa > 0):
                    a, fa = m, fm
                else:
                    b = m
            return math.sqrt(a * b)

        crossings = []
        for j in np.nonzero(np.diff(np.sign(np.abs(L) - 1.0)))[0]:
            fc = refine(lambda f: abs(self.loop_gain(f, k)) - 1.0, fs[j], fs[j + 1])
            ang = math.degrees(np.angle(self.loop_gain(fc, k)))
            crossings.append({"f_hz": fc, "angle_deg": ang, "distance_deg": 180.0 - abs(ang)})
        phase_x = []
        for j in np.nonzero(np.diff(np.sign(L.imag)))[0]:
            if L[j].real >= 0.0 and L[j + 1].real >= 0.0:
                continue
            fp = refine(lambda f: self.loop_gain(f, k).imag, fs[j], fs[j + 1])
            Lp = self.loop_gain(fp, k)
            if Lp.real < 0.0:
                phase_x.append({"f_hz": fp, "gain_margin_db": -20.0 * math.log10(abs(Lp))})
        out = {"gain_crossings": crossings, "phase_crossings": phase_x,
               "first_crossover_hz": crossings[0]["f_hz"] if crossings else None,
               "phase_margin_deg": min(c["distance_deg"] for c in crossings) if crossings else None,
               "gain_margin_db": (min((p["gain_margin_db"] for p in phase_x), key=abs)
                                  if phase_x else None)}
        return out

    # --- closed-loop poles (Pade) ---
    def state_space(self, pade_order=4):
        """Closed loop (A, Bc, Cq) with Pade approximants of the delay and the hold."""
        nf, n, nch = self.nf, self.n, self.nch
        g = self.gain
        # per actuator valve block: w^2/(s^2+2 z w s+w^2) * pade(tau) * zoh_pade(T), a series
        # of three factors, each realised on its own time scale (a companion form of the whole
        # product would be hopelessly ill-conditioned)
        blocks = []
        for i, h in enumerate(self.hyd):
            facs = [(np.array([h["wv"] ** 2]),
                     np.array([1.0, 2.0 * h["zv"] * h["wv"], h["wv"] ** 2]), h["wv"])]
            if h["tau"] > 0:
                pn, pd = pade(h["tau"], pade_order)
                facs.append((pn, pd, 1.0 / h["tau"]))
            # hold: (1 - e^{-sT})/(sT) ~ (pd - pn)/(s T pd), pd - pn has only odd powers
            pn, pd = pade(self.T, pade_order)
            diff = np.polysub(pd, pn)
            assert abs(diff[-1]) <= 1e-12 * np.max(np.abs(diff))
            facs.append((diff[:-1] / self.T, pd, 1.0 / self.T))
            blocks.append(series([scaled_ss(nm, dn, w0) for nm, dn, w0 in facs]))
        nv = [b[0].shape[0] for b in blocks]
        nint = int(np.sum(g["ki"] != 0.0))
        nhp = int(np.sum((g["fhp"] > 0.0) & (g["kdp"] != 0.0)))
        # state = [q, v, P, valve states, integrators, hp states]
        iq, iv, iP = 0, nf, 2 * nf
        ivl = iP + nch
        ii = ivl + sum(nv)
        ih = ii + nint
        ns = ih + nhp
        A = np.zeros((ns, ns))
        Bc = np.zeros((ns, nf))          # command r
        # mechanics
        A[iq:iv, iv:iP] = np.eye(nf)
        A[iv:iP, iq:iv] = self.Aq
        A[iv:iP, iv:iP] = self.Av
        A[iv:iP, iP:ivl] = self.B @ self.Ef
        # controller output d = Dx x + Dr r (linear in the state, no algebraic loop)
        Dx = np.zeros((nf, ns))
        Dr = np.zeros((nf, nf))
        GpG = self.Gp @ self.G
        Dx[:, iq:iv] -= g["kp"][:, None] * GpG
        Dx[:, iv:iP] -= g["kvb"][:, None] * GpG
        Dx -= g["kab"][:, None] * A[iv:iP, :]                    # the platen's own q''
        Dr += np.diag(g["kp"])
        # integrators xi' = r - qhat, d += K_i xi
        col = ii
        for k in range(nf):
            if g["ki"][k] != 0.0:
                A[col, iq:iv] = -GpG[k]
                Bc[col, k] = 1.0
                Dx[k, col] += g["ki"][k]
                col += 1
        # dp_dof = G+ Edp P;  HP = 1 - a/(s+a): eta' = -a eta + u, y = u - a eta
        dpd = self.Gp @ self.Edp
        col = ih
        for k in range(nf):
            if g["kdp"][k] == 0.0:
                continue
            Dx[k, iP:ivl] -= g["kdp"][k] * dpd[k]
            if g["fhp"][k] > 0.0:
                a = 2.0 * math.pi * g["fhp"][k]
                A[col, col] = -a
                A[col, iP:ivl] = dpd[k]
                Dx[k, col] += g["kdp"][k] * a
                col += 1
        # (feedforward adds derivatives of r: it changes no pole, so it is left out here)
        # actuator drive D = G d - K_fb N N^T Ef P  (into the valve blocks), spool X = C x
        Dd = self.G @ Dx
        Dd[:, iP:ivl] -= self.kfb * (self.N @ self.N.T @ self.Ef)
        Ddr = self.G @ Dr
        Xrow = np.zeros((n, ns))
        off = ivl
        for i, (Ab_, Bb_, Cb_, Db_) in enumerate(blocks):
            m = Ab_.shape[0]
            assert abs(Db_[0, 0]) < 1e-12      # strictly proper: no algebraic loop
            A[off:off + m, off:off + m] += Ab_
            A[off:off + m, :] += Bb_ @ Dd[i:i + 1, :]
            Bc[off:off + m, :] += Bb_ @ Ddr[i:i + 1, :]
            Xrow[i, off:off + m] = Cb_[0]
            off += m
        # chambers
        for i, h in enumerate(self.hyd):
            c = self.tab.beta / h["V0"]
            ra = iP + h["ia"]
            A[ra, :] += c * h["Kqa"] * Xrow[i]
            A[ra, iv:iP] -= c * h["Aa"] * self.G[i]
            A[ra, ra] -= c * h["CL"]
            if h["ib"] is not None:
                rb = iP + h["ib"]
                A[ra, rb] += c * h["CL"]
                A[rb, :] -= c * h["Kqb"] * Xrow[i]
                A[rb, iv:iP] += c * h["Ab"] * self.G[i]
                A[rb, rb] -= c * h["CL"]
                A[rb, ra] += c * h["CL"]
        # (Dx took the mechanics rows A[iv:iP] above, complete before the chambers were added)
        Cq = np.zeros((nf, ns))
        Cq[:, iq:iv] = np.eye(nf)
        return A, Bc, Cq

    def closed_loop_poles(self, pade_order=4):
        A, _, _ = self.state_space(pade_order)
        return np.linalg.eigvals(A)

    def stability(self, pade_order=4, zero_tol=1e-6):
        """(stable, max real part of the other poles, number of poles at s = 0, poles).

        Each double-acting actuator contributes one exact pole at s = 0: with a critically
        centred valve at null (no pressure-flow coefficient) and K_qa = K_qb (always, with
        p_a0 + p_b0 = P_s + P_R), the sum p_a + p_b obeys (V0/beta) s (P_a + P_b) =
        -(A_a - A_b) s S: cross-port leakage does not touch it, so its level is undetermined
        (neutral). Those poles are counted apart; the loop is called stable when every other
        pole has a negative real part.
        """
        poles = self.closed_loop_poles(pade_order)
        zero = np.abs(poles) < zero_tol
        n_double = sum(1 for h in self.hyd if h["ib"] is not None)
        rest = poles[~zero]
        maxre = float(np.max(rest.real)) if rest.size else -np.inf
        return maxre < 0.0 and int(np.sum(zero)) == n_double, maxre, int(np.sum(zero)), poles

    def shut_valve_modes(self):
        """Frequencies (Hz) of the platen on its oil columns (valves shut, no leakage)."""
        k = np.array([self.tab.beta * (h["Aa"] ** 2 + h["Ab"] ** 2) / h["V0"] for h in self.hyd])
        Mg, _ = self.tab.generalised_forces(np.zeros(self.nf), np.zeros(self.nf), self.f0)
        Kt = self.Gamma @ np.diag(k) @ self.G - Mg @ self.Aq
        lam = np.linalg.eigvals(np.linalg.solve(Mg, Kt))
        return np.sort(np.sqrt(lam.astype(complex)).real / (2.0 * math.pi))


_CACHE = {}


def _loop(table_dict):
    key = json.dumps(table_dict, sort_keys=True)
    if key not in _CACHE:
        _CACHE[key] = Loop(table_dict)
    return _CACHE[key]


def transfer_matrix(table_dict, f_hz):
    """H (6 x 6 complex) of the `table` dict at f_hz: H[i][j] = pose_i / command_j."""
    return _loop(table_dict).transfer(f_hz)


# ---------------------------------------------------------------- CLI

def fmt(z):
    return f"{abs(z):9.3e}/{math.degrees(np.angle(z)):7.1f}"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scenario")
    ap.add_argument("--freqs", default="0.5,1,2,5,10,20,40")
    ap.add_argument("--json", dest="json_out")
    ap.add_argument("--no-margins", action="store_true")
    args = ap.parse_args(argv)
    with open(args.scenario) as f:
        sc = json.load(f)
    if "table" not in sc:
        sys.exit(f"{args.scenario}: no `table` key")
    if sc.get("specimen") is not None:
        sys.exit(f"{args.scenario}: a specimen is not supported by this reference "
                 f"(bare table only): remove `specimen`")
    try:
        lp = _loop(sc["table"])
    except ValueError as e:
        sys.exit(f"{args.scenario}: {e}")
    freqs = [float(x) for x in args.freqs.split(",") if x.strip()]
    free_names = [DOFS[k] for k in lp.free]
    print(f"free DOFs: {' '.join(free_names)}")
    print("static forces f0 (kN): " + " ".join(f"{n}={x / 1e3:.1f}"
                                              for n, x in zip(lp.tab.names, lp.f0)))
    print("null pressures (MPa) / flow gains K_qa, K_qb (m^3/s):")
    for n_, h in zip(lp.tab.names, lp.hyd):
        pb = f"{h['pb0'] / 1e6:.3f}" if h["pb0"] is not None else "-"
        print(f"  {n_}: p_a0={h['pa0'] / 1e6:.3f} p_b0={pb} K_qa={h['Kqa']:.4f} K_qb={h['Kqb']:.4f}")
    print("valves-shut modes (Hz): " + " ".join(f"{x:.2f}" for x in lp.shut_valve_modes()))
    stable, maxre, nzero, poles = lp.stability()
    print(f"closed-loop poles (Pade 4 for delay and hold): {nzero} at s = 0 (the double-acting "
          f"actuators' mean-pressure modes), the others' max real part {maxre:.4g} 1/s -> "
          f"{'STABLE' if stable else 'NOT STABLE'}")
    osc = sorted((p for p in poles if p.imag > 1e-6), key=lambda p: -p.real / abs(p))
    print("  least damped: " + ", ".join(f"{p.imag / (2 * math.pi):.2f} Hz (zeta {-p.real / abs(p):.3f})"
                                         for p in osc[:6]))
    dg = float(np.max(np.abs(lp.Gamma - lp.G.T)))
    if dg > 1e-6:
        print(f"note: force transmission differs from G^T by {dg:.3g} (tilted pad axes)")
    out = {"about": "tools/reference/multi_axis_loop.py: small-signal MIMO closed loop, "
                    "H[i][j] = pose_i / command_j (m, rad), linearised at neutral",
           "dofs": DOFS, "free_dofs": free_names,
           "static_forces_n": {n_: float(x) for n_, x in zip(lp.tab.names, lp.f0)},
           "closed_loop_max_real_pole_1_s": maxre, "poles_at_zero": nzero, "stable": stable,
           "frequencies_hz": freqs, "real": [], "imag": [], "magnitude": [], "phase_deg": []}
    for f in freqs:
        H = lp.transfer(f)
        H[np.abs(H) < 1e-12 * np.max(np.abs(H))] = 0.0      # round-off of exact zeros
        print(f"\nf = {f:g} Hz   |H| / phase(deg), rows pose, columns command")
        print("         " + "".join(f"{d:>18s}" for d in DOFS))
        for i in range(6):
            print(f"{DOFS[i]:>7s}  " + "".join(f"{fmt(H[i, j]):>18s}" for j in range(6)))
        out["real"].append([[H[i, j].real for j in range(6)] for i in range(6)])
        out["imag"].append([[H[i, j].imag for j in range(6)] for i in range(6)])
        out["magnitude"].append([[abs(H[i, j]) for j in range(6)] for i in range(6)])
        out["phase_deg"].append([[math.degrees(np.angle(H[i, j])) for j in range(6)]
                                 for i in range(6)])
    if not args.no_margins:
        print("\nper-DOF loop (broken at the DOF drive, others closed):")
        out["margins"] = {}
        for kk, k in enumerate(lp.free):
            m = lp.margins(kk)
            out["margins"][DOFS[k]] = m
            cr = ", ".join(f"{c['f_hz']:.2f} Hz @ {c['angle_deg']:.0f} deg"
                           for c in m["gain_crossings"])
            gm = m["gain_margin_db"]
            print(f"  {DOFS[k]:>5s}: |L|=1 at {cr}; phase margin {m['phase_margin_deg']:.1f} deg, "
                  f"gain margin {'-' if gm is None else f'{gm:.1f} dB'}")
    if args.json_out:
        with open(args.json_out, "w") as f:
            f.write(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
