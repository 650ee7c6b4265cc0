//! The multi-axis linearisation ([`TableLinearisation`]) against the nonlinear closed loop
//! ([`forward_table_loop`]): small sines per DOF (x, z and pitch at 0.5 Hz, 2 Hz and past
//! their oil columns, 4.7–9.6 Hz for x and 34–40 Hz for z and pitch) on the loop test table
//! (`tools/reference/loop_table.json`, frictionless pads, constant supply), the fundamental
//! of every pose DOF fitted by least squares over whole cycles once steady, against the
//! transfer matrix's diagonal term and the command's largest off-diagonal term, within 2 %
//! and 2° (the bar).
//!
//! Each run drives the three DOFs at once at three different frequencies (each DOF at each
//! frequency over the three runs), fitted together (sines and cosines of the three, a
//! constant and a slope): the runs stay short in a debug build. RK4 takes one step per
//! controller period (two pieces, cut where the delayed drive arrives; `h·ω_v = 0.75` for
//! the 246 Hz spools): two steps change no fitted number by more than 0.004 % and 0.004°.
//!
//! # The valves' rest opening
//!
//! A critically centred valve's land passes `K·x·√Δp` onto a different drop on either side
//! of its null. At the loop test table's null pressures the leakage flows (across the
//! horizontal actuators' pistons from `p_b0 = 13.2` to `p_a0 = 7.9` MPa, to return from the
//! vertical ones' `p_a0 = 3.3` MPa), and the loop opens each valve slightly to make it up
//! (−2.1e-4 and +8.1e-5 of full opening): a small signal sees that side's gain only, 13 %
//! below the mean of the two sides for the horizontals and 41 % above it for the verticals.
//! So the nonlinear loop's small-signal response is the linearisation with
//! [`FlowGains::AtRest`]; the mean ([`FlowGains::Mean`], the NumPy reference's) is its
//! fundamental only where both sides' drops are equal, which the last test checks on a
//! variant of the table with its null pressures at mid-supply.

#[path = "common/loop_table.rs"]
mod loop_table;

use loop_table::LoopTable;
use nalgebra::{Complex, DMatrix, DVector};
use platen_integrate::{forward_table_loop, LoopMethod, Motion, PoseMotion, TableLoopRun};
use platen_model::multi_axis::{Dof, MultiAxisTable};
use platen_system::{FlowGains, TableHydraulics, TableLinearisation};

/// The command's sample rate (the controller's), Hz.
const RATE_HZ: f64 = 2048.0;
/// The command is still this long first, so that the valves settle at their rest openings,
/// s.
const QUIET_S: f64 = 0.5;
/// Then the sines run this long before the fit, s.
const SETTLE_S: f64 = 1.0;
/// The fit's window: whole cycles of every frequency here, s.
const FIT_S: f64 = 2.0;

/// One DOF's sine in a run.
#[derive(Clone, Copy)]
struct Sine {
    dof: Dof,
    f_hz: f64,
    amplitude: f64,
}

/// Runs the three sines `sines` together (distinct frequencies) and returns, per sine, the
/// fundamental of each pose DOF at its frequency over its amplitude.
fn measure(rig: &LoopTable, sines: &[Sine; 3]) -> Vec<[Complex<f64>; 6]> {
    let n = ((QUIET_S + SETTLE_S + FIT_S) * RATE_HZ).round() as usize;
    let t: Vec<f64> = (0..=n).map(|i| i as f64 / RATE_HZ).collect();
    let zero = vec![0.0; t.len()];
    let mut dofs: [Motion; 6] = std::array::from_fn(|_| {
        Motion::new(t.clone(), zero.clone(), zero.clone(), zero.clone()).unwrap()
    });
    for s in sines {
        let w = std::f64::consts::TAU * s.f_hz;
        let at = |g: &dyn Fn(f64) -> f64| -> Vec<f64> {
            t.iter()
                .map(|&x| if x < QUIET_S { 0.0 } else { g(x - QUIET_S) })
                .collect()
        };
        dofs[s.dof.index()] = Motion::new(
            t.clone(),
            at(&|x| s.amplitude * (w * x).sin()),
            at(&|x| s.amplitude * w * (w * x).cos()),
            at(&|x| -s.amplitude * w * w * (w * x).sin()),
        )
        .unwrap();
    }
    let command = PoseMotion::new(dofs).unwrap();
    let (run, stats) = forward_table_loop(&TableLoopRun {
        table: &rig.table,
        hydraulics: &rig.hydraulics,
        controller: &rig.controller,
        specimen: None,
        command: &command,
        method: LoopMethod::Rk4 {
            steps_per_period: 1,
        },
    })
    .unwrap();
    assert_eq!(stats.saturated_time_s, 0.0);
    assert!(stats.cavitation_at_s.is_none());
    // The fit over the last FIT_S: sines and cosines of the three frequencies (of the time
    // since the sines started), a constant and a slope.
    let from = t.partition_point(|&x| x < QUIET_S + SETTLE_S - 1e-9);
    let rows = t.len() - from;
    let mid = 0.5 * (t[from] + t[t.len() - 1]);
    let basis = DMatrix::from_fn(rows, 8, |r, c| {
        let x = t[from + r];
        match c {
            6 => 1.0,
            7 => x - mid,
            _ => {
                let phase = std::f64::consts::TAU * sines[c / 2].f_hz * (x - QUIET_S);
                if c % 2 == 0 {
                    phase.sin()
                } else {
                    phase.cos()
                }
            }
        }
    });
    let svd = basis.svd(true, true);
    let mut out = vec![[Complex::new(0.0, 0.0); 6]; 3];
    for d in Dof::ALL {
        let y = run.column(&format!("{}_{}", d.name(), d.unit())).unwrap();
        let coef = svd
            .solve(&DVector::from_column_slice(&y[from..]), 1e-12)
            .unwrap();
        for (j, s) in sines.iter().enumerate() {
            // y = Re(H)·A·sin + Im(H)·A·cos for the command A·sin.
            out[j][d.index()] = Complex::new(coef[2 * j], coef[2 * j + 1]) / s.amplitude;
        }
    }
    out
}

/// The worst differences (gain relative, phase in degrees) of the measured fundamentals
/// from `lin`'s diagonal term and largest off-diagonal term, each checked against 2 % and 2°;
/// an off-diagonal term that symmetry makes zero is checked to be next to nothing in the
/// nonlinear loop too (below 1e-3 of the diagonal: the harmonics of the run's other sines
/// fall on the same frequencies, 0.5 Hz dividing them all, at about 1e-4).
fn compare(lin: &TableLinearisation, sines: &[Sine], measured: &[[Complex<f64>; 6]]) -> (f64, f64) {
    let wrap = |d: f64| (d + 540.0).rem_euclid(360.0) - 180.0;
    let (mut worst_gain, mut worst_phase) = (0.0f64, 0.0f64);
    for (s, m) in sines.iter().zip(measured) {
        let talk = lin
            .cross_talk(s.f_hz)
            .into_iter()
            .find(|c| c.command == s.dof)
            .unwrap();
        let (other, h_other) = talk.largest.unwrap();
        let mut terms = vec![(s.dof, talk.diagonal)];
        if h_other.norm() > 1e-9 * talk.diagonal.norm() {
            terms.push((other, h_other));
        } else {
            let off = Dof::ALL
                .iter()
                .filter(|&&d| d != s.dof)
                .map(|d| m[d.index()].norm())
                .fold(0.0, f64::max);
            println!(
                "{:>5} {:4} Hz: off-diagonal zero by symmetry, nonlinear {:.1e} of the diagonal",
                s.dof.name(),
                s.f_hz,
                off / talk.diagonal.norm()
            );
            assert!(off < 1e-3 * talk.diagonal.norm());
        }
        for (response, h) in terms {
            let x = m[response.index()];
            let dg = x.norm() / h.norm() - 1.0;
            let dp = wrap((x.arg() - h.arg()).to_degrees());
            println!(
                "{:>5} {:4} Hz → {:>5}: nonlinear {:.5e} ∠{:8.3}°, linear {:.5e} ∠{:8.3}°: \
                 {:+.3} %, {:+.3}°",
                s.dof.name(),
                s.f_hz,
                response.name(),
                x.norm(),
                x.arg().to_degrees(),
                h.norm(),
                h.arg().to_degrees(),
                100.0 * dg,
                dp
            );
            assert!(
                dg.abs() < 0.02 && dp.abs() < 2.0,
                "{} at {} Hz → {}",
                s.dof.name(),
                s.f_hz,
                response.name()
            );
            worst_gain = worst_gain.max(dg.abs());
            worst_phase = worst_phase.max(dp.abs());
        }
    }
    (worst_gain, worst_phase)
}

/// The loop test table at small amplitudes (each valve's excursion well inside its rest
/// opening) follows the linearisation with the rest side's flow gains: x, z and pitch at
/// 0.5 Hz, 2 Hz and 20 Hz (x) or 50 Hz (z, pitch), the diagonal and the largest cross-talk.
#[test]
fn small_sines_on_the_loop_table_follow_the_linearisation_at_rest() {
    let rig = loop_table::loop_table();
    let lin = TableLinearisation::with_flow_gains(
        &rig.table,
        &rig.hydraulics,
        &rig.controller,
        None,
        FlowGains::AtRest,
    )
    .unwrap();
    // Per frequency (m and rad): every valve's excursion, all three sines together, stays
    // below about a third of its rest opening (−2.1e-4 horizontal, +8.1e-5 vertical).
    let sine = |dof: Dof, f_hz: f64| {
        let translation = match f_hz {
            0.5 => 4e-6,
            2.0 => 1e-6,
            _ => 1e-7,
        };
        let amplitude = if dof.is_rotation() {
            0.25 * translation
        } else {
            translation
        };
        Sine {
            dof,
            f_hz,
            amplitude,
        }
    };
    let runs = [
        [sine(Dof::X, 0.5), sine(Dof::Z, 2.0), sine(Dof::Pitch, 50.0)],
        [sine(Dof::X, 2.0), sine(Dof::Z, 50.0), sine(Dof::Pitch, 0.5)],
        [sine(Dof::X, 20.0), sine(Dof::Z, 0.5), sine(Dof::Pitch, 2.0)],
    ];
    let (mut gain, mut phase) = (0.0f64, 0.0f64);
    for sines in &runs {
        let (g, p) = compare(&lin, sines, &measure(&rig, sines));
        gain = gain.max(g);
        phase = phase.max(p);
    }
    println!("worst: {:.3} %, {:.3}°", 100.0 * gain, phase);
}

/// The loop test table with its null pressures at mid-supply (the horizontal actuators
/// double-ended, the vertical ones' area carrying the weight at half the supply), where a
/// land's two gains are equal: a larger sine follows the linearisation with the mean gains
/// (the reference's model).
#[test]
fn with_null_pressures_at_mid_supply_a_larger_sine_follows_the_mean_gains() {
    let rig = mid_supply(loop_table::loop_table());
    let lin = TableLinearisation::new(&rig.table, &rig.hydraulics, &rig.controller, None).unwrap();
    for a in lin.actuators() {
        let mid = 0.5 * (rig.hydraulics.supply_pressure_pa() + rig.hydraulics.return_pressure_pa());
        assert!((a.null_pressure_a_pa / mid - 1.0).abs() < 1e-6);
    }
    let sines = [
        Sine {
            dof: Dof::X,
            f_hz: 0.5,
            amplitude: 1e-4,
        },
        Sine {
            dof: Dof::Z,
            f_hz: 2.0,
            amplitude: 1e-4,
        },
        Sine {
            dof: Dof::Pitch,
            f_hz: 50.0,
            amplitude: 1e-6,
        },
    ];
    let (g, p) = compare(&lin, &sines, &measure(&rig, &sines));
    println!("worst: {:.3} %, {:.3}°", 100.0 * g, p);
}

/// The table of `rig` with its horizontal actuators double-ended (`A_b = A_a`) and its
/// vertical ones' area such that their null pressure is mid-supply.
fn mid_supply(rig: LoopTable) -> LoopTable {
    let statics =
        TableLinearisation::new(&rig.table, &rig.hydraulics, &rig.controller, None).unwrap();
    let mid = 0.5 * (rig.hydraulics.supply_pressure_pa() + rig.hydraulics.return_pressure_pa());
    let mut parts = rig.table.parts().clone();
    let mut hydraulics = rig.hydraulics.parts().clone();
    for ((a, h), lin) in parts
        .actuators
        .iter_mut()
        .zip(hydraulics.actuators.iter_mut())
        .zip(statics.actuators())
    {
        if a.rod_side_area_m2 > 0.0 {
            a.rod_side_area_m2 = a.cap_side_area_m2;
        } else {
            a.cap_side_area_m2 = lin.static_force_n / mid;
        }
        h.cap_area_m2 = a.cap_side_area_m2;
        h.rod_area_m2 = a.rod_side_area_m2;
    }
    let table = MultiAxisTable::new(parts).unwrap();
    let strokes: Vec<f64> = table.actuators().iter().map(|a| a.stroke_m).collect();
    LoopTable {
        hydraulics: TableHydraulics::new(hydraulics, &strokes).unwrap(),
        table,
        controller: rig.controller,
    }
}
