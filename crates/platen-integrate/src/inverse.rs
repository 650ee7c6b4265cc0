//! Inverse runs: the actuator force a prescribed motion needs (Eq. 1–4, Eq. 23).

use platen_model::{force_terms, ForceTerms, PlatenModel, Specimen};

use crate::hysteretic::{HystereticBuilding, StoreyEvent};
use crate::output::{Sample, SampleSink, SpecimenSample};
use crate::Motion;

/// Computes, at every sample of `motion`, the actuator force and its decomposition and
/// delivers it to `sink`.
///
/// While the platen moves the force is [`platen_model::force_terms`]. At rest friction is
/// set-valued, and the motion alone does not fix the actuator force:
///
/// * by default only `v = 0` exactly is at rest, and the dissipative force there is taken as
///   zero (`sign(0) = 0`, as Eq. 23 reads);
/// * with a velocity dead band ([`Motion::with_rest_velocity`]) every sample with
///   `|v| ≤ rest_velocity_m_s` is at rest, and the friction is the static reaction that
///   balances the other forces (inertial and elastic, `S = F_I + F_E`) within the static
///   threshold `F_s(u)`: `F_D = −clamp(S, −F_s, F_s)`. The actuator then supplies only what
///   friction cannot hold, `F_A = sign(S)·max(|S| − F_s, 0)`, the smallest force that keeps
///   the platen at rest, and the friction no longer flips by `2F_s` with the sign of a noisy
///   velocity. The velocity-dependent terms are evaluated at `v = 0`; `u` and `a` are used as
///   given, and the sample is marked stuck.
pub fn inverse<M: PlatenModel, S: SampleSink>(model: &M, motion: &Motion, sink: &mut S) {
    let (u, v, a) = (motion.u_m(), motion.v_m_s(), motion.a_m_s2());
    let band = motion.rest_velocity_m_s();
    for i in 0..motion.len() {
        let at_rest = band.is_some_and(|b| v[i].abs() <= b);
        let terms = if at_rest {
            static_reaction(model, u[i], a[i], 0.0)
        } else {
            force_terms(model, u[i], v[i], a[i])
        };
        sink.accept(&prescribed_sample(motion, i, terms, at_rest, None));
    }
}

/// The forces on a platen at rest at `u` with acceleration `a` carrying a specimen whose
/// base shear is `base_shear_n` (0 without one): friction is the static reaction to the
/// inertial and elastic forces and the base shear, within `±F_s(u)`. The returned
/// `actuator_n` excludes the base shear (the caller adds it).
fn static_reaction<M: PlatenModel>(
    model: &M,
    u_m: f64,
    a_m_s2: f64,
    base_shear_n: f64,
) -> ForceTerms {
    let still = force_terms(model, u_m, 0.0, a_m_s2);
    let mut held = still.inertial_n + still.elastic_n;
    if base_shear_n != 0.0 {
        // (Not added at 0: `−0.0 + 0.0` would change the bare platen's output bits.)
        held += base_shear_n;
    }
    let threshold = model.static_threshold_n(u_m);
    let dissipative_n = -held.clamp(-threshold, threshold);
    ForceTerms {
        dissipative_n,
        actuator_n: held + dissipative_n - base_shear_n,
        ..still
    }
}

/// The force terms at sample `i` of `motion` for a platen carrying a specimen whose base
/// shear is `base_shear_n` (the actuator force adds it; at rest friction holds against it too),
/// and whether the sample is in the rest band.
fn specimen_terms<M: PlatenModel>(
    model: &M,
    motion: &Motion,
    i: usize,
    base_shear_n: f64,
) -> (ForceTerms, bool) {
    let (u, v, a) = (motion.u_m()[i], motion.v_m_s()[i], motion.a_m_s2()[i]);
    let at_rest = motion.rest_velocity_m_s().is_some_and(|b| v.abs() <= b);
    let mut terms = if at_rest {
        static_reaction(model, u, a, base_shear_n)
    } else {
        force_terms(model, u, v, a)
    };
    terms.actuator_n += base_shear_n;
    (terms, at_rest)
}

/// RK4 sub-steps of the specimen per sample interval of an inverse run. The base
/// acceleration is linear inside an interval, so the specimen's equations are smooth there;
/// at 1024 Hz and 8 Hz, 8 sub-steps put RK4's relative error per interval near 1e-14.
pub const INVERSE_SPECIMEN_SUBSTEPS: u32 = 8;

/// [`inverse`] for a platen carrying `specimen`: the prescribed platen motion drives the
/// specimen (from rest relative to the platen at the first sample, the base acceleration
/// linear between samples, RK4 with [`INVERSE_SPECIMEN_SUBSTEPS`] sub-steps per interval), and
/// the actuator force adds its base shear: `F_A = F_I + F_E + F_D + B`. At rest (the dead
/// band of [`Motion::with_rest_velocity`]) friction holds against `F_I + F_E + B`.
pub fn inverse_specimen<M: PlatenModel, S: SampleSink>(
    model: &M,
    specimen: &Specimen,
    motion: &Motion,
    sink: &mut S,
) {
    if specimen.is_hysteretic() {
        return inverse_hysteretic(model, specimen, motion, sink);
    }
    const NS: usize = Specimen::MAX_STOREYS;
    let (t, a) = (motion.t_s(), motion.a_m_s2());
    let ns = specimen.len();
    // State: z[..ns], zd[..ns].
    let (mut z, mut zd) = ([0.0; NS], [0.0; NS]);
    let rates = |acc: f64, z: &[f64; NS], zd: &[f64; NS], out: &mut [f64; NS]| {
        specimen.storey_accelerations(acc, &z[..ns], &zd[..ns], &mut out[..ns]);
    };
    for i in 0..motion.len() {
        if i > 0 {
            let (a0, a1) = (a[i - 1], a[i]);
            let steps = INVERSE_SPECIMEN_SUBSTEPS;
            let h = (t[i] - t[i - 1]) / f64::from(steps);
            let acc = |s: f64| a0 + (a1 - a0) * s / f64::from(steps);
            for k in 0..steps {
                let s0 = f64::from(k);
                let (mut k1, mut k2, mut k3, mut k4) = ([0.0; NS], [0.0; NS], [0.0; NS], [0.0; NS]);
                let (mut zs, mut zds) = ([0.0; NS], [0.0; NS]);
                rates(acc(s0), &z, &zd, &mut k1);
                for j in 0..ns {
                    zs[j] = z[j] + 0.5 * h * zd[j];
                    zds[j] = zd[j] + 0.5 * h * k1[j];
                }
                let v2 = zds;
                rates(acc(s0 + 0.5), &zs, &zds, &mut k2);
                for j in 0..ns {
                    zs[j] = z[j] + 0.5 * h * v2[j];
                    zds[j] = zd[j] + 0.5 * h * k2[j];
                }
                let v3 = zds;
                rates(acc(s0 + 0.5), &zs, &zds, &mut k3);
                for j in 0..ns {
                    zs[j] = z[j] + h * v3[j];
                    zds[j] = zd[j] + h * k3[j];
                }
                let v4 = zds;
                rates(acc(s0 + 1.0), &zs, &zds, &mut k4);
                for j in 0..ns {
                    z[j] += h / 6.0 * (zd[j] + 2.0 * (v2[j] + v3[j]) + v4[j]);
                    zd[j] += h / 6.0 * (k1[j] + 2.0 * (k2[j] + k3[j]) + k4[j]);
                }
            }
        }
        let base_shear_n = specimen.base_shear_n(&z[..ns], &zd[..ns]);
        let (terms, at_rest) = specimen_terms(model, motion, i, base_shear_n);
        let mut zdd = [0.0; NS];
        rates(a[i], &z, &zd, &mut zdd);
        let mut spec = SpecimenSample::new(ns, base_shear_n);
        for j in 0..ns {
            spec.u_m[j] = z[j];
            spec.a_m_s2[j] = specimen.absolute_acceleration_m_s2(j, a[i], zdd[j]);
            spec.drift_m[j] = specimen.drift_m(j, &z[..ns]);
        }
        sink.accept(&prescribed_sample(motion, i, terms, at_rest, Some(spec)));
    }
}

/// [`inverse_specimen`] for a specimen whose storeys yield: the storeys are stepped by
/// [`HystereticBuilding`] (the same RK4 sub-steps, with every yield and unloading event of a
/// bilinear storey located inside them), and the samples carry each storey's restoring force,
/// hysteretic force and hysteretic energy.
fn inverse_hysteretic<M: PlatenModel, S: SampleSink>(
    model: &M,
    specimen: &Specimen,
    motion: &Motion,
    sink: &mut S,
) {
    inverse_building(model, HystereticBuilding::new(specimen), motion, sink);
}

/// [`inverse_specimen`] with the specimen's storey events: every yield and unloading of a
/// bilinear storey, in time order, at the instant located inside the sub-step (a linear or
/// Bouc–Wen specimen has none).
pub fn inverse_specimen_events<M: PlatenModel, S: SampleSink>(
    model: &M,
    specimen: &Specimen,
    motion: &Motion,
    sink: &mut S,
) -> Vec<StoreyEvent> {
    if !specimen.is_hysteretic() {
        inverse_specimen(model, specimen, motion, sink);
        return Vec::new();
    }
    let mut building = HystereticBuilding::new(specimen);
    building.log_events();
    inverse_building(model, building, motion, sink).take_events()
}

/// The hysteretic inverse run of `building`, which it returns at the end.
fn inverse_building<M: PlatenModel, S: SampleSink>(
    model: &M,
    mut building: HystereticBuilding,
    motion: &Motion,
    sink: &mut S,
) -> HystereticBuilding {
    let (t, a) = (motion.t_s(), motion.a_m_s2());
    let ns = building.len();
    for i in 0..motion.len() {
        if i > 0 {
            let (a0, a1) = (a[i - 1], a[i]);
            let steps = INVERSE_SPECIMEN_SUBSTEPS;
            let h = (t[i] - t[i - 1]) / f64::from(steps);
            let acc = |s: f64| a0 + (a1 - a0) * s / f64::from(steps);
            for k in 0..steps {
                building.step(t[i - 1], h, f64::from(k), &acc);
            }
        }
        let y = building.y;
        let base_shear_n = building.base_shear_n(&y);
        let (terms, at_rest) = specimen_terms(model, motion, i, base_shear_n);
        let zdd = building.relative_accelerations(a[i], &y);
        let mut spec = SpecimenSample::new(ns, base_shear_n);
        spec.hysteretic = true;
        let mut below = 0.0;
        for (j, zdd) in zdd[..ns].iter().enumerate() {
            spec.u_m[j] = y.z[j];
            spec.a_m_s2[j] = a[i] + zdd;
            spec.drift_m[j] = y.z[j] - below;
            below = y.z[j];
            spec.force_n[j] = building.force_n(j, &y);
            spec.hysteretic_force_n[j] = building.hysteretic_force_n(j, &y);
            spec.hysteretic_j[j] = y.e[j];
        }
        spec.yield_excursions = building.yield_events;
        sink.accept(&prescribed_sample(motion, i, terms, at_rest, Some(spec)));
    }
    building
}

/// The output sample of an inverse run at sample `i` of the prescribed `motion`: its force
/// `terms`, stuck when in the rest band or exactly still.
fn prescribed_sample(
    motion: &Motion,
    i: usize,
    terms: ForceTerms,
    at_rest: bool,
    specimen: Option<SpecimenSample>,
) -> Sample {
    let (v, a) = (motion.v_m_s()[i], motion.a_m_s2()[i]);
    Sample {
        index: i,
        t_s: motion.t_s()[i],
        u_m: motion.u_m()[i],
        v_m_s: v,
        a_m_s2: a,
        terms,
        stuck: at_rest || (v == 0.0 && a == 0.0),
        specimen,
        system: None,
    }
}
