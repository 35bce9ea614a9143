//! Manoeuvre reference cases (models::manoeuvre::ManoeuvreGenerator).
//!
//! The output `rudder_command` is a direct-feedthrough output: an importer samples it at t_k
//! after the step to t_k, before setting the inputs of row k, so row k (k >= 1) holds the command
//! at t_k for the inputs of row k - 1, evaluated on the generator as committed by the steps so
//! far; row 0 holds it for the inputs of row 0 (set before initialization ends).

use models::hull::DEG;
use models::manoeuvre::{ManoeuvreGenerator, ManoeuvreKind};
use std::io::Write;

fn case(
    out: &mut dyn Write,
    mut g: ManoeuvreGenerator,
    h: f64,
    n: usize,
    input: impl Fn(f64) -> (f64, f64),
) -> std::io::Result<()> {
    writeln!(out, "time,heading,yaw_rate,rudder_command")?;
    let mut held = input(0.0);
    let mut now = 0.0;
    for k in 0..=n {
        let t = k as f64 * h;
        let (psi, r) = input(t);
        let sampled = g.clone().command(now, held.0, held.1);
        writeln!(out, "{t:?},{psi:?},{r:?},{sampled:?}")?;
        let next = (k + 1) as f64 * h;
        g.command(t, psi, r);
        now = t + (next - t);
        held = (psi, r);
    }
    Ok(())
}

/// Zig-zag 10/10 executed at 10 s, heading = 0.3 sin(0.05 (t - 10)) after execute;
/// h = 0.1 s, 300 s.
pub fn zigzag(out: &mut dyn Write) -> std::io::Result<()> {
    let g = ManoeuvreGenerator::new(
        ManoeuvreKind::ZigZag {
            rudder: 10.0 * DEG,
            check: 10.0 * DEG,
        },
        10.0,
        0.0,
    );
    case(out, g, 0.1, 3000, |t| {
        if t > 10.0 {
            let s = 0.05 * (t - 10.0);
            (0.3 * s.sin(), 0.015 * s.cos())
        } else {
            (0.0, 0.0)
        }
    })
}

/// Pull-out with 20 deg for 60 s from 10 s, heading = 0.01 t; h = 0.5 s, 200 s.
pub fn pull_out(out: &mut dyn Write) -> std::io::Result<()> {
    let g = ManoeuvreGenerator::new(
        ManoeuvreKind::PullOut {
            rudder: 20.0 * DEG,
            hold: 60.0,
        },
        10.0,
        0.0,
    );
    case(out, g, 0.5, 400, |t| (0.01 * t, 0.01))
}
