//! Coupled-system studies: each runs one or more system files from `systems/` through the
//! shipsim master (in process, the same code as `shipsim run`), computes the quantities a source
//! publishes, and compares them with the published values, or with [DERIVED] ones: values
//! computed from a source's equations where the source prints none.
//!
//! The same study functions serve the system tests (`tests/tests/studies.rs` asserts that every
//! check passes) and the validation report (`cargo xtask report`, which writes every study's
//! table and figures to Markdown).
//!
//! A study is `fn(&Env) -> Result<Report, String>`; register it in [`crate::studies::STUDIES`].

use shipsim::campaign::table::Table;
use shipsim::campaign::{execute, Campaign, CampaignOptions, CampaignOutcome, CampaignSpec};
use shipsim::plot::{plot_panels, Panel, Series};
use shipsim::results::ResultsTable;
use shipsim::run::{run_system, Output, RunOptions};
use shipsim::system::System;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// A campaign run by a study ([`Env::campaign`]).
pub struct CampaignResult {
    pub outcome: CampaignOutcome,
    pub runs: Table,
    pub derived: Table,
}

/// Where the FMUs, system files and outputs are.
#[derive(Clone, Debug)]
pub struct Env {
    /// Workspace root.
    pub root: PathBuf,
    /// Built FMUs (`SHIPSIM_FMU_DIR`, default `target/fmu`).
    pub fmu_dir: PathBuf,
    /// Where runs write CSVs and figures (`target/studies/<study id>/` by default).
    pub out_dir: PathBuf,
}

impl Env {
    /// The default environment; `out` names the output folder below `target/`.
    pub fn new(out: &str) -> Result<Env, String> {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"))
            .parent()
            .ok_or("no workspace root")?
            .to_path_buf();
        let fmu_dir = std::env::var_os("SHIPSIM_FMU_DIR")
            .map(PathBuf::from)
            .unwrap_or_else(|| root.join("target/fmu"));
        if !fmu_dir.is_dir() {
            return Err(format!(
                "{} is missing: run `cargo xtask build-fmus` first (or set SHIPSIM_FMU_DIR)",
                fmu_dir.display()
            ));
        }
        let out_dir = root.join("target").join(out);
        Ok(Env {
            root,
            fmu_dir,
            out_dir,
        })
    }

    /// Runs `systems/<file>` with `--set`-style overrides (`instance.variable=value`), writing
    /// `<out_dir>/<csv>`; returns the recorded table. FMU paths of the system file are resolved
    /// by file name in [`Env::fmu_dir`].
    pub fn run(&self, file: &str, sets: &[String], csv: &str) -> Result<ResultsTable, String> {
        self.run_steps(file, sets, csv, None)
    }

    /// [`Env::run`] stopped after `steps` base steps (Some) instead of at the file's stop time.
    pub fn run_steps(
        &self,
        file: &str,
        sets: &[String],
        csv: &str,
        steps: Option<u64>,
    ) -> Result<ResultsTable, String> {
        let mut system = self.system(file)?;
        system.apply_overrides(sets).map_err(|e| e.to_string())?;
        if let Some(n) = steps {
            system.stop_time = Some(system.start_time + n as f64 * system.step_size);
        }
        std::fs::create_dir_all(&self.out_dir).map_err(|e| e.to_string())?;
        let out = self.out_dir.join(csv);
        run_system(&system, Output::File(out.clone()), &RunOptions::default())
            .map_err(|e| format!("{file}: {e}"))?;
        ResultsTable::read(&out).map_err(|e| e.to_string())
    }

    /// Runs `campaigns/<file>` on `systems/<system>` (FMUs from [`Env::fmu_dir`]) afresh into
    /// `<out_dir>/campaign`; returns the outcome, the run table and the derived table.
    pub fn campaign(&self, file: &str, system: &str) -> Result<CampaignResult, String> {
        let spec = CampaignSpec::load(&self.root.join("campaigns").join(file))
            .map_err(|e| e.to_string())?;
        let campaign = Campaign::new(spec, self.system(system)?).map_err(|e| e.to_string())?;
        let out = self.out_dir.join("campaign");
        let _ = std::fs::remove_dir_all(&out);
        let opts = CampaignOptions {
            output: out.clone(),
            ..Default::default()
        };
        let outcome = execute::run(&campaign, &opts).map_err(|e| e.to_string())?;
        let read = |name: &str| Table::read(&out.join(name)).map_err(|e| e.to_string());
        Ok(CampaignResult {
            outcome,
            runs: read("runs.parquet")?,
            derived: read("derived.parquet")?,
        })
    }

    /// `systems/<file>` with its FMU paths resolved by file name in [`Env::fmu_dir`].
    pub fn system(&self, file: &str) -> Result<System, String> {
        let path = self.root.join("systems").join(file);
        let mut system = System::load(&path).map_err(|e| e.to_string())?;
        for inst in &mut system.instances {
            let name = inst
                .fmu
                .file_name()
                .ok_or_else(|| format!("{}: instance {} has no FMU file", file, inst.name))?;
            let candidate = self.fmu_dir.join(name);
            if !candidate.exists() {
                return Err(format!(
                    "{}: instance {}: {} is missing: run `cargo xtask build-fmus`",
                    file,
                    inst.name,
                    candidate.display()
                ));
            }
            inst.fmu = candidate;
        }
        Ok(system)
    }

    /// Draws a figure into the output folder; returns its path.
    pub fn figure(&self, name: &str, title: &str, panels: &[Panel]) -> Result<PathBuf, String> {
        let p = self.out_dir.join(name);
        plot_panels(&p, title, panels).map_err(|e| e.to_string())?;
        Ok(p)
    }
}

/// A curve from a table column, scaled (e.g. by 180/π for degrees).
pub fn series(
    table: &ResultsTable,
    column: &str,
    label: &str,
    scale: f64,
) -> Result<Series, String> {
    Ok(Series {
        label: label.to_string(),
        t: table.time().to_vec(),
        y: col(table, column)?.iter().map(|v| v * scale).collect(),
    })
}

/// A curve restricted to t0 ≤ t ≤ t1 (readable windows of long runs).
pub fn series_window(
    table: &ResultsTable,
    column: &str,
    label: &str,
    scale: f64,
    t0: f64,
    t1: f64,
) -> Result<Series, String> {
    Ok(window(series(table, column, label, scale)?, t0, t1))
}

/// The part of a curve with t0 ≤ t ≤ t1.
fn window(s: Series, t0: f64, t1: f64) -> Series {
    let (t, y): (Vec<f64>, Vec<f64>) =
        s.t.iter()
            .zip(&s.y)
            .filter(|(t, _)| (t0..=t1).contains(*t))
            .map(|(t, y)| (*t, *y))
            .unzip();
    Series {
        label: s.label,
        t,
        y,
    }
}

/// A horizontal line at `y` over the times `t`.
pub fn constant_series(t: &[f64], y: f64, label: &str) -> Series {
    Series {
        label: label.into(),
        t: t.to_vec(),
        y: vec![y; t.len()],
    }
}

/// One compared quantity.
#[derive(Clone, Debug)]
pub struct Check {
    pub quantity: String,
    /// The published value as the source prints it ([DERIVED] where it was computed from the
    /// source's equations).
    pub published: String,
    pub ours: String,
    /// The acceptance rule, in words.
    pub tolerance: String,
    pub pass: bool,
}

impl Check {
    /// |ours − published| ≤ tol.
    pub fn abs(quantity: &str, published: f64, ours: f64, tol: f64, unit: &str) -> Check {
        Check {
            quantity: quantity.to_string(),
            published: format!("{} {unit}", fmt_num(published)).trim().to_string(),
            ours: format!("{} {unit}", fmt_num(ours)).trim().to_string(),
            tolerance: format!("±{} {unit}", fmt_num(tol)).trim().to_string(),
            pass: (ours - published).abs() <= tol,
        }
    }

    /// |ours − published| ≤ rel·|published|.
    pub fn rel(quantity: &str, published: f64, ours: f64, rel: f64, unit: &str) -> Check {
        Check {
            quantity: quantity.to_string(),
            published: format!("{} {unit}", fmt_num(published)).trim().to_string(),
            ours: format!("{} {unit}", fmt_num(ours)).trim().to_string(),
            tolerance: format!("±{}%", rel * 100.0),
            pass: (ours - published).abs() <= rel * published.abs(),
        }
    }

    /// lo ≤ ours ≤ hi (for published ranges such as "60-78 %").
    pub fn range(
        quantity: &str,
        published: &str,
        ours: f64,
        lo: f64,
        hi: f64,
        unit: &str,
    ) -> Check {
        Check {
            quantity: quantity.to_string(),
            published: published.to_string(),
            ours: format!("{} {unit}", fmt_num(ours)).trim().to_string(),
            tolerance: format!("[{lo}, {hi}] {unit}").trim().to_string(),
            pass: (lo..=hi).contains(&ours),
        }
    }

    /// A qualitative statement from the source and whether our run shows it.
    pub fn holds(quantity: &str, published: &str, ours: String, pass: bool) -> Check {
        Check {
            quantity: quantity.to_string(),
            published: published.to_string(),
            ours,
            tolerance: "holds".to_string(),
            pass,
        }
    }
}

/// Four significant digits, plain notation where readable.
pub fn fmt_num(v: f64) -> String {
    if v == 0.0 || (1e-3..1e6).contains(&v.abs()) {
        let digits = (3 - v.abs().log10().floor() as i32).clamp(0, 8) as usize;
        format!("{v:.digits$}")
    } else {
        format!("{v:.4e}")
    }
}

/// The result of one study.
#[derive(Clone, Debug, Default)]
pub struct Report {
    pub id: String,
    pub title: String,
    /// Source document and section.
    pub source: String,
    /// System files run.
    pub systems: Vec<String>,
    pub checks: Vec<Check>,
    /// (caption, path) of the figures.
    pub figures: Vec<(String, PathBuf)>,
    /// Readings taken, deviations explained.
    pub notes: Vec<String>,
}

impl Report {
    pub fn passed(&self) -> bool {
        self.checks.iter().all(|c| c.pass)
    }

    /// The table and figures as Markdown; figure links relative to `rel_to`.
    pub fn to_markdown(&self, rel_to: &Path) -> String {
        let mut m = String::new();
        let _ = writeln!(m, "## {}\n", self.title);
        let _ = writeln!(m, "Source: {}. Systems: {}.\n", self.source, {
            let v: Vec<String> = self
                .systems
                .iter()
                .map(|s| format!("`systems/{s}`"))
                .collect();
            v.join(", ")
        });
        m.push_str(
            "| quantity | published | ours | tolerance | |\n| --- | --- | --- | --- | --- |\n",
        );
        for c in &self.checks {
            let _ = writeln!(
                m,
                "| {} | {} | {} | {} | {} |",
                c.quantity,
                c.published,
                c.ours,
                c.tolerance,
                if c.pass { "pass" } else { "**FAIL**" }
            );
        }
        m.push('\n');
        for n in &self.notes {
            let _ = writeln!(m, "- {n}");
        }
        if !self.notes.is_empty() {
            m.push('\n');
        }
        for (caption, path) in &self.figures {
            let rel = path.strip_prefix(rel_to).unwrap_or(path);
            let _ = writeln!(m, "![{caption}]({})\n", rel.display());
        }
        m
    }

    /// Panics with the whole table when any check fails (for the system tests).
    pub fn assert_passed(&self) {
        let table: Vec<String> = self
            .checks
            .iter()
            .map(|c| {
                format!(
                    "{} {}: published {}, ours {}, tolerance {}",
                    if c.pass { "ok  " } else { "FAIL" },
                    c.quantity,
                    c.published,
                    c.ours,
                    c.tolerance
                )
            })
            .collect();
        println!("{}\n{}", self.title, table.join("\n"));
        assert!(
            self.passed(),
            "{}: checks failed:\n{}",
            self.title,
            table.join("\n")
        );
    }
}

/// The `--set` overrides of a run as the notes print them ("its defaults" when there are none).
pub fn overrides_text(sets: &[&str]) -> String {
    if sets.is_empty() {
        "its defaults".to_string()
    } else {
        format!("--set {}", sets.join(" --set "))
    }
}

// ------------------------------------------------------------------------------------------
// Columns and statistics
// ------------------------------------------------------------------------------------------

/// A column of a recorded table.
pub fn col<'a>(table: &'a ResultsTable, column: &str) -> Result<&'a [f64], String> {
    table.column(column).map_err(|e| e.to_string())
}

/// The last value of a column.
pub fn last(table: &ResultsTable, column: &str) -> Result<f64, String> {
    col(table, column)?
        .last()
        .copied()
        .ok_or_else(|| format!("empty column {column}"))
}

/// The part of a column from time `t0` on.
pub fn after<'a>(table: &'a ResultsTable, column: &str, t0: f64) -> Result<&'a [f64], String> {
    let t = table.time();
    let start = t.iter().position(|&x| x >= t0).unwrap_or(t.len());
    Ok(&col(table, column)?[start..])
}

/// Mean of a slice.
pub fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// Variance of a slice (population, about its mean).
pub fn variance(v: &[f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mean = mean(v);
    v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / v.len() as f64
}

/// Standard deviation of a slice (population).
pub fn std_dev(v: &[f64]) -> f64 {
    variance(v).sqrt()
}

/// Largest |v| (0 for an empty slice).
pub fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// RMS of a − b.
pub fn rms_diff(a: &[f64], b: &[f64]) -> f64 {
    (a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / a.len() as f64).sqrt()
}

// ------------------------------------------------------------------------------------------
// Noise seeds: a published realisation against the spread of many
// ------------------------------------------------------------------------------------------

/// Min, max, mean and median of a statistic over the noise seeds.
#[derive(Clone, Copy, Debug)]
pub struct Spread {
    pub n: usize,
    pub min: f64,
    pub max: f64,
    pub mean: f64,
    pub median: f64,
}

impl Spread {
    /// The spread of the values `v` (one per seed).
    pub fn of(v: &[f64]) -> Spread {
        let mut s = v.to_vec();
        s.sort_by(|a, b| a.total_cmp(b));
        let n = s.len();
        Spread {
            n,
            min: s[0],
            max: s[n - 1],
            mean: s.iter().sum::<f64>() / n as f64,
            median: if n % 2 == 1 {
                s[n / 2]
            } else {
                0.5 * (s[n / 2 - 1] + s[n / 2])
            },
        }
    }

    /// The spread of `f` over the runs.
    pub fn over<T>(runs: &[T], f: impl Fn(&T) -> f64) -> Spread {
        Spread::of(&runs.iter().map(f).collect::<Vec<_>>())
    }

    /// Whether a printed value lies within min..max, widened by half a unit of its last digit.
    pub fn covers(&self, printed: &str) -> bool {
        let v: f64 = printed.parse().unwrap_or(f64::NAN);
        let h = half_digit(printed);
        (self.min - h..=self.max + h).contains(&v)
    }
}

/// "min .. max (mean m)".
impl std::fmt::Display for Spread {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} .. {} (mean {})",
            fmt_num(self.min),
            fmt_num(self.max),
            fmt_num(self.mean)
        )
    }
}

/// Half a unit of the last digit of a printed number.
pub fn half_digit(printed: &str) -> f64 {
    let d = printed.split('.').nth(1).map_or(0, |f| f.len() as i32);
    0.5 * 10f64.powi(-d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checks_decide_and_format() {
        assert!(Check::abs("x", 1.0, 1.05, 0.1, "m").pass);
        assert!(!Check::rel("x", 10.0, 10.3, 0.02, "").pass);
        assert!(Check::range("r", "60-78 %", 70.0, 60.0, 78.0, "%").pass);
        assert_eq!(fmt_num(34.8123), "34.81");
        assert_eq!(fmt_num(0.012345), "0.01235");
        assert!((variance(&[1.0, 3.0]) - 1.0).abs() < 1e-15);
        assert!((std_dev(&[1.0, 3.0]) - 1.0).abs() < 1e-15);
        assert_eq!(max_abs(&[1.0, -3.0]), 3.0);
    }

    #[test]
    fn spreads_cover_printed_values() {
        let s = Spread::of(&[3.0, 1.0, 2.0, 4.0]);
        assert_eq!(
            (s.n, s.min, s.max, s.mean, s.median),
            (4, 1.0, 4.0, 2.5, 2.5)
        );
        assert_eq!(half_digit("0.00072"), 0.000005);
        assert_eq!(half_digit("54"), 0.5);
        // "4.00" ± 0.005 and "1" ± 0.5 touch the range; "4.1" ± 0.05 and "0.9" ± 0.05 do not
        assert!(s.covers("4.00") && s.covers("1") && !s.covers("4.1") && !s.covers("0.9"));
        assert_eq!(s.to_string(), "1.000 .. 4.000 (mean 2.500)");
    }
}
