//! Derived KPIs across arms, computed after the runs: one row per design point and
//! replication, e.g. `roll_reduction = 100 * (1 - roll_var[on] / roll_var[off])`.
//!
//! An expression is arithmetic (`+ - * / ^`, parentheses, `sqrt`, `abs`, `exp`, `log`, `sin`,
//! `cos`, ...; evaluated in f64 by the `exmex` crate) over KPI names. `kpi[arm]` is the KPI of
//! the run of that arm; a bare `kpi` is allowed when the campaign has no arms. A row whose
//! runs are not all done, or failed, gets NaN and says why in its status.

use super::spec::CampaignSpec;
use crate::error::{Error, Result};
use exmex::{Express, FlatEx, FloatOpsFactory, MakeOperators};

/// The longest derived expression [characters] and its deepest nesting of parentheses: real
/// expressions are a line; the parser's time grows faster than the length (`2^2^...^2` with
/// 100,000 operators took a minute).
pub const MAX_EXPRESSION_CHARS: usize = 1000;
pub const MAX_EXPRESSION_DEPTH: usize = 32;

/// Refuses an expression over [`MAX_EXPRESSION_CHARS`] or nested deeper than
/// [`MAX_EXPRESSION_DEPTH`].
fn bounded(expr: &str) -> std::result::Result<(), String> {
    let chars = expr.chars().count();
    if chars > MAX_EXPRESSION_CHARS {
        return Err(format!(
            "{chars} characters, more than the {MAX_EXPRESSION_CHARS} a derived expression may have"
        ));
    }
    let (mut depth, mut deepest) = (0usize, 0usize);
    for c in expr.chars() {
        match c {
            '(' => {
                depth += 1;
                deepest = deepest.max(depth);
            }
            ')' => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    if deepest > MAX_EXPRESSION_DEPTH {
        return Err(format!(
            "parentheses nested {deepest} deep, more than the {MAX_EXPRESSION_DEPTH} a derived \
             expression may have"
        ));
    }
    Ok(())
}

/// The functions a derived expression may call: exmex's named operators (`sqrt`, `abs`, `ln`,
/// `log10`, `atan2`, `min`, ...), without its constants (`PI`, `E`).
/// Sorted by name.
pub fn functions() -> Vec<&'static str> {
    let mut names: Vec<&'static str> = FloatOpsFactory::<f64>::make()
        .iter()
        .filter(|op| op.constant().is_none())
        .map(|op| op.repr())
        .filter(|r| r.starts_with(|c: char| c.is_ascii_alphabetic()))
        .collect();
    names.sort_unstable();
    names
}

/// A name called like a function (`name(`) that is no function and no KPI column: exmex read it
/// as a variable and the message was "no KPI 'name'", or a parse error that did not say which
/// name was wrong. The message names it and lists the functions there are.
fn unknown_function(expr: &str, kpi_columns: &[String]) -> std::result::Result<(), String> {
    let known = functions();
    let chars: Vec<char> = expr.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let word_start = chars[i].is_ascii_alphabetic() || chars[i] == '_';
        // a letter after a digit or a point belongs to a number (1e5)
        let in_number = i > 0 && (chars[i - 1].is_ascii_alphanumeric() || chars[i - 1] == '.');
        if !word_start || in_number {
            i += 1;
            continue;
        }
        let start = i;
        while i < chars.len() && (chars[i].is_ascii_alphanumeric() || chars[i] == '_') {
            i += 1;
        }
        let word: String = chars[start..i].iter().collect();
        let called = chars[i..].iter().find(|c| !c.is_whitespace()) == Some(&'(');
        if called && !known.contains(&word.as_str()) && !kpi_columns.contains(&word) {
            return Err(format!(
                "unknown function '{word}'{}; the functions are {} (and the operators + - * / ^)",
                crate::error::did_you_mean(&word, known.iter().copied()),
                known.join(", ")
            ));
        }
    }
    Ok(())
}

/// One compiled derived KPI.
pub struct DerivedKpi {
    pub name: String,
    expr: FlatEx<f64>,
    /// Per variable of the expression (in exmex's order): (KPI column index, arm index).
    inputs: Vec<(usize, usize)>,
}

/// `kpi[arm]` → `{kpi[arm]}` (exmex reads any text in braces as one variable name).
fn braced(expr: &str) -> String {
    let mut out = String::with_capacity(expr.len() + 8);
    let chars: Vec<char> = expr.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c.is_ascii_alphabetic() || c == '_' {
            let start = i;
            while i < chars.len() && (chars[i].is_ascii_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            let word: String = chars[start..i].iter().collect();
            if i < chars.len() && chars[i] == '[' {
                if let Some(close) = chars[i..].iter().position(|c| *c == ']') {
                    let arm: String = chars[i + 1..i + close].iter().collect();
                    out.push_str(&format!("{{{word}[{}]}}", arm.trim()));
                    i += close + 1;
                    continue;
                }
            }
            out.push_str(&word);
            continue;
        }
        out.push(c);
        i += 1;
    }
    out
}

impl DerivedKpi {
    /// Compiles the campaign's derived KPIs against its KPI columns and arms.
    pub fn compile(spec: &CampaignSpec, kpi_columns: &[String]) -> Result<Vec<DerivedKpi>> {
        let arms: Vec<&str> = spec.arms.iter().map(|a| a.name.as_str()).collect();
        spec.derived
            .iter()
            .map(|d| {
                // a refused long expression is quoted by its start only
                let quoted: String = d.expr.chars().take(80).collect();
                let more = if quoted.len() < d.expr.len() {
                    "..."
                } else {
                    ""
                };
                let err = |m: String| {
                    Error::Other(format!(
                        "campaign {}: derived kpi '{}' = \"{quoted}{more}\": {m}",
                        spec.source.display(),
                        d.name,
                    ))
                };
                bounded(&d.expr).map_err(err)?;
                unknown_function(&d.expr, kpi_columns).map_err(err)?;
                let text = braced(&d.expr);
                let expr = FlatEx::<f64>::parse(&text).map_err(|e| err(e.to_string()))?;
                let mut inputs = Vec::new();
                for v in expr.var_names() {
                    let (kpi, arm) = match v.split_once('[') {
                        Some((k, a)) => (k, Some(a.trim_end_matches(']'))),
                        None => (v.as_str(), None),
                    };
                    let col = kpi_columns.iter().position(|c| c == kpi).ok_or_else(|| {
                        err(format!(
                            "no KPI '{kpi}'{}",
                            crate::error::did_you_mean(kpi, kpi_columns.iter().map(|s| s.as_str()))
                        ))
                    })?;
                    let arm = match (arm, arms.is_empty()) {
                        (None, true) => 0,
                        (None, false) => {
                            return Err(err(format!(
                                "write {kpi}[arm] with one of the arms {arms:?}"
                            )))
                        }
                        (Some(a), _) => arms
                            .iter()
                            .position(|x| *x == a)
                            .ok_or_else(|| err(format!("no arm '{a}' (arms: {arms:?})")))?,
                    };
                    inputs.push((col, arm));
                }
                Ok(DerivedKpi {
                    name: d.name.clone(),
                    expr,
                    inputs,
                })
            })
            .collect()
    }

    /// The value from the KPIs of one design point and replication: `kpis[arm][column]`.
    pub fn eval(&self, kpis: &[Vec<f64>]) -> f64 {
        let vars: Vec<f64> = self.inputs.iter().map(|&(c, a)| kpis[a][c]).collect();
        self.expr.eval(&vars).unwrap_or(f64::NAN)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_or_deep_expressions_are_refused() {
        assert!(bounded("100 * (1 - a[on] / a[off])").is_ok());
        let long = vec!["2"; 100_000].join("^");
        assert!(bounded(&long)
            .unwrap_err()
            .contains("199999 characters, more than the 1000"));
        let deep = format!("{}1{}", "(".repeat(40), ")".repeat(40));
        assert!(bounded(&deep)
            .unwrap_err()
            .contains("nested 40 deep, more than the 32"));
    }

    #[test]
    fn an_unknown_function_is_named_with_the_functions_there_are() {
        let kpis = ["roll_var".to_string(), "y_mean".to_string()];
        for ok in [
            "100 * (1 - roll_var[on] / roll_var[off])",
            "sqrt(roll_var[on]) + abs (y_mean) + atan2(1, 2) + log10(2) + 1e5 * 2.5e-3",
            "y_mean * (2)",
        ] {
            assert_eq!(unknown_function(ok, &kpis), Ok(()), "{ok}");
        }
        let e = unknown_function("100 * sqr(roll_var[on])", &kpis).unwrap_err();
        assert!(
            e.starts_with("unknown function 'sqr' (did you mean 'sqrt'")
                && e.contains("; the functions are abs, acos, acosh, asin,")
                && e.contains("atan2")
                && e.contains("sqrt")
                && !e.contains("PI"),
            "{e}"
        );
        // the two-argument functions, as docs/campaigns.md writes them
        let two = FlatEx::<f64>::parse("min(1, 2) + max(3, 4) + atan2(0, 1)").unwrap();
        assert_eq!(two.eval(&[]).unwrap(), 5.0);
        let e = unknown_function("mean (y_mean)", &kpis).unwrap_err();
        assert!(e.starts_with("unknown function 'mean'"), "{e}");
    }

    #[test]
    fn arm_references_become_single_variables() {
        assert_eq!(
            braced("100 * (1 - roll_var[on] / roll_var[ off ])"),
            "100 * (1 - {roll_var[on]} / {roll_var[off]})"
        );
        assert_eq!(braced("sqrt(a_1) + b"), "sqrt(a_1) + b");
    }
}
