//! Counts and failures of a fuzz run, and the files it writes under target/fuzz/.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

/// The oracle's failure kinds (docs/fuzzing.md).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum FailKind {
    /// The process died: a signal, or an exit the fuzzer did not make (an FMU calling exit()).
    Crash,
    /// One call went over the per-call limit.
    Hang,
    /// A call returned fmi2OK and a Real output was NaN or infinite afterwards.
    NonFinite,
    /// A panic message reached stderr.
    Panic,
    /// shipsim exited with status 101 (a panic) on a malformed file.
    Exit101,
    /// shipsim failed without a message on stderr.
    NoMessage,
    /// The case could not be set up (the FMU did not load, say).
    Setup,
}

impl FailKind {
    pub fn name(self) -> &'static str {
        match self {
            FailKind::Crash => "crash",
            FailKind::Hang => "hang",
            FailKind::NonFinite => "nonfinite",
            FailKind::Panic => "panic",
            FailKind::Exit101 => "exit101",
            FailKind::NoMessage => "nomessage",
            FailKind::Setup => "setup",
        }
    }
}

/// One failing case, reproducible from (kind, target, seed, unit).
#[derive(Clone, Debug)]
pub struct Failure {
    pub fail: FailKind,
    /// calls, state, param, toml, osp, md.
    pub case: &'static str,
    /// The FMU's model identifier, or the base file of a malformed file.
    pub target: String,
    pub seed: u64,
    pub unit: u64,
    pub detail: String,
    /// The calls of the unit up to the failing one (FMU cases), or the command line (files).
    pub calls: Vec<String>,
}

impl Failure {
    /// One line: the oracle's verdict, the coordinates that replay it, the calls.
    pub fn line(&self) -> String {
        format!(
            "{} case={} target={} seed={} unit={} | {} | calls: {}",
            self.fail.name(),
            self.case,
            self.target,
            self.seed,
            self.unit,
            self.detail.replace(['\n', '\r'], " "),
            self.calls.join("; ")
        )
    }

    /// The command that replays this case.
    pub fn replay(&self) -> String {
        format!(
            "cargo run --release -p system-tests --bin fuzz -- replay {} {} {} {}",
            self.case, self.target, self.seed, self.unit
        )
    }
}

/// What a run did.
#[derive(Clone, Debug, Default)]
pub struct Report {
    /// FMI calls made (the oracle's own reads of the outputs not counted).
    pub calls: u64,
    /// fmi2DeSerializeFMUstate calls with mutated bytes.
    pub states: u64,
    /// Units finished or failed, per case kind.
    pub units: BTreeMap<&'static str, u64>,
    /// Lines the children or shipsim wrote that were not records (FMU prints, messages).
    pub stray: u64,
    pub failures: Vec<Failure>,
}

impl Report {
    pub fn merge(&mut self, o: Report) {
        self.calls += o.calls;
        self.states += o.states;
        for (k, v) in o.units {
            *self.units.entry(k).or_default() += v;
        }
        self.stray += o.stray;
        self.failures.extend(o.failures);
    }

    pub fn cases(&self) -> u64 {
        self.units.values().sum()
    }

    /// Failures per kind and target: `hang: Waves 3, Wind 1`.
    pub fn by_kind(&self) -> BTreeMap<(FailKind, &'static str), BTreeMap<String, u64>> {
        let mut m: BTreeMap<(FailKind, &'static str), BTreeMap<String, u64>> = BTreeMap::new();
        for f in &self.failures {
            *m.entry((f.fail, f.case))
                .or_default()
                .entry(f.target.clone())
                .or_default() += 1;
        }
        m
    }

    /// The summary printed at the end of a run.
    pub fn summary(&self, secs: f64) -> String {
        let mut s = String::new();
        let per_min = |n: u64| n as f64 * 60.0 / secs.max(1e-9);
        let _ = writeln!(
            s,
            "fuzz: {} FMI calls, {} mutated states, {} cases ({}) in {:.0} s ({:.0} calls/min, {:.0} states/min, {:.0} cases/min)",
            self.calls,
            self.states,
            self.cases(),
            self.units
                .iter()
                .map(|(k, v)| format!("{k} {v}"))
                .collect::<Vec<_>>()
                .join(", "),
            secs,
            per_min(self.calls),
            per_min(self.states),
            per_min(self.cases()),
        );
        if self.failures.is_empty() {
            let _ = writeln!(s, "fuzz: 0 failures");
        } else {
            let _ = writeln!(s, "fuzz: {} failures", self.failures.len());
            for ((kind, case), targets) in self.by_kind() {
                let list: Vec<String> = targets.iter().map(|(t, n)| format!("{t} {n}")).collect();
                let _ = writeln!(s, "  {} ({case}): {}", kind.name(), list.join(", "));
            }
        }
        s
    }

    /// Sorts the failures (runs in parallel finish in any order) and writes them, one line
    /// each, to `path`, with the replay command under each.
    pub fn write(&mut self, path: &Path) -> std::io::Result<()> {
        self.failures.sort_by(|a, b| {
            (a.fail, a.case, &a.target, a.seed, a.unit)
                .cmp(&(b.fail, b.case, &b.target, b.seed, b.unit))
        });
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)?;
        }
        let mut text = String::new();
        for f in &self.failures {
            let _ = writeln!(text, "{}\n    replay: {}", f.line(), f.replay());
        }
        std::fs::write(path, text)
    }
}
