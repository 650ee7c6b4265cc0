#!/usr/bin/env python3
"""Writes crates/platen-scenario/presets/lhpost6.json (compiled into platen), the LHPOST6 multi-axis table preset, and prints its capacity
check: each published LHPOST6 figure against what the preset's geometry and hydraulics give
through the closed forms platen uses (docs/lhpost6.md has the table of every value and its
source; this script is the source of both).

Usage (from the repository root, Python 3 with NumPy; SciPy for --controller-check):
    python3 tools/make_lhpost6_preset.py                       # writes the JSON, prints the check
    python3 tools/make_lhpost6_preset.py --check               # prints the check, writes nothing
    python3 tools/make_lhpost6_preset.py --controller-check    # the check and the controller's
                                                               # closed loop, writes nothing
The output is deterministic (sorted keys, values rounded as below).

Structure: PUBLISHED values (with their source), ASSUMED values (with the reason), then
derive() solves the remaining values from the published figures (the originals' V angle and
stroke, the new pair's stroke, size and valve, the struts' pressure, the vertical area and
valves, the chamber volumes) and rounds them; make_table() builds the preset, with the
controller (CONTROLLER_GAINS, tuned with tools/reference/multi_axis_loop.py, which
--controller-check runs on the bare table and with a rigid payload); Capacities computes, from
the preset dict alone, what platen will compute:

* force limits: push A_cap P_s - A_rod P_R, pull A_rod P_s - A_cap P_R (>= 0); single-acting
  (A_rod = 0): push A_cap P_s, pull 0 (no uplift);
* no-load velocity: double-acting extend K sqrt((A_a P_s - A_b P_R)/(A_a^3 + A_b^3)), retract
  the same with the roles swapped; single-acting extend K sqrt(P_s - p_a0)/A_a, retract
  K sqrt(p_a0 - P_R)/A_a at its static pressure p_a0 = f_0/A_a; K = m Q_r / sqrt(dp_r/2);
* per DOF at neutral, bare table: stroke = the largest excursion both ways with every actuator
  within its stroke (exact kinematics, bisection); velocity = the largest v both ways with
  |dstroke_i/dq . e_k v| within each actuator's extend/retract velocity; force (moment) = the
  largest generalised force both ways whose minimum-norm actuator forces, added to the
  minimum-norm forces that hold the platen still (weight, struts), stay within every
  actuator's push/pull; acceleration = the same for the wrench M e_k (through the centre of
  mass) -- as platen-model's MultiAxisTable::capacities;
* overturning moment = min(roll, pitch) moment capacity, bare and with the rated payload (20 MN
  centred on the top surface) added to the forces the verticals hold.

The kinematics (elem, rot, Table.actuator_lines, strut_lines, mass_matrix, geometry_matrix,
passive_wrench) are copied from tools/reference/multi_axis_cases.py.
"""

import json
import math
import os
import sys

import numpy as np

G = 9.80665
G_VEC = np.array([0.0, 0.0, -G])
OUT_JSON = os.path.join("crates", "platen-scenario", "presets", "lhpost6.json")
L_PER_MIN = 1.0 / 60000.0          # m^3/s per l/min

# ------------------------------------------------------------------ published values
# [P] paper  = Ozcelik, Luco, Conte, Trombetti, Restrepo (2008), Earthquake Engng Struct. Dyn.
#              37:243-268 (/work/shared/paper/lhpost-mechanical-model.md)
# [D1]       = https://ucsd.designsafe-ci.org/equipment-portfolio/ (LHPOST components)
# [D6]       = https://ucsd.designsafe-ci.org/equipment-portfolio-lhpost6 (LHPOST6)
# [N]        = https://par.nsf.gov/biblio/10540300 ("Dynamic model of the UC San Diego NHERI
#              six-degree-of-freedom large high-performance outdoor shake table", abstract)
# [I]        = the issue (LHPOST6 specification, Van Den Einde et al. 2021, Front. Built
#              Environ. 6:580333)
PLATEN_DIMS_M = (12.2, 7.6, 2.2)           # [D1], [P] 1.2
PLATEN_MASS_KG = 134.8e3                   # [P] 3.2 (from drawings)
ORIG_PUSH_N, ORIG_PULL_N = 4.2e6, 2.6e6    # [P] 1.2, each original horizontal actuator
ORIG_VALVES = 2                            # [D1] two four-stage servo-valves per actuator
VALVE_RATED_FLOW = 10000 * L_PER_MIN       # [D1] 10 000 l/min
VALVE_RATED_DROP_PA = 7e6                  # [D1] at 7 MPa
VALVE_HZ = 246.0                           # [P] 1.5 (pilot/third-stage resonance)
PAD_FROM_EDGE_M = 0.9                      # [I] three bearings per long side, 0.9 m in
PAD_MU = 0.0044                            # [P] 3.4, mu_e on the vertical bearings
N_STRUTS = 3                               # [N] "the three hold-down struts"
STRUT_AREA_M2 = 0.15                       # [P] 3.1
STRUT_PIN_TO_PIN_M = 3.3                   # [P] 2, h
STRUT_GAS_LENGTH_M = 2.1                   # [P] 2, l0 (gas volume A l0)
STRUT_EXPONENT = 1.44                      # [P] 2, gamma
PAYLOAD_N = 20e6                           # [D6], [P] 1.2
OVERTURNING_N_M = 50e6                     # [P] 1.2, [I]
PUBLISHED_AXES = {                         # [I]: stroke m, velocity m/s, acceleration g
    "x": (0.89, 3.0, 3.7),
    "y": (0.38, 2.5, 1.85),
    "z": (0.127, 0.5, 3.4),
}

# ------------------------------------------------------------------ assumed values
SUPPLY_PA, RETURN_PA = 20.7e6, 0.35e6      # the lhpost-2008 preset's (3000 psi; 50 psi)
BETA_PA = 1.0e9                            # the lhpost-2008 preset's effective bulk modulus
LEAKAGE = 2e-11                            # the lhpost-2008 preset's, every actuator
VALVE_ZETA, VALVE_DELAY_S = 0.5, 0.5e-3    # the lhpost-2008 preset's
ACCUMULATOR = {"precharge_pressure_pa": 13.8e6, "volume_m3": 8.0,
               "polytropic_exponent": 1.4, "pump_flow_m3_s": 0.05}   # the lhpost-2008 preset's
ORIG_CAP_M2, ORIG_ROD_M2 = 0.2051, 0.1291  # lhpost-2008: A_a P_s - A_b P_R = 4.2 MN, etc.
DEAD_LENGTH_M = 0.285                      # lhpost-2008: oil column 1.035 m beyond the 0.75 m
H_LENGTH_M = 4.0                           # the originals: swivel to swivel at neutral
H_APEX_HALF_M = 1.5                        # the originals' platen points: y = +-1.5 m, end faces
NEW_ANGLE_DEG = 71.0                       # the new pair: 71 deg from x (19 deg from y), the far
#                                            arm of each end's V; the y stroke needs >= 70.7 deg
#                                            at 5 m (min_new_angle_deg(), docs/lhpost6.md)
NEW_LENGTH_M = 5.0                         # the new pair: swivel to swivel at neutral
NEW_APEX_Y_M = 0.0                         # the new pair's platen points: mid end faces
CLEARANCE_M = 0.5                          # wanted: an actuator's axis this far from the platen's
#                                            outline (its body's radius, about 0.25 m, and as much
#                                            again) at every x, y stroke corner
H_HEIGHT_M = -PLATEN_DIMS_M[2] / 2         # horizontal actuators at the centre of mass height
NEW_VALVES = 1                             # one valve on each (smaller) new actuator
PAD_X_M = PLATEN_DIMS_M[0] / 2 - PAD_FROM_EDGE_M   # end bearings 0.9 m from the ends too
V_BODY_M = 1.5                             # pads' base_m: 1.5 m below the contact (not used)
V_VALVES = 2                               # two valves per vertical actuator
STRUT_X_M = (-4.0, 0.0, 4.0)               # along the centreline
STRUT_PIN_DEPTH_M = 0.85                   # platen pins inside the box, 0.85 m below the top
#                                            (0.25 m above the centre of mass): the open-loop
#                                            free flight is neutrally stable for 0.65-1.09 m


# ------------------------------------------------------------------ the controller
# At the published rate ([I]). The gains are assumed: tuned with the independent linearised loop
# tools/reference/multi_axis_loop.py (--controller-check prints its poles, margins and |H|; the
# reasons are in docs/lhpost6.md, "Controller"). Per DOF, in its own units (per m, or per rad
# for roll, pitch, yaw: with D = G d and G+ feedback the lever arm cancels, so a per-rad gain
# means what the same per-m gain means). Absent keys are 0.
CONTROLLER_RATE_HZ = 2048                  # [I]
DELTA_P_HIGHPASS_HZ = 0.1                  # the lhpost-2008 preset's
CONTROLLER_GAINS = {
    # horizontal DOFs: position, velocity and acceleration feedforward, acceleration feedback
    "x": {"displacement_gain_per_m": 1.51, "velocity_feedforward_s_per_m": 0.31,
          "acceleration_feedforward_s2_per_m": 0.0123, "acceleration_feedback_s2_per_m": 0.0138},
    "y": {"displacement_gain_per_m": 1.43, "velocity_feedforward_s_per_m": 0.349,
          "acceleration_feedforward_s2_per_m": 0.0114, "acceleration_feedback_s2_per_m": 0.0135},
    "yaw": {"displacement_gain_per_m": 2.31, "velocity_feedforward_s_per_m": 0.351,
            "acceleration_feedforward_s2_per_m": 0.00763,
            "acceleration_feedback_s2_per_m": 0.00936},
    # vertical DOFs: the same, and delta-p feedback through a high-pass
    "z": {"displacement_gain_per_m": 57.8, "velocity_feedforward_s_per_m": 0.666,
          "acceleration_feedforward_s2_per_m": 0.00236, "acceleration_feedback_s2_per_m": 0.00258,
          "delta_p_gain_per_pa": 3.9e-8, "delta_p_highpass_hz": DELTA_P_HIGHPASS_HZ},
    "roll": {"displacement_gain_per_m": 71.9, "velocity_feedforward_s_per_m": 0.643,
             "acceleration_feedforward_s2_per_m": 0.00171,
             "acceleration_feedback_s2_per_m": 0.00209,
             "delta_p_gain_per_pa": 4.51e-8, "delta_p_highpass_hz": DELTA_P_HIGHPASS_HZ},
    "pitch": {"displacement_gain_per_m": 102.0, "velocity_feedforward_s_per_m": 0.541,
              "acceleration_feedforward_s2_per_m": 0.00267,
              "acceleration_feedback_s2_per_m": 0.00221,
              "delta_p_gain_per_pa": 3.98e-8, "delta_p_highpass_hz": DELTA_P_HIGHPASS_HZ},
}
FORCE_BALANCE_GAIN = 3e-8                  # force-balance poles at -26.5, -33.3 1/s (30-38 ms)
CHECK_FREQS_HZ = (0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 40.0, 60.0)
CHECK_PAYLOAD = {"mass_kg": 200e3,         # the rigid payload of the controller check: a 200 t
                 "centre_m": (0.5, 0.0, 3.0),   # block 4 x 4 x 6 m (about 2.1 t/m3), its centre
                 "size_m": (4.0, 4.0, 6.0)}     # 3 m above the reference point, 0.5 m off in x
GAIN_KEYS = ("displacement_gain_per_m", "integral_gain_per_m_s", "velocity_feedforward_s_per_m",
             "acceleration_feedforward_s2_per_m", "velocity_feedback_s_per_m",
             "acceleration_feedback_s2_per_m", "delta_p_gain_per_pa", "delta_p_highpass_hz")


def r6(x):
    """Rounded for the JSON: 6 decimals (um, or 1e-6 of the unit); no negative zero."""
    return float(round(float(x), 6)) + 0.0


# ------------------------------------------------------------------ kinematics (copied from
# tools/reference/multi_axis_cases.py)

def elem(axis, a):
    c, s = math.cos(a), math.sin(a)
    if axis == "x":
        return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    if axis == "y":
        return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rot(ang):
    roll, pitch, yaw = ang
    return elem("z", yaw) @ elem("y", pitch) @ elem("x", roll)


def skew(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


class Table:
    def __init__(self, d):
        p = d["platen"]
        self.m = float(p["mass_kg"])
        self.Ic = np.array(p["inertia_kg_m2"], dtype=float)
        self.c = np.array(p["centre_of_mass_m"], dtype=float)
        self.act = d["actuators"]
        self.struts = d["hold_down_struts"]
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


def pose(q):
    q = np.asarray(q, dtype=float)
    return q[0:3], rot(q[3:6])


# ------------------------------------------------------------------ capacities

class Capacities:
    """What the preset's geometry and hydraulics give, bare table at neutral."""

    def __init__(self, d):
        self.d = d
        self.tab = Table(d)
        self.ps = d["supply_pressure_pa"]
        self.pr = d["return_pressure_pa"]
        t0, R0 = pose(np.zeros(6))
        self.G6 = self.tab.geometry_matrix(t0, R0)          # unit wrenches at neutral
        self.pinv = np.linalg.pinv(self.G6)                 # minimum-norm resolution
        F, M = self.tab.passive_wrench(t0, R0)
        self.hold = -np.concatenate([F, M])                 # what the actuators must give
        self.still = self.resolve(self.hold)
        self.M6 = self.tab.mass_matrix(R0)
        self.limits = [self.force_limits(a) for a in d["actuators"]]
        self.dstroke = self.stroke_gradient()
        # the stroke gradient is the unit wrench (virtual work), checked
        assert np.max(np.abs(self.dstroke - self.G6.T)) < 1e-6

    def resolve(self, wrench):
        f = self.pinv @ wrench
        assert np.max(np.abs(self.G6 @ f - wrench)) <= 1e-9 * max(1.0, np.max(np.abs(wrench)))
        return f

    def force_limits(self, a):
        A, B = a["cap_side_area_m2"], a["rod_side_area_m2"]
        push = max(A * self.ps - B * self.pr, 0.0)
        pull = max(B * self.ps - A * self.pr, 0.0)
        return -pull, push

    def scale(self, f, still=None):
        """The largest k >= 0 with still + k f and still - k f within every force limit."""
        still = self.still if still is None else still

        def reach(sign):
            k = math.inf
            for fi, f0, (lo, hi) in zip(f, still, self.limits):
                x = sign * fi
                if x > 1e-12 * np.max(np.abs(f)):
                    k = min(k, max((hi - f0) / x, 0.0))
                elif x < -1e-12 * np.max(np.abs(f)):
                    k = min(k, max((lo - f0) / x, 0.0))
            return k

        return min(reach(1.0), reach(-1.0))

    def force(self, k, still=None):
        e = np.zeros(6)
        e[k] = 1.0
        return self.scale(self.resolve(e), still)

    def acceleration(self, k):
        e = np.zeros(6)
        e[k] = 1.0
        return self.scale(self.resolve(self.M6 @ e))

    def stroke_gradient(self, h=1e-7):
        n = len(self.d["actuators"])
        J = np.zeros((n, 6))
        for k in range(6):
            qp, qm = np.zeros(6), np.zeros(6)
            qp[k], qm[k] = h, -h
            sp = [s for s, _, _ in self.tab.actuator_lines(*pose(qp))]
            sm = [s for s, _, _ in self.tab.actuator_lines(*pose(qm))]
            J[:, k] = (np.array(sp) - np.array(sm)) / (2.0 * h)
        return J

    def gain(self, a):
        sv = a["servo_valve"]
        return sv["count"] * sv["rated_flow_m3_s"] / math.sqrt(sv["rated_pressure_drop_pa"] / 2.0)

    def velocity_limits(self, i):
        """(extend, retract) no-load velocity of actuator i, m/s."""
        a = self.d["actuators"][i]
        K = self.gain(a)
        A, B = a["cap_side_area_m2"], a["rod_side_area_m2"]
        if B > 0.0:
            den = A ** 3 + B ** 3
            ext = K * math.sqrt(max(A * self.ps - B * self.pr, 0.0) / den)
            ret = K * math.sqrt(max(B * self.ps - A * self.pr, 0.0) / den)
        else:
            p0 = self.still[i] / A
            ext = K * math.sqrt(max(self.ps - p0, 0.0)) / A
            ret = K * math.sqrt(max(p0 - self.pr, 0.0)) / A
        return ext, ret

    def velocity(self, k):
        v = math.inf
        for i in range(len(self.d["actuators"])):
            ext, ret = self.velocity_limits(i)
            g = self.dstroke[i, k]
            if abs(g) > 1e-9:
                v = min(v, ext / abs(g), ret / abs(g))   # both signs of v
        return v

    def stroke(self, k):
        def fits(x):
            q = np.zeros(6)
            q[k] = x
            lines = self.tab.actuator_lines(*pose(q))
            return all(abs(s) <= a["stroke_m"] for (s, _, _), a in zip(lines, self.d["actuators"]))

        def one_way(sign):
            hi = 1e-3
            while fits(sign * hi) and hi < 1e3:
                hi *= 2.0
            lo = 0.0
            for _ in range(60):
                mid = 0.5 * (lo + hi)
                if fits(sign * mid):
                    lo = mid
                else:
                    hi = mid
            return lo

        return min(one_way(1.0), one_way(-1.0))

    def still_with_payload(self, payload_n):
        """The holding forces with a payload's weight at the reference point (centred)."""
        return self.resolve(self.hold + np.array([0.0, 0.0, payload_n, 0.0, 0.0, 0.0]))

    def overturning(self, payload_n=0.0):
        still = self.still_with_payload(payload_n)
        return min(self.force(3, still), self.force(4, still))

    def static_payload(self):
        """The largest centred vertical load the actuators carry on top of the platen."""
        u = self.resolve(np.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0]))
        k = math.inf
        for fi, f0, (lo, hi) in zip(u, self.still, self.limits):
            if fi > 1e-12:
                k = min(k, (hi - f0) / fi)
            elif fi < -1e-12:
                k = min(k, (lo - f0) / fi)
        return k

    def open_loop_stiffness(self, h=1e-6):
        """-dW/dq at neutral with the actuator forces held at their static values: the
        platen's free flight linearised (gravity, struts, pads on their fixed lines)."""
        def wrench(q):
            t, R = pose(q)
            F, M = self.tab.passive_wrench(t, R)
            for fi, (_, u, x) in zip(self.still, self.tab.actuator_lines(t, R)):
                F = F + fi * u
                M = M + np.cross(x - t, fi * u)
            return np.concatenate([F, M])

        K = np.zeros((6, 6))
        for k in range(6):
            qp, qm = np.zeros(6), np.zeros(6)
            qp[k], qm[k] = h, -h
            K[:, k] = -(wrench(qp) - wrench(qm)) / (2.0 * h)
        return K

    def oil_column_modes(self):
        """Frequencies (Hz) of the platen on its oil columns and struts, valves shut."""
        t0, R0 = pose(np.zeros(6))
        K = np.zeros((6, 6))
        for a, (_, u, x) in zip(self.d["actuators"], self.tab.actuator_lines(t0, R0)):
            V = a["chamber_volume_m3"]
            k = self.d["oil_bulk_modulus_pa"] * (a["cap_side_area_m2"] ** 2
                                                  + a["rod_side_area_m2"] ** 2) / V
            J = np.concatenate([u, np.cross(x, u)])
            K += k * np.outer(J, J)
        for s, (_, n, x, _) in zip(self.d["hold_down_struts"], self.tab.strut_lines(t0, R0)):
            k = s["polytropic_exponent"] * s["pressure_pa"] * s["area_m2"] ** 2 / s["gas_volume_m3"]
            J = np.concatenate([n, np.cross(x, n)])
            K += k * np.outer(J, J)
        L = np.linalg.cholesky(self.M6)
        Li = np.linalg.inv(L)
        lam = np.linalg.eigvalsh(Li @ (0.5 * (K + K.T)) @ Li.T)
        return [math.sqrt(max(x, 0.0)) / (2.0 * math.pi) for x in lam]


# ------------------------------------------------------------------ the preset

def box_inertia(m, dims):
    a, b, c = dims
    return [[m / 12.0 * (b * b + c * c), 0.0, 0.0],
            [0.0, m / 12.0 * (a * a + c * c), 0.0],
            [0.0, 0.0, m / 12.0 * (a * a + b * b)]]


def valve(count, flow):
    return {"count": count, "rated_flow_m3_s": r6(flow),
            "rated_pressure_drop_pa": VALVE_RATED_DROP_PA,
            "natural_frequency_hz": VALVE_HZ, "damping_ratio": VALVE_ZETA,
            "delay_s": VALVE_DELAY_S}


def single_volume(cap, rod, column_m):
    """One chamber volume whose oil-column stiffness beta (A_a^2 + A_b^2)/V equals that of the
    two chambers of an effective column length each, beta (A_a^2/(A_a l) + A_b^2/(A_b l))."""
    return column_m * (cap * cap + rod * rod) / (cap + rod)


def make_table(v, new_angle_deg=NEW_ANGLE_DEG, new_length_m=NEW_LENGTH_M):
    """The preset's `table` from the values `v` (see derive()); the new pair's angle and length
    may be varied (the layout check)."""
    half_x = PLATEN_DIMS_M[0] / 2.0
    depth = PLATEN_DIMS_M[2]
    horizontal = []
    # (name, end sign, side sign, original?): the originals h1 (+x end, towards +y) and h3 (-x,
    # towards -y) at the V angle, 4 m long, platen points at y = +-1.5 m; the new pair h2 (+x end,
    # towards -y) and h4 (-x, towards +y) at NEW_ANGLE_DEG, NEW_LENGTH_M long, platen points in the
    # middle of the end faces. Symmetric under a half turn about z (not about the x-z or y-z
    # planes).
    for name, ex, sy, original in (("h1", 1, 1, True), ("h2", 1, -1, False),
                                   ("h3", -1, -1, True), ("h4", -1, 1, False)):
        if original:
            th, length, apex_y = v["v_angle_rad"], H_LENGTH_M, sy * H_APEX_HALF_M
            stroke, valves, flow = v["h_stroke_m"], ORIG_VALVES, VALVE_RATED_FLOW
        else:
            th, length, apex_y = math.radians(new_angle_deg), new_length_m, -ex * NEW_APEX_Y_M
            stroke, valves, flow = v["new_stroke_m"], NEW_VALVES, v["new_valve_flow_m3_s"]
        platen = [ex * half_x, apex_y, H_HEIGHT_M]
        base = [platen[0] + ex * length * math.cos(th), platen[1] + sy * length * math.sin(th),
                H_HEIGHT_M]
        k = 1.0 if original else v["new_scale"]
        cap, rod = v["orig_cap_m2"] * k, v["orig_rod_m2"] * k
        if not original:
            cap, rod = round(cap, 4), round(rod, 4)
        horizontal.append({
            "name": name, "base_m": [r6(x) for x in base], "platen_m": [r6(x) for x in platen],
            "cap_side_area_m2": cap, "rod_side_area_m2": rod,
            "chamber_volume_m3": round(single_volume(cap, rod, stroke + DEAD_LENGTH_M), 4),
            "stroke_m": stroke, "leakage_m3_s_per_pa": LEAKAGE,
            "servo_valve": valve(valves, flow),
        })
    vertical = []
    pad_y = PLATEN_DIMS_M[1] / 2.0 - PAD_FROM_EDGE_M
    n = 0
    for x in (PAD_X_M, 0.0, -PAD_X_M):
        for y in (pad_y, -pad_y):
            n += 1
            contact = [r6(x), r6(y), r6(-depth)]
            vertical.append({
                "name": f"v{n}", "base_m": [r6(x), r6(y), r6(-depth - V_BODY_M)],
                "pad": {"axis": [0.0, 0.0, 1.0], "contact_m": contact,
                        "friction_coefficient": PAD_MU},
                "cap_side_area_m2": v["v_area_m2"], "rod_side_area_m2": 0.0,
                "chamber_volume_m3": round(v["v_area_m2"] * (v["v_stroke_m"] + DEAD_LENGTH_M), 4),
                "stroke_m": v["v_stroke_m"], "leakage_m3_s_per_pa": LEAKAGE,
                "servo_valve": valve(V_VALVES, v["v_valve_flow_m3_s"]),
            })
    struts = []
    for j, x in enumerate(STRUT_X_M):
        pin = [r6(x), 0.0, r6(-STRUT_PIN_DEPTH_M)]
        struts.append({
            "name": f"s{j + 1}", "platen_m": pin,
            "base_m": [pin[0], pin[1], r6(pin[2] - STRUT_PIN_TO_PIN_M)],
            "area_m2": STRUT_AREA_M2, "pressure_pa": v["strut_pressure_pa"],
            "gas_volume_m3": r6(STRUT_AREA_M2 * STRUT_GAS_LENGTH_M),
            "polytropic_exponent": STRUT_EXPONENT,
        })
    for a in horizontal + vertical:
        # every chamber keeps oil at either end of the stroke
        for area in (a["cap_side_area_m2"], a["rod_side_area_m2"]):
            assert a["chamber_volume_m3"] - area * a["stroke_m"] > 0.0, a["name"]
    inertia = box_inertia(PLATEN_MASS_KG, PLATEN_DIMS_M)
    return {
        "platen": {
            "mass_kg": PLATEN_MASS_KG,
            "inertia_kg_m2": [[r6(x) for x in row] for row in inertia],
            "centre_of_mass_m": [0.0, 0.0, r6(-depth / 2.0)],
        },
        "actuators": horizontal + vertical,
        "hold_down_struts": struts,
        "oil_bulk_modulus_pa": BETA_PA,
        "supply_pressure_pa": SUPPLY_PA,
        "return_pressure_pa": RETURN_PA,
        "accumulator": dict(ACCUMULATOR),
        "controller": controller(),
    }


def controller():
    """The preset's `controller`: every gain key written, absent ones as 0."""
    dof = {}
    for name, g in CONTROLLER_GAINS.items():
        full = {key: 0.0 for key in GAIN_KEYS}
        full.update(g)
        dof[name] = full
    return {"sample_rate_hz": CONTROLLER_RATE_HZ, "dof": dof,
            "force_balance_gain": FORCE_BALANCE_GAIN}


def limits_block():
    out = {}
    for axis, (stroke, vel, acc_g) in PUBLISHED_AXES.items():
        out[axis] = {"stroke_m": stroke, "velocity_m_s": vel,
                     "acceleration_m_s2": r6(acc_g * G)}
    out["overturning_moment_n_m"] = OVERTURNING_N_M
    return out


def bisect(f, lo, hi, n=100):
    """The root of an increasing f on [lo, hi]."""
    for _ in range(n):
        mid = 0.5 * (lo + hi)
        if f(mid) < 0.0:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def derive():
    """Solves the values the sources do not give from the published figures, and rounds
    them. Each step uses only the values fixed before it."""
    v = {"orig_cap_m2": ORIG_CAP_M2, "orig_rod_m2": ORIG_ROD_M2, "new_scale": 1.0,
         "new_stroke_m": 1.0, "new_valve_flow_m3_s": VALVE_RATED_FLOW,
         "v_stroke_m": PUBLISHED_AXES["z"][0], "v_area_m2": 0.3, "v_valve_flow_m3_s": 0.1,
         "strut_pressure_pa": 13.8e6}
    notes = {}
    # 1. The originals' V angle. The new pair sets both horizontal accelerations (step 5). The
    #    force balance splits a horizontal force between the two pairs, each pair (h1 with h3,
    #    h2 with h4) acting as one force through the reference point along its own direction
    #    (angle th from x for the originals, phi for the new pair): each new actuator carries
    #    F_x sin(th) / (2 sin(th + phi)) of an x force and F_y cos(th) / (2 sin(th + phi)) of a
    #    y force. With its pull limiting both, a_y / a_x = tan(th) (published 1.85/3.7), whatever
    #    phi is (a symmetric V, phi = th, gives the same angle).
    v["v_angle_rad"] = math.atan(PUBLISHED_AXES["y"][2] / PUBLISHED_AXES["x"][2])
    # 2. The originals' stroke: the published x stroke with the exact kinematics (the new pair,
    #    with a long stroke for now, does not limit x).
    v["h_stroke_m"] = 1.0

    def stroke_capacity(key, k, s):
        v[key] = s
        return Capacities(make_table(v)).stroke(k)

    s = bisect(lambda s: stroke_capacity("h_stroke_m", 0, s) - PUBLISHED_AXES["x"][0], 0.3, 1.5)
    v["h_stroke_m"] = math.ceil(s * 1000.0) / 1000.0
    notes["h_stroke_exact_m"] = s
    # 3. The struts' pressure: bare, the verticals (single-acting) can pull the platen down
    #    no faster than its weight and the struts' pull: a_z,down = (m g + n p A) / m = 3.4 g.
    az = PUBLISHED_AXES["z"][2] * G
    p = (az - G) * PLATEN_MASS_KG / (N_STRUTS * STRUT_AREA_M2)
    v["strut_pressure_pa"] = round(p, -4)
    notes["strut_pressure_exact_pa"] = p
    # 4. The new pair's stroke: the published y stroke, exact kinematics. It does not limit x
    #    (checked) because the pair is at least 66.9 deg from x: see docs/lhpost6.md.
    s = bisect(lambda s: stroke_capacity("new_stroke_m", 1, s) - PUBLISHED_AXES["y"][0], 0.05, 1.0)
    v["new_stroke_m"] = math.ceil(s * 1000.0) / 1000.0
    notes["new_stroke_exact_m"] = s
    assert Capacities(make_table(v)).stroke(0) >= PUBLISHED_AXES["x"][0], "the new pair limits x"
    # 5. The new pair's size: its areas are the originals' scaled by k, so that a_x = 3.7 g;
    #    the check shows a_y = 1.85 g follows (step 1). k = 1: all four like the originals.
    cap = Capacities(make_table(v))
    notes["ax_all_original_g"] = cap.acceleration(0) / G
    notes["ay_all_original_g"] = cap.acceleration(1) / G

    def ax_of(k):
        v["new_scale"] = k
        return Capacities(make_table(v)).acceleration(0) / G - PUBLISHED_AXES["x"][2]

    k = bisect(ax_of, 0.05, 1.0)
    v["new_scale"] = k
    notes["new_scale_exact"] = k
    # 6. The new pair's valve: one valve, rated for the published y velocity (the new pair
    #    sets it: the originals allow 2.767 m/s / sin(th) = 6.2 m/s), rounded to 100 l/min.
    cap = Capacities(make_table(v))
    flow = v["new_valve_flow_m3_s"] * PUBLISHED_AXES["y"][1] / cap.velocity(1)
    notes["new_valve_flow_exact_l_min"] = flow / L_PER_MIN
    v["new_valve_flow_m3_s"] = round(flow / L_PER_MIN, -2) * L_PER_MIN
    # 7. The vertical area: the overturning moment with the rated payload (20 MN centred) on
    #    the pads is the published 50 MN m; the push side of the pads limits it there.
    def overturning(area):
        v["v_area_m2"] = area
        return Capacities(make_table(v)).overturning(PAYLOAD_N) - OVERTURNING_N_M

    area = bisect(overturning, 0.05, 2.0)
    v["v_area_m2"] = round(area, 4)
    notes["v_area_exact_m2"] = area
    # 8. The verticals' valves: the z velocity both ways; down (retract) is the slower, driven
    #    by the static pressure p_a0 - P_R only. Two valves per actuator, each rated for the
    #    flow that gives 0.5 m/s, rounded to 100 l/min.
    cap = Capacities(make_table(v))
    i = next(j for j, a in enumerate(cap.d["actuators"]) if "pad" in a)
    ext, ret = cap.velocity_limits(i)
    flow = v["v_valve_flow_m3_s"] * PUBLISHED_AXES["z"][1] / min(ext, ret)
    notes["v_valve_flow_exact_l_min"] = flow / L_PER_MIN
    v["v_valve_flow_m3_s"] = round(flow / L_PER_MIN, -2) * L_PER_MIN
    return v, notes


# ------------------------------------------------------------------ the check

def check(table, notes):
    cap = Capacities(table)
    rows = []

    def row(axis, qty, published, value, unit, scale=1.0, kind="="):
        rows.append((axis, qty, published / scale, value / scale, unit,
                     value / published, kind))

    for k, axis in enumerate(("x", "y", "z")):
        stroke, vel, acc_g = PUBLISHED_AXES[axis]
        row(axis, "stroke", stroke, cap.stroke(k), "m")
        row(axis, "velocity", vel, cap.velocity(k), "m/s")
        row(axis, "acceleration", acc_g * G, cap.acceleration(k), "g", G)
    row("roll/pitch", "overturning moment, 20 MN payload", OVERTURNING_N_M,
        cap.overturning(PAYLOAD_N), "MN.m", 1e6)
    row("z", "static payload", PAYLOAD_N, cap.static_payload(), "MN", 1e6, kind=">=")

    lines = []
    lines.append(f"{'axis':<11} {'quantity':<34} {'published':>10} {'platen':>10} {'unit':<5} "
                 f"{'ratio':>6}  meets")
    met = 0
    for axis, qty, pub, val, unit, ratio, kind in rows:
        ok = abs(ratio - 1.0) <= 0.05 if kind == "=" else ratio >= 0.95
        met += ok
        verdict = ("yes" if ok else "NO") + (" (a bound: >=)" if kind == ">=" else "")
        lines.append(f"{axis:<11} {qty:<34} {pub:>10.4g} {val:>10.4g} {unit:<5} {ratio:>6.3f}  "
                     f"{verdict}")
    lines.append("")
    lines.append(f"met (within 5 %, or at least the published bound): {met} of {len(rows)}")
    lines.append("")
    lines.append("information (no published figure):")
    info = [
        ("overturning moment, bare (roll, pitch)",
         f"{cap.force(3) / 1e6:.4g}, {cap.force(4) / 1e6:.4g} MN.m"),
        ("overturning moment, 20 MN payload (roll, pitch)",
         f"{cap.force(3, cap.still_with_payload(PAYLOAD_N)) / 1e6:.4g}, "
         f"{cap.force(4, cap.still_with_payload(PAYLOAD_N)) / 1e6:.4g} MN.m"),
        ("z acceleration up / down",
         "{:.4g} g / {:.4g} g".format(*z_up_down(cap))),
        ("z acceleration up / down, rigid 20 MN payload",
         "{:.4g} g / {:.4g} g".format(*z_up_down_payload(cap, PAYLOAD_N))),
        ("force through the reference point x, y, z",
         ", ".join(f"{cap.force(k) / 1e6:.4g}" for k in range(3)) + " MN"),
        ("roll, pitch, yaw angle",
         ", ".join(f"{cap.stroke(k):.4g}" for k in range(3, 6)) + " rad"),
        ("roll, pitch, yaw rate",
         ", ".join(f"{cap.velocity(k):.4g}" for k in range(3, 6)) + " rad/s"),
        ("roll, pitch, yaw angular acceleration",
         ", ".join(f"{cap.acceleration(k):.4g}" for k in range(3, 6)) + " rad/s2"),
    ]
    for i, a in enumerate(table["actuators"]):
        if i in (0, 1, 4):
            lo, hi = cap.limits[i]
            ext, ret = cap.velocity_limits(i)
            info.append((f"{a['name']}: push / pull, extend / retract",
                         f"{hi / 1e6:.4g} / {-lo / 1e6:.4g} MN, {ext:.4g} / {ret:.4g} m/s"))
    info.append(("static forces: h, v (each), struts' pull (each)",
                 f"{abs(round(cap.still[0] / 1e3, 6)):.4g} kN, {cap.still[4] / 1e6:.4g} MN, "
                 f"{cap.tab.strut_lines(np.zeros(3), np.eye(3))[0][3] / 1e6:.4g} MN"))
    info.append(("verticals' static pressure p_a0",
                 f"{cap.still[4] / table['actuators'][4]['cap_side_area_m2'] / 1e6:.4g} MPa"))
    info.append(("oil-column modes (valves shut)",
                 ", ".join(f"{f:.3g}" for f in cap.oil_column_modes()) + " Hz"))
    K = cap.open_loop_stiffness()
    lam = np.linalg.eigvals(np.linalg.solve(cap.M6, K))
    stable = all(abs(z.imag) <= 1e-9 * abs(z) and z.real > 0.0 for z in lam)
    freqs = sorted(math.sqrt(z.real) / (2 * math.pi) for z in lam if z.real > 0)
    info.append(("open loop at fixed forces: linearised free flight",
                 ("neutrally stable, " if stable else "UNSTABLE, ")
                 + ", ".join(f"{f:.3g}" for f in freqs) + " Hz"))
    e = np.zeros(6)
    e[0] = 1.0
    fx = cap.resolve(cap.M6 @ e) * cap.acceleration(0)
    info.append(("at a_x: h1 / h2 force, of their pull limits",
                 f"{abs(fx[0]) / 1e6:.4g} / {abs(fx[1]) / 1e6:.4g} MN, of "
                 f"{-cap.limits[0][0] / 1e6:.4g} / {-cap.limits[1][0] / 1e6:.4g} MN"))
    alone = []
    for pair, axis in ((("h2", "h4"), 0), (("h1", "h3"), 1)):
        t = json.loads(json.dumps(table))
        for a in t["actuators"]:
            if "platen_m" in a and a["name"] not in pair:
                a["stroke_m"] = 1e3
        alone.append(Capacities(t).stroke(axis))
    info.append(("x stroke the new pair allows; y, the originals",
                 f"{alone[0]:.4g} m; {alone[1]:.4g} m"))
    cl, sw = clearance(table), swivel_turn_deg(table)
    info.append(("h1 / h2 axis to the platen, worst stroke corner",
                 f"{cl['h1']:.3g} / {cl['h2']:.3g} m (wanted >= {CLEARANCE_M:g} m)"))
    info.append(("h1 / h2 swivel turn, worst stroke corner",
                 f"{sw['h1']:.3g} / {sw['h2']:.3g} deg"))
    info.append(("if the new pair were like the originals: a_x, a_y",
                 f"{notes['ax_all_original_g']:.4g} g, {notes['ay_all_original_g']:.4g} g"))
    for name, text in info:
        lines.append(f"  {name:<50} {text}")
    return "\n".join(lines), rows


def min_new_angle_deg(length=None):
    """The smallest angle from x of an actuator (horizontal, `length` m swivel to swivel) that
    reaches its stroke at the published y stroke Y but not at the published x stroke X (exact
    kinematics: its stroke at a translation q is sqrt(L^2 + 2 L |u.q| + q^2) - L at worst):
    Y sin(phi) - X cos(phi) >= (X^2 - Y^2) / (2 L)."""
    length = NEW_LENGTH_M if length is None else length
    X, Y = PUBLISHED_AXES["x"][0], PUBLISHED_AXES["y"][0]
    rhs = 0.0 if math.isinf(length) else (X * X - Y * Y) / (2.0 * length)
    phi = bisect(lambda a: Y * math.sin(a) - X * math.cos(a) - rhs, 0.0, math.pi / 2)
    return math.degrees(phi)


def stroke_corners():
    X, Y = PUBLISHED_AXES["x"][0], PUBLISHED_AXES["y"][0]
    return [(dx, dy) for dx in (-X, 0.0, X) for dy in (-Y, 0.0, Y)]


def clearance(table):
    """Per horizontal actuator (plan view): the smallest distance from its axis (platen point to
    base) to the platen's outline over the nine x, y stroke corners (-1 if the axis enters the
    platen)."""
    hx, hy = PLATEN_DIMS_M[0] / 2.0, PLATEN_DIMS_M[1] / 2.0
    out = {}
    for a in table["actuators"]:
        if "platen_m" not in a:
            continue
        worst = math.inf
        for dx, dy in stroke_corners():
            p = np.array(a["platen_m"][:2]) + [dx, dy]
            b = np.array(a["base_m"][:2])
            length = float(np.linalg.norm(b - p))
            u = (b - p) / length
            for cx, cy in ((hx, hy), (hx, -hy), (-hx, -hy), (-hx, hy)):
                w = np.array([cx + dx, cy + dy]) - p
                t = min(max(float(w @ u), 0.0), length)
                worst = min(worst, float(np.linalg.norm(w - t * u)))
            for t in np.linspace(0.05, length, 200):
                q = p + t * u
                if abs(q[0] - dx) < hx and abs(q[1] - dy) < hy:
                    worst = -1.0
        out[a["name"]] = worst
    return out


def swivel_turn_deg(table):
    """Per horizontal actuator: the largest turn of its axis (plan view) from neutral over the
    nine x, y stroke corners, degrees."""
    out = {}
    for a in table["actuators"]:
        if "platen_m" not in a:
            continue
        p0, b = np.array(a["platen_m"][:2]), np.array(a["base_m"][:2])
        u0 = (b - p0) / np.linalg.norm(b - p0)
        worst = 0.0
        for dx, dy in stroke_corners():
            u = b - (p0 + [dx, dy])
            u = u / np.linalg.norm(u)
            worst = max(worst, math.degrees(math.acos(min(1.0, float(u @ u0)))))
        out[a["name"]] = worst
    return out


def z_up_down(cap):
    e = np.zeros(6)
    e[2] = 1.0
    f = cap.resolve(cap.M6 @ e)
    up = down = math.inf
    for fi, f0, (lo, hi) in zip(f, cap.still, cap.limits):
        if fi > 1e-12:
            up = min(up, (hi - f0) / fi)
            down = min(down, (f0 - lo) / fi)
    return up / G, down / G


def z_up_down_payload(cap, payload_n):
    """Up and down z acceleration with a rigid centred payload (its weight on the pads, its
    mass moving with the platen's z): the verticals' margins over the loaded holding forces."""
    still = cap.still_with_payload(payload_n)
    u = cap.resolve(np.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0]))
    up = down = math.inf
    for fi, f0, (lo, hi) in zip(u, still, cap.limits):
        if fi > 1e-12:
            up = min(up, (hi - f0) / fi)
            down = min(down, (f0 - lo) / fi)
    mass = cap.tab.m + payload_n / G
    return up / mass / G, down / mass / G


# ------------------------------------------------------------------ the controller check

def with_payload(table, payload=None):
    """A copy of `table` whose platen carries a rigid block (mass, centre, size: its own
    inertia as a uniform box), merged into the platen's mass, centre of mass and inertia."""
    payload = CHECK_PAYLOAD if payload is None else payload
    t = json.loads(json.dumps(table))
    p = t["platen"]
    m0, m1 = p["mass_kg"], payload["mass_kg"]
    c0, c1 = np.array(p["centre_of_mass_m"]), np.array(payload["centre_m"])
    m = m0 + m1
    c = (m0 * c0 + m1 * c1) / m

    def about(inertia, mass, d):
        return np.array(inertia) + mass * (float(d @ d) * np.eye(3) - np.outer(d, d))

    inertia = (about(p["inertia_kg_m2"], m0, c0 - c)
               + about(box_inertia(m1, payload["size_m"]), m1, c1 - c))
    p["mass_kg"] = m
    p["centre_of_mass_m"] = [float(x) for x in c]
    p["inertia_kg_m2"] = inertia.tolist()
    return t


def loop_report(table, label):
    """Closed-loop poles, per-DOF margins and diagonal |H| of `table` by
    tools/reference/multi_axis_loop.py, as lines of text."""
    here = os.path.dirname(os.path.abspath(__file__))
    sys.path.insert(0, os.path.join(here, "reference"))
    import multi_axis_loop as mal   # noqa: E402 (NumPy + SciPy, needed only here)

    lp = mal.Loop(table)
    stable, maxre, nzero, poles = lp.stability()
    rest = [z for z in poles if abs(z) >= 1e-6]
    osc = sorted((z for z in rest if z.imag > 1e-6), key=lambda z: -z.real / abs(z))
    real = sorted((z.real for z in rest if abs(z.imag) <= 1e-6), reverse=True)
    zmin = min(-z.real / abs(z) for z in rest)
    lines = [f"{label}: {len(poles)} closed-loop poles (Pade 4 for the delay and the hold): "
             f"{'STABLE' if stable else 'NOT STABLE'}",
             f"  {nzero} at s = 0 (the four double-acting actuators' mean-pressure modes); the "
             f"others' largest real part {maxre:.4g} 1/s; least damping ratio {zmin:.3f}",
             "  least damped: " + ", ".join(
                 f"{z.imag / (2 * math.pi):.1f} Hz (zeta {-z.real / abs(z):.3f})" for z in osc[:5]),
             "  oscillatory below 60 Hz: " + (", ".join(
                 f"{z.imag / (2 * math.pi):.1f} Hz (zeta {-z.real / abs(z):.2f})"
                 for z in sorted(osc, key=lambda z: z.imag) if z.imag < 2 * math.pi * 60)
                 or "none"),
             "  slowest real: " + ", ".join(f"{x:.3g}" for x in real[:12]) + " 1/s"]
    lines.append("  per-DOF loop (broken at the DOF drive, the others closed): phase margin, "
                 "gain margin, |L| = 1 at")
    for kk, k in enumerate(lp.free):
        m = lp.margins(kk)
        gm = m["gain_margin_db"]
        lines.append(f"    {mal.DOFS[k]:>5s}: {m['phase_margin_deg']:5.1f} deg, "
                     + ("   -   " if gm is None else f"{gm:5.1f} dB")
                     + ", " + ", ".join(f"{c['f_hz']:.3g}" for c in m["gain_crossings"]) + " Hz")
    lines.append("  diagonal |H| (pose over command) | its phase lag as a delay, ms:")
    lines.append("    " + f"{'f (Hz)':>7s}" + "".join(f"{d:>7s}" for d in mal.DOFS) + "  |"
                 + "".join(f"{d:>7s}" for d in mal.DOFS))
    for f in CHECK_FREQS_HZ:
        h = np.diag(lp.transfer(f))
        delay = -np.angle(h) / (2.0 * math.pi * f) * 1e3
        lines.append("    " + f"{f:>7g}" + "".join(f"{abs(x):7.3f}" for x in h) + "  |"
                     + "".join(f"{x:7.1f}" for x in delay))
    return lines


def design_quantities(lp):
    """Per DOF of the reference's loop `lp`: K_v, the DOF's velocity per unit drive (each
    actuator's no-load K_q (A_a + A_b) / (A_a^2 + A_b^2), or K_q / A_a single-acting, combined
    by oil-column stiffness); w_h, its oil column with the other DOFs held (rad/s); c, its
    delta-p per unit acceleration (G+ of the actuators' delta-p under the minimum-norm forces
    that accelerate it)."""
    G, Gp = lp.G, lp.Gp
    kv = np.array([h["Kqa"] * (h["Aa"] + h["Ab"]) / (h["Aa"] ** 2 + h["Ab"] ** 2)
                   if h["ib"] is not None else h["Kqa"] / h["Aa"] for h in lp.hyd])
    adp = np.array([(h["Aa"] + h["Ab"]) / 2.0 if h["ib"] is not None else h["Aa"]
                    for h in lp.hyd])
    W = np.diag([lp.tab.beta * (h["Aa"] ** 2 + h["Ab"] ** 2) / h["V0"] for h in lp.hyd])
    Mg, _ = lp.tab.generalised_forces(np.zeros(lp.nf), np.zeros(lp.nf), lp.f0)
    Kt = G.T @ W @ G
    out = []
    for k in range(lp.nf):
        Kv = np.linalg.solve(Kt, G.T @ W @ (kv * G[:, k]))[k]
        c = (Gp @ (np.linalg.pinv(G.T) @ Mg[:, k] / adp))[k]
        out.append((Kv, math.sqrt(Kt[k, k] / Mg[k, k]), c))
    return out


def controller_check(table):
    p = CHECK_PAYLOAD
    here = os.path.dirname(os.path.abspath(__file__))
    sys.path.insert(0, os.path.join(here, "reference"))
    import multi_axis_loop as mal   # noqa: E402

    lp = mal.Loop(table)
    print("controller design quantities (bare table) and the gains normalised by them:")
    print(f"  {'DOF':>5s} {'K_v':>7s} {'w_h':>7s} {'f_h':>6s} {'c':>9s}   {'kappa':>6s} "
          f"{'alpha_a':>7s} {'alpha_dp':>8s} {'K_vf K_v':>8s} {'K_af/(K_ab+K_dp c)':>18s}")
    for k, (Kv, wh, c) in enumerate(design_quantities(lp)):
        g = {key: lp.gain[key][k] for key in mal.GAIN_NAMES}
        ab = g["kab"] + g["kdp"] * c
        print(f"  {mal.DOFS[k]:>5s} {Kv:7.4g} {wh:7.4g} {wh / (2 * math.pi):6.3g} {c:9.4g}   "
              f"{g['kp'] * Kv / wh:6.3f} {g['kab'] * Kv * wh:7.3f} {g['kdp'] * c * Kv * wh:8.3f} "
              f"{g['kvf'] * Kv:8.3f} {g['kaf'] / ab:18.3f}")
    print("  (K_v m/s per unit drive, or rad/s; w_h rad/s, f_h Hz; c Pa per m/s2, or per rad/s2)")
    for name in ("h1", "h2"):
        a = next(x for x in table["actuators"] if x["name"] == name)
        A, B = a["cap_side_area_m2"], a["rod_side_area_m2"]
        k_sum = table["oil_bulk_modulus_pa"] * (A - B) ** 2 / (a["chamber_volume_m3"] * (A + B))
        print(f"  {name}: delta-p per m of stroke at constant force (the mean-pressure mode), "
              f"beta (A_a - A_b)^2 / (V (A_a + A_b)) = {k_sum:.3g} Pa/m")
    alt = json.loads(json.dumps(table))
    for k, (Kv, wh, c) in enumerate(design_quantities(lp)):
        g = alt["controller"]["dof"][mal.DOFS[k]]
        if g["delta_p_gain_per_pa"] == 0.0 and g["acceleration_feedback_s2_per_m"] > 0.0:
            g["delta_p_gain_per_pa"] = g["acceleration_feedback_s2_per_m"] / c
            g["delta_p_highpass_hz"] = DELTA_P_HIGHPASS_HZ
            g["acceleration_feedback_s2_per_m"] = 0.0
    la = mal.Loop(alt)
    print("  x, y, yaw damped by delta-p feedback instead (K_dp = K_ab / c, through the "
          f"{DELTA_P_HIGHPASS_HZ:g} Hz high-pass; K_af kept): stable "
          f"{la.stability()[0]}, |H| x, y at 0.5, 1, 2, 5 Hz: "
          + ", ".join(f"{abs(la.transfer(f)[0, 0]):.3f} / {abs(la.transfer(f)[1, 1]):.3f}"
                      for f in (0.5, 1.0, 2.0, 5.0)))
    matched = json.loads(json.dumps(table))
    for k, (Kv, wh, c) in enumerate(design_quantities(lp)):
        g = matched["controller"]["dof"][mal.DOFS[k]]
        g["velocity_feedforward_s_per_m"] = 1.0 / Kv
        g["acceleration_feedforward_s2_per_m"] = (g["acceleration_feedback_s2_per_m"]
                                                  + g["delta_p_gain_per_pa"] * c)
    lm = mal.Loop(matched)
    h5 = np.diag(lm.transfer(5.0))
    print("  the feedforward matched instead (K_vf = 1/K_v, K_af = K_ab + K_dp c): |H| x, y, z at "
          "5 Hz " + ", ".join(f"{abs(h5[k]):.3f}" for k in range(3)) + "; lag as a delay, x at "
          "1, 5 Hz: " + ", ".join(f"{-np.angle(lm.transfer(f)[0, 0]) / (2 * math.pi * f) * 1e3:.1f}"
                                  for f in (1.0, 5.0)) + " ms")
    start = json.loads(json.dumps(table))
    g16 = {"displacement_gain_per_m": 16.0, "velocity_feedforward_s_per_m": 0.2,
           "acceleration_feedforward_s2_per_m": 0.008, "delta_p_gain_per_pa": 2e-8,
           "delta_p_highpass_hz": 0.1}
    start["controller"]["dof"] = {d: dict(g16) for d in mal.DOFS}
    start["controller"]["force_balance_gain"] = 1e-8
    ls = mal.Loop(start)
    st, _, _, poles = ls.stability()
    zmin = min(-z.real / abs(z) for z in poles if abs(z) >= 1e-6)
    print("  the uniaxial lhpost-2008 gains on every DOF (K_p 16, K_vf 0.2, K_af 0.008, K_dp 2e-8 "
          f"through 0.1 Hz; force balance 1e-8): stable {st}, least damping ratio {zmin:.3f}; "
          "|H| x, y, z at 0.5, 5, 10 Hz: " + "; ".join(
              ", ".join(f"{abs(ls.transfer(f)[k, k]):.3f}" for k in range(3))
              for f in (0.5, 5.0, 10.0)))
    print()
    print("controller check (tools/reference/multi_axis_loop.py, linearised at neutral, "
          "frictionless):")
    for line in loop_report(table, "bare table"):
        print(line)
    print()
    size = " x ".join(f"{x:g}" for x in p["size_m"])
    centre = ", ".join(f"{x:g}" for x in p["centre_m"])
    label = f"with a rigid {p['mass_kg'] / 1e3:g} t block ({size} m, centre at ({centre}) m)"
    for line in loop_report(with_payload(table), label):
        print(line)
    print()
    print("heavier rigid blocks, 8 x 6 x 6 m, centre at "
          f"({centre}) m: least damping ratio of the closed loop (negative: unstable)")
    for mass in (500e3, 1000e3, PAYLOAD_N / G):
        heavy = with_payload(table, {"mass_kg": mass, "centre_m": p["centre_m"],
                                     "size_m": (8.0, 6.0, 6.0)})
        poles = mal.Loop(heavy).closed_loop_poles()
        zeta = min(-z.real / abs(z) for z in poles if abs(z) >= 1e-6)
        print(f"  {mass / 1e3:6.0f} t: {zeta:.3f}")


def main():
    values, notes = derive()
    table = make_table(values)
    report, _ = check(table, notes)
    th = math.degrees(values["v_angle_rad"])
    print("derived values:")
    print(f"  V angle {th:.3f} deg from x (tan = 1/2); horizontal stroke "
          f"+-{values['h_stroke_m']} m (exact {notes['h_stroke_exact_m']:.5f})")
    h2 = table["actuators"][1]
    print(f"  new pair: {NEW_ANGLE_DEG:g} deg from x, {NEW_LENGTH_M:g} m; "
          f"stroke +-{values['new_stroke_m']} m (exact {notes['new_stroke_exact_m']:.5f}); "
          f"{values['new_scale']:.4f} x the originals' areas ({h2['cap_side_area_m2']} / "
          f"{h2['rod_side_area_m2']} m2); {NEW_VALVES} x "
          f"{values['new_valve_flow_m3_s'] / L_PER_MIN:.0f} l/min (exact "
          f"{notes['new_valve_flow_exact_l_min']:.0f})")
    print("  the y stroke without limiting x needs the new pair at >= "
          f"{min_new_angle_deg():.2f} deg from x ({min_new_angle_deg(math.inf):.2f} deg for a "
          "long actuator)")
    print(f"  struts {values['strut_pressure_pa'] / 1e6:.2f} MPa "
          f"(exact {notes['strut_pressure_exact_pa'] / 1e6:.4f}); vertical area "
          f"{values['v_area_m2']} m2 (exact {notes['v_area_exact_m2']:.5f}); vertical valves "
          f"{V_VALVES} x {values['v_valve_flow_m3_s'] / L_PER_MIN:.0f} l/min (exact "
          f"{notes['v_valve_flow_exact_l_min']:.0f})")
    print()
    print(report)
    print()
    print("the new pair's angle and length (each end's far arm, platen point in the middle of the "
          "end face):")
    print(f"  {'length':>6s}  {'y stroke needs':>14s}  "
          "axis to the platen at the worst stroke corner, m")
    angles = (68.0, 70.0, 71.0, 72.0, 74.0, 76.0)
    print(f"  {'m':>6s}  {'deg from x':>14s}  " + "".join(f"{a:>7g} deg" for a in angles))
    for length in (4.0, 5.0, 6.0):
        cl = [clearance(make_table(values, a, length))["h2"] for a in angles]
        print(f"  {length:6g}  {min_new_angle_deg(length):14.2f}  "
              + "".join(f"{c:11.2f}" for c in cl))
    if "--controller-check" in sys.argv[1:]:
        print()
        controller_check(table)
    if "--check" not in sys.argv[1:] and "--controller-check" not in sys.argv[1:]:
        doc = {"table": table, "limits": limits_block()}
        os.makedirs(os.path.dirname(OUT_JSON), exist_ok=True)
        with open(OUT_JSON, "w", newline="\n") as f:
            f.write(json.dumps(doc, indent=2, sort_keys=True) + "\n")
        print()
        print(f"wrote {OUT_JSON}")


if __name__ == "__main__":
    main()
