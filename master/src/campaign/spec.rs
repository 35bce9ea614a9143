//! The campaign file: what to vary, what to measure, and how to compare.
//!
//! ```toml
//! name = "rrs_polar"
//! system = "../systems/rrs.toml"      # TOML or OSP XML, relative to this file
//! stop_time = 1200.0                   # optional: overrides the system's
//! step_size = 0.05                     # optional: overrides the system's (an SSD may have none)
//! seed = 2026                          # campaign seed: random designs and replication seeds
//! fork_at = 200.0                      # optional: shared warm-up to t = 200 s
//! set = { "autopilot.adaptation_enabled" = true }   # optional: for every run
//!
//! [[factors]]                          # grids are crossed, first factor slowest
//! name = "direction_deg"               # column name (default: the variable)
//! variable = "waves.wave_direction"
//! range = [30, 150, 15]                # or values = [...], linspace = [a, b, n],
//! scale = 0.017453292519943295         #    uniform = [lo, hi], normal = [mean, std]
//! # zip = "a"                          # factors with one zip label vary together
//!
//! [sampling]                           # random factors: how many points, which design
//! method = "latin_hypercube"           # or "monte_carlo"
//! samples = 200
//!
//! [replications]                       # seeds per design point (see design.rs)
//! count = 10
//! seeds = ["waves.seed", "wind.seed", "sensors.seed"]
//!
//! [[arms]]                             # variants on the same seeds
//! name = "off"
//! set = { "autopilot.roll_mode" = 0 }
//!
//! [[kpis]]                             # per run, on the fly (kpi.rs)
//! name = "roll_var"
//! variable = "ship.roll"
//! stat = "variance"
//! window = [200, 1200]
//! scale = 57.29577951308232            # rad -> deg before the statistic
//!
//! [[derived]]                          # across arms, after the runs (derived.rs)
//! name = "roll_reduction"
//! expr = "100 * (1 - roll_var[on] / roll_var[off])"
//!
//! [series]                             # optional: decimated time series of some runs
//! runs = [0, 1]
//! variables = ["ship.roll"]
//! decimation = 20
//! ```
//!
//! Values are applied like `shipsim run --set`: as start values of parameters and inputs of
//! any instance, checked against the variable's type when the run's system is validated.

use super::kpi::{KpiSpec, Manoeuvre, Stat};
use crate::error::{Error, Result};
use crate::system::Value;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// The columns the run and derived tables have of their own (docs/campaigns.md, "Output
/// folder"); no factor, seed or KPI may take one of these names.
pub const TABLE_COLUMNS: [&str; 8] = [
    "run",
    "point",
    "replication",
    "arm",
    "status",
    "message",
    "wall_time",
    "key",
];

/// The most runs (and so design points) a campaign file may expand to. Runs are made from their
/// index when needed, but the journal and the tables of a finished campaign hold every run
/// (see the limits in docs/campaigns.md).
pub const MAX_RUNS: usize = 10_000_000;

/// The most samples of the random factors: each factor's samples are held in memory.
pub const MAX_SAMPLES: usize = 1_000_000;

/// A campaign file, checked.
#[derive(Debug, Clone)]
pub struct CampaignSpec {
    /// The campaign file.
    pub source: PathBuf,
    /// Its text (kept for the provenance sidecar).
    pub text: String,
    pub name: String,
    pub description: Option<String>,
    /// The base system file, resolved against the campaign file's folder.
    pub system: PathBuf,
    pub stop_time: Option<f64>,
    /// Overrides the system's step size (an SSD without a fixed-step annotation needs it).
    pub step_size: Option<f64>,
    pub seed: u64,
    pub fork_at: Option<f64>,
    /// Set in every run.
    pub set: Vec<(String, Value)>,
    pub factors: Vec<Factor>,
    pub sampling: Sampling,
    pub replications: Replications,
    pub arms: Vec<Arm>,
    pub kpis: Vec<KpiSpec>,
    pub derived: Vec<Derived>,
    pub series: Option<SeriesSpec>,
}

/// One varied quantity: a column of the run table, applied as `variable = scale * value`.
#[derive(Debug, Clone)]
pub struct Factor {
    pub name: String,
    pub variable: String,
    pub levels: Levels,
    pub scale: f64,
    pub zip: Option<String>,
}

/// A factor's values.
#[derive(Debug, Clone, PartialEq)]
pub enum Levels {
    /// A grid (lists, ranges and linspace are expanded when the file is read).
    Grid(Vec<f64>),
    /// Random, uniform on [low, high].
    Uniform { low: f64, high: f64 },
    /// Random, normal.
    Normal { mean: f64, std: f64 },
}

impl Levels {
    pub fn is_random(&self) -> bool {
        !matches!(self, Levels::Grid(_))
    }
}

/// How the random factors are sampled.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SamplingMethod {
    MonteCarlo,
    LatinHypercube,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sampling {
    pub method: SamplingMethod,
    pub samples: usize,
}

/// N seeds per design point, each derived for every named seed parameter.
#[derive(Debug, Clone, Default)]
pub struct Replications {
    pub count: u32,
    pub seeds: Vec<String>,
}

/// A variant compared on the same seeds.
#[derive(Debug, Clone)]
pub struct Arm {
    pub name: String,
    pub set: Vec<(String, Value)>,
}

/// A KPI computed across arms after the runs.
#[derive(Debug, Clone)]
pub struct Derived {
    pub name: String,
    pub expr: String,
}

/// Decimated time series of selected runs.
#[derive(Debug, Clone)]
pub struct SeriesSpec {
    pub runs: Vec<u64>,
    pub variables: Vec<String>,
    pub decimation: u32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Raw {
    name: Option<Spanned<String>>,
    description: Option<String>,
    system: String,
    stop_time: Option<f64>,
    step_size: Option<f64>,
    #[serde(default)]
    seed: u64,
    fork_at: Option<f64>,
    #[serde(default)]
    set: BTreeMap<String, toml::Value>,
    #[serde(default)]
    factors: Vec<Spanned<RawFactor>>,
    sampling: Option<RawSampling>,
    replications: Option<RawReplications>,
    #[serde(default)]
    arms: Vec<Spanned<RawArm>>,
    #[serde(default)]
    kpis: Vec<Spanned<RawKpi>>,
    #[serde(default)]
    derived: Vec<Spanned<RawDerived>>,
    series: Option<RawSeries>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFactor {
    name: Option<String>,
    variable: String,
    values: Option<Vec<toml::Value>>,
    range: Option<Vec<f64>>,
    linspace: Option<Vec<f64>>,
    uniform: Option<Vec<f64>>,
    normal: Option<Vec<f64>>,
    #[serde(default = "one")]
    scale: f64,
    zip: Option<String>,
}

fn one() -> f64 {
    1.0
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSampling {
    method: String,
    samples: usize,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawReplications {
    count: u32,
    seeds: Vec<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawArm {
    name: String,
    #[serde(default)]
    set: BTreeMap<String, toml::Value>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDerived {
    name: String,
    expr: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawKpi {
    name: String,
    variable: Option<String>,
    stat: Option<String>,
    window: Option<[f64; 2]>,
    #[serde(default = "one")]
    scale: f64,
    threshold: Option<f64>,
    above: Option<f64>,
    below: Option<f64>,
    target: Option<f64>,
    band: Option<f64>,
    manoeuvre: Option<String>,
    x: Option<String>,
    y: Option<String>,
    heading: Option<String>,
    rudder_angle: Option<f64>,
    execute_time: Option<f64>,
    length: Option<f64>,
    speed: Option<f64>,
    check_angle: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSeries {
    runs: Vec<u64>,
    variables: Vec<String>,
    #[serde(default = "one_u32")]
    decimation: u32,
}

fn one_u32() -> u32 {
    1
}

/// A TOML value as a system [`Value`].
fn value(v: &toml::Value) -> Option<Value> {
    Some(match v {
        toml::Value::Float(x) => Value::Real(*x),
        toml::Value::Integer(i) => Value::Integer(*i),
        toml::Value::Boolean(b) => Value::Boolean(*b),
        toml::Value::String(s) => Value::String(s.clone()),
        _ => return None,
    })
}

/// Reads campaign files, collecting every error with its line.
struct Reader<'a> {
    path: &'a Path,
    text: &'a str,
    lines: crate::format::LineIndex,
    errors: Vec<Error>,
}

impl CampaignSpec {
    /// Reads and checks a campaign file (the base system is read by [`super::Campaign::load`]).
    pub fn load(path: &Path) -> Result<CampaignSpec> {
        let text = crate::limits::read_text(path, crate::limits::MAX_SYSTEM_FILE, "campaign file")?;
        CampaignSpec::parse(path, &text)
    }

    /// Checks the text of a campaign file read from `path`.
    pub fn parse(path: &Path, text: &str) -> Result<CampaignSpec> {
        let raw: Raw = toml::from_str(text).map_err(|e| {
            let line = e
                .span()
                .map(|s| crate::format::LineIndex::new(text).line(s.start));
            Error::system(path, line, e.message().to_string())
        })?;
        let mut r = Reader {
            path,
            text,
            lines: crate::format::LineIndex::new(text),
            errors: Vec::new(),
        };
        let spec = r.spec(raw);
        crate::format::collected(r.errors)?;
        Ok(spec)
    }
}

impl Reader<'_> {
    fn line(&self, span: std::ops::Range<usize>) -> Option<usize> {
        Some(self.lines.line(span.start))
    }

    fn error(&mut self, line: Option<usize>, message: String) {
        self.errors.push(Error::system(self.path, line, message));
    }

    fn spec(&mut self, raw: Raw) -> CampaignSpec {
        let dir = self.path.parent().unwrap_or(Path::new("."));
        let name = match &raw.name {
            Some(n) => {
                let line = self.line(n.span());
                self.folder_name(n.get_ref(), line, "name")
            }
            None => {
                let stem = self.path.file_stem().map(|s| s.to_string_lossy());
                let stem = stem.unwrap_or_else(|| "campaign".into()).into_owned();
                self.folder_name(&stem, None, "the file's name (the default name)")
            }
        };
        for (what, t) in [("stop_time", raw.stop_time), ("fork_at", raw.fork_at)] {
            if t.is_some_and(|t| !t.is_finite()) {
                self.error(None, format!("{what} = {} must be finite", t.unwrap()));
            }
        }
        if let Some(h) = raw.step_size.filter(|h| !(*h > 0.0 && h.is_finite())) {
            self.error(
                None,
                format!("step_size = {h} must be a positive number of seconds"),
            );
        }
        let set = self.sets("set", &raw.set, None);
        let factors: Vec<Factor> = raw.factors.into_iter().map(|f| self.factor(f)).collect();
        let sampling = self.sampling(raw.sampling, &factors);
        let replications = self.replications(raw.replications);
        let arms = self.arms(raw.arms);
        let kpis = raw.kpis.into_iter().filter_map(|k| self.kpi(k)).collect();
        let derived = raw
            .derived
            .into_iter()
            .map(|d| {
                let line = self.line(d.span());
                let d = d.into_inner();
                self.not_reserved("derived kpi", &d.name, line);
                Derived {
                    name: d.name,
                    expr: d.expr,
                }
            })
            .collect();
        let series = raw.series.map(|s| SeriesSpec {
            runs: s.runs,
            variables: s.variables,
            decimation: s.decimation.max(1),
        });
        let spec = CampaignSpec {
            source: self.path.to_path_buf(),
            text: self.text.to_string(),
            name,
            description: raw.description,
            system: dir.join(&raw.system),
            stop_time: raw.stop_time,
            step_size: raw.step_size,
            seed: raw.seed,
            fork_at: raw.fork_at,
            set,
            factors,
            sampling,
            replications,
            arms,
            kpis,
            derived,
            series,
        };
        self.names(&spec);
        spec
    }

    /// The campaign's name, which is also its output folder `results/<name>`: one folder name,
    /// never a path (no `/` or `\\`, not `.` or `..`, not empty, no control characters), so that
    /// a campaign file cannot make `campaign run` write outside `results/`.
    fn folder_name(&mut self, name: &str, line: Option<usize>, what: &str) -> String {
        let why = if name.trim().is_empty() {
            Some("is empty")
        } else if name == "." || name == ".." {
            Some("is a relative folder, not a name")
        } else if name.contains(['/', '\\']) {
            Some("contains a path separator")
        } else if name.chars().any(char::is_control) {
            Some("contains a control character")
        } else {
            None
        };
        if let Some(why) = why {
            self.error(
                line,
                format!(
                    "campaign {what} {name:?} {why}: the name is the output folder \
                     results/<name>, so it must be one folder name (give `name = \"...\"`, or \
                     `--output DIR` to choose the folder)"
                ),
            );
        }
        name.to_string()
    }

    /// `{ "inst.var" = value, ... }` as (variable, value) pairs.
    fn sets(
        &mut self,
        what: &str,
        table: &BTreeMap<String, toml::Value>,
        line: Option<usize>,
    ) -> Vec<(String, Value)> {
        let mut out = Vec::new();
        for (k, v) in table {
            if crate::system::VarRef::parse(k).is_none() {
                self.error(line, format!("{what}: '{k}' is not instance.variable"));
                continue;
            }
            match value(v) {
                Some(v) => out.push((k.clone(), v)),
                None => self.error(
                    line,
                    format!("{what}: '{k}' = {v} is not a number, boolean or string"),
                ),
            }
        }
        out
    }

    fn factor(&mut self, f: Spanned<RawFactor>) -> Factor {
        let line = self.line(f.span());
        let f = f.into_inner();
        let name = f.name.clone().unwrap_or_else(|| f.variable.clone());
        self.not_reserved("factor", &name, line);
        let what = format!("factor '{name}'");
        if crate::system::VarRef::parse(&f.variable).is_none() {
            self.error(
                line,
                format!("{what}: variable '{}' is not instance.variable", f.variable),
            );
        }
        if !(f.scale.is_finite() && f.scale != 0.0) {
            self.error(
                line,
                format!("{what}: scale = {} must be finite and non-zero", f.scale),
            );
        }
        let given = [
            f.values.is_some(),
            f.range.is_some(),
            f.linspace.is_some(),
            f.uniform.is_some(),
            f.normal.is_some(),
        ];
        if given.iter().filter(|g| **g).count() != 1 {
            self.error(
                line,
                format!("{what}: give exactly one of values, range, linspace, uniform, normal"),
            );
        }
        let levels = match self.levels(&f) {
            Ok(l) => l,
            Err(m) => {
                self.error(line, format!("{what}: {m}"));
                Levels::Grid(Vec::new())
            }
        };
        if levels.is_random() && f.zip.is_some() {
            self.error(
                line,
                format!("{what}: random factors are sampled jointly; zip is for grids"),
            );
        }
        Factor {
            name,
            variable: f.variable,
            levels,
            scale: f.scale,
            zip: f.zip,
        }
    }

    fn levels(&self, f: &RawFactor) -> std::result::Result<Levels, String> {
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        if let Some(values) = &f.values {
            let mut out = Vec::new();
            for v in values {
                out.push(match v {
                    toml::Value::Float(x) if x.is_finite() => *x,
                    toml::Value::Integer(i) => *i as f64,
                    toml::Value::Boolean(b) => *b as i32 as f64,
                    v => return Err(format!("value {v} is not a finite number or boolean")),
                });
            }
            return nonempty(out);
        }
        if let Some(r) = &f.range {
            let [a, b, step] = r[..] else {
                return Err("range = [start, stop, step] (stop included)".into());
            };
            if !finite(r) || !(step > 0.0) || b < a {
                return Err(format!(
                    "range = {r:?}: needs finite start <= stop and step > 0"
                ));
            }
            // Points a + i*step up to b, with b included when it lies on the grid (to within
            // 1e-9 steps, the rounding of decimal steps).
            let n = ((b - a) / step + 1e-9).floor();
            if n > 1e6 {
                return Err(format!("range = {r:?} has more than a million points"));
            }
            return nonempty((0..=n as usize).map(|i| a + i as f64 * step).collect());
        }
        if let Some(l) = &f.linspace {
            let [a, b, n] = l[..] else {
                return Err("linspace = [start, stop, count]".into());
            };
            if !finite(l) || n < 1.0 || n.fract() != 0.0 || n > 1e6 {
                return Err(format!(
                    "linspace = {l:?}: needs finite ends and a whole count >= 1"
                ));
            }
            let n = n as usize;
            if n == 1 {
                return Ok(Levels::Grid(vec![a]));
            }
            let d = (b - a) / (n - 1) as f64;
            return Ok(Levels::Grid(
                (0..n)
                    .map(|i| if i == n - 1 { b } else { a + i as f64 * d })
                    .collect(),
            ));
        }
        if let Some(u) = &f.uniform {
            return match u[..] {
                [low, high] if finite(u) && low < high => Ok(Levels::Uniform { low, high }),
                _ => Err(format!(
                    "uniform = {u:?}: needs finite [low, high] with low < high"
                )),
            };
        }
        if let Some(n) = &f.normal {
            return match n[..] {
                [mean, std] if finite(n) && std > 0.0 => Ok(Levels::Normal { mean, std }),
                _ => Err(format!(
                    "normal = {n:?}: needs finite [mean, std] with std > 0"
                )),
            };
        }
        Ok(Levels::Grid(Vec::new()))
    }

    fn sampling(&mut self, s: Option<RawSampling>, factors: &[Factor]) -> Sampling {
        let random = factors.iter().any(|f| f.levels.is_random());
        let Some(s) = s else {
            if random {
                self.error(
                    None,
                    "random factors need [sampling] with method and samples".into(),
                );
            }
            return Sampling {
                method: SamplingMethod::MonteCarlo,
                samples: 0,
            };
        };
        let method = match s.method.as_str() {
            "monte_carlo" => SamplingMethod::MonteCarlo,
            "latin_hypercube" => SamplingMethod::LatinHypercube,
            m => {
                self.error(
                    None,
                    format!("sampling: method '{m}' is not monte_carlo or latin_hypercube"),
                );
                SamplingMethod::MonteCarlo
            }
        };
        if !random {
            self.error(
                None,
                "[sampling] is given but no factor is uniform or normal".into(),
            );
        }
        if s.samples == 0 || s.samples > MAX_SAMPLES {
            self.error(
                None,
                format!(
                    "sampling: samples = {} must be 1 ..= {}",
                    s.samples, MAX_SAMPLES
                ),
            );
        }
        Sampling {
            method,
            samples: s.samples,
        }
    }

    fn replications(&mut self, r: Option<RawReplications>) -> Replications {
        let Some(r) = r else {
            return Replications {
                count: 1,
                seeds: Vec::new(),
            };
        };
        if r.count == 0 {
            self.error(None, "replications: count must be at least 1".into());
        }
        if r.seeds.is_empty() {
            self.error(
                None,
                "replications: name the seed parameters in seeds = [...]".into(),
            );
        }
        for s in &r.seeds {
            self.not_reserved("seed", s, None);
            if crate::system::VarRef::parse(s).is_none() {
                self.error(
                    None,
                    format!("replications: seed '{s}' is not instance.variable"),
                );
            }
        }
        Replications {
            count: r.count,
            seeds: r.seeds,
        }
    }

    fn arms(&mut self, arms: Vec<Spanned<RawArm>>) -> Vec<Arm> {
        arms.into_iter()
            .map(|a| {
                let line = self.line(a.span());
                let a = a.into_inner();
                let set = self.sets(&format!("arm '{}'", a.name), &a.set, line);
                Arm { name: a.name, set }
            })
            .collect()
    }

    fn kpi(&mut self, k: Spanned<RawKpi>) -> Option<KpiSpec> {
        let line = self.line(k.span());
        let k = k.into_inner();
        let kpi = match &k.manoeuvre {
            Some(m) => manoeuvre_kpi(&k, m),
            None => stat_kpi(&k),
        };
        match kpi {
            Ok(kpi) => {
                for c in kpi.columns() {
                    self.not_reserved("kpi", &c, line);
                }
                Some(kpi)
            }
            Err(m) => {
                self.error(line, format!("kpi '{}': {m}", k.name));
                None
            }
        }
    }

    /// A factor, seed, KPI or derived KPI is a column of the run or derived table, beside the
    /// table's own columns ([`TABLE_COLUMNS`]): a name equal to one of those would give the table
    /// two columns of that name (Parquet readers then refuse the file).
    fn not_reserved(&mut self, what: &str, name: &str, line: Option<usize>) {
        if TABLE_COLUMNS.contains(&name) {
            self.error(
                line,
                format!(
                    "{what} name '{name}' is a column of the run tables ({}); choose another \
                     name (`name = \"...\"`)",
                    TABLE_COLUMNS.join(", ")
                ),
            );
        }
    }

    /// Column names are unique, plain identifiers (derived expressions refer to them).
    fn names(&mut self, spec: &CampaignSpec) {
        let mut seen = std::collections::HashSet::new();
        let kpi_names = spec.kpis.iter().flat_map(|k| k.columns());
        let arm_names = spec.arms.iter().map(|a| a.name.clone());
        let derived = spec.derived.iter().map(|d| d.name.clone());
        for (what, n) in kpi_names
            .map(|n| ("kpi", n))
            .chain(arm_names.map(|n| ("arm", n)))
            .chain(derived.map(|n| ("derived kpi", n)))
        {
            let ident = !n.is_empty()
                && !n.starts_with(|c: char| c.is_ascii_digit())
                && n.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
            if !ident {
                self.error(
                    None,
                    format!(
                    "{what} name '{n}' must be letters, digits and '_' (not starting with a digit)"
                ),
                );
            }
            if what != "arm" && !seen.insert(n.clone()) {
                self.error(None, format!("{what} name '{n}' is used twice"));
            }
        }
        if spec.arms.len() == 1 {
            self.error(
                None,
                "a single arm compares nothing: give two or more, or none".into(),
            );
        }
        let factor_names: std::collections::HashSet<_> =
            spec.factors.iter().map(|f| &f.name).collect();
        if factor_names.len() != spec.factors.len() {
            self.error(None, "two factors have the same name".into());
        }
        // factors, seeds, KPIs and derived KPIs share the tables' header
        let mut columns: std::collections::HashMap<String, &str> = Default::default();
        let factors = spec.factors.iter().map(|f| ("factor", f.name.clone()));
        let seeds = spec.replications.seeds.iter().map(|s| ("seed", s.clone()));
        let kpis = spec
            .kpis
            .iter()
            .flat_map(|k| k.columns())
            .map(|c| ("kpi", c));
        let derived = spec.derived.iter().map(|d| ("derived kpi", d.name.clone()));
        for (what, name) in factors.chain(seeds).chain(kpis).chain(derived) {
            match columns.get(&name) {
                Some(first) if *first != what => self.error(
                    None,
                    format!(
                        "{what} '{name}' has the name of a {first}: the run tables would have \
                         two columns '{name}'; rename one (`name = \"...\"`)"
                    ),
                ),
                _ => {
                    columns.insert(name, what);
                }
            }
        }
    }
}

fn nonempty(v: Vec<f64>) -> std::result::Result<Levels, String> {
    if v.is_empty() {
        return Err("no values".into());
    }
    Ok(Levels::Grid(v))
}

fn window(k: &RawKpi) -> std::result::Result<(f64, f64), String> {
    let (a, b) = k
        .window
        .map(|[a, b]| (a, b))
        .unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
    if a.is_nan() || b.is_nan() || a > b {
        return Err(format!("window = [{a}, {b}] must have start <= end"));
    }
    Ok((a, b))
}

fn stat_kpi(k: &RawKpi) -> std::result::Result<KpiSpec, String> {
    let variable = k
        .variable
        .clone()
        .ok_or("give variable (or manoeuvre for the manoeuvring KPIs)")?;
    let stat = k.stat.as_deref().ok_or("give stat")?;
    let need = |x: Option<f64>, what: &str| {
        x.filter(|v| v.is_finite())
            .ok_or_else(|| format!("stat '{stat}' needs a finite {what}"))
    };
    let stat = match stat {
        "mean" => Stat::Mean,
        "variance" => Stat::Variance,
        "std" => Stat::Std,
        "rms" => Stat::Rms,
        "min" => Stat::Min,
        "max" => Stat::Max,
        "max_abs" => Stat::MaxAbs,
        "final" => Stat::Final,
        "time_above" => Stat::TimeAbove {
            threshold: need(k.threshold, "threshold")?,
        },
        "first_time" => match (k.above, k.below) {
            (Some(a), None) if a.is_finite() => Stat::FirstAbove(a),
            (None, Some(b)) if b.is_finite() => Stat::FirstBelow(b),
            _ => return Err("stat 'first_time' needs one finite 'above' or 'below'".into()),
        },
        "settling_time" => {
            let band = need(k.band, "band")?;
            if band <= 0.0 {
                return Err(format!("band = {band} must be > 0"));
            }
            Stat::Settling {
                target: need(k.target, "target")?,
                band,
            }
        }
        s => {
            return Err(format!(
                "stat '{s}' is not one of mean, variance, std, rms, min, max, max_abs, final, \
                 time_above, first_time, settling_time"
            ))
        }
    };
    if !(k.scale.is_finite() && k.scale != 0.0) {
        return Err(format!("scale = {} must be finite and non-zero", k.scale));
    }
    Ok(KpiSpec::Stat {
        name: k.name.clone(),
        variable,
        stat,
        window: window(k)?,
        scale: k.scale,
    })
}

fn manoeuvre_kpi(k: &RawKpi, kind: &str) -> std::result::Result<KpiSpec, String> {
    let var = |v: &Option<String>, what: &str| {
        v.clone()
            .ok_or_else(|| format!("manoeuvre '{kind}' needs {what} = \"instance.variable\""))
    };
    let num = |v: Option<f64>, what: &str| {
        v.filter(|x| x.is_finite() && *x > 0.0)
            .ok_or_else(|| format!("manoeuvre '{kind}' needs {what} > 0"))
    };
    let manoeuvre = match kind {
        "turning_circle" => Manoeuvre::TurningCircle {
            x: var(&k.x, "x")?,
            y: var(&k.y, "y")?,
            heading: var(&k.heading, "heading")?,
        },
        "zigzag" => Manoeuvre::ZigZag {
            heading: var(&k.heading, "heading")?,
            check_angle: num(k.check_angle, "check_angle [rad]")?,
            rudder_sign: match k.rudder_angle {
                Some(a) if a < 0.0 => -1.0,
                _ => 1.0,
            },
            speed: num(k.speed, "speed [m/s] (the approach speed U of the IMO L/U)")?,
        },
        m => return Err(format!("manoeuvre '{m}' is not turning_circle or zigzag")),
    };
    Ok(KpiSpec::Manoeuvre {
        name: k.name.clone(),
        manoeuvre,
        execute_time: k
            .execute_time
            .filter(|t| t.is_finite())
            .ok_or("manoeuvre KPIs need execute_time [s] (the Manoeuvre FMU's)")?,
        length: num(k.length, "length [m] (for the IMO criteria)")?,
    })
}
