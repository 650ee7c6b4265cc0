#!/usr/bin/env python3
"""Independent references for the six-DOF (multi-axis) platen (Python/NumPy/SciPy, not platen).

Conventions (those of the project's design brief; nothing here is taken from the Rust code):

  * Axes: x longitudinal, y transverse, z up. Gravity g = 9.80665 m/s^2 along -z,
    g_vec = (0, 0, -g).
  * Reference point = centre of the platen's top surface at the neutral pose. Pose
    q = (x, y, z, roll, pitch, yaw): the reference point moves by t = (x, y, z) m and the
    platen turns by R = Rz(yaw) Ry(pitch) Rx(roll) (rad). A platen point p (platen frame,
    measured from the reference point) is at t + R p in table axes. At neutral the platen
    frame coincides with the table axes.
  * Platen: rigid, mass m, inertia I_c (about the centre of mass, platen axes), centre of
    mass c (platen frame). In table axes r_c = R c, I_w = R I_c R^T.
  * Angular velocity (table axes) w = vee(Rdot R^T), angular acceleration
    wdot = vee(Rddot R^T + Rdot Rdot^T); Rdot and Rddot by the product rule of the three
    elementary rotations (Rddot = A''BC + AB''C + ABC'' + 2(A'B'C + A'BC' + AB'C'),
    A = Rz, B = Ry, C = Rx). No "E matrix" formula is used for w; the standard ZYX relation
    w = yaw' e_z + Rz pitch' e_y + Rz Ry roll' e_x is only asserted against it.
  * Swivel actuator i ("platen_m" given): base b_i (table axes, fixed), platen point p_i.
    L_i = |t + R p_i - b_i|, stroke = L_i - L_i0 (L_i0 at neutral),
    n_i = (t + R p_i - b_i) / L_i; its force f_i acts on the platen along +n_i at t + R p_i.
  * Bearing ("pad") actuator i: fixed unit axis a_i (table axes) through contact_i (table
    axes, on the platen's underside at neutral). The underside is the platen-frame plane
    p_z = contact_i,z. At pose q the axis meets it at X_i = contact_i + s_i a_i,
        s_i = (contact_i,z - e3^T R^T (contact_i - t)) / (e3^T R^T a_i),
    stroke = s_i (0 at neutral); its force f_i acts on the platen along +a_i at X_i.
  * Hold-down strut j: base b_j, platen point p_j, length L_j, unit vector n_j
    (base -> platen) as a swivel. Gas: V = V0 - A (L - L0), p = p0 (V0/V)^gamma; force on
    the platen p A along -n_j at t + R p_j (pulls the platen towards the base). Expanded for
    a vertical strut of pin-to-pin height h this gives the horizontal restoring force of two
    struts K_e u + K'_e u^3 / h^2 with K_e = 2 p0 A / h, K'_e = 1/2 (gamma h / l0 - 1) K_e,
    l0 = V0 / A.
  * Wrench about the CURRENT reference point t: F = sum f_i, M = sum (r_i x f_i) with r_i the
    point of application minus t.

Cases written to tests/data/reference/multi_axis.json (and multi_axis_forces.csv):

  * "table": an LHPOST6-like table, deliberately not symmetric (off-centre centre of mass,
    full inertia tensor, 4 horizontal swivels h1..h4, 6 pads v1..v6 under the platen, v3's
    axis slightly tilted, 2 hold-down struts s1, s2), in the project's JSON table shape.
    The struts' platen pins are at z = -0.2 m (inside the platen box, above the centre of
    mass) and spread in x and y: with the pads' forces on fixed lines (a circulatory
    coupling [F]x between translation and rotation, F = the pads' total ~5.9 MN) and pins at
    the underside, free flight under prescribed forces is unstable (divergence or flutter,
    growth rate ~1 /s); with these pins the linearised free flight at neutral is neutrally
    stable (frequencies about 0.10, 0.24, 0.39, 0.49, 0.52, 0.63 Hz).
    "stroke_m" is the actuator's full stroke; it enters no computation here, nor do
    "friction_coefficient" (every case is frictionless) and the pads' "base_m".
  * "kinematics": 50 seeded random poses with strokes, unit vectors (n_i or a_i), points of
    application, strut lengths and strut forces p A.
  * "newton_euler": all six coordinates q_k = A_k sin(2 pi f_k t + phi_k) at once; the wrench
    about the current reference point that all forces EXCEPT gravity must exert:
        F = m a_c - m g_vec,  a_c = t'' + wdot x r_c + w x (w x r_c),
        M = I_w wdot + w x (I_w w) + r_c x F.
  * "modes" / "modes_symmetric": neutral pose, valves shut; axial springs only
    (actuator k = beta (A_cap^2/V + A_rod^2/V), V = chamber_volume_m3 for each chamber;
    strut k = gamma p0 A^2 / V0), K = sum k J^T J, J = [u^T, (r x u)^T] (u along n_i at p_i
    for swivels and struts, along a_i at contact_i for pads); mass matrix about the
    reference point [[m I3, -m [r_c]x], [m [r_c]x, I_c - m [r_c]x [r_c]x]], r_c = c;
    K phi = w^2 M phi by scipy.linalg.eigh, phi^T M phi = 1, largest |component| positive.
    "modes_symmetric" is for "table_symmetric" (centre of mass on the z axis, diagonal
    inertia, actuators symmetric about the x-z and y-z planes, all pad axes vertical).
  * "strut_paper": the horizontal restoring force of two vertical struts (h = 3.3 m,
    A = 0.15 m^2, p0 = 13.8 MPa, V0 = 0.315 m^3, gamma = 1.44) for u_x = 0, 0.05 .. 0.75 m,
    exact (no expansion); "force_n" is positive when it pulls back towards neutral
    (= -F_x for the platen displaced to +x).
  * "forward": frictionless free flight of "table" from rest at neutral over 0..5 s under
    gravity, the struts and actuator forces f_i(t) = f_i0 + ramp(t) (a1 sin(2 pi f1 t) +
    a2 sin(2 pi f2 t)), ramp = sin^2(pi t / 2) for t < 1 s, then 1. f_0 is the minimum-norm
    static set at neutral (zero net wrench with gravity and the struts' pull). The forces are
    the 1024 Hz columns of multi_axis_forces.csv (t_s, {name}_force_n); between samples the
    force is the LINEAR INTERPOLANT of the printed samples. State (t, theta, t', theta'),
    theta = (roll, pitch, yaw); t'' and wdot from the 6x6 Newton-Euler system about the
    reference point (its matrix is the mass matrix above at the current pose), theta'' from
    wdot = E(theta) theta'' + wdot(theta, theta', 0), where E's columns are w(theta, e_k) from
    the Rdot construction. Every 1/1024 s interval is integrated separately with DOP853,
    rtol 1e-11, atol 1e-13. Written: pose and rates (Euler-angle rates) every 64th sample.

Usage (from the repository root, with numpy and scipy installed):
    python3 tools/reference/multi_axis_cases.py
The output is deterministic (same inputs, same SciPy/NumPy/libm -> same bytes).
"""

import json
import math
import os

import numpy as np
from scipy.integrate import solve_ivp
from scipy.linalg import eigh

G = 9.80665
G_VEC = np.array([0.0, 0.0, -G])
BETA = 1.5e9
FS_HZ = 1024
DURATION_S = 5.0
OUTPUT_EVERY = 64
OUT_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                       "tests", "data", "reference")
JSON_NAME = "multi_axis.json"
FORCES_NAME = "multi_axis_forces.csv"

# Hold-down struts (the paper's): pin to pin h, area, pressure, gas volume = A l0, exponent.
STRUT_H = 3.3
STRUT_A = 0.15
STRUT_P0 = 13.8e6
STRUT_L0 = 2.1
STRUT_V0 = 0.315
STRUT_GAMMA = 1.44

# Horizontal (double-acting) and vertical (single-acting) actuators.
H_CAP, H_ROD, H_VOL, H_STROKE = 0.0418, 0.0318, 0.04, 1.5
V_CAP, V_ROD, V_VOL, V_STROKE = 0.0645, 0.0, 0.03, 0.5
PAD_MU = 0.005
PAD_BASE_DEPTH = 1.5          # pads' base_m = contact - 1.5 m along the axis (not used)


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def lst(v):
    return [float(x) for x in np.asarray(v, dtype=float).ravel()]


def swivel(name, base, platen):
    return {"name": name, "base_m": lst(base), "platen_m": lst(platen),
            "cap_side_area_m2": H_CAP, "rod_side_area_m2": H_ROD,
            "chamber_volume_m3": H_VOL, "stroke_m": H_STROKE}


def pad(name, contact, axis=(0.0, 0.0, 1.0)):
    a = unit(axis)
    c = np.asarray(contact, dtype=float)
    return {"name": name, "base_m": lst(c - PAD_BASE_DEPTH * a),
            "pad": {"axis": lst(a), "contact_m": lst(c), "friction_coefficient": PAD_MU},
            "cap_side_area_m2": V_CAP, "rod_side_area_m2": V_ROD,
            "chamber_volume_m3": V_VOL, "stroke_m": V_STROKE}


def strut(name, platen, direction):
    p = np.asarray(platen, dtype=float)
    return {"name": name, "base_m": lst(p - STRUT_H * unit(direction)), "platen_m": lst(p),
            "area_m2": STRUT_A, "pressure_pa": STRUT_P0, "gas_volume_m3": STRUT_V0,
            "polytropic_exponent": STRUT_GAMMA}


def make_table():
    """LHPOST6-like (7.6 m x 12.2 m, 180 t), deliberately not symmetric."""
    return {
        "platen": {
            "mass_kg": 180000.0,
            "inertia_kg_m2": [[9.2e5, -1.2e4, 8.0e3],
                              [-1.2e4, 2.35e6, -5.0e3],
                              [8.0e3, -5.0e3, 3.05e6]],
            "centre_of_mass_m": [0.12, -0.08, -0.45],
        },
        "actuators": [
            swivel("h1", [8.55, 0.42, -0.55], [6.1, 0.40, -0.5]),
            swivel("h2", [-8.65, -0.33, -0.47], [-6.1, -0.30, -0.5]),
            swivel("h3", [1.52, 6.35, -0.5], [1.5, 3.8, -0.5]),
            swivel("h4", [-2.03, -6.25, -0.53], [-2.0, -3.8, -0.5]),
            pad("v1", [4.6, 2.4, -1.0]),
            pad("v2", [4.4, -2.3, -1.0]),
            pad("v3", [0.1, 2.6, -1.0], [0.02, 0.0, 0.9998]),
            pad("v4", [-0.2, -2.5, -1.0]),
            pad("v5", [-4.5, 2.3, -1.0]),
            pad("v6", [-4.7, -2.4, -1.0]),
        ],
        "hold_down_struts": [
            strut("s1", [1.6, 2.05, -0.2], [0.03, -0.02, 1.0]),
            strut("s2", [-1.5, -2.1, -0.2], [-0.02, 0.025, 1.0]),
        ],
        "oil_bulk_modulus_pa": BETA,
    }


def make_table_symmetric():
    return {
        "platen": {
            "mass_kg": 180000.0,
            "inertia_kg_m2": [[9.2e5, 0.0, 0.0], [0.0, 2.35e6, 0.0], [0.0, 0.0, 3.05e6]],
            "centre_of_mass_m": [0.0, 0.0, -0.45],
        },
        "actuators": [
            swivel("h1", [8.1, 3.4, -0.5], [6.1, 2.0, -0.5]),       # a V at each end
            swivel("h2", [8.1, -3.4, -0.5], [6.1, -2.0, -0.5]),
            swivel("h3", [-8.1, 3.4, -0.5], [-6.1, 2.0, -0.5]),
            swivel("h4", [-8.1, -3.4, -0.5], [-6.1, -2.0, -0.5]),
            pad("v1", [4.5, 2.4, -1.0]),
            pad("v2", [4.5, -2.4, -1.0]),
            pad("v3", [0.0, 2.5, -1.0]),
            pad("v4", [0.0, -2.5, -1.0]),
            pad("v5", [-4.5, 2.4, -1.0]),
            pad("v6", [-4.5, -2.4, -1.0]),
        ],
        "hold_down_struts": [
            strut("s1", [2.0, 0.0, -1.0], [0.0, 0.0, 1.0]),
            strut("s2", [-2.0, 0.0, -1.0], [0.0, 0.0, 1.0]),
        ],
        "oil_bulk_modulus_pa": BETA,
    }


# ---------------------------------------------------------------- rotations

def elem(axis, a):
    """(R, dR/da, d2R/da2) of an elementary rotation about x, y or z."""
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
    """R, Rdot, Rddot by the product rule, R = A B C = Rz(yaw) Ry(pitch) Rx(roll)."""
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
    """Axial vector of the skew part of W."""
    return 0.5 * np.array([W[2, 1] - W[1, 2], W[0, 2] - W[2, 0], W[1, 0] - W[0, 1]])


def skew(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def omega_and_dot(ang, rate, acc):
    R, Rd, Rdd = rot_derivs(ang, rate, acc)
    w = vee(Rd @ R.T)
    wd = vee(Rdd @ R.T + Rd @ Rd.T)
    return R, w, wd


def e_matrix_numeric(ang):
    """Columns w(theta, e_k): w is linear in the Euler rates (built from Rdot R^T)."""
    cols = []
    for k in range(3):
        e = np.zeros(3)
        e[k] = 1.0
        cols.append(omega_and_dot(ang, e, np.zeros(3))[1])
    return np.column_stack(cols)


def e_matrix_standard(ang):
    roll, pitch, yaw = ang
    Rz = elem("z", yaw)[0]
    Ry = elem("y", pitch)[0]
    return np.column_stack([Rz @ Ry @ np.array([1.0, 0.0, 0.0]),
                            Rz @ np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])])


# ---------------------------------------------------------------- table geometry

class Table:
    def __init__(self, d):
        p = d["platen"]
        self.m = float(p["mass_kg"])
        self.Ic = np.array(p["inertia_kg_m2"], dtype=float)
        self.c = np.array(p["centre_of_mass_m"], dtype=float)
        self.act = d["actuators"]
        self.struts = d["hold_down_struts"]
        self.beta = float(d["oil_bulk_modulus_pa"])
        self.names = [a["name"] for a in self.act]
        self.strut_names = [s["name"] for s in self.struts]
        self.L0 = {}
        for a in self.act:
            if "platen_m" in a:
                self.L0[a["name"]] = float(np.linalg.norm(np.array(a["platen_m"])
                                                          - np.array(a["base_m"])))
        for s in self.struts:
            self.L0[s["name"]] = float(np.linalg.norm(np.array(s["platen_m"])
                                                      - np.array(s["base_m"])))

    def actuator_lines(self, t, R):
        """Per actuator: (stroke, unit vector, world point of the force)."""
        out = []
        for a in self.act:
            if "platen_m" in a:
                x = t + R @ np.array(a["platen_m"])
                d = x - np.array(a["base_m"])
                L = float(np.linalg.norm(d))
                out.append((L - self.L0[a["name"]], d / L, x))
            else:
                ax = np.array(a["pad"]["axis"], dtype=float)
                c = np.array(a["pad"]["contact_m"], dtype=float)
                e3 = np.array([0.0, 0.0, 1.0])
                s = (c[2] - e3 @ (R.T @ (c - t))) / (e3 @ (R.T @ ax))
                out.append((float(s), ax, c + s * ax))
        return out

    def strut_lines(self, t, R):
        """Per strut: (length, unit vector base -> platen, world point, force magnitude p A)."""
        out = []
        for s in self.struts:
            x = t + R @ np.array(s["platen_m"])
            d = x - np.array(s["base_m"])
            L = float(np.linalg.norm(d))
            A, V0 = s["area_m2"], s["gas_volume_m3"]
            V = V0 - A * (L - self.L0[s["name"]])
            p = s["pressure_pa"] * (V0 / V) ** s["polytropic_exponent"]
            out.append((L, d / L, x, p * A))
        return out

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

    def geometry_matrix(self, t, R):
        """6 x n: column i is [u_i; r_i x u_i] of actuator i (r about the reference point t)."""
        cols = []
        for _, u, x in self.actuator_lines(t, R):
            cols.append(np.concatenate([u, np.cross(x - t, u)]))
        return np.column_stack(cols)

    def passive_wrench(self, t, R):
        """Wrench about t of gravity and the struts."""
        rc = R @ self.c
        F = self.m * G_VEC
        M = np.cross(rc, self.m * G_VEC)
        for _, n, x, fa in self.strut_lines(t, R):
            f = -fa * n
            F = F + f
            M = M + np.cross(x - t, f)
        return F, M


def required_wrench(tab, pose, rate, acc):
    """Wrench about the current reference point of all forces except gravity."""
    t = np.asarray(pose[0:3])
    R, w, wd = omega_and_dot(pose[3:6], rate[3:6], acc[3:6])
    rc = R @ tab.c
    Iw = R @ tab.Ic @ R.T
    ac = np.asarray(acc[0:3]) + np.cross(wd, rc) + np.cross(w, np.cross(w, rc))
    F = tab.m * ac - tab.m * G_VEC
    M = Iw @ wd + np.cross(w, Iw @ w) + np.cross(rc, F)
    return w, wd, F, M


# ---------------------------------------------------------------- cases

def kinematics(tab):
    rng = np.random.default_rng(20250611)
    lim = np.array([0.5, 0.5, 0.1, 0.2, 0.2, 0.2])
    out = []
    for _ in range(50):
        pose = lim * rng.uniform(-1.0, 1.0, 6)
        t = pose[0:3]
        R = rot(pose[3:6])
        strokes, units, points = {}, {}, {}
        for name, (s, u, x) in zip(tab.names, tab.actuator_lines(t, R)):
            assert abs(np.linalg.norm(u) - 1.0) < 1e-14
            strokes[name] = float(s)
            units[name] = lst(u)
            points[name] = lst(x)
        lengths, forces = {}, {}
        for name, (L, n, x, fa) in zip(tab.strut_names, tab.strut_lines(t, R)):
            assert abs(np.linalg.norm(n) - 1.0) < 1e-14
            lengths[name] = L
            forces[name] = float(fa)
        # the pads' points lie on the platen's underside
        for a, (s, u, x) in zip(tab.act, tab.actuator_lines(t, R)):
            if "pad" in a:
                pz = (R.T @ (x - t))[2]
                assert abs(pz - a["pad"]["contact_m"][2]) < 1e-12
        out.append({"pose": lst(pose), "strokes_m": strokes, "unit_vectors": units,
                    "points_m": points, "strut_lengths_m": lengths, "strut_forces_n": forces})
    return out


NE_AMPL = [0.3, 0.2, 0.05, 0.05, 0.04, 0.06]
NE_FREQ = [0.4, 0.63, 1.7, 1.13, 0.87, 1.41]
NE_PHASE = [0.3, 1.1, 2.0, 0.7, 2.6, 1.5]


def ne_motion(t):
    q, qd, qdd = [], [], []
    for A, f, ph in zip(NE_AMPL, NE_FREQ, NE_PHASE):
        w = 2.0 * math.pi * f
        q.append(A * math.sin(w * t + ph))
        qd.append(A * w * math.cos(w * t + ph))
        qdd.append(-A * w * w * math.sin(w * t + ph))
    return np.array(q), np.array(qd), np.array(qdd)


def newton_euler(tab):
    samples = []
    for k in range(40):
        ts = (k + 0.5) * 0.125
        q, qd, qdd = ne_motion(ts)
        w, wd, F, M = required_wrench(tab, q, qd, qdd)
        # finite-difference checks of w and wdot against the pose
        h = 1e-5
        Rp, Rm, R0 = rot(ne_motion(ts + h)[0][3:6]), rot(ne_motion(ts - h)[0][3:6]), rot(q[3:6])
        w_fd = vee((Rp - Rm) / (2.0 * h) @ R0.T)
        assert np.max(np.abs(w_fd - w)) < 1e-8, (w_fd, w)
        wp = omega_and_dot(ne_motion(ts + h)[0][3:6], ne_motion(ts + h)[1][3:6], np.zeros(3))[1]
        wm = omega_and_dot(ne_motion(ts - h)[0][3:6], ne_motion(ts - h)[1][3:6], np.zeros(3))[1]
        assert np.max(np.abs((wp - wm) / (2.0 * h) - wd)) < 1e-7
        # the standard ZYX relation agrees with vee(Rdot R^T)
        assert np.max(np.abs(e_matrix_standard(q[3:6]) @ qd[3:6] - w)) < 1e-15
        samples.append({"t_s": ts, "pose": lst(q), "rates": lst(qd), "accelerations": lst(qdd),
                        "omega_rad_s": lst(w), "omega_dot_rad_s2": lst(wd),
                        "force_n": lst(F), "moment_n_m": lst(M)})
    return {"amplitudes": NE_AMPL, "frequencies_hz": NE_FREQ, "phases_rad": NE_PHASE,
            "samples": samples}


def modes(tab):
    t0, R0 = np.zeros(3), np.eye(3)
    K = np.zeros((6, 6))
    for a, (_, u, x) in zip(tab.act, tab.actuator_lines(t0, R0)):
        V = a["chamber_volume_m3"]
        k = tab.beta * (a["cap_side_area_m2"] ** 2 / V + a["rod_side_area_m2"] ** 2 / V)
        J = np.concatenate([u, np.cross(x, u)])
        K += k * np.outer(J, J)
    for s, (_, n, x, _) in zip(tab.struts, tab.strut_lines(t0, R0)):
        k = s["polytropic_exponent"] * s["pressure_pa"] * s["area_m2"] ** 2 / s["gas_volume_m3"]
        J = np.concatenate([n, np.cross(x, n)])
        K += k * np.outer(J, J)
    M = tab.mass_matrix(R0)
    assert np.array_equal(K, K.T) or np.max(np.abs(K - K.T)) <= 1e-9 * np.max(np.abs(K))
    assert np.max(np.abs(M - M.T)) == 0.0
    K = 0.5 * (K + K.T)
    assert np.all(np.linalg.eigvalsh(M) > 0.0)
    lam, phi = eigh(K, M)
    assert np.all(lam > 0.0)
    assert np.all(np.diff(lam) > 1e-3 * lam[1:])        # well separated: shapes unique
    shapes = []
    for i in range(6):
        v = phi[:, i]
        assert abs(v @ M @ v - 1.0) < 1e-10
        assert np.linalg.norm(K @ v - lam[i] * (M @ v)) < 1e-8 * lam[i] * np.linalg.norm(M @ v)
        j = int(np.argmax(np.abs(v)))
        if v[j] < 0.0:
            v = -v
        shapes.append(lst(v))
    return {"frequencies_hz": [math.sqrt(x) / (2.0 * math.pi) for x in lam], "shapes": shapes,
            "stiffness_matrix": [lst(r) for r in K], "mass_matrix": [lst(r) for r in M]}


def strut_paper():
    h, A, p0, V0, g = STRUT_H, STRUT_A, STRUT_P0, STRUT_V0, STRUT_GAMMA
    us = [0.05 * k for k in range(16)]
    force = []
    for u in us:
        L = math.hypot(u, h)
        V = V0 - A * (L - h)
        p = p0 * (V0 / V) ** g
        force.append(2.0 * p * A * u / L)     # = -F_x of two struts, platen at +u
    ke = 2.0 * p0 * A / h
    l0 = V0 / A
    kep = 0.5 * (g * h / l0 - 1.0) * ke
    assert abs(ke / 1.2545e6 - 1.0) < 1e-4
    u = us[-1]
    cubic_ratio = kep * u ** 2 / (ke * h ** 2)
    exact_ratio = (force[-1] - ke * u) / (ke * u)
    assert 0.032 < cubic_ratio < 0.034 and 0.02 < exact_ratio < 0.04
    assert 29e3 < kep * u ** 3 / h ** 2 < 31e3
    return {"h_m": h, "area_m2": A, "pressure_pa": p0, "gas_volume_m3": V0,
            "polytropic_exponent": g, "u_m": us, "force_n": force,
            "k_e_n_per_m": ke, "k_e_prime_n_per_m": kep,
            "cubic_term_ratio_at_0_75_m": cubic_ratio, "exact_excess_ratio_at_0_75_m": exact_ratio,
            "note": "force_n: restoring force of two struts (positive back towards neutral, "
                    "= -F_x); expansion K_e u + K'_e u^3/h^2"}


# ---------------------------------------------------------------- forward

# per actuator: (a1 N, f1 Hz, a2 N, f2 Hz)
EXCITATION = {
    "h1": (100e3, 1.3, 50e3, 2.7),
    "h2": (-80e3, 1.1, 60e3, 2.3),
    "h3": (90e3, 1.45, -50e3, 2.9),
    "h4": (70e3, 1.7, 60e3, 2.5),
    "v1": (20e3, 1.9, 10e3, 1.15),
    "v2": (-15e3, 2.1, 12e3, 1.55),
    "v3": (25e3, 1.2, -10e3, 3.0),
    "v4": (18e3, 2.6, 10e3, 1.35),
    "v5": (-20e3, 1.6, 12e3, 2.2),
    "v6": (15e3, 2.4, -10e3, 2.8),
}


def static_forces(tab):
    t0, R0 = np.zeros(3), np.eye(3)
    Gm = tab.geometry_matrix(t0, R0)
    F, M = tab.passive_wrench(t0, R0)
    rhs = -np.concatenate([F, M])
    f0 = np.linalg.pinv(Gm) @ rhs
    assert np.max(np.abs(Gm @ f0 - rhs)) < 1e-6
    return f0


def force_record(tab):
    f0 = static_forces(tab)
    n = int(round(DURATION_S * FS_HZ))
    rec = np.zeros((n + 1, len(tab.names)))
    for k in range(n + 1):
        t = k / FS_HZ
        ramp = math.sin(0.5 * math.pi * t) ** 2 if t < 1.0 else 1.0
        for i, name in enumerate(tab.names):
            a1, fr1, a2, fr2 = EXCITATION[name]
            var = a1 * math.sin(2.0 * math.pi * fr1 * t) + a2 * math.sin(2.0 * math.pi * fr2 * t)
            rec[k, i] = float(repr(float(f0[i] + ramp * var)))
    return f0, rec


def rhs_factory(tab, fk, dfk, tk):
    Mfull_c = tab.c
    zero3 = np.zeros(3)

    def rhs(tt, y):
        t, ang, v, rate = y[0:3], y[3:6], y[6:9], y[9:12]
        f = fk + dfk * (tt - tk)
        R, w, wd0 = omega_and_dot(ang, rate, zero3)     # wd0 = wdot at theta'' = 0
        F, M = tab.passive_wrench(t, R)
        for fi, (_, u, x) in zip(f, tab.actuator_lines(t, R)):
            F = F + fi * u
            M = M + np.cross(x - t, fi * u)
        rc = R @ Mfull_c
        Iw = R @ tab.Ic @ R.T
        b = np.concatenate([F - tab.m * np.cross(w, np.cross(w, rc)),
                            M - np.cross(w, Iw @ w)
                            - tab.m * np.cross(rc, np.cross(w, np.cross(w, rc)))])
        acc = np.linalg.solve(tab.mass_matrix(R), b)
        E = e_matrix_numeric(ang)
        angacc = np.linalg.solve(E, acc[3:6] - wd0)
        return np.concatenate([v, rate, acc[0:3], angacc])

    return rhs


def forward(tab, rec):
    n = rec.shape[0] - 1
    h = 1.0 / FS_HZ
    y = np.zeros(12)
    samples = [{"t_s": 0.0, "pose": lst(y[0:6]), "rates": lst(y[6:12])}]
    peak = np.zeros(6)
    checks = 0
    for k in range(n):
        tk, tk1 = k / FS_HZ, (k + 1) / FS_HZ
        rhs = rhs_factory(tab, rec[k], (rec[k + 1] - rec[k]) * FS_HZ, tk)
        sol = solve_ivp(rhs, (tk, tk1), y, method="DOP853", rtol=1e-11, atol=1e-13,
                        first_step=h)
        assert sol.success, sol.message
        y = sol.y[:, -1]
        peak = np.maximum(peak, np.abs(y[0:6]))
        if (k + 1) % OUTPUT_EVERY == 0:
            samples.append({"t_s": tk1, "pose": lst(y[0:6]), "rates": lst(y[6:12])})
            # consistency: the inverse (required_wrench) reproduces the applied wrench
            ydot = rhs(tk1, y)
            _, _, Freq, Mreq = required_wrench(tab, y[0:6], y[6:12], ydot[6:12])
            R = rot(y[3:6])
            F, M = np.zeros(3), np.zeros(3)
            for fi, (_, u, x) in zip(rec[k + 1], tab.actuator_lines(y[0:3], R)):
                F += fi * u
                M += np.cross(x - y[0:3], fi * u)
            for _, nn, x, fa in tab.strut_lines(y[0:3], R):
                F += -fa * nn
                M += np.cross(x - y[0:3], -fa * nn)
            assert np.max(np.abs(Freq - F)) < 1e-6 and np.max(np.abs(Mreq - M)) < 1e-6
            checks += 1
    assert peak[0] < 0.3 and peak[1] < 0.3 and peak[2] < 0.05 and np.all(peak[3:6] < 0.05), peak
    return samples, peak


def main():
    os.makedirs(OUT_DIR, exist_ok=True)
    table_d = make_table()
    sym_d = make_table_symmetric()
    tab, sym = Table(table_d), Table(sym_d)
    for T in (tab, sym):
        assert np.allclose(T.Ic, T.Ic.T, rtol=0.0, atol=0.0)
        assert np.all(np.linalg.eigvalsh(T.Ic) > 0.0)
        for s in T.struts:
            assert abs(T.L0[s["name"]] - STRUT_H) < 1e-12
    # the ZYX relation against vee(Rdot R^T) at a few angles
    rng = np.random.default_rng(7)
    for _ in range(20):
        ang = 0.3 * rng.uniform(-1.0, 1.0, 3)
        assert np.max(np.abs(e_matrix_numeric(ang) - e_matrix_standard(ang))) < 1e-15

    f0, rec = force_record(tab)
    samples, peak = forward(tab, rec)
    with open(os.path.join(OUT_DIR, FORCES_NAME), "w") as f:
        f.write("t_s," + ",".join(f"{n}_force_n" for n in tab.names) + "\n")
        for k in range(rec.shape[0]):
            f.write(repr(k / FS_HZ) + "," + ",".join(repr(float(x)) for x in rec[k]) + "\n")

    md = modes(tab)
    ms = modes(sym)
    neutral = {n: tab.L0[n] for n in list(tab.L0)}
    out = {
        "about": "Independent reference (Python/NumPy/SciPy, not platen) written by "
                 "tools/reference/multi_axis_cases.py; see its docstring for the conventions: "
                 "x longitudinal, y transverse, z up, g = 9.80665 m/s^2 along -z; pose "
                 "(x, y, z, roll, pitch, yaw), R = Rz(yaw) Ry(pitch) Rx(roll), platen point p at "
                 "t + R p; reference point = centre of the top surface at neutral; wrenches "
                 "about the current reference point; strut gas V = V0 - A (L - L0).",
        "table": table_d,
        "table_symmetric": sym_d,
        "neutral_lengths_m": neutral,
        "kinematics": kinematics(tab),
        "newton_euler": newton_euler(tab),
        "modes": md,
        "modes_symmetric": ms,
        "strut_paper": strut_paper(),
        "forward": {
            "sample_rate_hz": FS_HZ,
            "duration_s": DURATION_S,
            "forces_csv": FORCES_NAME,
            "forces_note": "forces_n per actuator are the columns {name}_force_n of "
                           "forces_csv (5121 samples, t_s = k/1024); linear interpolant "
                           "between samples; frictionless",
            "static_forces_n": {n: float(x) for n, x in zip(tab.names, f0)},
            "excitation": {n: {"a1_n": a1, "f1_hz": f1, "a2_n": a2, "f2_hz": f2}
                           for n, (a1, f1, a2, f2) in EXCITATION.items()},
            "output_every": OUTPUT_EVERY,
            "rtol": 1e-11,
            "atol": 1e-13,
            "samples": samples,
        },
    }
    with open(os.path.join(OUT_DIR, JSON_NAME), "w") as f:
        f.write(json.dumps(out, indent=1, sort_keys=True) + "\n")
    print("modes (Hz):", " ".join(f"{x:.4f}" for x in md["frequencies_hz"]))
    print("modes_symmetric (Hz):", " ".join(f"{x:.4f}" for x in ms["frequencies_hz"]))
    print("static forces (kN):", " ".join(f"{n}={x / 1e3:.1f}" for n, x in zip(tab.names, f0)))
    print("forward peak |q|:", " ".join(f"{x:.5g}" for x in peak))
    print(f"forward final pose: {samples[-1]['pose']}")


if __name__ == "__main__":
    main()
