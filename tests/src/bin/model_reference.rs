//! Prints the Rust model's response to a named reference input as CSV (round-trip float
//! formatting), so that tests/python can check that FMPy and libcosim, driving the FMU with the
//! same inputs, reproduce the Rust model to 1e-12.
//!
//! The time grid and the step sizes are computed as FMPy computes them
//! (t_k = t0 + k*h; step = t_{k+1} - t_k), so the comparison isolates the FMU wrapper.
//!
//! Usage: `model-reference <case>`; `model-reference --list` lists the cases.

use models::steering_gear::{SteeringGear, SteeringGearParams};
use std::io::Write;

/// The cases: name, description.
const CASES: [(&str, &str); 1] = [(
    "steering_gear_sine",
    "SteeringGear with default (003 RRS) parameters, rudder_command = 0.5 sin(0.8 t) rad, \
     h = 0.01 s, 30 s: both the angle limit (22 deg) and the rate limit (15 deg/s) engage",
)];

/// Columns: `time`; `rudder_command`, the input set at `time` and held until the next row;
/// the outputs at `time` as an importer samples them before setting that row's input (FMPy's
/// order: sample, apply input, step). Row 0 holds the outputs after initialization.
fn steering_gear_sine(out: &mut impl Write) -> std::io::Result<()> {
    let h = 0.01;
    let n = 3000;
    let command = |t: f64| 0.5 * (0.8 * t).sin();
    let mut gear = SteeringGear::new(SteeringGearParams::default(), 0.0).expect("valid preset");
    writeln!(
        out,
        "time,rudder_command,rudder_angle,rudder_rate,rate_saturated_time"
    )?;
    gear.set_command(command(0.0));
    for k in 0..=n {
        let t = k as f64 * h;
        let cmd = command(t);
        writeln!(
            out,
            "{t:?},{cmd:?},{:?},{:?},{:?}",
            gear.angle(),
            gear.rate(),
            gear.rate_saturated_time()
        )?;
        let next = (k + 1) as f64 * h;
        gear.step(cmd, next - t);
    }
    Ok(())
}

fn main() {
    match std::env::args().nth(1).as_deref() {
        Some("steering_gear_sine") => {
            let mut out = std::io::BufWriter::new(std::io::stdout().lock());
            if let Err(e) = steering_gear_sine(&mut out).and_then(|_| out.flush()) {
                eprintln!("model-reference: writing CSV: {e}");
                std::process::exit(1);
            }
        }
        Some("--list") => {
            for (name, desc) in CASES {
                println!("{name}: {desc}");
            }
        }
        other => {
            eprintln!(
                "model-reference: unknown case {other:?}; cases: {}",
                CASES.map(|c| c.0).join(", ")
            );
            std::process::exit(2);
        }
    }
}
