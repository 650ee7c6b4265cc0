"""platen from Python against independent truth: the SciPy references in tests/data/reference
(made by tools/reference/make_reference.py, not by platen) and Eq. 23 evaluated in NumPy."""

from __future__ import annotations

import numpy as np
import pytest

import platen
from conftest import REFERENCE, read_csv

#: The bar of the workspace for these references (the reference itself is cross-checked to
#: 1.6e-10 m; platen's RK4 at the sample interval measures about 4e-9 m against it).
REFERENCE_BAR_M = 2e-6

#: Identified-model parameters of `identified_nonpaper` (tests/data/reference/README.md,
#: "Case 1"): deliberately not the paper's.
NONPAPER_IDENTIFIED = {
    "effective_mass_kg": 95_000.0,
    "stiffness_n_per_m": 2.1e6,
    "coulomb_force_n": 18_000.0,
    "viscous_coefficient": 30_000.0,
    "viscous_exponent": 0.7,
    "low_velocity_force_n": 8_000.0,
    "low_velocity_decay_s_per_m": 50.0,
}


def nonpaper_full_model():
    """The `full` object and pressure whose derived coefficients (Eq. 5–8) are those of the
    `full_nonpaper` reference ("Case 2"): Mₑ = 120 t, M̄′ₑ = 8000 kg, h = 3.3 m,
    Kₑ = 1.5 MN/m, K′ₑ = 2.0 MN/m, F_μ = 20 kN, Cₑ = 40 kN/(m/s)^0.5, a = 10 kN, b = 60 s/m,
    c_β = 150 kN/(m/s)^0.5, β = 0.5, μ⁽ⁱᵛ⁾F_hd = 10 kN. Solved backwards: M₁ = 0 →
    M₂ = 6M̄′ₑ/5, 2M̄ₑ = 2M₂/3; p₀ = Kₑh/(2A); γ = (1 + 2K′ₑ/Kₑ)·l₀/h; hinge share
    H = μ⁽ⁱᵛ⁾/(γh/2l₀) with κ = 1 and a_h = 0.1 m; bearing μ = F_μ/F_hd − H."""
    h, l0, area = 3.3, 2.1, 0.15
    ke, kp, mp, f_mu, hinge_force = 1.5e6, 2.0e6, 8000.0, 20e3, 10e3
    p0 = ke * h / (2 * area)
    f_hd = 2 * p0 * area
    gamma = (1 + 2 * kp / ke) * l0 / h
    share = hinge_force / f_hd / (gamma * h / (2 * l0))
    m2 = 6 * mp / 5
    full = {
        "platen_mass_kg": 120e3 - 2 * m2 / 3,
        "actuator_moving_mass_kg": 0.0,
        "strut_piston_mass_kg": 0.0,
        "strut_cylinder_mass_kg": m2,
        "strut_height_m": h,
        "strut_piston_length_m": l0,
        "strut_area_m2": area,
        "gas_heat_capacity_ratio": gamma,
        "supported_weight_n": 0.0,
        "bearing_friction_coefficient": f_mu / f_hd - share,
        "lateral_friction_coefficient": 0.0,
        "lateral_normal_force_n": 0.0,
        "hinge_swivel_friction_coefficient": share * h / (2 * 0.1),
        "hinge_radius_m": 0.1,
        "hinge_force_distribution_factor": 1.0,
        "viscous_coefficient": 40e3,
        "viscous_exponent": 0.5,
        "strut_viscous_coefficient": 150e3,
        "strut_viscous_exponent": 0.5,
        "low_velocity_force_n": 10e3,
        "low_velocity_decay_s_per_m": 60.0,
    }
    return {"full": full, "hold_down_pressure_mpa": p0 / 1e6}


def test_forward_on_arrays_matches_the_scipy_reference_with_stick_phases():
    force = read_csv(REFERENCE / "identified_nonpaper_force.csv")
    ref = read_csv(REFERENCE / "identified_nonpaper_reference.csv")
    run = platen.forward(force["t_s"], force["force_n"], model={"identified": NONPAPER_IDENTIFIED})
    du = np.max(np.abs(run["u_m"] - ref["u_m"]))
    assert du < REFERENCE_BAR_M, f"max |Δu| = {du:.3e} m"
    # The reference sticks 7 times (the initial one and 6 later) and reverses 14 times.
    s = run.summary
    assert (s["stick_events"], s["reversals"], s["breakaways"]) == (6, 14, 7), s
    # In stick the reference's velocity is exactly 0: so is platen's, sample for sample.
    stuck = (ref["v_m_s"][1:] == 0.0) & (ref["v_m_s"][:-1] == 0.0)
    assert stuck.sum() > 1000
    assert np.all(run["v_m_s"][1:][stuck] == 0.0)


def test_forward_on_the_full_model_matches_the_scipy_reference():
    force = read_csv(REFERENCE / "full_nonpaper_force.csv")
    ref = read_csv(REFERENCE / "full_nonpaper_reference.csv")
    run = platen.forward(
        force["t_s"],
        force["force_n"],
        model=nonpaper_full_model(),
        integrator={"method": "rk4", "step_s": 1 / 2048},
    )
    du = np.max(np.abs(run["u_m"] - ref["u_m"]))
    assert du < REFERENCE_BAR_M, f"max |Δu| = {du:.3e} m"
    s = run.summary
    assert (s["stick_events"], s["reversals"], s["breakaways"]) == (3, 7, 4), s


@pytest.mark.parametrize("integrator", [None, {"method": "dopri5", "rtol": 1e-9}])
def test_simulate_of_a_scenario_dict_matches_the_scipy_reference(integrator):
    scenario = {
        "name": "non-paper identified model, 12 s with stick phases",
        "model": {"preset": "lhpost-2008", "identified": NONPAPER_IDENTIFIED},
        "excitation": {"force_csv": str(REFERENCE / "identified_nonpaper_force.csv")},
    }
    if integrator:
        scenario["integrator"] = integrator
    run = platen.simulate(scenario)
    ref = read_csv(REFERENCE / "identified_nonpaper_reference.csv")
    du = np.max(np.abs(run["u_m"] - ref["u_m"]))
    assert du < REFERENCE_BAR_M, f"max |Δu| = {du:.3e} m"
    assert run.summary["name"] == scenario["name"]
    assert run.summary["solver"]["method"] == (integrator or {"method": "rk4"})["method"]


#: Relative bar of the inverse against Eq. 23: both evaluate the same formula in double
#: precision, so they differ by a few ulp of the largest term (pow and exp of two libms).
INVERSE_RELATIVE = 1e-9


def test_inverse_is_eq_23_evaluated_in_numpy():
    """F_A = Mₑ·a + Kₑ·u + [F_μ + Cₑ|v|^α + a·e^(−b|v|)]·sign(v), term by term, on an
    analytic sine motion with a constant offset (so u, v and a all pass through zero)."""
    p = NONPAPER_IDENTIFIED
    t = np.arange(0, 5 * 1024 + 1) / 1024
    w = 2 * np.pi * 0.7
    u = 0.01 + 0.15 * np.sin(w * t)
    v = 0.15 * w * np.cos(w * t)
    a = -0.15 * w * w * np.sin(w * t)
    run = platen.inverse(t, u, v, a, model={"identified": p})
    speed = np.abs(v)
    inertial = p["effective_mass_kg"] * a
    elastic = p["stiffness_n_per_m"] * u
    dissipative = np.sign(v) * (
        p["coulomb_force_n"]
        + p["viscous_coefficient"] * speed ** p["viscous_exponent"]
        + p["low_velocity_force_n"] * np.exp(-p["low_velocity_decay_s_per_m"] * speed)
    )
    total = inertial + elastic + dissipative
    scale = np.abs(inertial) + np.abs(elastic) + np.abs(dissipative)
    for name, expected in [
        ("inertial_force_n", inertial),
        ("elastic_force_n", elastic),
        ("dissipative_force_n", dissipative),
        ("force_n", total),
    ]:
        err = np.max(np.abs(run[name] - expected) / scale)
        assert err < INVERSE_RELATIVE, f"{name}: {err:.2e} relative"
    # The motion is passed through unchanged.
    assert np.array_equal(run["u_m"], u) and np.array_equal(run["a_m_s2"], a)


def test_inverse_derives_a_missing_velocity_and_acceleration_to_second_order():
    t = np.arange(0, 4 * 1024 + 1) / 1024
    w = 2 * np.pi * 0.6
    u = 0.2 * np.sin(w * t)
    run = platen.inverse(t, u)
    # Central differences inside: error = h²/6·|u‴| + O(h⁴), at most h²/6 × 0.2·w³ = 1.70e-6 m/s.
    h = 1 / 1024
    bound = h * h / 6 * 0.2 * w**3
    inner = slice(1, -1)
    dv = np.max(np.abs(run["v_m_s"][inner] - 0.2 * w * np.cos(w * t[inner])))
    assert 0.99 * bound < dv < 1.01 * bound, (dv, bound)
