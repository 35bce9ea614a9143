//! `shipsim stats FILE.csv [--window T0:T1] [--columns a,b,...] [--system FILE] [--json]`:
//! window statistics of the columns of a recorded CSV, with the campaigns' accumulator
//! ([`shipsim::campaign::kpi::StatAccumulator`]: Welford mean and population variance,
//! RMS, extremes), so that a single run's numbers equal a campaign KPI over the same window.
//!
//! Units: a CSV has none, and names no system file, so `stats` cannot find them by itself.
//! With `--system FILE` (the system file that wrote the CSV) each column `instance.variable`
//! is looked up in the model description of that instance's FMU (unpacked, the binaries not
//! loaded) and printed with its unit (the variance in unit^2); without it the header says how
//! to get them.

use clap::Args;
use shipsim::campaign::kpi::{Stat, StatAccumulator};
use shipsim::error::{Error, Result};
use shipsim::plot::parse_window;
use shipsim::results::ResultsTable;
use shipsim::system::{System, VarRef};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The statistics printed, in order, with their column titles.
const STATS: [(Stat, &str); 7] = [
    (Stat::Mean, "mean"),
    (Stat::Variance, "variance"),
    (Stat::Std, "std"),
    (Stat::Rms, "rms"),
    (Stat::Min, "min"),
    (Stat::Max, "max"),
    (Stat::MaxAbs, "max_abs"),
];

#[derive(Args)]
pub struct StatsArgs {
    /// A CSV with a `time` column (as written by `shipsim run`).
    pub csv: PathBuf,
    /// Only the samples with T0 <= time <= T1 (either side may be left out: `200:`, `:600`).
    #[arg(long, value_name = "T0:T1")]
    pub window: Option<String>,
    /// The columns, comma-separated; `*` and `?` match any text / one character (e.g.
    /// `ship.*,gear.rudder_angle`). Default: every column but time.
    #[arg(long, value_name = "A,B,...")]
    pub columns: Option<String>,
    /// The system file that wrote the CSV (TOML, OSP XML, SSP or FMU): the units of the
    /// columns are read from its FMUs' model descriptions (a CSV has none).
    #[arg(long, value_name = "FILE")]
    pub system: Option<PathBuf>,
    /// One JSON object instead of the table (NaN as null).
    #[arg(long)]
    pub json: bool,
}

/// One column's statistics over the window.
struct ColumnStats {
    name: String,
    n: usize,
    values: [f64; 7],
    unit: Unit,
}

/// A column's unit, as the system file's FMUs declare it.
#[derive(Clone, Debug, PartialEq)]
enum Unit {
    /// No `--system`: not looked up.
    NotAsked,
    /// The variable's unit (of a Real variable, following its declaredType).
    Of(String),
    /// The variable declares none (or is an Integer or Boolean).
    None,
    /// The column is not a variable of the system's instances.
    NotFound,
}

impl Unit {
    /// The cell of the table's `unit` column.
    fn cell(&self) -> &str {
        match self {
            Unit::Of(u) => u,
            Unit::None => "-",
            Unit::NotFound | Unit::NotAsked => "?",
        }
    }

    fn json(&self) -> serde_json::Value {
        match self {
            Unit::Of(u) => serde_json::json!(u),
            _ => serde_json::Value::Null,
        }
    }

    /// The unit of the variance: the square (`m^2`, `(m/s)^2`).
    fn squared(&self) -> serde_json::Value {
        match self {
            Unit::Of(u) => serde_json::json!(squared(u)),
            _ => serde_json::Value::Null,
        }
    }
}

/// `unit^2`, parenthesised unless the unit is one name (`m^2`, `rad^2`, `(m/s)^2`, `(N.m)^2`);
/// the dimensionless `1` stays `1`.
fn squared(unit: &str) -> String {
    if unit == "1" {
        unit.to_string()
    } else if unit.chars().all(char::is_alphabetic) {
        format!("{unit}^2")
    } else {
        format!("({unit})^2")
    }
}

/// `shipsim stats`.
pub fn run(args: &StatsArgs) -> Result<()> {
    let file = args.csv.display().to_string();
    let window = match args.window.as_deref() {
        Some(w) => parse_window(w)?,
        None => (f64::NEG_INFINITY, f64::INFINITY),
    };
    let table = ResultsTable::read(&args.csv)?;
    let time = table
        .column("time")
        .map_err(|_| Error::Other(format!("{file}: no column 'time'")))?;
    let selected = select(&table, args.columns.as_deref(), &file)?;
    let units = match &args.system {
        Some(system) => {
            let names: Vec<&str> = selected.iter().map(|&c| table.names[c].as_str()).collect();
            units(system, &names)?
        }
        None => vec![Unit::NotAsked; selected.len()],
    };
    let inside: Vec<usize> = (0..time.len())
        .filter(|&k| time[k] >= window.0 && time[k] <= window.1)
        .collect();
    let (Some(&first), Some(&last)) = (inside.first(), inside.last()) else {
        let span = match (time.first(), time.last()) {
            (Some(a), Some(b)) => format!("t = {a} .. {b}"),
            _ => "no rows".into(),
        };
        return Err(Error::Other(format!(
            "{file}: no sample in the window [{}, {}] (the file has {span})",
            window.0, window.1
        )));
    };
    let stats: Vec<ColumnStats> = selected
        .iter()
        .zip(units)
        .map(|(&c, unit)| {
            let mut acc = StatAccumulator::new(Stat::Mean, window, 1.0);
            for &k in &inside {
                acc.push(time[k], table.columns[c][k]);
            }
            ColumnStats {
                name: table.names[c].clone(),
                n: inside.len(),
                values: STATS.map(|(s, _)| {
                    let mut a = acc;
                    a.stat = s;
                    a.value()
                }),
                unit,
            }
        })
        .collect();
    let span = (time[first], time[last]);
    let system = args.system.as_ref().map(|s| s.display().to_string());
    if args.json {
        println!("{}", json(&file, span, &stats, system.as_deref()));
    } else {
        print!("{}", table_text(&file, span, &stats, system.as_deref()));
    }
    Ok(())
}

/// The units of the columns `names` (`instance.variable`) in the system file `system`: each
/// instance's FMU unpacked once (model description read, binaries not loaded). A column that
/// is not a variable of the system gets [`Unit::NotFound`] and a warning; a system that has
/// none of the columns is an error (it is not the system that wrote the CSV).
fn units(system: &Path, names: &[&str]) -> Result<Vec<Unit>> {
    let sys = System::load(system)?;
    let mut unpacked: HashMap<&Path, shipsim::fmu::UnpackedFmu> = HashMap::new();
    for inst in &sys.instances {
        if !unpacked.contains_key(inst.fmu.as_path()) {
            sys.require_fmu(inst)?;
            let fmu = shipsim::fmu::UnpackedFmu::open(&inst.fmu)?;
            unpacked.insert(inst.fmu.as_path(), fmu);
        }
    }
    let unit = |name: &str| -> Unit {
        let Some(r) = VarRef::parse(name) else {
            return Unit::NotFound;
        };
        let Some(inst) = sys.instances.iter().find(|i| i.name == r.instance) else {
            return Unit::NotFound;
        };
        let md = &unpacked[inst.fmu.as_path()].model_description;
        let variables = &md.model_variables.variables;
        match variables.iter().find(|v| v.name == r.variable) {
            None => Unit::NotFound,
            Some(v) => match md.real_unit(v) {
                Some(u) if !u.is_empty() => Unit::Of(u.to_string()),
                _ => Unit::None,
            },
        }
    };
    let units: Vec<Unit> = names.iter().map(|n| unit(n)).collect();
    let missing: Vec<&str> = names
        .iter()
        .zip(&units)
        .filter(|(_, u)| **u == Unit::NotFound)
        .map(|(n, _)| *n)
        .collect();
    let system = system.display();
    if !names.is_empty() && missing.len() == names.len() {
        return Err(Error::Other(format!(
            "{system}: none of the columns is a variable of its instances (e.g. '{}'): is it \
             the system file that wrote the CSV?",
            missing[0]
        )));
    }
    for n in missing {
        eprintln!("warning: column '{n}' is not a variable of {system}: its unit is unknown (?)");
    }
    Ok(units)
}

/// The indices of the selected columns, in the order of the pattern list (each column once).
/// Text columns (recorded String variables) are not selected: a pattern that matches only
/// text is an error that says so.
fn select(table: &ResultsTable, patterns: Option<&str>, file: &str) -> Result<Vec<usize>> {
    let names = &table.names;
    let Some(patterns) = patterns else {
        return Ok((0..names.len()).filter(|&c| names[c] != "time").collect());
    };
    let mut out = Vec::new();
    for p in patterns.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let matched: Vec<usize> = (0..names.len())
            .filter(|&c| glob(p.as_bytes(), names[c].as_bytes()))
            .collect();
        if let Some(t) = table.text.iter().find(|t| glob(p.as_bytes(), t.as_bytes())) {
            if matched.is_empty() {
                return Err(Error::Other(format!(
                    "{file}: column '{t}' is text (a String variable); stats are of numbers"
                )));
            }
        }
        if matched.is_empty() {
            let candidates = names.iter().map(String::as_str);
            return Err(Error::Other(format!(
                "{file}: no column matches '{p}'{}",
                shipsim::error::did_you_mean(p, candidates)
            )));
        }
        for c in matched {
            if !out.contains(&c) {
                out.push(c);
            }
        }
    }
    Ok(out)
}

/// Does `name` match `pattern` (`*`: any text, `?`: one character)?
fn glob(pattern: &[u8], name: &[u8]) -> bool {
    // Iterative, remembering only the last `*` (and where it started matching): linear in
    // practice and O(len(pattern) * len(name)) at worst, however many stars.
    let (mut p, mut n) = (0, 0);
    let mut star: Option<(usize, usize)> = None;
    while n < name.len() {
        match pattern.get(p) {
            Some(b'*') => {
                star = Some((p, n));
                p += 1;
            }
            Some(&c) if c == b'?' || c == name[n] => {
                p += 1;
                n += 1;
            }
            _ => match star {
                Some((sp, sn)) => {
                    p = sp + 1;
                    n = sn + 1;
                    star = Some((sp, sn + 1));
                }
                None => return false,
            },
        }
    }
    pattern[p..].iter().all(|&c| c == b'*')
}

/// A number in 7 significant digits: fixed between 1e-3 and 1e7, else with an exponent.
fn number(x: f64) -> String {
    let a = x.abs();
    if x.is_nan() || x == 0.0 || (1e-3..1e7).contains(&a) {
        let digits = if a == 0.0 || x.is_nan() {
            6
        } else {
            (6 - a.log10().floor() as i32).clamp(0, 9) as usize
        };
        format!("{x:.digits$}")
    } else {
        format!("{x:.6e}")
    }
}

/// The aligned table: a header line, then one row per column.
/// With a system file, a `unit` column after the name (the unit of the mean, std, rms, min,
/// max and max_abs; the variance is in its square, as the first line says); without one, the
/// first line says how to get units.
fn table_text(file: &str, span: (f64, f64), stats: &[ColumnStats], system: Option<&str>) -> String {
    let n = stats.first().map_or(0, |s| s.n);
    let mut out = format!("{file}: {n} samples, t = {} .. {} s; ", span.0, span.1);
    match system {
        Some(system) => out.push_str(&format!(
            "units from the FMUs of {system} (variance in unit^2)\n"
        )),
        None => out.push_str(
            "no units (a CSV has none): give --system FILE, the system file that wrote it\n",
        ),
    }
    let cells: Vec<Vec<String>> = stats
        .iter()
        .map(|s| s.values.iter().map(|&x| number(x)).collect())
        .collect();
    let name_w = stats.iter().map(|s| s.name.len()).max().unwrap_or(0).max(6);
    let widths: Vec<usize> = (0..STATS.len())
        .map(|j| {
            let w = cells.iter().map(|r| r[j].len()).max().unwrap_or(0);
            w.max(STATS[j].1.len())
        })
        .collect();
    let unit_w = stats
        .iter()
        .map(|s| s.unit.cell().chars().count())
        .max()
        .unwrap_or(0)
        .max(4);
    out.push_str(&format!("{:<name_w$}", "column"));
    if system.is_some() {
        out.push_str(&format!("  {:<unit_w$}", "unit"));
    }
    for (j, (_, title)) in STATS.iter().enumerate() {
        out.push_str(&format!("  {title:>w$}", w = widths[j]));
    }
    out.push('\n');
    for (s, row) in stats.iter().zip(&cells) {
        out.push_str(&format!("{:<name_w$}", s.name));
        if system.is_some() {
            out.push_str(&format!("  {:<unit_w$}", s.unit.cell()));
        }
        for (j, cell) in row.iter().enumerate() {
            out.push_str(&format!("  {cell:>w$}", w = widths[j]));
        }
        out.push('\n');
    }
    out
}

/// `{"file", "samples", "t0", "t1", "system", "columns": [{"name", "unit", "variance_unit",
/// "mean", "variance", ...}, ...]}`, the columns in the order of the table; `system` and the
/// units are null without `--system` (and a unit is null where the system declares none).
fn json(
    file: &str,
    span: (f64, f64),
    stats: &[ColumnStats],
    system: Option<&str>,
) -> serde_json::Value {
    let mut columns = Vec::new();
    for s in stats {
        let mut m = serde_json::Map::new();
        m.insert("name".into(), serde_json::json!(s.name));
        m.insert("unit".into(), s.unit.json());
        m.insert("variance_unit".into(), s.unit.squared());
        for ((_, title), x) in STATS.iter().zip(s.values) {
            m.insert(title.to_string(), serde_json::json!(x));
        }
        columns.push(serde_json::Value::Object(m));
    }
    serde_json::json!({
        "file": file,
        "samples": stats.first().map_or(0, |s| s.n),
        "t0": span.0,
        "t1": span.1,
        "system": system,
        "columns": columns,
    })
}

#[cfg(test)]
mod tests {
    use super::{glob, squared};

    #[test]
    fn squared_units() {
        assert_eq!(squared("m"), "m^2");
        assert_eq!(squared("rad"), "rad^2");
        assert_eq!(squared("m/s"), "(m/s)^2");
        assert_eq!(squared("N.m"), "(N.m)^2");
        assert_eq!(squared("1"), "1");
    }

    #[test]
    fn globs() {
        let m = |p: &str, n: &str| glob(p.as_bytes(), n.as_bytes());
        assert!(m("ship.*", "ship.roll") && m("*.roll", "ship.roll") && m("s?ip.r*l", "ship.roll"));
        assert!(m("*", "") && m("**a**", "xay") && m("ship.roll", "ship.roll"));
        assert!(!m("ship.*", "gear.rudder") && !m("s?ip", "sip") && !m("*.roll", "ship.rolls"));
        // Many stars against a long name that does not match: the recursive matcher this
        // replaced took 50 s here (exponential); this one answers at once.
        let name = "a".repeat(60);
        assert!(!m("*a*a*a*a*a*a*a*a*a*a*a*a*b", &name));
        assert!(m("*a*a*a*a*a*a*a*a*a*a*a*a*", &name));
    }
}
