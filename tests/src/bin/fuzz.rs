//! `fuzz`: the FMI fuzzer of issue 19 (docs/fuzzing.md).
//!
//! ```text
//! fuzz suite  [--fmu-dir D] [--shipsim BIN] [--jobs N] [--out DIR] [--no-files] [--only K,..]
//! fuzz run    --minutes N [--seed S] [same options]
//! fuzz replay <case> <target> <seed> <unit> [--fmu-dir D] [--shipsim BIN]
//! fuzz child  <kind> <dir> <seed> <from> <to>      (internal: one batch of units)
//! ```
//! `suite` runs the fixed-seed suite of `cargo xtask test`; `run` runs seeded rounds until N
//! minutes have passed. Both print counts and failures by kind and FMU, write every failing
//! case as one line under DIR (default target/fuzz/) and exit with status 1 on any failure.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use system_tests::fuzz::files::{Bases, Family, MdBase};
use system_tests::fuzz::report::Report;
use system_tests::fuzz::runner::{run_all, Env, Target, Task};
use system_tests::fuzz::units::Kind;
use system_tests::fuzz::watch::Limits;
use system_tests::fuzz::{child_main, ffi, plan};

struct Options {
    fmu_dir: PathBuf,
    shipsim: PathBuf,
    jobs: usize,
    out: PathBuf,
    files: bool,
    minutes: Option<f64>,
    seed: Option<u64>,
    /// Only these case kinds (calls, state, param, toml, osp, md); empty: all.
    only: Vec<String>,
    positional: Vec<String>,
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ lives in the workspace")
        .to_path_buf()
}

fn parse(args: &[String]) -> Result<Options, String> {
    let root = root();
    let mut o = Options {
        fmu_dir: std::env::var_os("SHIPSIM_FMU_DIR")
            .map(PathBuf::from)
            .unwrap_or_else(|| root.join("target/fmu")),
        shipsim: root.join("target/release/shipsim"),
        jobs: std::thread::available_parallelism().map_or(2, |n| n.get()),
        out: root.join("target/fuzz"),
        files: true,
        minutes: None,
        seed: None,
        only: Vec::new(),
        positional: Vec::new(),
    };
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = |name: &str| {
            it.next()
                .cloned()
                .ok_or_else(|| format!("{name} needs a value"))
        };
        match a.as_str() {
            "--fmu-dir" => o.fmu_dir = value(a)?.into(),
            "--shipsim" => o.shipsim = value(a)?.into(),
            "--out" => o.out = value(a)?.into(),
            "--no-files" => o.files = false,
            "--jobs" => o.jobs = value(a)?.parse().map_err(|e| format!("--jobs: {e}"))?,
            "--minutes" => {
                let m: f64 = value(a)?.parse().map_err(|e| format!("--minutes: {e}"))?;
                if !(m > 0.0 && m.is_finite()) {
                    return Err(format!("--minutes {m}: must be a positive number"));
                }
                o.minutes = Some(m);
            }
            "--only" => o.only = value(a)?.split(',').map(String::from).collect(),
            "--seed" => o.seed = Some(value(a)?.parse().map_err(|e| format!("--seed: {e}"))?),
            s if s.starts_with("--") => return Err(format!("unknown option {s}")),
            s => o.positional.push(s.to_string()),
        }
    }
    Ok(o)
}

/// Unpacks every FMU of the folder (sorted by name).
fn targets(dir: &Path) -> Result<Vec<Target>, String> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: {e} (run `cargo xtask build-fmus`)", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "fmu"))
        .collect();
    paths.sort();
    if paths.is_empty() {
        return Err(format!("no .fmu files in {}", dir.display()));
    }
    paths
        .iter()
        .map(|p| {
            let u = ffi::Unpacked::open(p).map_err(|e| format!("{}: {e}", p.display()))?;
            let name = ffi::Model::new(&u.md).name;
            Ok(Target { name, unpacked: u })
        })
        .collect()
}

/// The bases of the malformed-file cases: systems/, OSP exports, and the model descriptions
/// of three FMUs (or of every target when none of those is there).
fn bases(o: &Options, targets: &[Target]) -> Result<Bases, String> {
    let wanted = ["SteeringGear", "Waves", "RrsAutopilot"];
    let pick: Vec<&Target> = match targets
        .iter()
        .filter(|t| wanted.contains(&t.name.as_str()))
        .count()
    {
        0 => targets.iter().collect(),
        _ => targets
            .iter()
            .filter(|t| wanted.contains(&t.name.as_str()))
            .collect(),
    };
    let mds = pick
        .iter()
        .map(|t| {
            let xml = std::fs::read_to_string(t.unpacked.dir.join("modelDescription.xml"))
                .map_err(|e| e.to_string())?;
            Ok(MdBase {
                name: t.name.clone(),
                xml,
                binary: t.unpacked.binary.clone(),
                model_identifier: t.name.clone(),
            })
        })
        .collect::<Result<Vec<_>, String>>()?;
    if !o.shipsim.is_file() {
        return Err(format!(
            "{} not found: build it with `cargo build --release -p shipsim`",
            o.shipsim.display()
        ));
    }
    let work = o.out.join("work");
    Bases::prepare(&root(), &o.fmu_dir, &o.shipsim, &work, mds)
}

fn env(o: &Options) -> Result<Env, String> {
    let targets = targets(&o.fmu_dir)?;
    let files = if o.files {
        Some(bases(o, &targets)?)
    } else {
        None
    };
    Ok(Env {
        exe: std::env::current_exe().map_err(|e| e.to_string())?,
        targets,
        limits: Limits::default(),
        files,
    })
}

/// Prints the summary, writes the failures file; the exit status.
fn finish(mut report: Report, started: Instant, file: &Path) -> i32 {
    print!("{}", report.summary(started.elapsed().as_secs_f64()));
    if let Err(e) = report.write(file) {
        eprintln!("fuzz: cannot write {}: {e}", file.display());
        return 2;
    }
    if report.failures.is_empty() {
        0
    } else {
        println!(
            "fuzz: every failing case, with its replay command: {}",
            file.display()
        );
        1
    }
}

fn progress(started: Instant) -> impl Fn(&Report) + Sync {
    move |r: &Report| {
        let s = started.elapsed().as_secs();
        println!(
            "[{:>3}:{:02}] {} calls, {} states, {} cases, {} failures",
            s / 60,
            s % 60,
            r.calls,
            r.states,
            r.cases(),
            r.failures.len()
        );
    }
}

/// The tasks of the kinds `--only` names.
fn only(o: &Options, tasks: Vec<Task>) -> Vec<Task> {
    tasks
        .into_iter()
        .filter(|t| o.only.is_empty() || o.only.iter().any(|k| k == t.case()))
        .collect()
}

fn suite(o: &Options) -> Result<i32, String> {
    let env = env(o)?;
    let started = Instant::now();
    let tasks = only(o, plan::suite(&env.targets, o.files));
    println!(
        "fuzz suite: seed {}, {} FMUs, {} tasks on {} workers",
        plan::SUITE_SEED,
        env.targets.len(),
        tasks.len(),
        o.jobs
    );
    let report = run_all(
        &env,
        tasks,
        o.jobs,
        &Vec::new,
        &progress(started),
        Duration::from_secs(30),
    );
    Ok(finish(report, started, &o.out.join("suite-failures.txt")))
}

fn long_run(o: &Options) -> Result<i32, String> {
    let minutes = o.minutes.ok_or("run needs --minutes N")?;
    let seed = o.seed.unwrap_or_else(|| {
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(1, |d| d.as_secs())
    });
    let env = env(o)?;
    let started = Instant::now();
    let deadline = started + Duration::from_secs_f64(minutes * 60.0);
    println!(
        "fuzz run: seed {seed}, {minutes} min, {} FMUs, {} workers",
        env.targets.len(),
        o.jobs
    );
    let round = std::sync::atomic::AtomicU64::new(0);
    let more = || {
        if Instant::now() >= deadline {
            return Vec::new();
        }
        let r = round.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
        only(o, plan::long_round(&env.targets, seed, r, o.files))
            .into_iter()
            .filter(|_| Instant::now() < deadline)
            .collect()
    };
    // Tasks are small: the queue is refilled one round at a time and stops at the deadline.
    let tasks = more();
    let report = run_all(
        &env,
        tasks,
        o.jobs,
        &more,
        &progress(started),
        Duration::from_secs(60),
    );
    println!(
        "fuzz run: seed {seed}, {} rounds",
        round.load(std::sync::atomic::Ordering::SeqCst)
    );
    Ok(finish(
        report,
        started,
        &o.out.join(format!("run-{seed}-failures.txt")),
    ))
}

fn replay(o: &Options) -> Result<i32, String> {
    let [case, target, seed, unit] = o.positional.as_slice() else {
        return Err("usage: fuzz replay <case> <target> <seed> <unit>".into());
    };
    let seed: u64 = seed.parse().map_err(|e| format!("seed: {e}"))?;
    let unit: u64 = unit.parse().map_err(|e| format!("unit: {e}"))?;
    let o = Options {
        files: Family::parse(case).is_some(),
        ..Options {
            positional: Vec::new(),
            ..clone_options(o)
        }
    };
    let env = env(&o)?;
    let task = if let Some(kind) = Kind::parse(case) {
        let i = env
            .targets
            .iter()
            .position(|t| t.name == *target)
            .ok_or_else(|| format!("no FMU {target} in {}", o.fmu_dir.display()))?;
        Task::Fmu {
            kind,
            target: i,
            seed,
            units: unit..unit + 1,
        }
    } else if let Some(family) = Family::parse(case) {
        Task::File {
            family,
            seed,
            units: unit..unit + 1,
        }
    } else {
        return Err(format!(
            "unknown case kind {case}: calls, state, param, toml, osp or md"
        ));
    };
    let started = Instant::now();
    let report = task.run(&env);
    for f in &report.failures {
        println!("{}", f.line());
    }
    Ok(finish(report, started, &o.out.join("replay-failures.txt")))
}

fn clone_options(o: &Options) -> Options {
    Options {
        fmu_dir: o.fmu_dir.clone(),
        shipsim: o.shipsim.clone(),
        jobs: o.jobs,
        out: o.out.clone(),
        files: o.files,
        minutes: o.minutes,
        seed: o.seed,
        only: o.only.clone(),
        positional: o.positional.clone(),
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("child") {
        std::process::exit(child_main(&args[1..]));
    }
    let result = parse(args.get(1..).unwrap_or_default()).and_then(|o| {
        match args.first().map(String::as_str) {
            Some("suite") => suite(&o),
            Some("run") => long_run(&o),
            Some("replay") => replay(&o),
            _ => Err("usage: fuzz suite|run --minutes N [--seed S]|replay <case> <target> <seed> <unit> [--fmu-dir D] [--shipsim BIN] [--jobs N] [--out DIR] [--no-files] [--only calls,state,param,toml,osp,md]".into()),
        }
    });
    match result {
        Ok(code) => std::process::exit(code),
        Err(e) => {
            eprintln!("fuzz: {e}");
            std::process::exit(2);
        }
    }
}
