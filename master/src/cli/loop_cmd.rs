//! `shipsim loop SYSTEM ...`: loop analysis through the FMUs ([`shipsim::analysis`],
//! docs/loop-analysis.md).
//!
//! - `--break "a.y -> b.u"`: the loop transfer function at that connection and its margins;
//! - `--input X --output Y [--output Z ...]`: the frequency response from X to each output;
//! - the same with `--amplitudes A1,A2,...` and one frequency: the describing function.
//!
//! Tables (CSV and Parquet) and plots go to `-o DIR` (default `<system name>_loop/`);
//! `--json` prints one JSON object on one line on stdout.

use clap::Args;
use shipsim::analysis::{self, Injection, Options};
use shipsim::error::{Error, Result};
use shipsim::run::{load_fmus, RunOptions};
use shipsim::system::System;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

#[derive(Args)]
pub struct LoopArgs {
    /// The system file.
    pub system: PathBuf,
    /// Measure the loop at this connection ("instance.output -> instance.input"): L(jw),
    /// gain and phase margins, crossover, delay margin, sensitivity peak.
    #[arg(long = "break", value_name = "CONNECTION")]
    pub break_at: Option<String>,
    /// Inject into this input (or tunable parameter) for a frequency response or describing
    /// function; a connection "a.y -> b.u" injects on it.
    #[arg(long, conflicts_with = "break_at")]
    pub input: Option<String>,
    /// A response is measured at this variable (repeat for several).
    #[arg(long = "output", value_name = "INSTANCE.VARIABLE")]
    pub outputs: Vec<String>,
    /// Frequencies [rad/s]: "LO:HI:N" (N log-spaced) or "W1,W2,..." (default: 20 from 0.001
    /// to 0.3 times pi/h).
    #[arg(long)]
    pub frequencies: Option<String>,
    /// The sinusoid's amplitude, in the input's unit (default 0.01).
    #[arg(long)]
    pub amplitude: Option<f64>,
    /// A describing function over these amplitudes ("A1,A2,..." or "LO:HI:N"), at one
    /// frequency.
    #[arg(long, requires = "input", conflicts_with = "amplitude")]
    pub amplitudes: Option<String>,
    /// The operating point [s] (default: the start, after initialization).
    #[arg(long)]
    pub at: Option<f64>,
    /// Whole periods in each correlation window (more where a period is under 50 steps).
    #[arg(long, default_value_t = 4)]
    pub periods: u32,
    /// Settling time before the window [s] (default: 3 periods of each frequency).
    #[arg(long)]
    pub settle: Option<f64>,
    /// Skip the linearity check (each frequency measured again at twice the amplitude).
    #[arg(long)]
    pub no_linearity: bool,
    /// Set a parameter or start value, as `shipsim run --set`.
    #[arg(long = "set", value_name = "INSTANCE.VARIABLE=VALUE")]
    pub set: Vec<String>,
    /// Parallel forks (default: every core).
    #[arg(long, short)]
    pub jobs: Option<usize>,
    /// Folder of the tables and plots (default: <system name>_loop in the current folder).
    #[arg(long = "dir", short = 'o')]
    pub dir: Option<PathBuf>,
    /// Print one JSON object on one line on stdout.
    #[arg(long)]
    pub json: bool,
}

/// "LO:HI:N" log-spaced, or a comma-separated list.
fn parse_list(what: &str, spec: &str) -> Result<Vec<f64>> {
    let bad = || {
        Error::Other(format!(
            "--{what} \"{spec}\": give \"LO:HI:N\" (N log-spaced values) or \"X1,X2,...\""
        ))
    };
    let parts: Vec<&str> = spec.split(':').collect();
    if parts.len() == 3 {
        let lo: f64 = parts[0].trim().parse().map_err(|_| bad())?;
        let hi: f64 = parts[1].trim().parse().map_err(|_| bad())?;
        let n: usize = parts[2].trim().parse().map_err(|_| bad())?;
        if !(lo > 0.0 && hi > lo && n >= 1) {
            return Err(bad());
        }
        return Ok(analysis::log_space(lo, hi, n));
    }
    spec.split(',')
        .map(|x| x.trim().parse::<f64>().map_err(|_| bad()))
        .collect()
}

pub fn run(args: &LoopArgs, interrupt: Arc<AtomicBool>) -> Result<()> {
    let mut system = System::load(&args.system)?;
    system.apply_overrides(&args.set)?;
    let fmus = load_fmus(&system)?;
    let opts = Options {
        at: args.at,
        frequencies: args
            .frequencies
            .as_deref()
            .map(|f| parse_list("frequencies", f))
            .transpose()?,
        amplitude: args.amplitude.unwrap_or(0.01),
        periods: args.periods,
        settle: args.settle,
        linearity: !args.no_linearity,
        jobs: args.jobs,
        run: RunOptions {
            interrupt: Some(interrupt),
            ..Default::default()
        },
    };
    let stem = args
        .system
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "system".into());
    let dir = args
        .dir
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{stem}_loop")));
    let json = match (&args.break_at, &args.input) {
        (Some(c), _) => margins(&system, &fmus, c, &opts, &dir)?,
        (None, Some(input)) => {
            if args.outputs.is_empty() {
                return Err(Error::Other(
                    "--input needs one or more --output variables to measure".into(),
                ));
            }
            let injection = match input.contains("->") {
                true => Injection::Connection(input.clone()),
                false => Injection::Input(input.clone()),
            };
            match &args.amplitudes {
                Some(a) => describing(&system, &fmus, &injection, args, &opts, a, &dir)?,
                None => response(&system, &fmus, &injection, &args.outputs, &opts, &dir)?,
            }
        }
        (None, None) => {
            return Err(Error::Other(
                "give --break \"a.y -> b.u\" (margins) or --input X --output Y (a response)".into(),
            ))
        }
    };
    if args.json {
        println!("{json}");
    }
    Ok(())
}

fn opt(x: Option<f64>) -> serde_json::Value {
    x.map_or(serde_json::Value::Null, serde_json::Value::from)
}

fn margins(
    system: &System,
    fmus: &[Arc<shipsim::fmu::Fmu>],
    connection: &str,
    opts: &Options,
    dir: &std::path::Path,
) -> Result<serde_json::Value> {
    let (points, m) = analysis::loop_margins(system, fmus, connection, opts)?;
    let written = analysis::write_margins(dir, &points, &m, connection)?;
    let shown = |x: Option<f64>, unit: &str| {
        x.map_or("none in the range".into(), |v| format!("{v:.3} {unit}"))
    };
    eprintln!(
        "loop at {connection}: gain margin {} at {}, phase margin {} at crossover {}, delay margin {}, sensitivity peak {:.3} ({:.2} dB) at {:.4} rad/s; {} points",
        shown(m.gain_margin_db, "dB"),
        shown(m.gain_margin_rad_s, "rad/s"),
        shown(m.phase_margin_deg, "deg"),
        shown(m.crossover_rad_s, "rad/s"),
        shown(m.delay_margin_s, "s"),
        m.sensitivity_peak,
        20.0 * m.sensitivity_peak.log10(),
        m.sensitivity_peak_rad_s,
        points.len()
    );
    eprintln!(
        "wrote {}, {}",
        written.table.display(),
        written
            .plots
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    Ok(serde_json::json!({
        "connection": connection,
        "gain_margin_db": opt(m.gain_margin_db),
        "gain_margin_rad_s": opt(m.gain_margin_rad_s),
        "phase_margin_deg": opt(m.phase_margin_deg),
        "crossover_rad_s": opt(m.crossover_rad_s),
        "delay_margin_s": opt(m.delay_margin_s),
        "sensitivity_peak": m.sensitivity_peak,
        "sensitivity_peak_rad_s": m.sensitivity_peak_rad_s,
        "gain_crossovers": m.gain_crossovers.iter().map(|c| serde_json::json!({"omega_rad_s": c.omega, "phase_margin_deg": c.margin})).collect::<Vec<_>>(),
        "phase_crossovers": m.phase_crossovers.iter().map(|c| serde_json::json!({"omega_rad_s": c.omega, "gain_margin_db": c.margin})).collect::<Vec<_>>(),
        "points": points.len(),
        "table": written.table,
        "parquet": written.parquet,
        "plots": written.plots,
    }))
}

fn response(
    system: &System,
    fmus: &[Arc<shipsim::fmu::Fmu>],
    injection: &Injection,
    outputs: &[String],
    opts: &Options,
    dir: &std::path::Path,
) -> Result<serde_json::Value> {
    let points = analysis::frequency_response(system, fmus, injection, outputs, opts)?;
    let title = format!("response to {}", injection_name(injection));
    let written = analysis::write_response(dir, &points, &title)?;
    let rows: Vec<serde_json::Value> = points
        .iter()
        .flat_map(|p| {
            p.outputs.iter().map(move |o| {
                serde_json::json!({
                    "omega_rad_s": p.omega,
                    "output": o.name,
                    "gain_db": 20.0 * o.ratio.norm().log10(),
                    "phase_deg": o.ratio.arg().to_degrees(),
                    "re": o.ratio.re,
                    "im": o.ratio.im,
                    "distortion": o.distortion,
                    "gain_change_db": opt(o.gain_change_db),
                    "phase_change_deg": opt(o.phase_change_deg),
                })
            })
        })
        .collect();
    eprintln!(
        "{title}: {} frequencies, {} outputs; wrote {}",
        points.len(),
        outputs.len(),
        written.table.display()
    );
    Ok(serde_json::json!({
        "input": injection_name(injection),
        "table": written.table,
        "parquet": written.parquet,
        "plots": written.plots,
        "rows": rows,
    }))
}

fn injection_name(i: &Injection) -> &str {
    match i {
        Injection::Input(n) | Injection::Connection(n) => n,
    }
}

fn describing(
    system: &System,
    fmus: &[Arc<shipsim::fmu::Fmu>],
    injection: &Injection,
    args: &LoopArgs,
    opts: &Options,
    amplitudes: &str,
    dir: &std::path::Path,
) -> Result<serde_json::Value> {
    let amplitudes = parse_list("amplitudes", amplitudes)?;
    let omega = match opts.frequencies.as_deref() {
        Some([w]) => *w,
        _ => {
            return Err(Error::Other(
                "--amplitudes: give one frequency with --frequencies W".into(),
            ))
        }
    };
    let output = match args.outputs.as_slice() {
        [o] => o,
        _ => {
            return Err(Error::Other(
                "--amplitudes: give one --output variable".into(),
            ))
        }
    };
    let points =
        analysis::describing_function(system, fmus, injection, output, omega, &amplitudes, opts)?;
    let title = format!(
        "describing function {} -> {output}",
        injection_name(injection)
    );
    let written = analysis::write_describing(dir, &points, &title)?;
    let rows: Vec<serde_json::Value> = points
        .iter()
        .map(|p| {
            let o = &p.outputs[0];
            serde_json::json!({
                "amplitude": p.amplitude,
                "omega_rad_s": p.omega,
                "output": o.name,
                "gain": o.ratio.norm(),
                "gain_db": 20.0 * o.ratio.norm().log10(),
                "phase_deg": o.ratio.arg().to_degrees(),
                "re": o.ratio.re,
                "im": o.ratio.im,
                "distortion": o.distortion,
            })
        })
        .collect();
    eprintln!(
        "{title}: {} amplitudes; wrote {}",
        points.len(),
        written.table.display()
    );
    Ok(serde_json::json!({
        "input": injection_name(injection),
        "table": written.table,
        "parquet": written.parquet,
        "plots": written.plots,
        "rows": rows,
    }))
}
