//! Manoeuvre through the `fmi2*` symbols its crate exports, as a C importer calls them: the
//! checks every FMU runs, and a closed loop with the container ship against
//! `models::manoeuvre::run`, bit for bit, by variable name.

use fmi2_export::fmi2::fmi2OK;
use models::hull::container_ship::ContainerShip;
use models::hull::DEG;
use models::manoeuvre::{run, ContainerShipRun, ManoeuvreGenerator, ManoeuvreKind, ManoeuvreShip};

fmi2_export::fmu_tests!(manoeuvre_fmu::ManoeuvreFmu);

/// The FMU in a closed loop with the Rust container ship, sampling the command after setting the
/// heading of the current time (as a Gauss-Seidel master with the ship first would), reproduces
/// `models::manoeuvre::run` exactly, for a turning circle and a zig-zag.
#[test]
fn closed_loop_reproduces_the_rust_manoeuvre_run() {
    for (kind, a, b) in [(1, 35.0 * DEG, 0.0), (2, 10.0 * DEG, 10.0 * DEG)] {
        let h = 0.1;
        let n = 3000;
        let make = || ContainerShipRun {
            ship: ContainerShip::at_equilibrium(80.0).unwrap(),
            shaft_command_rpm: 80.0,
        };
        let mut g = ManoeuvreGenerator::new(
            if kind == 1 {
                ManoeuvreKind::TurningCircle { rudder: a }
            } else {
                ManoeuvreKind::ZigZag {
                    rudder: a,
                    check: b,
                }
            },
            10.0,
            0.0,
        );
        let rust = run(&mut make(), &mut g, h, n as f64 * h);
        let mut fmu = fmu();
        assert_eq!(fmu.setup(0.0, None), fmi2OK);
        assert_eq!(fmu.enter_initialization(), fmi2OK);
        fmu.set("kind", kind).set("rudder_angle", a);
        if kind == 2 {
            fmu.set("check_angle", b);
        }
        assert_eq!(fmu.exit_initialization(), fmi2OK);
        let mut ship = make();
        for (k, expected) in rust.iter().enumerate().take(n) {
            let t = k as f64 * h;
            let s = ship.sample();
            fmu.set("heading", s.psi).set("yaw_rate", s.r);
            let cmd = fmu.real("rudder_command");
            assert_eq!(cmd, expected.rudder_command, "kind {kind} step {k}");
            fmu.step(t, h);
            ship.advance(cmd, h);
        }
        assert_eq!(ship.sample(), {
            let mut last = rust[n];
            last.rudder_command = 0.0;
            last
        });
        assert_eq!(fmu.terminate(), fmi2OK);
        if kind == 2 {
            assert!(
                rust.iter().any(|s| s.rudder_command < 0.0),
                "zig-zag switched"
            );
        }
    }
}
