//! Our own FMUs (from `cargo xtask build-fmus`, $SHIPSIM_FMU_DIR) run coupled in the master.
//! Fails, never skips, when they have not been built.
mod common;
use common::*;
use shipsim::run::{run_system, Output, RunOptions};
use shipsim::system::System;

#[test]
fn steering_gears_coupled_with_events_under_both_algorithms() {
    let d = tempfile::tempdir().unwrap();
    std::fs::copy(our_fmu("SteeringGear"), d.path().join("SteeringGear.fmu")).unwrap();
    for algo in ["jacobi", "gauss-seidel"] {
        let p = write_system(
            d.path(),
            "gears.toml",
            &format!(
                r#"
connections = ["first.rudder_angle -> second.rudder_command"]
[simulation]
stop_time = 40.0
step_size = 0.01
algorithm = "{algo}"
[[instances]]
name = "first"
fmu = "SteeringGear.fmu"
parameters = {{ rudder_command = 0.2 }}
[[instances]]
name = "second"
fmu = "SteeringGear.fmu"
step_multiple = 5
[[events]]
time = 20.0
set = "first.rudder_command"
value = -0.3
[output]
variables = ["first.rudder_angle", "first.rudder_rate", "second.rudder_angle"]
decimation = 10
"#
            ),
        );
        let out = d.path().join(format!("{algo}.csv"));
        let (_, s) = run_system(
            &System::load(&p).unwrap(),
            Output::File(out.clone()),
            &RunOptions::default(),
        )
        .unwrap();
        assert_eq!(s.macro_steps, 4000);
        assert_eq!(s.fmu_steps, 4000 + 800);
        let (h, rows) = read_csv(&out);
        assert_eq!(rows.len(), 401);
        let at = |t: f64, c: &str| rows[(t * 10.0).round() as usize][col(&h, c)];
        // Both gears settle on the command, then follow the event's new command.
        assert!(
            (at(19.9, "first.rudder_angle") - 0.2).abs() < 1e-6,
            "{algo}"
        );
        assert!(
            (at(19.9, "second.rudder_angle") - 0.2).abs() < 1e-4,
            "{algo}"
        );
        assert!(
            (at(40.0, "first.rudder_angle") + 0.3).abs() < 1e-6,
            "{algo}"
        );
        assert!(
            (at(40.0, "second.rudder_angle") + 0.3).abs() < 1e-4,
            "{algo}"
        );
        // The rate limit (15 deg/s default) holds through the coupling.
        let rmax = rows
            .iter()
            .map(|r| r[col(&h, "first.rudder_rate")].abs())
            .fold(0.0, f64::max);
        assert!(
            rmax <= 15f64.to_radians() + 1e-9 && rmax > 0.1,
            "{algo}: {rmax}"
        );
    }
}
