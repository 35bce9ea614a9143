//! The loop analysis (`shipsim::analysis`, `shipsim loop`) on our FMUs ($SHIPSIM_FMU_DIR):
//! the FirstOrderLag example against the exact response of the lag behind a zero-order hold,
//! the steering gear's rate limit against its describing function [Klugt1987, sec. 5.2.2],
//! the margins of the DDG-51 heading loop repeatable and refined to the crossings, and the
//! command line's JSON and errors.
//!
//! Tolerances: 1e-6 relative for the lag (measured ~1e-15: an exact model behind an exact
//! hold); 1 % and 0.5 deg for the describing function (the limiter is followed by a 1 ms
//! servo lag and the step's zero-order hold, 0.18 deg at 0.63 rad/s for h = 0.01 s).
mod common;
use common::*;
use num_complex::Complex64;
use shipsim::analysis::{self, Injection, Options};
use shipsim::run::load_fmus;
use shipsim::system::{Algorithm, System};
use std::path::{Path, PathBuf};

fn example_fmu(name: &str) -> PathBuf {
    let p = fmu_dir()
        .join("../fmu-examples")
        .join(format!("{name}.fmu"));
    assert!(
        p.is_file(),
        "{} is missing: run `cargo xtask build-fmus`",
        p.display()
    );
    p
}

fn system(dir: &Path, text: &str) -> System {
    System::load(&write_system(dir, "sys.toml", text)).unwrap()
}

#[test]
fn the_lag_is_the_exact_sampled_response() {
    let dir = tempfile::tempdir().unwrap();
    let (h, k, t): (f64, f64, f64) = (0.1, 1.5, 2.0);
    let sys = system(
        dir.path(),
        &format!(
            "[simulation]\nstop_time = 1.0\nstep_size = {h}\n[[instances]]\nname = \"lag\"\n\
             fmu = \"{}\"\nparameters = {{ gain = {k}, time_constant = {t} }}\n",
            example_fmu("FirstOrderLag").display()
        ),
    );
    let fmus = load_fmus(&sys).unwrap();
    let opts = Options {
        frequencies: Some(analysis::log_space(0.02, 20.0, 10)),
        settle: Some(80.0),
        ..Default::default()
    };
    let input = Injection::Input("lag.u".into());
    let points =
        analysis::frequency_response(&sys, &fmus, &input, &["lag.y".into()], &opts).unwrap();
    assert_eq!(points.len(), 10);
    let a = (-h / t).exp();
    for p in &points {
        let z = Complex64::from_polar(1.0, p.omega * h);
        let exact = (1.0 - a) * k / (z - a);
        let got = p.outputs[0].ratio;
        assert!(
            (got - exact).norm() / exact.norm() < 1e-6,
            "{} rad/s: {got} vs {exact}",
            p.omega
        );
        assert_eq!(
            p.outputs[0].gain_change_db,
            Some(0.0),
            "linear: exact at twice the amplitude"
        );
        assert!(p.outputs[0].distortion < 1e-9);
    }
}

#[test]
fn the_rate_limit_has_its_describing_function() {
    let dir = tempfile::tempdir().unwrap();
    let rate = 15f64.to_radians();
    let sys = system(
        dir.path(),
        &format!(
            "[simulation]\nstop_time = 1.0\nstep_size = 0.01\n[[instances]]\nname = \"gear\"\n\
             fmu = \"{}\"\nparameters = {{ rate_max = {rate}, angle_max = 3.0, time_constant = 0.001 }}\n",
            our_fmu("SteeringGear").display()
        ),
    );
    let fmus = load_fmus(&sys).unwrap();
    let b = 0.63;
    let a = 3.0 * rate / b;
    let opts = Options {
        periods: 10,
        ..Default::default()
    };
    let input = Injection::Input("gear.rudder_command".into());
    let points = analysis::describing_function(
        &sys,
        &fmus,
        &input,
        "gear.rudder_angle",
        b,
        &[0.1 * a, a],
        &opts,
    )
    .unwrap();
    // Below the limit the gear follows (gain 1, the servo's small lag) ...
    let small = points[0].outputs[0].ratio;
    assert!((small.norm() - 1.0).abs() < 1e-3, "{small}");
    // ... at a*b = 3 rate: the triangle wave's fundamental, 0.4244 a, 58.4 deg behind.
    let n = points[1].outputs[0].ratio;
    assert!((n.norm() - 0.4244).abs() < 0.01 * 0.4244, "{}", n.norm());
    assert!(
        (-n.arg().to_degrees() - 58.4).abs() < 0.5,
        "{}",
        n.arg().to_degrees()
    );
    assert!(
        points[1].outputs[0].distortion > 0.05,
        "a triangle has harmonics"
    );
}

/// The DDG-51 heading loop of systems/autopilot_current.toml, noiseless.
fn heading_loop() -> (System, Vec<std::sync::Arc<shipsim::fmu::Fmu>>) {
    // The file's own stop time and algorithm (400 s, Jacobi).
    let mut sys = our_system("autopilot_current.toml", 400.0, Algorithm::Jacobi);
    sys.apply_overrides(&["sensors.noise_scale=0".into()])
        .unwrap();
    let fmus = load_fmus(&sys).unwrap();
    (sys, fmus)
}

#[test]
fn heading_loop_margins_are_refined_to_the_crossings_and_repeatable() {
    let (sys, fmus) = heading_loop();
    let opts = Options::default();
    let c = "ap.rudder_command -> gear.rudder_command";
    let (points, m) = analysis::loop_margins(&sys, &fmus, c, &opts).unwrap();
    let near = |w: f64| points.iter().find(|p| (p.omega - w).abs() < 1e-12).unwrap();
    // The crossings are measured points (|L| = 1 within 0.01 dB, phase -180 within 0.05 deg).
    let wc = points
        .iter()
        .min_by(|a, b| (a.l.norm().ln().abs()).total_cmp(&b.l.norm().ln().abs()))
        .unwrap();
    assert!((20.0 * wc.l.norm().log10()).abs() < 0.01, "{wc:?}");
    assert!((wc.omega / m.crossover_rad_s.unwrap() - 1.0).abs() < 1e-3);
    let _ = near(wc.omega);
    assert!(
        m.phase_margin_deg.unwrap() > 30.0 && m.gain_margin_db.unwrap() > 10.0,
        "{m:?}"
    );
    // A second analysis gives the same bits: every fork starts from the same state.
    let (again, m2) = analysis::loop_margins(&sys, &fmus, c, &opts).unwrap();
    assert_eq!(m, m2);
    assert_eq!(points.len(), again.len());
    // From a later operating point (a checkpoint at 100 s) the loop is the same LTI loop.
    let later = Options {
        at: Some(100.0),
        ..Default::default()
    };
    let (_, m3) = analysis::loop_margins(&sys, &fmus, c, &later).unwrap();
    assert!(
        (m3.phase_margin_deg.unwrap() - m.phase_margin_deg.unwrap()).abs() < 0.5,
        "{m3:?}"
    );
}

#[test]
fn the_command_line_prints_json_and_names_what_is_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let sysfile = Path::new(env!("CARGO_MANIFEST_DIR")).join("../systems/autopilot_current.toml");
    let text = std::fs::read_to_string(&sysfile).unwrap().replace(
        "../target/fmu/",
        &format!("{}/", our_fmu("NomotoShip").parent().unwrap().display()),
    );
    let sys = write_system(dir.path(), "heading.toml", &text);
    let run = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_shipsim"))
            .arg("loop")
            .arg(&sys)
            .args(args)
            .current_dir(dir.path())
            .output()
            .unwrap()
    };
    let out = run(&[
        "--break",
        "ap.rudder_command->gear.rudder_command",
        "--set",
        "sensors.noise_scale=0",
        "--json",
        "--no-linearity",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert_eq!(stdout.lines().count(), 1, "{stdout}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    for key in [
        "gain_margin_db",
        "phase_margin_deg",
        "crossover_rad_s",
        "delay_margin_s",
        "sensitivity_peak",
    ] {
        assert!(v[key].as_f64().is_some(), "{key}: {v}");
    }
    let table = dir.path().join(v["table"].as_str().unwrap());
    assert!(table.is_file() && dir.path().join("heading_loop/bode.png").is_file());
    assert!(dir.path().join("heading_loop/nyquist.png").is_file());
    assert!(dir.path().join("heading_loop/loop.parquet").is_file());
    for (args, expected) in [
        (
            vec!["--break", "ap.rudder_comand -> gear.rudder_command"],
            "no such connection",
        ),
        (vec!["--break", "ap.rudder_command"], "give a connection as"),
        (
            vec![
                "--break",
                "ap.rudder_command -> gear.rudder_command",
                "--at",
                "0.01",
            ],
            "communication point",
        ),
        (
            vec![
                "--break",
                "ap.rudder_command -> gear.rudder_command",
                "--frequencies",
                "100",
            ],
            "Nyquist",
        ),
        (vec!["--input", "gear.rudder_command"], "--output"),
        (
            vec![
                "--input",
                "ship.k_prime",
                "--output",
                "ship.heading",
                "--frequencies",
                "0.1",
            ],
            "only inputs and tunable parameters",
        ),
        (
            vec![
                "--input",
                "gear.rudder_command",
                "--output",
                "gear.rudder_angel",
            ],
            "did you mean",
        ),
    ] {
        let out = run(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && err.contains(expected),
            "{args:?}: {err}"
        );
    }
}
