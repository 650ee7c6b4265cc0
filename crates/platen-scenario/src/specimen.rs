//! The scenario's `specimen`, for every table: a shear building (`storeys`) or a general
//! linear specimen (its four matrices), read and checked once, with JSON paths in the
//! errors. The uniaxial platen takes either as a [`Specimen`] (a general one by the `x`
//! column of its influence); a multi-axis table takes either as a [`LinearSpecimen`] (the
//! storeys along `x`).

use nalgebra::DMatrix;
use platen_model::multi_axis::LinearSpecimen;
use platen_model::{Hysteresis, ModelError, Specimen, Storey};

use crate::ctx::Ctx;
use crate::error::Result;
use crate::file::{HysteresisSpec, SpecimenSpec};

/// How far from the reference point a table's points (and a specimen's levers, a pose) may
/// lie in a scenario, m (rad for a rotation): the largest shake tables span about 20 m, so a
/// value beyond is a unit slip (millimetres written as metres) or a typing error, refused at
/// its key.
pub const PLAUSIBLE_GEOMETRY_M: f64 = 100.0;

/// `specimen` of a uniaxial scenario: storeys, or the four matrices on the platen's axis.
pub(crate) fn platen_specimen(ctx: &Ctx, given: Option<&SpecimenSpec>) -> Result<Option<Specimen>> {
    let Some(s) = given else {
        return Ok(None);
    };
    if !s.is_general() {
        return storeys(ctx, s).map(Some);
    }
    let general = linear(ctx, s)?;
    Specimen::general(&general).map(Some).map_err(|e| match e {
        ModelError::InvalidTable { path, expected } => ctx.invalid(&path, "(as given)", expected),
        other => ctx.invalid("specimen", "", other.to_string()),
    })
}

/// `specimen` of a multi-axis scenario: storeys (along x) or the four matrices.
pub(crate) fn table_specimen(
    ctx: &Ctx,
    given: Option<&SpecimenSpec>,
) -> Result<Option<LinearSpecimen>> {
    let Some(s) = given else {
        return Ok(None);
    };
    if !s.is_general() {
        // The storeys' reader: the same checks, each storey's value named by its path.
        let building = storeys(ctx, s)?;
        if let Some(i) = s.storeys.iter().position(|st| st.hysteresis.is_some()) {
            return Err(ctx.invalid(
                &format!("specimen.storeys[{i}].hysteresis"),
                "(given)",
                "no hysteresis on a multi-axis table yet: its storeys are linear (a yielding \
                 storey runs on the uniaxial platen's inverse runs)",
            ));
        }
        if let Some(i) = s.storeys.iter().position(|st| st.height_m.is_some()) {
            return Err(ctx.invalid(
                &format!("specimen.storeys[{i}].height_m"),
                "(given)",
                "no height on a multi-axis table yet: its summary gives no drift ratios",
            ));
        }
        return Ok(Some(LinearSpecimen::from_storeys(&building)));
    }
    linear(ctx, s).map(Some)
}

/// The validated `specimen.storeys`, with JSON paths in its errors.
fn storeys(ctx: &Ctx, given: &SpecimenSpec) -> Result<Specimen> {
    let storeys = given
        .storeys
        .iter()
        .map(|s| Storey {
            mass_kg: s.mass_kg,
            stiffness_n_per_m: s.stiffness_n_per_m,
            damping_n_s_per_m: s.damping_n_s_per_m,
        })
        .collect();
    let storey_error = |e: ModelError| match e {
        ModelError::InvalidStorey { index, source } => match *source {
            ModelError::InvalidParameter {
                name,
                value,
                expected,
            } => ctx.invalid(
                &format!("specimen.storeys[{index}].{name}"),
                value,
                expected,
            ),
            other => ctx.invalid(&format!("specimen.storeys[{index}]"), "", other.to_string()),
        },
        other => ctx.invalid("specimen.storeys", given.storeys.len(), other.to_string()),
    };
    let building = Specimen::new(storeys).map_err(storey_error)?;
    let hysteresis = given
        .storeys
        .iter()
        .enumerate()
        .map(|(i, s)| {
            s.hysteresis
                .as_ref()
                .map(|h| hysteresis(ctx, i, h))
                .transpose()
        })
        .collect::<Result<Vec<_>>>()?;
    let heights = given.storeys.iter().map(|s| s.height_m).collect();
    building
        .with_hysteresis(hysteresis)
        .and_then(|b| b.with_heights(heights))
        .map_err(storey_error)
}

/// Storey `i`'s validated `hysteresis`, its errors at their JSON path.
fn hysteresis(ctx: &Ctx, i: usize, given: &HysteresisSpec) -> Result<Hysteresis> {
    let (law, built) = match given {
        HysteresisSpec::Bilinear(b) => (
            "bilinear",
            Hysteresis::bilinear(b.yield_force_n, b.post_yield_stiffness_ratio),
        ),
        HysteresisSpec::BoucWen(b) => (
            "bouc_wen",
            Hysteresis::bouc_wen(
                b.yield_force_n,
                b.post_yield_stiffness_ratio,
                b.exponent,
                b.beta_share,
            ),
        ),
    };
    built.map_err(|e| match e {
        ModelError::InvalidParameter {
            name,
            value,
            expected,
        } => ctx.invalid(
            &format!("specimen.storeys[{i}].hysteresis.{law}.{name}"),
            value,
            expected,
        ),
        other => ctx.invalid(
            &format!("specimen.storeys[{i}].hysteresis"),
            "",
            other.to_string(),
        ),
    })
}

/// The validated general linear specimen of `specimen` (its four matrices), with JSON paths
/// in its errors.
fn linear(ctx: &Ctx, s: &SpecimenSpec) -> Result<LinearSpecimen> {
    if !s.storeys.is_empty() {
        return Err(ctx.invalid(
            "specimen.storeys",
            "(given)",
            "storeys or the four matrices, not both",
        ));
    }
    let matrix = |key: &str,
                  m: &Option<Vec<Vec<f64>>>,
                  cols: Option<usize>|
     -> Result<DMatrix<f64>> {
        let at = format!("specimen.{key}");
        let m = m
            .as_ref()
            .ok_or_else(|| ctx.invalid(&at, "(absent)", "a matrix: a general linear specimen needs mass_matrix, stiffness_matrix, damping_matrix and influence"))?;
        let n = m.len();
        let width = cols.unwrap_or(n);
        if let Some((r, row)) = m.iter().enumerate().find(|(_, row)| row.len() != width) {
            return Err(ctx.invalid(
                &format!("{at}[{r}]"),
                format!("{} numbers", row.len()),
                format!("{width} numbers"),
            ));
        }
        Ok(DMatrix::from_fn(n, width, |r, c| m[r][c]))
    };
    let mass = matrix("mass_matrix", &s.mass_matrix, None)?;
    let stiffness = matrix("stiffness_matrix", &s.stiffness_matrix, None)?;
    let damping = matrix("damping_matrix", &s.damping_matrix, None)?;
    let influence = matrix("influence", &s.influence, Some(6))?;
    if let Some((r, c)) = (0..influence.nrows())
        .flat_map(|r| (0..6).map(move |c| (r, c)))
        .find(|&(r, c)| influence[(r, c)].abs() > PLAUSIBLE_GEOMETRY_M)
    {
        return Err(ctx.invalid(
            &format!("specimen.influence[{r}][{c}]"),
            influence[(r, c)],
            format!(
                "a share of the platen's motion within ±{PLAUSIBLE_GEOMETRY_M} (a rotation's lever \
                 in m: no specimen stands {PLAUSIBLE_GEOMETRY_M} m from the reference point)"
            ),
        ));
    }
    LinearSpecimen::new(mass, stiffness, damping, influence).map_err(|e| match e {
        ModelError::InvalidTable { path, expected } => ctx.invalid(&path, "(as given)", expected),
        other => ctx.invalid("specimen", "", other.to_string()),
    })
}
