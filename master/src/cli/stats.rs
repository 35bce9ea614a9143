//! `shipsim stats FILE.csv [--window T0:T1] [--columns a,b,...] [--json]`: window statistics of
//! the columns of a recorded CSV, with the campaigns' accumulator
//! ([`shipsim::campaign::kpi::StatAccumulator`]: Welford mean and population variance,
//! RMS, extremes), so that a single run's numbers equal a campaign KPI over the same window.

use clap::Args;
use shipsim::campaign::kpi::{Stat, StatAccumulator};
use shipsim::error::{Error, Result};
use shipsim::plot::parse_window;
use shipsim::results::ResultsTable;
use std::path::PathBuf;

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
    /// One JSON object instead of the table (NaN as null).
    #[arg(long)]
    pub json: bool,
}

/// One column's statistics over the window.
struct ColumnStats {
    name: String,
    n: usize,
    values: [f64; 7],
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
        .map(|&c| {
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
            }
        })
        .collect();
    let span = (time[first], time[last]);
    if args.json {
        println!("{}", json(&file, span, &stats));
    } else {
        print!("{}", table_text(&file, span, &stats));
    }
    Ok(())
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
fn table_text(file: &str, span: (f64, f64), stats: &[ColumnStats]) -> String {
    let n = stats.first().map_or(0, |s| s.n);
    let mut out = format!("{file}: {n} samples, t = {} .. {} s\n", span.0, span.1);
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
    out.push_str(&format!("{:<name_w$}", "column"));
    for (j, (_, title)) in STATS.iter().enumerate() {
        out.push_str(&format!("  {title:>w$}", w = widths[j]));
    }
    out.push('\n');
    for (s, row) in stats.iter().zip(&cells) {
        out.push_str(&format!("{:<name_w$}", s.name));
        for (j, cell) in row.iter().enumerate() {
            out.push_str(&format!("  {cell:>w$}", w = widths[j]));
        }
        out.push('\n');
    }
    out
}

/// `{"file", "samples", "t0", "t1", "columns": [{"name", "mean", "variance", ...}, ...]}`,
/// the columns in the order of the table.
fn json(file: &str, span: (f64, f64), stats: &[ColumnStats]) -> serde_json::Value {
    let mut columns = Vec::new();
    for s in stats {
        let mut m = serde_json::Map::new();
        m.insert("name".into(), serde_json::json!(s.name));
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
        "columns": columns,
    })
}

#[cfg(test)]
mod tests {
    use super::glob;

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
