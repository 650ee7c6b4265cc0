//! Inverse runs: the actuator force a prescribed motion needs (Eq. 1–4, Eq. 23).

use platen_model::{force_terms, PlatenModel};

use crate::output::{Sample, SampleSink};
use crate::record::Motion;

/// Computes, at every sample of `motion`, the actuator force and its decomposition
/// ([`platen_model::force_terms`]: `sign(0) = 0` at rest) and delivers it to `sink`.
pub fn inverse<M: PlatenModel, S: SampleSink>(model: &M, motion: &Motion, sink: &mut S) {
    let (t, u, v, a) = (motion.t_s(), motion.u_m(), motion.v_m_s(), motion.a_m_s2());
    for i in 0..motion.len() {
        let terms = force_terms(model, u[i], v[i], a[i]);
        sink.accept(&Sample {
            index: i,
            t_s: t[i],
            u_m: u[i],
            v_m_s: v[i],
            a_m_s2: a[i],
            terms,
            stuck: v[i] == 0.0 && a[i] == 0.0,
        });
    }
}
