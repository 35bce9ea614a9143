//! Units: SI base-unit exponents plus a factor and an offset, as FMI 2.0 defines them
//! (FMI 2.0, sec. 2.2.2, `BaseUnit`), and the conversion of values between two units.
//!
//! A [`Unit`] is `value_SI = factor * value + offset` with the exponents of the eight base
//! units of FMI 2.0 in the order kg, m, s, A, K, mol, cd, rad ([`BASE_UNITS`]). Units come
//! from two places:
//!
//! - an FMU's `UnitDefinitions` ([`Unit::from_base_unit`], [`Unit::from_definition`]), or any
//!   other file that states exponents, factor and offset (SSP 1.0 `Unit` elements have the
//!   same `BaseUnit`);
//! - the built-in table of common units, by name, for values typed by users
//!   ([`Unit::parse`]; the table is [`BUILT_IN`] and `docs/units.md`). Names combine with
//!   `a/b`, `a.b` (or `a*b`), `a^n` and Modelica's `a2` / `s-1`, e.g. `kN.m`, `deg/s`, `m/s2`.
//!
//! **Conversion** ([`Unit::conversion_to`]) is allowed only when the exponents agree; it maps
//! x in the first unit to `(f1 * x + o1 - o2) / f2` in the second, skipping a multiplication
//! by 1 and an addition of 0, so that between equal units a value keeps its bits.
//!
//! **The `rad` exponent** ([`RadRule`]). FMI 2.0 (sec. 2.2.2) lets a model description omit
//! `rad`: the radian is the SI derived unit 1, so PythonFMU declares its `radian` with rad = 0
//! where our FMUs declare rad = 1. Other tools differ: OMSimulator and FMPy do not compare
//! units of connections at all, and SSP 1.0 (its `Unit`/`BaseUnit` elements) compares the
//! exponents, rad included. Here [`RadRule::Strict`] compares all eight exponents (SSP); with
//! [`RadRule::Omittable`] a rad exponent of 0 on a side that may omit it matches any rad
//! exponent when the seven others agree (so 90 deg converts to PythonFMU's `radian`, and
//! rad/s to a `1/s` declared by an FMU). The built-in units always carry their true rad
//! exponent: `Hz` (s-1, a count of cycles) is not an angular velocity, and `rpm` is
//! 2 pi/60 rad/s; neither omits rad.

use crate::error::did_you_mean;
use crate::model_description::{self, BaseUnit, ModelDescription};
use std::f64::consts::PI;
use std::fmt;

/// The base units of FMI 2.0 sec. 2.2.2, in the order of [`Unit::exponents`].
pub const BASE_UNITS: [&str; 8] = ["kg", "m", "s", "A", "K", "mol", "cd", "rad"];

/// Index of `rad` in [`Unit::exponents`].
pub const RAD: usize = 7;

/// A unit: `value_SI = factor * value + offset`, with SI exponents (kg, m, s, A, K, mol, cd,
/// rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Unit {
    pub exponents: [i32; 8],
    pub factor: f64,
    pub offset: f64,
}

/// How the `rad` exponent is compared (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RadRule {
    /// All eight exponents must agree (SSP 1.0).
    Strict,
    /// A rad exponent of 0 on the sides marked `true` (from, to) matches any rad exponent
    /// (FMI 2.0 lets a model description omit rad).
    Omittable { from: bool, to: bool },
}

/// A conversion from one unit to another (same dimension).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Conversion {
    pub from: Unit,
    pub to: Unit,
}

/// Why a unit text is not a unit, or two units do not convert.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnitError(pub String);

impl fmt::Display for UnitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for UnitError {}

/// One built-in unit: names (aliases), exponents (kg, m, s, A, K, mol, cd, rad), factor.
type Entry = (&'static [&'static str], [i32; 8], f64);

const fn e(kg: i32, m: i32, s: i32, rad: i32) -> [i32; 8] {
    [kg, m, s, 0, 0, 0, 0, rad]
}

/// The built-in units by name (case-sensitive; `docs/units.md` has this table). Compounds
/// such as `km/h`, `N.m`, `deg/s` and `m/s2` are built from these by [`Unit::parse`].
pub const BUILT_IN: &[Entry] = &[
    (&["1"], e(0, 0, 0, 0), 1.0),
    (&["%"], e(0, 0, 0, 0), 0.01),
    (&["m"], e(0, 1, 0, 0), 1.0),
    (&["km"], e(0, 1, 0, 0), 1000.0),
    (&["cm"], e(0, 1, 0, 0), 0.01),
    (&["mm"], e(0, 1, 0, 0), 0.001),
    // The nautical mile (1852 m, exact); `nm` is not the nanometre here.
    (&["nm", "NM", "nmi"], e(0, 1, 0, 0), 1852.0),
    (&["ft"], e(0, 1, 0, 0), 0.3048),
    (&["s"], e(0, 0, 1, 0), 1.0),
    (&["min"], e(0, 0, 1, 0), 60.0),
    (&["h"], e(0, 0, 1, 0), 3600.0),
    (&["kg"], e(1, 0, 0, 0), 1.0),
    (&["t"], e(1, 0, 0, 0), 1000.0),
    (&["N"], e(1, 1, -2, 0), 1.0),
    (&["kN"], e(1, 1, -2, 0), 1000.0),
    (&["Nm"], e(1, 2, -2, 0), 1.0),
    (&["kNm"], e(1, 2, -2, 0), 1000.0),
    (&["J"], e(1, 2, -2, 0), 1.0),
    (&["W"], e(1, 2, -3, 0), 1.0),
    (&["kW"], e(1, 2, -3, 0), 1000.0),
    (&["Pa"], e(1, -1, -2, 0), 1.0),
    (&["rad"], e(0, 0, 0, 1), 1.0),
    (&["deg"], e(0, 0, 0, 1), PI / 180.0),
    // The knot: one nautical mile per hour, 1852/3600 m/s.
    (&["kn", "knot", "knots"], e(0, 1, -1, 0), 1852.0 / 3600.0),
    // Revolutions per minute as an angular velocity: 2 pi/60 rad/s.
    (&["rpm"], e(0, 0, -1, 1), 2.0 * PI / 60.0),
    (&["Hz"], e(0, 0, -1, 0), 1.0),
    (&["A"], [0, 0, 0, 1, 0, 0, 0, 0], 1.0),
    (&["K"], [0, 0, 0, 0, 1, 0, 0, 0], 1.0),
    (&["mol"], [0, 0, 0, 0, 0, 1, 0, 0], 1.0),
    (&["cd"], [0, 0, 0, 0, 0, 0, 1, 0], 1.0),
];

/// Degrees Celsius: K with offset 273.15 (alone only, not in a compound).
const CELSIUS: [&str; 2] = ["degC", "°C"];

impl Unit {
    /// The dimensionless unit 1.
    pub const ONE: Unit = Unit {
        exponents: [0; 8],
        factor: 1.0,
        offset: 0.0,
    };

    /// A `BaseUnit` of a model description.
    pub fn from_base_unit(b: &BaseUnit) -> Unit {
        Unit {
            exponents: b.exponents(),
            factor: b.factor,
            offset: b.offset,
        }
    }

    /// A unit of a model description's `UnitDefinitions`; `None` without a `BaseUnit` (then
    /// the unit is only a name, FMI 2.0 sec. 2.2.2).
    pub fn from_definition(u: &model_description::Unit) -> Option<Unit> {
        u.base_unit.as_ref().map(Unit::from_base_unit)
    }

    /// A unit name of the built-in table, or a compound of them: `a/b`, `a.b`, `a*b`, `a^n`,
    /// `a2`, `s-1` (Modelica), e.g. `km/h`, `kN.m`, `deg/s`, `m/s^2`, `1/s`. Spaces around
    /// the operators are allowed.
    pub fn parse(text: &str) -> Result<Unit, UnitError> {
        let t: String = text.chars().filter(|c| !c.is_whitespace()).collect();
        if t.is_empty() {
            return Err(UnitError("empty unit".into()));
        }
        if CELSIUS.contains(&t.as_str()) {
            return Ok(Unit {
                exponents: [0, 0, 0, 0, 1, 0, 0, 0],
                factor: 1.0,
                offset: 273.15,
            });
        }
        let mut unit = Unit::ONE;
        let mut divide = false;
        let mut rest = t.as_str();
        loop {
            let end = rest.find(['/', '.', '*']).unwrap_or(rest.len());
            let term = term(&rest[..end], text)?;
            unit = if divide {
                unit.divide(&term)
            } else {
                unit.multiply(&term)
            };
            if end == rest.len() {
                return Ok(unit);
            }
            divide = rest.as_bytes()[end] == b'/';
            rest = &rest[end + 1..];
        }
    }

    /// The product of two units (offsets must be 0).
    pub fn multiply(&self, o: &Unit) -> Unit {
        let mut exponents = self.exponents;
        for (a, b) in exponents.iter_mut().zip(o.exponents) {
            *a = a.saturating_add(b);
        }
        Unit {
            exponents,
            factor: self.factor * o.factor,
            offset: 0.0,
        }
    }

    /// The quotient of two units (offsets must be 0).
    pub fn divide(&self, o: &Unit) -> Unit {
        self.multiply(&o.powi(-1))
    }

    /// The unit to the power n (offset must be 0).
    pub fn powi(&self, n: i32) -> Unit {
        Unit {
            exponents: self.exponents.map(|x| x.saturating_mul(n)),
            factor: self.factor.powi(n),
            offset: 0.0,
        }
    }

    /// x in this unit, in SI: `factor * x + offset`.
    pub fn to_si(&self, x: f64) -> f64 {
        let y = if self.factor == 1.0 {
            x
        } else {
            self.factor * x
        };
        if self.offset == 0.0 {
            y
        } else {
            y + self.offset
        }
    }

    /// x in SI, in this unit: `(x - offset) / factor`.
    pub fn from_si(&self, x: f64) -> f64 {
        let y = if self.offset == 0.0 {
            x
        } else {
            x - self.offset
        };
        if self.factor == 1.0 {
            y
        } else {
            y / self.factor
        }
    }

    /// Do the exponents agree (under the rad rule)?
    pub fn same_dimension(&self, to: &Unit, rule: RadRule) -> bool {
        let (a, b) = (self.exponents, to.exponents);
        if a[..RAD] != b[..RAD] {
            return false;
        }
        match rule {
            RadRule::Strict => a[RAD] == b[RAD],
            RadRule::Omittable { from, to } => {
                a[RAD] == b[RAD] || (from && a[RAD] == 0) || (to && b[RAD] == 0)
            }
        }
    }

    /// The conversion from this unit to `to`, if their exponents agree (under the rad rule).
    pub fn conversion_to(&self, to: &Unit, rule: RadRule) -> Option<Conversion> {
        self.same_dimension(to, rule).then_some(Conversion {
            from: *self,
            to: *to,
        })
    }

    /// The exponents as text in the order of [`BASE_UNITS`], e.g. `kg.m2.s-2` for N.m and
    /// `s-1.rad` for rad/s; `1` when dimensionless.
    pub fn dimension(&self) -> String {
        let parts: Vec<String> = BASE_UNITS
            .iter()
            .zip(self.exponents)
            .filter(|(_, x)| *x != 0)
            .map(|(n, x)| match x {
                1 => n.to_string(),
                x => format!("{n}{x}"),
            })
            .collect();
        if parts.is_empty() {
            "1".into()
        } else {
            parts.join(".")
        }
    }
}

/// One factor of a compound unit: a built-in name with an optional exponent (`^n` or
/// trailing digits, Modelica style).
fn term(t: &str, whole: &str) -> Result<Unit, UnitError> {
    let unknown = || {
        let names = BUILT_IN
            .iter()
            .flat_map(|(names, _, _)| names.iter().copied());
        UnitError(format!(
            "unknown unit '{whole}'{} (known: {}, degC; combined with /, ., ^)",
            did_you_mean(t.split('^').next().unwrap_or(t), names.clone()),
            names.collect::<Vec<_>>().join(", ")
        ))
    };
    let (name, power) = match t.split_once('^') {
        Some((n, p)) => (n, p.parse::<i32>().map_err(|_| unknown())?),
        None => {
            let digits = t
                .char_indices()
                .find(|&(i, c)| i > 0 && (c.is_ascii_digit() || c == '-'))
                .map_or(t.len(), |(i, _)| i);
            match &t[digits..] {
                "" => (t, 1),
                p => (&t[..digits], p.parse::<i32>().map_err(|_| unknown())?),
            }
        }
    };
    if power.unsigned_abs() > MAX_POWER {
        return Err(UnitError(format!(
            "unit '{whole}': the exponent {power} of '{name}' is out of range (at most {MAX_POWER} in size)"
        )));
    }
    let entry = BUILT_IN.iter().find(|(names, _, _)| names.contains(&name));
    let (_, exponents, factor) = entry.ok_or_else(unknown)?;
    Ok(Unit {
        exponents: *exponents,
        factor: *factor,
        offset: 0.0,
    }
    .powi(power))
}

/// The largest exponent of one term of a typed unit (`m^16`): physical units stay far below
/// it, and it keeps the factor finite and the exponent sums far from overflow.
const MAX_POWER: u32 = 16;

impl Conversion {
    /// x in `from`, in `to`: `(f1 * x + o1 - o2) / f2`, without the operations that are
    /// identities (between equal units x keeps its bits).
    pub fn apply(&self, x: f64) -> f64 {
        if self.from.factor == self.to.factor && self.from.offset == self.to.offset {
            return x;
        }
        self.to.from_si(self.from.to_si(x))
    }

    /// The conversion as `to = gain * from + offset` (for connections): gain = f1/f2,
    /// offset = (o1 - o2)/f2.
    pub fn gain_offset(&self) -> (f64, f64) {
        (
            self.from.factor / self.to.factor,
            (self.from.offset - self.to.offset) / self.to.factor,
        )
    }
}

/// The unit a model description declares by `name`: its `BaseUnit`, or, when the FMU gives
/// none, the built-in unit of that name. The flag says whether the unit came from the FMU
/// (whose rad exponent FMI 2.0 lets omit).
pub fn declared(md: &ModelDescription, name: &str) -> Result<(Unit, bool), UnitError> {
    if let Some(u) = md.unit(name).and_then(Unit::from_definition) {
        return Ok((u, true));
    }
    Unit::parse(name).map(|u| (u, false)).map_err(|_| {
        UnitError(format!(
            "the FMU defines unit '{name}' without a BaseUnit and it is not a built-in unit"
        ))
    })
}

/// A value typed by a user: a number (or `pi` expression) with an optional unit.
#[derive(Debug, Clone, PartialEq)]
pub struct Quantity {
    pub value: f64,
    /// The unit as written (trimmed), if any.
    pub unit: Option<String>,
}

impl Quantity {
    /// `90`, `90 deg`, `90deg`, `15 kn`, `-1.5e3 N.m`, `pi/2`, `2*pi`, `-pi`, `pi/2 rad`.
    /// A number is Rust's `f64` syntax; a `pi` expression is numbers and `pi` (or `π`)
    /// joined by `*` and `/`, evaluated left to right with an optional leading sign (so
    /// `pi/2` is `PI / 2.0`, exactly `FRAC_PI_2`). The unit is the rest of the text.
    pub fn parse(text: &str) -> Result<Quantity, String> {
        let t = text.trim();
        if let Ok(v) = t.parse::<f64>() {
            return Ok(Quantity {
                value: v,
                unit: None,
            });
        }
        let (value, rest) = expression(t).ok_or_else(|| format!("'{t}' is not a number"))?;
        let rest = rest.trim();
        Ok(Quantity {
            value,
            unit: (!rest.is_empty()).then(|| rest.to_string()),
        })
    }
}

/// The longest prefix of `t` that is a number: the value and the rest of the text.
fn number(t: &str) -> Option<(f64, &str)> {
    if let Some(rest) = t.strip_prefix("pi").or_else(|| t.strip_prefix('π')) {
        return Some((PI, rest));
    }
    let b = t.as_bytes();
    let digits = |mut i: usize| {
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        i
    };
    let mut i = digits(0);
    if i < b.len() && b[i] == b'.' {
        i = digits(i + 1);
    }
    if i == 0 || (i == 1 && b[0] == b'.') {
        return None;
    }
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        let mut j = i + 1;
        if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
            j += 1;
        }
        let k = digits(j);
        if k > j {
            i = k;
        }
    }
    Some((t[..i].parse().ok()?, &t[i..]))
}

/// A sign and numbers joined by `*` and `/` (left to right), then the rest of the text.
fn expression(t: &str) -> Option<(f64, &str)> {
    let (sign, t) = match t.as_bytes().first() {
        Some(b'-') => (-1.0, &t[1..]),
        Some(b'+') => (1.0, &t[1..]),
        _ => (1.0, t),
    };
    let (mut value, mut rest) = number(t.trim_start())?;
    loop {
        let r = rest.trim_start();
        let Some(op) = r.chars().next().filter(|c| *c == '*' || *c == '/') else {
            break;
        };
        let Some((x, after)) = number(r[1..].trim_start()) else {
            break;
        };
        value = if op == '*' { value * x } else { value / x };
        rest = after;
    }
    Some((if sign < 0.0 { -value } else { value }, rest))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compounds_and_exponents() {
        let n_m = Unit::parse("N.m").unwrap();
        assert_eq!(n_m.exponents, [1, 2, -2, 0, 0, 0, 0, 0]);
        assert_eq!(Unit::parse("kg.m2/s2").unwrap().exponents, n_m.exponents);
        assert_eq!(Unit::parse("kg*m^2/s^2").unwrap().exponents, n_m.exponents);
        assert_eq!(
            Unit::parse("s-1").unwrap().exponents,
            Unit::parse("1/s").unwrap().exponents
        );
        assert_eq!(Unit::parse("deg / s").unwrap().dimension(), "s-1.rad");
        assert!(Unit::parse("furlong").is_err());
        // Exponents stay small: no overflow, no infinite factor (km^400 would be inf).
        assert_eq!(Unit::parse("m^16").unwrap().exponents[1], 16);
        for absurd in [
            "m^17",
            "km^400/km^400",
            "m^2147483647.m^2147483647",
            "s-2147483648",
        ] {
            assert!(Unit::parse(absurd).is_err(), "{absurd}");
        }
        assert!(Unit::parse("m/").is_err());
    }

    #[test]
    fn quantities() {
        let q = |s: &str| Quantity::parse(s).unwrap();
        assert_eq!(q("90deg").unit.as_deref(), Some("deg"));
        assert_eq!(q("1e3 m").value, 1000.0);
        assert_eq!(q("-pi").value, -PI);
        assert_eq!(q("2*pi").value, 2.0 * PI);
        assert_eq!(q("3 * pi / 4 rad").value, 3.0 * PI / 4.0);
        assert_eq!(q("pi/2 rad").unit.as_deref(), Some("rad"));
        assert!(Quantity::parse("deg").is_err());
    }
}
