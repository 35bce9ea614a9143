//! Manoeuvre system test: the shipsim master runs the `Manoeuvre` FMU in a loop with the
//! `ContainerShip` FMU (systems/container_ship_turning_circle.toml) and the turning-circle metrics
//! of the recorded run equal those of the Rust-only loop (`models::manoeuvre::run` with the same
//! ship, generator and step), which the models tests state and check against the spec.
//!
//! Needs the release master (`cargo build --release -p shipsim`, or env SHIPSIM_BIN) and the
//! FMUs (`cargo xtask build-fmus`, or env SHIPSIM_FMU_DIR). Fails with a message saying which is
//! missing.

use models::hull::container_ship::{ContainerShip, L};
use models::hull::DEG;
use models::manoeuvre::{
    run, turning_circle, ContainerShipRun, ManoeuvreGenerator, ManoeuvreKind, Sample,
    TurningCircleMetrics,
};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("workspace root")
        .to_path_buf()
}

fn shipsim() -> PathBuf {
    let p = std::env::var_os("SHIPSIM_BIN")
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("target/release/shipsim"));
    assert!(
        p.exists(),
        "{} is missing: run `cargo build --release -p shipsim` (or set SHIPSIM_BIN)",
        p.display()
    );
    p
}

fn fmu_dir() -> PathBuf {
    let d = std::env::var_os("SHIPSIM_FMU_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("target/fmu"));
    for f in ["ContainerShip.fmu", "Manoeuvre.fmu"] {
        assert!(
            d.join(f).exists(),
            "{} is missing: run `cargo xtask build-fmus` (or set SHIPSIM_FMU_DIR)",
            d.join(f).display()
        );
    }
    d
}

/// Runs a system file from systems/ with its FMU paths pointed at [`fmu_dir`], with the given
/// algorithm; returns the CSV columns by name.
fn run_system(file: &str, algorithm: &str) -> HashMap<String, Vec<f64>> {
    let text = std::fs::read_to_string(root().join("systems").join(file))
        .unwrap_or_else(|e| panic!("reading systems/{file}: {e}"));
    let fmus = fmu_dir();
    let text = text.replace("../target/fmu/", &format!("{}/", fmus.display()));
    let dir = std::env::temp_dir().join(format!(
        "shipsim-manoeuvre-{}-{algorithm}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    let sys = dir.join(file);
    std::fs::write(&sys, text).unwrap();
    let csv = dir.join("out.csv");
    let out = Command::new(shipsim())
        .arg("run")
        .arg(&sys)
        .arg("--output")
        .arg(&csv)
        .arg("--algorithm")
        .arg(algorithm)
        .arg("--quiet")
        .output()
        .expect("starting shipsim");
    assert!(
        out.status.success(),
        "shipsim failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let data = std::fs::read_to_string(&csv).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let mut lines = data.lines();
    let names: Vec<String> = lines
        .next()
        .expect("header")
        .split(',')
        .map(str::to_string)
        .collect();
    let mut cols: HashMap<String, Vec<f64>> = names.iter().map(|n| (n.clone(), vec![])).collect();
    for line in lines {
        for (n, v) in names.iter().zip(line.split(',')) {
            cols.get_mut(n)
                .unwrap()
                .push(v.parse().unwrap_or_else(|_| panic!("{n}: {v:?}")));
        }
    }
    cols
}

fn samples(c: &HashMap<String, Vec<f64>>) -> Vec<Sample> {
    let col = |n: &str| {
        c.get(n)
            .unwrap_or_else(|| panic!("column {n} missing from the shipsim output"))
    };
    (0..col("time").len())
        .map(|k| Sample {
            t: col("time")[k],
            x: col("ship.x")[k],
            y: col("ship.y")[k],
            psi: col("ship.heading")[k],
            r: col("ship.yaw_rate")[k],
            speed: col("ship.speed")[k],
            roll: col("ship.roll")[k],
            drift: col("ship.drift_angle")[k],
            rudder: col("ship.rudder_angle")[k],
            rudder_command: col("manoeuvre.rudder_command")[k],
        })
        .collect()
}

fn rust_only() -> (Vec<Sample>, TurningCircleMetrics) {
    let mut ship = ContainerShipRun {
        ship: ContainerShip::at_equilibrium(80.0).unwrap(),
        shaft_command_rpm: 80.0,
    };
    let mut g = ManoeuvreGenerator::new(
        ManoeuvreKind::TurningCircle { rudder: 35.0 * DEG },
        10.0,
        0.0,
    );
    let s = run(&mut ship, &mut g, 0.1, 1500.0);
    let m = turning_circle(&s, 10.0).unwrap();
    (s, m)
}

/// Relative agreement required of every length, speed and time metric, and absolute agreement
/// of the angles [rad]. The loops differ only in how the time grid is accumulated (the master's
/// t_k = k h and step t_(k+1) - t_k against the Rust loop's repeated h), i.e. by round-off.
/// Measured: the trajectories are bit-identical under both algorithms (the command depends on
/// time only, so the co-simulation loop delay does not enter).
const REL: f64 = 1e-9;
const ABS_ANGLE: f64 = 1e-9;

#[test]
fn container_ship_turning_circle_through_the_master_matches_the_rust_run() {
    let (rust, m) = rust_only();
    for algorithm in ["jacobi", "gauss-seidel"] {
        let c = run_system("container_ship_turning_circle.toml", algorithm);
        let s = samples(&c);
        assert_eq!(s.len(), rust.len(), "{algorithm}: one row per 0.1 s step");
        // The command sequence is the Rust loop's, sample for sample (the master records the
        // command produced at each communication point, which the ship held over the next step).
        for (a, b) in s.iter().zip(&rust) {
            assert_eq!(
                a.rudder_command, b.rudder_command,
                "{algorithm} at t = {}",
                a.t
            );
        }
        let f = turning_circle(&s, 10.0).unwrap();
        let worst = s
            .iter()
            .zip(&rust)
            .map(|(a, b)| ((a.x - b.x).hypot(a.y - b.y), (a.roll - b.roll).abs()))
            .fold((0.0f64, 0.0f64), |m, d| (m.0.max(d.0), m.1.max(d.1)));
        println!(
            "{algorithm}: largest deviation from the Rust run over 1500 s: position {:.3e} m, \
             roll {:.3e} rad",
            worst.0, worst.1
        );
        println!(
            "{algorithm}: advance {:.3} m ({:.3} L), transfer {:.3} m, tactical diameter {:.3} m \
             ({:.3} L), steady diameter {:.3} m, speed loss {:.4} %, steady heel {:.4} deg",
            f.advance,
            f.advance / L,
            f.transfer,
            f.tactical_diameter,
            f.tactical_diameter / L,
            f.steady_diameter,
            100.0 * f.speed_loss,
            f.steady_heel / DEG
        );
        for (name, a, b) in [
            ("advance", f.advance, m.advance),
            ("transfer", f.transfer, m.transfer),
            (
                "tactical_diameter",
                f.tactical_diameter,
                m.tactical_diameter,
            ),
            ("steady_diameter", f.steady_diameter, m.steady_diameter),
            ("steady_speed", f.steady_speed, m.steady_speed),
            ("time_to_90", f.time_to_90, m.time_to_90),
            ("time_to_180", f.time_to_180, m.time_to_180),
        ] {
            assert!(
                (a - b).abs() <= REL * b.abs(),
                "{algorithm}: {name} {a} (shipsim) vs {b} (Rust)"
            );
        }
        for (name, a, b) in [
            ("speed_loss", f.speed_loss, m.speed_loss),
            ("steady_heel", f.steady_heel, m.steady_heel),
            ("peak_heel", f.peak_heel, m.peak_heel),
            (
                "initial_inward_heel",
                f.initial_inward_heel,
                m.initial_inward_heel,
            ),
            ("steady_drift", f.steady_drift, m.steady_drift),
        ] {
            assert!(
                (a - b).abs() <= ABS_ANGLE,
                "{algorithm}: {name} {a} (shipsim) vs {b} (Rust)"
            );
        }
        // Physics the spec states (container_ship.md sections 1 and 5.4).
        assert!(f.steady_heel < 0.0, "outward heel in a starboard turn");
        assert!(f.initial_inward_heel > 0.0, "inverse initial roll");
    }
}
