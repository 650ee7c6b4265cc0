//! The friction law of the platen's force balance: Coulomb and linear viscous friction, or,
//! where the records support it, a Stribeck term and a viscous exponent other than 1, each
//! found on a grid and kept only beyond [`FRICTION_TERM_T`] standard errors.

use super::design::{mechanics_columns, mechanics_design, mechanics_signs, ForceFrom, Law};
use super::PlantInput;
use crate::error::Result;
use crate::system::fit::LinearFit;
use crate::system::SystemRecord;

/// Samples slower than this are left out of the fits of a richer friction law, m/s: the
/// Stribeck term lives at a few mm/s, and above [`SLIP_SPEED_M_S`](super::design::SLIP_SPEED_M_S) there is little of it
/// left to see (e^(−2) at b = 200 s/m). Four times the velocity noise of a 5 µm displacement
/// sensor differenced at 204.8 Hz (0.72 mm/s), so a stuck platen's samples stay out.
pub const LOW_SLIP_SPEED_M_S: f64 = 0.003;
/// The Stribeck decays `b` tried, s/m (a decay speed 1/b of 40 to 1.25 mm/s).
pub const DECAY_GRID_S_PER_M: [f64; 6] = [25.0, 50.0, 100.0, 200.0, 400.0, 800.0];
/// The viscous exponents `α` tried.
pub const EXPONENT_GRID: [f64; 10] = [0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2];
/// A richer friction term is kept only when its coefficient is this many (batch-means)
/// standard errors from 0: the records support it well beyond chance (two-sided p < 0.3 %).
pub const FRICTION_TERM_T: f64 = 3.0;

/// The friction law the corrected records support ([`Law`]): the best of the grids of
/// [`DECAY_GRID_S_PER_M`] (or none) and [`EXPONENT_GRID`] above [`LOW_SLIP_SPEED_M_S`]; the
/// Stribeck term kept when its amplitude is positive and [`FRICTION_TERM_T`] standard errors
/// from 0, an exponent other than 1 when the score of `α = 1` (the coefficient of `v·ln|v|`)
/// is. Without either, Coulomb and linear viscous friction above [`SLIP_SPEED_M_S`](super::design::SLIP_SPEED_M_S), as
/// before any richer law was tried. Returns the fit and its law.
pub(super) fn friction_law(
    records: &[SystemRecord],
    periods: &[f64],
    fitted: &[usize],
    input: &PlantInput,
    from: ForceFrom,
    storeys: usize,
) -> Result<Option<(LinearFit, Law)>> {
    let fit = |law: &Law| -> Result<Option<LinearFit>> {
        let m = mechanics_columns(from, storeys, fitted.len(), law);
        let design = mechanics_design(records, periods, fitted, input, from, storeys, 0.0, law)?;
        Ok(design.fit(&mechanics_signs(m), &vec![false; m]))
    };
    let low = |exponent: f64, decay_s_per_m: Option<f64>| Law {
        exponent,
        decay_s_per_m,
        slip_speed_m_s: LOW_SLIP_SPEED_M_S,
        exponent_score: false,
    };
    // Every law of a grid, fitted once, in the grid's order (decays outer, exponents inner).
    let grid = |decays: &[Option<f64>], exponents: &[f64]| -> Result<Vec<(LinearFit, Law)>> {
        let mut out = Vec::with_capacity(decays.len() * exponents.len());
        for &b in decays {
            for &alpha in exponents {
                let law = low(alpha, b);
                if let Some(f) = fit(&law)? {
                    out.push((f, law));
                }
            }
        }
        Ok(out)
    };
    // The fit of least residual among `fits` (the first of equals).
    let best = |fits: Vec<(LinearFit, Law)>| -> Option<(LinearFit, Law)> {
        fits.into_iter()
            .reduce(|a, b| if b.0.rss < a.0.rss { b } else { a })
    };
    let t = |f: &LinearFit, j: usize| f.coef[j] / f.estimates[j].std_error;
    let last = |f: &LinearFit| f.coef.len() - 1;
    let decays: Vec<Option<f64>> = DECAY_GRID_S_PER_M.iter().map(|&b| Some(b)).collect();
    let with_stribeck = grid(&decays, &EXPONENT_GRID)?;
    // The Stribeck term: its amplitude at the best decay and exponent.
    let stribeck = match best(with_stribeck.clone()) {
        Some((f, law)) if f.coef[last(&f)] > 0.0 && t(&f, last(&f)) > FRICTION_TERM_T => {
            law.decay_s_per_m
        }
        _ => None,
    };
    // The exponent: the score of α = 1 with the Stribeck term as found.
    let score_law = Law {
        exponent_score: true,
        ..low(1.0, stribeck)
    };
    let exponent_free = fit(&score_law)?.is_some_and(|f| t(&f, last(&f)).abs() > FRICTION_TERM_T);
    if stribeck.is_none() && !exponent_free {
        return Ok(fit(&Law::LINEAR)?.map(|f| (f, Law::LINEAR)));
    }
    if stribeck.is_none() {
        return Ok(best(grid(&[None], &EXPONENT_GRID)?));
    }
    // With the Stribeck term: the grid's own fits at its decay (every exponent, or α = 1).
    Ok(best(
        with_stribeck
            .into_iter()
            .filter(|(_, law)| {
                law.decay_s_per_m == stribeck && (exponent_free || law.exponent == 1.0)
            })
            .collect(),
    ))
}
