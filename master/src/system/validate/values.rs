//! Values: a written value converted to the variable's type (and, for a Real with a unit, to
//! the variable's declared unit, [`crate::units`]) and checked against the variable's declared
//! range; and the start values of an instance checked against what FMI 2.0 lets a master set
//! before and during initialization.

use super::Checker;
use crate::error::did_you_mean;
use crate::model_description::{ModelDescription, ScalarVariable, VarType, Variability};
use crate::system::{InstanceSpec, StartValue, TypedValue, Value, ValueSpec};
use crate::units::{self, Quantity, RadRule, Unit};

/// A written value as a value of variable `sv` of `md`, or why it does not fit: its type, its
/// unit (a value with a unit is converted to the declared unit) and its declared min/max
/// (FMI 2.0, sec. 2.2.7), which the FMU's fmi2SetXXX would otherwise refuse during the run.
pub(super) fn convert(
    value: &Value,
    md: &ModelDescription,
    sv: &ScalarVariable,
) -> std::result::Result<TypedValue, String> {
    let t = sv.var_type().expect("checked at load");
    let bad = || format!("value {value} does not fit a {t} variable");
    let tv = match (t, value) {
        (VarType::Real, Value::Real(v)) => TypedValue::Real(*v),
        (VarType::Real, Value::Integer(v)) => TypedValue::Real(*v as f64),
        (VarType::Real, Value::Text(s) | Value::String(s)) => TypedValue::Real(real(s, md, sv)?),
        (VarType::Integer | VarType::Enumeration, Value::Integer(v)) => {
            TypedValue::Integer(i32::try_from(*v).map_err(|_| bad())?)
        }
        (VarType::Integer | VarType::Enumeration, Value::Text(s)) => {
            TypedValue::Integer(s.trim().parse::<i32>().map_err(|_| bad())?)
        }
        (VarType::Boolean, Value::Boolean(b)) => TypedValue::Boolean(*b),
        (VarType::Boolean, Value::Integer(i)) if *i == 0 || *i == 1 => TypedValue::Boolean(*i == 1),
        (VarType::Boolean, Value::Text(s)) => TypedValue::Boolean(match s.trim() {
            "true" | "1" => true,
            "false" | "0" => false,
            _ => return Err(bad()),
        }),
        (VarType::String, Value::String(s)) | (VarType::String, Value::Text(s)) => {
            TypedValue::String(s.clone())
        }
        _ => return Err(bad()),
    };
    in_range(&tv, value, md, sv)?;
    Ok(tv)
}

/// A Real written as text: a plain number as parsed (its bits untouched), a `pi` expression,
/// or either with a unit, converted to the variable's declared unit.
fn real(text: &str, md: &ModelDescription, sv: &ScalarVariable) -> Result<f64, String> {
    let q = Quantity::parse(text).map_err(|m| format!("value {text:?}: {m}"))?;
    let Some(unit) = q.unit else {
        return Ok(q.value);
    };
    let Some(declared) = md.real_unit(sv) else {
        return Err(format!(
            "value {text:?} has unit '{unit}' but the variable declares no unit; write it without a unit"
        ));
    };
    if unit == declared {
        return Ok(q.value);
    }
    let (to, to_fmu) = units::declared(md, declared).map_err(|e| format!("value {text:?}: {e}"))?;
    let (from, from_fmu) = match Unit::parse(&unit) {
        Ok(u) => (u, false),
        Err(e) => match md.unit(&unit).and_then(Unit::from_definition) {
            Some(u) => (u, true),
            None => return Err(format!("value {text:?}: {e}")),
        },
    };
    let rule = RadRule::Omittable {
        from: from_fmu,
        to: to_fmu,
    };
    let c = from.conversion_to(&to, rule).ok_or_else(|| {
        format!(
            "value {text:?}: unit '{unit}' ({}) does not convert to the variable's unit '{declared}' ({}): their SI exponents differ",
            from.dimension(),
            to.dimension()
        )
    })?;
    if to_fmu && from.exponents[units::RAD] != to.exponents[units::RAD] {
        ambiguous_rad(text, declared, &to)?;
    }
    Ok(c.apply(q.value))
}

/// A declared unit that omits rad (rad = 0) under a name the built-in table knows with
/// another factor, e.g. an FMU's `rpm` as s-1 with factor 1/60 where the table's `rpm` is
/// 2 pi/60 rad/s: a value converted to it through the rad rule would be off by 2 pi, so it must
/// be written in the declared unit itself.
fn ambiguous_rad(text: &str, declared: &str, to: &Unit) -> Result<(), String> {
    match Unit::parse(declared) {
        Ok(b) if b.factor != to.factor || b.offset != to.offset => Err(format!(
            "value {text:?} is ambiguous: the FMU declares '{declared}' without rad ({}, factor {}) where the built-in '{declared}' is {} with factor {}; write the value in {declared}",
            to.dimension(),
            to.factor,
            b.dimension(),
            b.factor
        )),
        _ => Ok(()),
    }
}

/// The declared min and max of a variable (a Real's own, else its declared type's).
fn range(md: &ModelDescription, sv: &ScalarVariable) -> (Option<f64>, Option<f64>) {
    if let Some(r) = &sv.real {
        let ty = md.real_declared_type(sv);
        let min = r.min.or(ty.and_then(|t| t.min));
        return (min, r.max.or(ty.and_then(|t| t.max)));
    }
    match sv.integer.as_ref().or(sv.enumeration.as_ref()) {
        Some(i) => (i.min.map(f64::from), i.max.map(f64::from)),
        None => (None, None),
    }
}

/// The value is a number (not NaN) and lies in the declared range.
fn in_range(
    tv: &TypedValue,
    written: &Value,
    md: &ModelDescription,
    sv: &ScalarVariable,
) -> Result<(), String> {
    let x = match tv {
        TypedValue::Real(x) => *x,
        TypedValue::Integer(i) => f64::from(*i),
        _ => return Ok(()),
    };
    if x.is_nan() {
        return Err(format!("value {written} is not a number (NaN)"));
    }
    let (min, max) = range(md, sv);
    if min.is_none() && max.is_none() {
        return Ok(());
    }
    if min.is_none_or(|lo| x >= lo) && max.is_none_or(|hi| x <= hi) {
        return Ok(());
    }
    let shown = written.to_string();
    let typed_unit = match written {
        Value::Text(s) | Value::String(s) => Quantity::parse(s).ok().and_then(|q| q.unit),
        _ => None,
    };
    let converted = match (md.real_unit(sv), typed_unit) {
        (Some(u), Some(t)) if t != u => format!(" (= {x} {u})"),
        _ => String::new(),
    };
    let lo = min.map_or("-inf".to_string(), |v| v.to_string());
    let hi = max.map_or("inf".to_string(), |v| v.to_string());
    Err(format!(
        "value {shown}{converted} is outside the declared range [{lo}, {hi}]"
    ))
}

impl Checker<'_> {
    /// The start values of instance `i`: each names an existing variable, fits its type, unit
    /// and range, and is settable in "Instantiated" (applied before initialization) or in
    /// "InitializationMode" (FMI 2.0 section 4.2.4); a constant cannot be set at all.
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
                        "{}instance '{}': no variable '{}' to set to {}{}",
                        set_origin(inst, v),
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
            let refused = |m: String| {
                format!(
                    "{}instance '{}', variable '{}': {m}",
                    set_origin(inst, v),
                    inst.name,
                    v.variable
                )
            };
            let tv = match convert(&v.value, md, sv) {
                Ok(tv) => tv,
                Err(m) => {
                    let e = self.err(v.line, refused(m));
                    self.errors.push(e);
                    continue;
                }
            };
            if let Some(w) = bare_angle(&v.value, &tv, md, sv) {
                let w = format!("{}: {}{}", self.loc(v.line), set_origin(inst, v), w);
                self.warnings.push(format!(
                    "{w} (instance '{}', variable '{}')",
                    inst.name, v.variable
                ));
            }
            let before = sv.settable_in_instantiated();
            if sv.variability == Variability::Constant {
                let e = self.err(v.line, refused(format!(
                    "it is a constant (its value {} is fixed by the FMU) and cannot be set (value {})",
                    sv.start_text().unwrap_or_else(|| "?".into()), v.value
                )));
                self.errors.push(e);
                continue;
            }
            if !before && !sv.settable_in_initialization_mode() {
                let e = self.err(v.line, refused(format!(
                    "{} {} with initial={} cannot be set (value {}): only parameters, inputs and variables with initial exact/approx can",
                    sv.causality, sv.variability,
                    sv.effective_initial().map(|x| format!("{x:?}").to_lowercase()).unwrap_or_else(|| "none".into()),
                    v.value
                )));
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

/// A number without a unit on a variable in radians, above a full turn: most likely meant in
/// degrees (`--set waves.wave_direction=90` is 90 rad). Said, not refused: 7 rad is a value.
fn bare_angle(
    value: &Value,
    tv: &TypedValue,
    md: &ModelDescription,
    sv: &ScalarVariable,
) -> Option<String> {
    let TypedValue::Real(x) = *tv else {
        return None;
    };
    let bare = match value {
        Value::Real(_) | Value::Integer(_) => true,
        Value::Text(t) | Value::String(t) => Quantity::parse(t).is_ok_and(|q| q.unit.is_none()),
        Value::Boolean(_) => false,
    };
    (bare && md.real_unit(sv) == Some("rad") && x.abs() > std::f64::consts::TAU).then(|| {
        format!(
            "{x} has no unit and is taken in the variable's, rad ({x} rad = {:.0} deg); for degrees write \"{x} deg\"",
            x.to_degrees()
        )
    })
}

/// `--set inst.var=value: ` for a value set on the command line (or by a campaign or the
/// Python package, the same way: unparsed text without a line), else "".
fn set_origin(inst: &InstanceSpec, v: &ValueSpec) -> String {
    match (&v.value, v.line) {
        (Value::Text(t), None) => format!("--set {}.{}={t}: ", inst.name, v.variable),
        _ => String::new(),
    }
}
