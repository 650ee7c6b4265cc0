//! `platen model`: a preset's parameters and derived quantities.

use anyhow::Result;
use serde_json::Value;

use platen_model::Preset;

use crate::Form;

pub fn run(preset: &str, pressure_mpa: Option<f64>, form: Form, json_out: bool) -> Result<()> {
    let preset = Preset::from_name(preset)?;
    let pressure_pa = match pressure_mpa {
        Some(p) if !(p.is_finite() && p >= 0.0) => {
            anyhow::bail!("--pressure-mpa {p}: expected a pressure >= 0 MPa")
        }
        Some(p) => p * 1e6,
        None => preset.nominal_pressure_pa(),
    };
    let value = platen_scenario::describe_model(preset, pressure_pa, matches!(form, Form::Full))?;
    if json_out {
        outln!("{}", serde_json::to_string_pretty(&value)?);
    } else if let Value::Object(m) = &value {
        for (k, v) in m {
            if !v.is_object() {
                outln!("{k:>34}  {v}");
            }
        }
        for section in ["limits", "physical"] {
            if let Some(Value::Object(sub)) = m.get(section) {
                outln!("  {section}:");
                for (k, v) in sub {
                    outln!("{k:>34}  {v}");
                }
            }
        }
    }
    Ok(())
}
