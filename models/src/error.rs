//! Parameter errors and the parameter checks shared by every model's validating constructor.
//!
//! A check returns `Ok(())` or a [`ParamError`] that names the parameter, its value and the rule
//! it breaks; its text is `parameter <name> = <value> <rule>`. The same rule always has the same
//! text:
//!
//! | check | accepts | rule text |
//! | --- | --- | --- |
//! | [`check_positive`] | finite and > 0 | `must be finite and > 0` |
//! | [`check_non_negative`] | finite and ≥ 0 | `must be finite and >= 0` |
//! | [`check_finite`] | finite | `must be finite` |
//! | [`check_positive_or_infinite`] | > 0, +∞ included (a depth ratio of infinite depth) | `must be > 0 (inf allowed)` |
//! | [`check_mass_matrix_2x2`] | finite entries, non-zero determinant | `must be finite`, `mass matrix must be invertible` |
//! | [`require`] | whatever the caller states | the caller's rule |
//!
//! Models whose constructors report a `String` (the disturbances, the sensors, some observers)
//! use the same checks through `From<ParamError> for String`; the controllers through
//! `From<ParamError> for ControlError`.

use std::fmt;

/// A parameter outside its legal range.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamError {
    /// The parameter's name (the model's name; an FMU may report it under its own,
    /// see [`ParamError::renamed`]).
    pub name: String,
    /// The rejected value.
    pub value: f64,
    /// The rule the value breaks, e.g. `must be finite and > 0`.
    pub rule: &'static str,
}

impl ParamError {
    pub fn new(name: impl Into<String>, value: f64, rule: &'static str) -> Self {
        ParamError {
            name: name.into(),
            value,
            rule,
        }
    }

    /// The same error under another parameter name: `names` maps a model's parameter name to
    /// the name a user sees (an FMU variable); a name not in the list is kept.
    pub fn renamed(mut self, names: &[(&str, &str)]) -> Self {
        if let Some((_, to)) = names.iter().find(|(from, _)| *from == self.name) {
            self.name = (*to).to_string();
        }
        self
    }
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "parameter {} = {} {}", self.name, self.value, self.rule)
    }
}

impl std::error::Error for ParamError {}

impl From<ParamError> for String {
    fn from(e: ParamError) -> Self {
        e.to_string()
    }
}

/// `Ok(())` when `ok`, otherwise the error `parameter <name> = <value> <rule>`.
pub fn require(ok: bool, name: &str, value: f64, rule: &'static str) -> Result<(), ParamError> {
    if ok {
        Ok(())
    } else {
        Err(ParamError::new(name, value, rule))
    }
}

/// `value` is finite and > 0.
pub fn check_positive(name: &str, value: f64) -> Result<(), ParamError> {
    require(
        value.is_finite() && value > 0.0,
        name,
        value,
        "must be finite and > 0",
    )
}

/// `value` is finite and ≥ 0.
pub fn check_non_negative(name: &str, value: f64) -> Result<(), ParamError> {
    require(
        value.is_finite() && value >= 0.0,
        name,
        value,
        "must be finite and >= 0",
    )
}

/// `value` is finite.
pub fn check_finite(name: &str, value: f64) -> Result<(), ParamError> {
    require(value.is_finite(), name, value, "must be finite")
}

/// `value` is > 0, +∞ included (NaN is not).
pub fn check_positive_or_infinite(name: &str, value: f64) -> Result<(), ParamError> {
    require(value > 0.0, name, value, "must be > 0 (inf allowed)")
}

/// The 2×2 sway-yaw mass matrix `m` (entries `m11` … `m22`) is finite and invertible.
pub fn check_mass_matrix_2x2(m: &[[f64; 2]; 2]) -> Result<(), ParamError> {
    let names = [["m11", "m12"], ["m21", "m22"]];
    for i in 0..2 {
        for j in 0..2 {
            check_finite(names[i][j], m[i][j])?;
        }
    }
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    require(
        det.abs() > 0.0,
        "m (determinant)",
        det,
        "mass matrix must be invertible",
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checks_accept_and_reject_as_documented() {
        let inf = f64::INFINITY;
        for (v, positive, non_negative, finite, positive_or_inf) in [
            (1.0, true, true, true, true),
            (0.0, false, true, true, false),
            (-1.0, false, false, true, false),
            (inf, false, false, false, true),
            (-inf, false, false, false, false),
            (f64::NAN, false, false, false, false),
        ] {
            assert_eq!(check_positive("x", v).is_ok(), positive, "{v}");
            assert_eq!(check_non_negative("x", v).is_ok(), non_negative, "{v}");
            assert_eq!(check_finite("x", v).is_ok(), finite, "{v}");
            assert_eq!(
                check_positive_or_infinite("x", v).is_ok(),
                positive_or_inf,
                "{v}"
            );
        }
    }

    #[test]
    fn message_names_parameter_value_and_rule() {
        let e = check_positive("time_constant", -1.0).unwrap_err();
        assert_eq!(
            e.to_string(),
            "parameter time_constant = -1 must be finite and > 0"
        );
        assert_eq!(String::from(e.clone()), e.to_string());
        let e = check_non_negative("sigma", f64::NAN).unwrap_err();
        assert_eq!(
            e.to_string(),
            "parameter sigma = NaN must be finite and >= 0"
        );
        let e = require(false, "e_w3_min", 2.0, "must be <= e_w3_max").unwrap_err();
        assert_eq!(e.to_string(), "parameter e_w3_min = 2 must be <= e_w3_max");
    }

    #[test]
    fn mass_matrix_must_be_finite_and_invertible() {
        assert!(check_mass_matrix_2x2(&[[1.0, 0.5], [0.5, 2.0]]).is_ok());
        let e = check_mass_matrix_2x2(&[[1.0, 2.0], [2.0, 4.0]]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "parameter m (determinant) = 0 mass matrix must be invertible"
        );
        let e = check_mass_matrix_2x2(&[[1.0, 0.0], [f64::NAN, 1.0]]).unwrap_err();
        assert_eq!(e.name, "m21");
    }

    #[test]
    fn renamed_maps_listed_names_only() {
        let names = [("u0", "nominal_speed"), ("t", "t_prime")];
        let e = check_positive("u0", 0.0).unwrap_err().renamed(&names);
        assert_eq!(
            e.to_string(),
            "parameter nominal_speed = 0 must be finite and > 0"
        );
        let e = check_finite("rudder_max", f64::NAN)
            .unwrap_err()
            .renamed(&names);
        assert_eq!(e.name, "rudder_max");
    }
}
