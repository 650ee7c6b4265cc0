//! The elastic force: the stiffness from the constant-velocity portions of triangle tests
//! (Eq. 16/17, Table I), per test and per pressure group.

use crate::estimate::{Estimate, Parameter};
use crate::groups::Groups;
use crate::regression::Regression;
use crate::warning::{Flag, StiffnessSource, Warning};
use crate::work::Work;

/// A group's stiffness and where it comes from.
pub(crate) type GroupStiffness = (Option<Estimate>, StiffnessSource);

impl Work {
    /// Eq. 16/17 over the constant-velocity portions, with the inertial force `M̂·ā` of what
    /// acceleration the low-pass leaves there subtracted: `F̄ − M̂ā = Kₑū + βḡ + c`, where
    /// `βḡ` is the force impulse at the reversals (see [`Work::estimate_mass`]).
    pub(crate) fn estimate_stiffness(&mut self, mass: Option<&Estimate>) {
        let p = self.pairs(|j, m| self.on_plateau(j) && self.on_plateau(m));
        let m_hat = mass.map_or(0.0, |e| e.value);
        let y: Vec<f64> = p.f.iter().zip(&p.a).map(|(f, a)| f - m_hat * a).collect();
        let Some(reg) = Regression::fit(&[&p.u, &p.g], &y) else {
            self.stiffness = None;
            self.used_for_stiffness = false;
            return;
        };
        let l = self.correlation();
        let (k, mut var) = reg.coefficient(0, l);
        if let Some(m) = mass.filter(|m| m.std_error.is_finite()) {
            // K moves with M̂ by −(the coefficient ā gets on the same design).
            let dk_dm = -reg.project(&p.a)[0];
            var += (dk_dm * m.std_error).powi(2);
        }
        self.stiffness = Some(Estimate::new(k, var.sqrt(), reg.dof(l)));
        self.elastic_curve = p.curve(&p.u, &y, reg.coef[1]);
        self.used_for_stiffness = !self
            .flags
            .iter()
            .any(|f| matches!(f, Flag::ShortPlateau { .. }));
    }
}

/// `Kₑ` of group `g`: the mean of its usable triangle tests.
pub(crate) fn group_stiffness_from_triangles(work: &[Work], g: usize) -> GroupStiffness {
    let used: Vec<Estimate> = work
        .iter()
        .filter(|w| w.group == g && w.used_for_stiffness)
        .filter_map(|w| w.stiffness)
        .collect();
    (Estimate::pooled(&used), StiffnessSource::TriangleTests)
}

/// The stiffness at the reference pressure, with a warning when it does not come from
/// triangle tests, and warnings for groups whose triangle stiffnesses disagree.
pub(crate) fn stiffness_parameter(
    work: &[Work],
    groups: &Groups,
    group_stiffness: &[GroupStiffness],
    warnings: &mut Vec<Warning>,
) -> Parameter {
    let (k_ref, k_src) = group_stiffness[groups.reference];
    let stiffness_param = match k_ref {
        Some(k) => {
            if k_src != StiffnessSource::TriangleTests {
                warnings.push(Warning::StiffnessNotFromTriangles { source: k_src });
            }
            Parameter::Estimated(k)
        }
        None => Parameter::NotIdentifiable {
            reason: "no usable triangle test, and no sine tests at two or more frequencies, at \
                     the reference pressure"
                .into(),
        },
    };
    // Stiffnesses within a group should agree; measured against the reference pressure's
    // (so that the near-zero stiffness of 0 MPa tests is not judged against itself).
    let k_scale = k_ref.map_or(0.0, |k| k.value.abs());
    for (g, key) in groups.keys.iter().enumerate() {
        let ks: Vec<f64> = work
            .iter()
            .filter(|w| w.group == g && w.used_for_stiffness)
            .filter_map(|w| w.stiffness.map(|e| e.value))
            .collect();
        if ks.len() >= 2 {
            let mean = ks.iter().sum::<f64>() / ks.len() as f64;
            let spread = ks.iter().map(|k| (k - mean).abs()).fold(0.0, f64::max);
            let scale = mean.abs().max(k_scale);
            if scale > 0.0 && spread > 0.1 * scale {
                warnings.push(Warning::StiffnessSpread {
                    pressure_pa: *key,
                    spread_n_per_m: spread,
                    mean_n_per_m: mean,
                });
            }
        }
    }
    stiffness_param
}
