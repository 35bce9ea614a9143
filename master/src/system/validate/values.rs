//! Values: a written value converted to the variable's type, and the start values of an
//! instance checked against what FMI 2.0 lets a master set before and during initialization.

use super::Checker;
use crate::error::did_you_mean;
use crate::model_description::VarType;
use crate::system::{InstanceSpec, StartValue, TypedValue, Value};

/// A written value as a value of FMI type `t`, or why it does not fit.
pub(super) fn convert(value: &Value, t: VarType) -> std::result::Result<TypedValue, String> {
    let bad = || format!("value {value} does not fit a {t} variable");
    Ok(match (t, value) {
        (VarType::Real, Value::Real(v)) => TypedValue::Real(*v),
        (VarType::Real, Value::Integer(v)) => TypedValue::Real(*v as f64),
        (VarType::Real, Value::Text(s)) => TypedValue::Real(s.parse::<f64>().map_err(|_| bad())?),
        (VarType::Integer | VarType::Enumeration, Value::Integer(v)) => {
            TypedValue::Integer(i32::try_from(*v).map_err(|_| bad())?)
        }
        (VarType::Integer | VarType::Enumeration, Value::Text(s)) => {
            TypedValue::Integer(s.parse::<i32>().map_err(|_| bad())?)
        }
        (VarType::Boolean, Value::Boolean(b)) => TypedValue::Boolean(*b),
        (VarType::Boolean, Value::Integer(i)) if *i == 0 || *i == 1 => TypedValue::Boolean(*i == 1),
        (VarType::Boolean, Value::Text(s)) => TypedValue::Boolean(match s.as_str() {
            "true" | "1" => true,
            "false" | "0" => false,
            _ => return Err(bad()),
        }),
        (VarType::String, Value::String(s)) | (VarType::String, Value::Text(s)) => {
            TypedValue::String(s.clone())
        }
        _ => return Err(bad()),
    })
}

impl Checker<'_> {
    /// The start values of instance `i`: each names an existing variable, fits its type, and is
    /// settable in "Instantiated" (applied before initialization) or in "InitializationMode"
    /// (FMI 2.0 section 4.2.4).
    pub(super) fn start_values(&mut self, i: usize, inst: &InstanceSpec) -> Vec<StartValue> {
        let md = self.mds[i];
        let mut svs = Vec::new();
        for v in &inst.values {
            let Some(vi) = md
                .model_variables
                .variables
                .iter()
                .position(|x| x.name == v.variable)
            else {
                let e = self.err(
                    v.line,
                    format!(
                        "instance '{}': no variable '{}' to set to {}{}",
                        inst.name,
                        v.variable,
                        v.value,
                        did_you_mean(&v.variable, self.var_names(i))
                    ),
                );
                self.errors.push(e);
                continue;
            };
            let sv = &md.model_variables.variables[vi];
            let t = sv.var_type().expect("checked at load");
            let tv = match convert(&v.value, t) {
                Ok(tv) => tv,
                Err(m) => {
                    let e = self.err(
                        v.line,
                        format!("instance '{}', variable '{}': {m}", inst.name, v.variable),
                    );
                    self.errors.push(e);
                    continue;
                }
            };
            let before = sv.settable_in_instantiated();
            if !before && !sv.settable_in_initialization_mode() {
                let e = self.err(v.line, format!(
                    "instance '{}', variable '{}' ({}, {}, initial={}) cannot be set (value {}): only parameters, inputs and variables with initial exact/approx can",
                    inst.name, v.variable, sv.causality, sv.variability,
                    sv.effective_initial().map(|x| format!("{x:?}").to_lowercase()).unwrap_or_else(|| "none".into()),
                    v.value
                ));
                self.errors.push(e);
                continue;
            }
            svs.push(StartValue {
                vr: sv.value_reference,
                value: tv,
                before_init: before,
                variable: v.variable.clone(),
            });
        }
        svs
    }
}
