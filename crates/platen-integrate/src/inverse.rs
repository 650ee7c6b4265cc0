//! Inverse runs: the actuator force a prescribed motion needs (Eq. 1–4, Eq. 23).

use platen_model::{force_terms, ForceTerms, PlatenModel};

use crate::output::{Sample, SampleSink};
use crate::record::Motion;

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
    let (t, u, v, a) = (motion.t_s(), motion.u_m(), motion.v_m_s(), motion.a_m_s2());
    let band = motion.rest_velocity_m_s();
    for i in 0..motion.len() {
        let at_rest = band.is_some_and(|b| v[i].abs() <= b);
        let terms = if at_rest {
            static_reaction(model, u[i], a[i])
        } else {
            force_terms(model, u[i], v[i], a[i])
        };
        sink.accept(&Sample {
            index: i,
            t_s: t[i],
            u_m: u[i],
            v_m_s: v[i],
            a_m_s2: a[i],
            terms,
            stuck: at_rest || (v[i] == 0.0 && a[i] == 0.0),
        });
    }
}

/// The forces on a platen at rest at `u` with acceleration `a`: friction is the static
/// reaction to the inertial and elastic forces, within `±F_s(u)`.
fn static_reaction<M: PlatenModel>(model: &M, u_m: f64, a_m_s2: f64) -> ForceTerms {
    let still = force_terms(model, u_m, 0.0, a_m_s2);
    let held = still.inertial_n + still.elastic_n;
    let threshold = model.static_threshold_n(u_m);
    let dissipative_n = -held.clamp(-threshold, threshold);
    ForceTerms {
        dissipative_n,
        actuator_n: held + dissipative_n,
        ..still
    }
}
