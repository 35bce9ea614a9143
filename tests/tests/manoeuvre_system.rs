//! Manoeuvre system test: the shipsim master runs the `Manoeuvre` FMU in a loop with the
//! `ContainerShip` FMU (systems/container_ship_turning_circle.toml) and the turning-circle metrics
//! of the recorded run equal those of the Rust-only loop (`models::manoeuvre::run` with the same
//! ship, generator and step), which the models tests check against the container-ship model of
//! Son & Nomoto (1982) as implemented in Fossen's MSS.
//!
//! Needs the release master (`cargo build --release -p shipsim`, or env SHIPSIM_BIN) and the
//! FMUs (`cargo xtask build-fmus`, or env SHIPSIM_FMU_DIR). Fails with a message saying which is
//! missing.

use models::hull::container_ship::{ContainerShip, L};
use models::hull::DEG;
use models::manoeuvre::{
    run, turning_circle, zigzag, ContainerShipRun, ManoeuvreGenerator, ManoeuvreKind,
    ManoeuvreShip, Sample, TurningCircleMetrics,
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
fn run_system(file: &str, algorithm: &str, extra: &[&str]) -> HashMap<String, Vec<f64>> {
    let text = std::fs::read_to_string(root().join("systems").join(file))
        .unwrap_or_else(|e| panic!("reading systems/{file}: {e}"));
    let fmus = fmu_dir();
    let text = text.replace("../target/fmu/", &format!("{}/", fmus.display()));
    static RUNS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = RUNS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!(
        "shipsim-manoeuvre-{}-{n}-{algorithm}",
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
        .args(extra)
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
        let c = run_system("container_ship_turning_circle.toml", algorithm, &[]);
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
        // The physics of the container ship (Son & Nomoto 1982; MSS example exRRD3): outward
        // steady heel and an inverse (non-minimum-phase) initial roll.
        assert!(f.steady_heel < 0.0, "outward heel in a starboard turn");
        assert!(f.initial_inward_heel > 0.0, "inverse initial roll");
    }
}

/// The 10/10 zig-zag through the master (the same system file with kind = 2, Jacobi). The
/// generator decides a rudder reversal from the heading it was given, which under Jacobi is the
/// heading of the previous communication point: each reversal comes one step (0.1 s) later than in
/// `models::manoeuvre::run`, which decides from the heading at the current point. The master run
/// must equal the Rust loop with exactly that exchange (written out below) to 1e-9, and the
/// effect of the delay on the metrics is printed (measured: first overshoot +0.057 deg, second
/// +0.105 deg, period +0.6 s at h = 0.1 s).
#[test]
fn container_ship_zigzag_through_the_master_is_the_rust_run_with_a_one_step_decision_delay() {
    let a = 10.0 * DEG;
    let h = 0.1;
    let n = 6000;
    let make = || ContainerShipRun {
        ship: ContainerShip::at_equilibrium(80.0).unwrap(),
        shaft_command_rpm: 80.0,
    };
    let gen = ManoeuvreGenerator::new(
        ManoeuvreKind::ZigZag {
            rudder: a,
            check: a,
        },
        10.0,
        0.0,
    );
    let undelayed = run(&mut make(), &mut gen.clone(), h, n as f64 * h);
    let m0 = zigzag(&undelayed, 10.0, 1.0, a).unwrap();
    // The Jacobi exchange: the command at t_k comes from the generator as committed at t_(k-1)
    // with the heading of t_(k-1); the commit at t_k sees the heading of t_k.
    let mut ship = make();
    let mut g = gen;
    let mut held = ship.sample();
    let mut jacobi = Vec::with_capacity(n + 1);
    for k in 0..=n {
        let t = k as f64 * h;
        let mut smp = ship.sample();
        let cmd = g.clone().command(t, held.psi, held.r);
        smp.rudder_command = cmd;
        jacobi.push(smp);
        if k == n {
            break;
        }
        g.command(t, smp.psi, smp.r);
        held = smp;
        ship.advance(cmd, h);
    }
    let m = zigzag(&jacobi, 10.0, 1.0, a).unwrap();

    let set = [
        "--stop-time",
        "600",
        "--set",
        "manoeuvre.kind=2",
        "--set",
        "manoeuvre.rudder_angle=0.17453292519943295",
        "--set",
        "manoeuvre.check_angle=0.17453292519943295",
    ];
    let c = run_system("container_ship_turning_circle.toml", "jacobi", &set);
    let s = samples(&c);
    assert_eq!(s.len(), jacobi.len());
    for (p, q) in s.iter().zip(&jacobi) {
        assert_eq!(p.rudder_command, q.rudder_command, "t = {}", p.t);
        assert!((p.psi - q.psi).abs() < 1e-9 && (p.x - q.x).abs() < 1e-9 * (1.0 + q.x.abs()));
    }
    let f = zigzag(&s, 10.0, 1.0, a).unwrap();
    println!(
        "10/10 zig-zag through shipsim (Jacobi): initial turning time {:.3} s, first overshoot \
         {:.4} deg, second overshoot {:.4} deg, period {:.2} s; the undelayed Rust loop: {:.3} s, \
         {:.4} deg, {:.4} deg, {:.2} s",
        f.initial_turning_time,
        f.first_overshoot / DEG,
        f.second_overshoot / DEG,
        f.period,
        m0.initial_turning_time,
        m0.first_overshoot / DEG,
        m0.second_overshoot / DEG,
        m0.period
    );
    for (name, x, y) in [
        (
            "initial_turning_time",
            f.initial_turning_time,
            m.initial_turning_time,
        ),
        ("first_overshoot", f.first_overshoot, m.first_overshoot),
        ("second_overshoot", f.second_overshoot, m.second_overshoot),
        (
            "first_overshoot_time",
            f.first_overshoot_time,
            m.first_overshoot_time,
        ),
        (
            "second_overshoot_time",
            f.second_overshoot_time,
            m.second_overshoot_time,
        ),
        ("period", f.period, m.period),
    ] {
        assert!(
            (x - y).abs() <= 1e-9 * (1.0 + y.abs()),
            "{name}: {x} vs {y}"
        );
    }
    // Before the first reversal the runs are the same; the reversal is exactly one step late.
    assert!((f.initial_turning_time - m0.initial_turning_time).abs() < 1e-9);
    let first_switch = |v: &[Sample]| v.iter().position(|p| p.rudder_command < 0.0).unwrap();
    assert_eq!(first_switch(&s), first_switch(&undelayed) + 1);
}
