//! Runs the pure-Rust RRS model loop (`system_tests::model_loop::rrs`): `systems/rrs.toml`
//! directly on the `models` crate, no FMI. Prints one JSON line
//! `{"stop_time":..,"macro_steps":..,"wall_s":..}` (wall_s: the step loop only, as the
//! "step loop" wall time of `shipsim run`).
//!
//! Usage: `rrs-model-loop [--stop-time S] [--csv FILE] [--roll-mode 0|1|2] [--seed N]
//! [--wave-direction RAD]`. Without `--csv` nothing is recorded; with it the recorded columns
//! of the system file are written as `shipsim run` writes them.

use models::controllers::rrs::RollMode;
use std::io::BufWriter;
use std::path::PathBuf;
use system_tests::model_loop::rrs::{run, RrsParams, COLUMNS, STOP_TIME};
use system_tests::model_loop::{CsvWriter, LoopSummary};

const USAGE: &str = "usage: rrs-model-loop [--stop-time S] [--csv FILE] [--roll-mode 0|1|2] \
                     [--seed N] [--wave-direction RAD]";

struct Args {
    stop_time: f64,
    csv: Option<PathBuf>,
    params: RrsParams,
}

fn parse_args() -> Result<Args, String> {
    let mut a = Args {
        stop_time: STOP_TIME,
        csv: None,
        params: RrsParams::default(),
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let mut value = || it.next().ok_or(format!("{flag} needs a value"));
        let bad = |v: &str| format!("{flag} {v}: not a valid value");
        match flag.as_str() {
            "--stop-time" => {
                let v = value()?;
                a.stop_time = v.parse().map_err(|_| bad(&v))?;
            }
            "--csv" => a.csv = Some(PathBuf::from(value()?)),
            "--roll-mode" => {
                let v = value()?;
                a.params.roll_mode = match v.as_str() {
                    "0" => RollMode::Off,
                    "1" => RollMode::On,
                    "2" => RollMode::Forced,
                    _ => return Err(bad(&v)),
                };
            }
            "--seed" => {
                let v = value()?;
                a.params.waves_seed = v.parse().map_err(|_| bad(&v))?;
            }
            "--wave-direction" => {
                let v = value()?;
                a.params.wave_direction = v.parse().map_err(|_| bad(&v))?;
            }
            "-h" | "--help" => {
                println!("{USAGE}");
                std::process::exit(0);
            }
            _ => return Err(format!("unknown argument {flag}\n{USAGE}")),
        }
    }
    Ok(a)
}

fn run_loop(a: &Args) -> Result<LoopSummary, String> {
    let Some(path) = &a.csv else {
        return run(a.stop_time, &a.params, |_, _| {});
    };
    let file = std::fs::File::create(path)
        .map_err(|e| format!("cannot create {}: {e}", path.display()))?;
    let out = BufWriter::with_capacity(1 << 16, file);
    let write_error = |e: std::io::Error| format!("writing {}: {e}", path.display());
    let mut csv = CsvWriter::new(out, &COLUMNS).map_err(write_error)?;
    let summary = run(a.stop_time, &a.params, |t, v| csv.row(t, &v.recorded()))?;
    csv.finish().map_err(write_error)?;
    Ok(summary)
}

fn main() {
    let result = parse_args().and_then(|a| run_loop(&a));
    match result {
        Ok(s) => println!(
            "{{\"stop_time\":{},\"macro_steps\":{},\"wall_s\":{}}}",
            s.stop_time,
            s.macro_steps,
            s.wall.as_secs_f64()
        ),
        Err(e) => {
            eprintln!("rrs-model-loop: {e}");
            std::process::exit(1);
        }
    }
}
