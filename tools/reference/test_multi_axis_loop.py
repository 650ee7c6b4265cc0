"""Self-checks of tools/reference/multi_axis_loop.py (pytest; numpy + scipy).

    python3 -m pytest tools/reference/test_multi_axis_loop.py -q

The closed forms below are written out here from the equations (Merritt's linearised valve,
chambers and mass), not taken from the module.
"""

import copy
import json
import math
import os
import sys

import numpy as np
import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import multi_axis_loop as mal  # noqa: E402

G_ACC = 9.80665
FREQS = [0.05, 0.5, 2.0, 5.0, 9.0, 20.0, 60.0]


def load_loop_table():
    with open(os.path.join(HERE, "loop_table.json")) as f:
        return json.load(f)["table"]


VALVE = {"count": 2, "rated_flow_m3_s": 0.1667, "rated_pressure_drop_pa": 7e6,
         "natural_frequency_hz": 246, "damping_ratio": 0.5, "delay_s": 0.0005}


def gains(kp, ki=0.0, kvf=0.0, kaf=0.0, kvb=0.0, kab=0.0, kdp=0.0, fhp=0.0):
    return {"displacement_gain_per_m": kp, "integral_gain_per_m_s": ki,
            "velocity_feedforward_s_per_m": kvf, "acceleration_feedforward_s2_per_m": kaf,
            "velocity_feedback_s_per_m": kvb, "acceleration_feedback_s2_per_m": kab,
            "delta_p_gain_per_pa": kdp, "delta_p_highpass_hz": fhp}


# ---------------------------------------------------------------- (1) one-DOF reductions

def one_dof_x_table(Aa, Ab, V0, CL, m, g):
    """Two identical double-acting actuators along +x, every DOF but x held, no struts."""
    acts = []
    for name, y in (("a1", 1.0), ("a2", -1.0)):
        acts.append({"name": name, "base_m": [-8.0, y, -0.5], "platen_m": [-6.0, y, -0.5],
                     "cap_side_area_m2": Aa, "rod_side_area_m2": Ab, "chamber_volume_m3": V0,
                     "leakage_m3_s_per_pa": CL, "stroke_m": 0.75, "servo_valve": dict(VALVE)})
    return {"platen": {"mass_kg": m, "inertia_kg_m2": [[1e5, 0, 0], [0, 2e5, 0], [0, 0, 3e5]],
                       "centre_of_mass_m": [0.0, 0.0, -0.5]},
            "actuators": acts, "hold_down_struts": [],
            "held_dofs": ["y", "z", "roll", "pitch", "yaw"],
            "oil_bulk_modulus_pa": 1.2e9, "supply_pressure_pa": 21e6, "return_pressure_pa": 0.5e6,
            "controller": {"sample_rate_hz": 1024, "dof": {"x": g}, "force_balance_gain": 3e-8}}


def valve_zoh(s, fs):
    wv = 2 * math.pi * VALVE["natural_frequency_hz"]
    zv = VALVE["damping_ratio"]
    T = 1.0 / fs
    return (wv ** 2 / (s ** 2 + 2 * zv * wv * s + wv ** 2) * np.exp(-s * VALVE["delay_s"])
            * (1 - np.exp(-s * T)) / (s * T))


def land_coefficient():
    return VALVE["count"] * VALVE["rated_flow_m3_s"] / math.sqrt(VALVE["rated_pressure_drop_pa"] / 2)


def uniaxial_double(s, n, M, Aa, Ab, V0, CL, beta, Ps, PR, g, fs):
    """U/R of n identical double-acting actuators on a mass M (Merritt's 3 x 3, closed form)."""
    K = land_coefficient()
    pa0 = Ab * (Ps + PR) / (Aa + Ab)          # f0 = 0, p_a0 + p_b0 = Ps + PR
    pb0 = Ps + PR - pa0
    Kqa = K * (math.sqrt(Ps - pa0) + math.sqrt(pa0 - PR)) / 2
    Kqb = K * (math.sqrt(Ps - pb0) + math.sqrt(pb0 - PR)) / 2
    c = V0 / beta
    # chambers:  (c s + CL) Pa - CL Pb = Kqa X - Aa s U ;  -CL Pa + (c s + CL) Pb = -Kqb X + Ab s U
    # mass:      M s^2 U = n (Aa Pa - Ab Pb)
    det = c * s * (c * s + 2 * CL)
    Nx = c * s * (Aa * Kqa + Ab * Kqb) + CL * (Aa - Ab) * (Kqa - Kqb)
    Nu = c * s * (Aa ** 2 + Ab ** 2) + CL * (Aa - Ab) ** 2
    Gu = n * Nx / (M * s ** 2 * det + n * s * Nu)                   # U / X
    Gp = ((Kqa + Kqb) - (Aa + Ab) * s * Gu) / (c * s + 2 * CL)      # (Pa - Pb) / X
    kp, ki = g["displacement_gain_per_m"], g["integral_gain_per_m_s"]
    kvf, kaf = g["velocity_feedforward_s_per_m"], g["acceleration_feedforward_s2_per_m"]
    kvb, kab = g["velocity_feedback_s_per_m"], g["acceleration_feedback_s2_per_m"]
    kdp, fhp = g["delta_p_gain_per_pa"], g["delta_p_highpass_hz"]
    hp = s / (s + 2 * math.pi * fhp) if fhp > 0 else 1.0
    Z = valve_zoh(s, fs)
    L = Z * (Gu * (kp + ki / s + kvb * s + kab * s ** 2) + kdp * hp * Gp)
    return Z * Gu * (kp + ki / s + kvf * s + kaf * s ** 2) / (1 + L)


@pytest.mark.parametrize("Aa,Ab,CL,g", [
    (0.05, 0.05, 0.0, gains(12.0, kvf=0.1)),
    (0.06, 0.035, 3e-11, gains(10.0, ki=3.0, kvf=0.15, kaf=1e-3, kvb=0.02, kab=2e-4,
                               kdp=1e-8, fhp=0.5)),
    (0.06, 0.035, 3e-11, gains(10.0, kvf=0.15, kdp=1e-8, fhp=0.0)),
])
def test_one_dof_double_acting_equals_uniaxial(Aa, Ab, CL, g):
    M, V0, fs = 30000.0, 0.03, 1024
    tab = one_dof_x_table(Aa, Ab, V0, CL, M, g)
    for f in FREQS:
        s = 2j * math.pi * f
        H = mal.transfer_matrix(tab, f)
        ref = uniaxial_double(s, 2, M, Aa, Ab, V0, CL, 1.2e9, 21e6, 0.5e6, g, fs)
        assert abs(H[0, 0] - ref) <= 1e-7 * abs(ref), (f, H[0, 0], ref)
        H2 = H.copy()
        H2[0, 0] = 0
        assert np.max(np.abs(H2)) == 0.0           # held rows/cols are exactly zero


def test_one_dof_single_acting_z_equals_uniaxial():
    """Two vertical single-acting pads carrying the weight, only z free (three-way valves)."""
    M, A, V0, CL, fs = 40000.0, 0.08, 0.02, 1e-11, 2048
    beta, Ps, PR = 1.4e9, 20e6, 0.3e6
    g = gains(20.0, kvf=0.5, kdp=3e-9, fhp=0.2, kvb=0.01)
    acts = [{"name": n, "base_m": [x, 0.0, -3.0],
             "pad": {"axis": [0, 0, 1], "contact_m": [x, 0.0, -1.0], "friction_coefficient": 0.01},
             "cap_side_area_m2": A, "rod_side_area_m2": 0.0, "chamber_volume_m3": V0,
             "leakage_m3_s_per_pa": CL, "stroke_m": 0.1, "servo_valve": dict(VALVE)}
            for n, x in (("v1", 2.0), ("v2", -2.0))]
    tab = {"platen": {"mass_kg": M, "inertia_kg_m2": [[1e5, 0, 0], [0, 2e5, 0], [0, 0, 3e5]],
                      "centre_of_mass_m": [0.0, 0.0, -0.5]},
           "actuators": acts, "held_dofs": ["x", "y", "roll", "pitch", "yaw"],
           "oil_bulk_modulus_pa": beta, "supply_pressure_pa": Ps, "return_pressure_pa": PR,
           "controller": {"sample_rate_hz": fs, "dof": {"z": g}, "force_balance_gain": 1e-8}}
    K = land_coefficient()
    pa0 = M * G_ACC / 2 / A
    Kq = K * (math.sqrt(Ps - pa0) + math.sqrt(pa0 - PR)) / 2
    c = V0 / beta
    for f in FREQS:
        s = 2j * math.pi * f
        # (c s + CL) P = Kq X - A s U ;  M s^2 U = 2 A P
        Gu = 2 * A * Kq / (M * s ** 2 * (c * s + CL) + 2 * A * A * s)
        Gp = (Kq - A * s * Gu) / (c * s + CL)
        hp = s / (s + 2 * math.pi * 0.2)
        Z = valve_zoh(s, fs)
        L = Z * (Gu * (20.0 + 0.01 * s) + 3e-9 * hp * Gp)
        ref = Z * Gu * (20.0 + 0.5 * s) / (1 + L)
        H = mal.transfer_matrix(tab, f)
        assert abs(H[2, 2] - ref) <= 1e-7 * abs(ref), (f, H[2, 2], ref)


# ---------------------------------------------------------------- (2) low frequency

def test_low_frequency_tracks_command():
    tab = load_loop_table()
    # what is left at 0.01 Hz is first order in f: the velocity error K_vf < 1/K_v and, for the
    # unequal-area horizontals, the Delta-p feedback of the mean-pressure drift through its
    # 0.1 Hz high-pass (about 1 % there); it shrinks tenfold per decade
    for f, tol in ((0.01, 2e-2), (0.001, 2e-3)):
        H = mal.transfer_matrix(tab, f)
        assert np.max(np.abs(np.diag(H) - 1.0)) < tol, (f, np.diag(H))
        off = H - np.diag(np.diag(H))
        assert np.max(np.abs(off)) < tol, (f, np.max(np.abs(off)))
    # and it departs from 1 at higher frequency (the check is not vacuous)
    assert np.max(np.abs(np.diag(mal.transfer_matrix(tab, 5.0)) - 1.0)) > 0.1


# ---------------------------------------------------------------- (3) symmetry

def xz_symmetric_table():
    """loop_table made asymmetric front/back and top/bottom but still mirror-symmetric in y."""
    tab = copy.deepcopy(load_loop_table())
    tab["platen"]["centre_of_mass_m"] = [0.4, 0.0, -0.9]
    tab["platen"]["inertia_kg_m2"] = [[900150.0, 0.0, 4.0e4], [0.0, 2266350.0, 0.0],
                                      [4.0e4, 0.0, 3099000.0]]
    for a in tab["actuators"]:
        if a["name"] in ("v1", "v2"):               # a mirror pair, moved together
            a["pad"]["contact_m"][0] = -4.6
            a["base_m"][0] = -4.6
        if a["name"] in ("h1", "h2"):
            a["platen_m"][2] = -0.4
            a["base_m"][2] = -0.5
    tab["hold_down_struts"][0]["platen_m"][0] = -5.5
    tab["hold_down_struts"][0]["base_m"][0] = -5.6
    tab["controller"]["dof"]["x"]["acceleration_feedback_s2_per_m"] = 1e-3
    return tab


def test_symmetry_about_xz_plane():
    tab = xz_symmetric_table()
    x, y, z, roll, pitch, yaw = range(6)
    for f in (0.5, 2.0, 5.0, 10.0):
        H = mal.transfer_matrix(tab, f)
        scale = np.max(np.abs(H))
        # in-plane commands (x, z, pitch) move nothing out of plane, and vice versa
        for i in (y, roll, yaw):
            for j in (x, z, pitch):
                assert abs(H[i, j]) < 1e-9 * scale, (f, i, j, H[i, j])
                assert abs(H[j, i]) < 1e-9 * scale, (f, j, i, H[j, i])
        # the in-plane coupling the asymmetry makes is there
        assert abs(H[pitch, x]) > 1e-5 and abs(H[z, x]) > 1e-6, (H[pitch, x], H[z, x])


def test_symmetry_broken_shows():
    tab = xz_symmetric_table()
    tab["platen"]["centre_of_mass_m"][1] = 0.3
    H = mal.transfer_matrix(tab, 2.0)
    assert abs(H[1, 0]) > 1e-4, H[1, 0]


# ---------------------------------------------------------------- mechanics and geometry

def test_geometry_and_forces():
    lp = mal.Loop(load_loop_table())
    tab = lp.tab
    for i, a in enumerate(tab.act):
        if "platen_m" in a:
            p, b = np.array(a["platen_m"]), np.array(a["base_m"])
            n = (p - b) / np.linalg.norm(p - b)
            row = np.concatenate([n, np.cross(p, n)])
        else:
            c, ax = np.array(a["pad"]["contact_m"]), np.array(a["pad"]["axis"], float)
            row = np.concatenate([ax, np.cross(c, ax)])
        assert np.max(np.abs(lp.G[i] - row)) < 1e-8
    assert np.max(np.abs(lp.Gamma - lp.G.T)) < 1e-9
    # equilibrium: the vertical pads carry the weight and the struts' pull equally
    pull = sum(s["pressure_pa"] * s["area_m2"] for s in tab.struts)
    w = tab.m * G_ACC + pull
    assert abs(sum(lp.f0) - w) < 1e-6 * w
    assert np.max(np.abs(lp.f0[4:] - w / 6)) < 1e-6 * w
    # B = generalised mass^-1 Gamma
    Mg, _ = tab.generalised_forces(np.zeros(6), np.zeros(6), lp.f0)
    assert np.max(np.abs(lp.B - np.linalg.solve(Mg, lp.Gamma))) < 1e-9 * np.max(np.abs(lp.B))
    assert np.max(np.abs(lp.Av)) < 1e-9


def test_strut_stiffness():
    """x only: the struts' horizontal stiffness sum p0 A / h; z only: sum gamma p0 A^2 / V0."""
    tab = copy.deepcopy(load_loop_table())
    st = tab["hold_down_struts"]
    h = 4.5 - 1.2
    kx = sum(s["pressure_pa"] * s["area_m2"] / h for s in st)
    kz = sum(s["polytropic_exponent"] * s["pressure_pa"] * s["area_m2"] ** 2 / s["gas_volume_m3"]
             for s in st)
    for free, k in (("x", kx), ("z", kz)):
        t = copy.deepcopy(tab)
        t["held_dofs"] = [d for d in mal.DOFS if d != free]
        tb = mal.Table(t)
        f0, _ = mal.static_forces(tb)
        Aq, _, _ = mal.linearise(tb, f0)
        m = t["platen"]["mass_kg"]
        assert abs(-Aq[0, 0] * m - k) < 1e-5 * k, (free, -Aq[0, 0] * m, k)


# ---------------------------------------------------------------- the two constructions agree

def test_state_space_matches_frequency_domain():
    """Pade state space vs the exact frequency-domain solve, on a table whose unequal
    actuators make the force-balance (null-space) loop work."""
    tab = xz_symmetric_table()
    for g in tab["controller"]["dof"].values():       # the state space leaves feedforward out
        g["velocity_feedforward_s_per_m"] = 0.0
    tab["controller"]["dof"]["roll"]["integral_gain_per_m_s"] = 2.0
    tab["controller"]["dof"]["z"]["velocity_feedback_s_per_m"] = 0.05
    tab["controller"]["force_balance_gain"] = 5e-8
    for a, area, count in zip(tab["actuators"], [0.2, 0.25, 0.2, 0.18, 0.5, 0.6, 0.45, 0.5, 0.55, 0.5],
                              [2, 3, 2, 2, 2, 1, 2, 3, 2, 2]):
        a["cap_side_area_m2"] = area
        a["servo_valve"]["count"] = count
    lp = mal.Loop(tab)
    A, B, C = lp.state_space(6)
    for f in (0.3, 3.0, 30.0):
        s = 2j * math.pi * f
        Hs = C @ np.linalg.solve(s * np.eye(A.shape[0]) - A, B)
        H = lp.transfer(f)
        assert np.max(np.abs(Hs - H)) < 1e-6 * np.max(np.abs(H))
        # and the force balance matters on this table (the check sees it)
        lp0 = mal.Loop(dict(tab, controller=dict(tab["controller"], force_balance_gain=0.0)))
        assert np.max(np.abs(lp0.transfer(f) - H)) > 1e-4 * np.max(np.abs(H))


def test_loop_table_is_stable():
    lp = mal.Loop(load_loop_table())
    stable, maxre, nzero, _ = lp.stability()
    assert stable and nzero == 4 and maxre < -0.1


def test_too_much_gain_is_unstable():
    tab = copy.deepcopy(load_loop_table())
    for g in tab["controller"]["dof"].values():
        g["delta_p_gain_per_pa"] = 0.0
    assert not mal.Loop(tab).stability()[0]


def test_force_balance_pole():
    """Two equal-area x actuators: their fight f1 - f2 moves nothing; only force balance acts.

    c s F_N = 2 A K_q X_N and X_N = -W(s) K_fb F_N, so the pole solves
    c s + 2 A K_q K_fb W(s) = 0 (W: valve, delay, hold), near s = -2 A K_q K_fb / c.
    Without force balance it is a second pole at s = 0 besides the mean-pressure ones.
    """
    A, V0, M, beta, Ps, PR, fs, kfb = 0.05, 0.03, 30000.0, 1.2e9, 21e6, 0.5e6, 1024, 3e-8
    tab = one_dof_x_table(A, A, V0, 0.0, M, gains(12.0, kvf=0.1))
    K = land_coefficient()
    pa0 = (Ps + PR) / 2
    Kq = K * (math.sqrt(Ps - pa0) + math.sqrt(pa0 - PR)) / 2
    c = V0 / beta
    s = -2 * A * Kq * kfb / c
    for _ in range(50):                       # Newton on c s + 2 A Kq kfb W(s) = 0
        h = 1e-6 * abs(s)
        F = c * s + 2 * A * Kq * kfb * valve_zoh(s, fs)
        dF = (c * (s + h) + 2 * A * Kq * kfb * valve_zoh(s + h, fs) - F) / h
        s = s - F / dF
    poles = mal.Loop(tab).closed_loop_poles(6)
    assert np.min(np.abs(poles - s)) < 1e-4 * abs(s), (s, poles[np.argmin(np.abs(poles - s))])
    tab["controller"]["force_balance_gain"] = 0.0
    stable, _, nzero, _ = mal.Loop(tab).stability()
    assert not stable and nzero == 3


def test_nonlinear_model_matches_multi_axis_cases():
    """With nothing held, accel() equals the forward model of multi_axis_cases.py."""
    import multi_axis_cases as mac
    d = load_loop_table()
    tab = mal.Table(d)
    ref = mac.Table(d)
    rng = np.random.default_rng(3)
    for _ in range(5):
        q = rng.uniform(-1, 1, 6) * [0.3, 0.3, 0.05, 0.05, 0.05, 0.05]
        qd = rng.uniform(-1, 1, 6) * [0.5, 0.5, 0.1, 0.2, 0.2, 0.2]
        f = rng.uniform(0.5e6, 3e6, len(d["actuators"]))
        rhs = mac.rhs_factory(ref, f, np.zeros_like(f), 0.0)
        want = rhs(0.0, np.concatenate([q, qd]))[6:12]
        got = tab.accel(q, qd, f)
        assert np.max(np.abs(got - want)) < 1e-9 * max(1.0, np.max(np.abs(want))), (got, want)
