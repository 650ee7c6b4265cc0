//! The model of a scenario ([`Model`]: identified or full form) and the values it lays over
//! its preset ([`ModelOverrides`]), validated by name with JSON paths in their errors.

use platen_model::{
    FullModel, IdentifiedKey, IdentifiedModel, ModelError, PhysicalKey, PlatenModel, Preset,
};

use crate::ctx::Ctx;
use crate::error::Result;
use crate::file::{given_values, ModelSpec};

/// A validated model in one of its two forms.
#[derive(Debug, Clone, PartialEq)]
pub enum Model {
    /// The identified model (Eq. 22/23).
    Identified(IdentifiedModel),
    /// The full Lagrangian model (Eq. 1–8).
    Full(Box<FullModel>),
}

impl Model {
    /// The platen's mass at displacement `u_m`, kg.
    pub fn mass_kg_at(&self, u_m: f64) -> f64 {
        match self {
            Model::Identified(m) => m.mass_kg(u_m),
            Model::Full(m) => m.mass_kg(u_m),
        }
    }

    /// `"identified"` or `"full"`.
    pub fn form(&self) -> &'static str {
        match self {
            Model::Identified(_) => "identified",
            Model::Full(_) => "full",
        }
    }
}

/// A model parameter of either form, by its contract name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelKey {
    /// One of the identified model's seven keys.
    Identified(IdentifiedKey),
    /// A physical parameter of the full model.
    Full(PhysicalKey),
}

impl ModelKey {
    /// `"identified"` or `"full"`: the form the key belongs to.
    pub fn form(self) -> &'static str {
        match self {
            ModelKey::Identified(_) => "identified",
            ModelKey::Full(_) => "full",
        }
    }

    /// The key's name.
    pub fn name(self) -> &'static str {
        match self {
            ModelKey::Identified(k) => k.name(),
            ModelKey::Full(k) => k.name(),
        }
    }
}

/// The values a scenario lays over its preset: the model form and its overrides.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelOverrides {
    full: bool,
    values: Vec<(ModelKey, f64)>,
}

impl ModelOverrides {
    /// The values laid over the preset, by key, in the order given (alphabetical for a
    /// scenario file); empty when the preset's own values run.
    pub fn values(&self) -> &[(ModelKey, f64)] {
        &self.values
    }

    /// `"identified"` or `"full"`.
    pub fn form(&self) -> &'static str {
        if self.full {
            "full"
        } else {
            "identified"
        }
    }

    /// The model of `preset` at `pressure_pa` with these overrides and then `extra` laid
    /// over it.
    ///
    /// # Errors
    /// [`ModelError::InvalidParameter`] for a value the model rejects, or
    /// [`ModelError::UnknownParameter`] for a key of the other form.
    pub fn build(
        &self,
        preset: Preset,
        pressure_pa: f64,
        extra: &[(ModelKey, f64)],
    ) -> std::result::Result<Model, ModelError> {
        let values = self.values.iter().chain(extra);
        if self.full {
            let mut p = preset.physical(pressure_pa)?;
            for &(key, value) in values {
                match key {
                    ModelKey::Full(k) => p.set(k, value),
                    other => return Err(wrong_form("full", other)),
                }
            }
            Ok(Model::Full(Box::new(p.build()?)))
        } else {
            let mut p = preset.identified(pressure_pa)?;
            for &(key, value) in values {
                match key {
                    ModelKey::Identified(k) => p.set(k, value),
                    other => return Err(wrong_form("identified", other)),
                }
            }
            Ok(Model::Identified(p.build()?))
        }
    }
}

/// A key of the other form, reported as an unknown parameter of `form`.
fn wrong_form(form: &'static str, key: ModelKey) -> ModelError {
    ModelError::UnknownParameter {
        form,
        name: key.name().to_owned(),
        known: format!("the parameters of the {form} model"),
    }
}

/// The scenario's model form and overrides, validated by name.
pub(crate) fn model_overrides(ctx: &Ctx, spec: &ModelSpec) -> Result<ModelOverrides> {
    let (full, given, section) = match (&spec.identified, &spec.full) {
        (Some(_), Some(_)) => return Err(ctx.invalid(
            "model",
            "{identified, full}",
            "either an `identified` object (identified model) or a `full` object (full Lagrangian model), not both",
        )),
        (_, Some(over)) => (true, given_values(over), "model.full"),
        (Some(over), None) => (false, given_values(over), "model.identified"),
        (None, None) => (false, Vec::new(), "model.identified"),
    };
    let values = given
        .into_iter()
        .map(|(name, value)| {
            let key = if full {
                PhysicalKey::from_name(&name).map(ModelKey::Full)
            } else {
                IdentifiedKey::from_name(&name).map(ModelKey::Identified)
            };
            key.map(|k| (k, value))
                .map_err(|e| ctx.model_error(section, e))
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(ModelOverrides { full, values })
}

/// The model of `preset` at `pressure_pa` with `overrides`, with JSON paths in its errors.
pub(crate) fn build_model(
    ctx: &Ctx,
    preset: Preset,
    pressure_pa: f64,
    overrides: &ModelOverrides,
) -> Result<Model> {
    let section = if overrides.full {
        "model.full"
    } else {
        "model.identified"
    };
    overrides
        .build(preset, pressure_pa, &[])
        .map_err(|e| ctx.model_error(section, e))
}
