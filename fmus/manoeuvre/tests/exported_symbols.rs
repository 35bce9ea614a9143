//! Calls the `fmi2*` symbols that `export_fmu!` emitted for Manoeuvre (linked from this crate's
//! rlib), as a C importer would, and checks them against the generator bit for bit, and a
//! closed loop with the container ship against `models::manoeuvre::run`.

use fmi2::*;
use fmi2_export::FmuModel;
use manoeuvre_fmu::ManoeuvreFmu as Fmu;
use models::hull::container_ship::ContainerShip;
use models::hull::DEG;
use models::manoeuvre::{run, ContainerShipRun, ManoeuvreGenerator, ManoeuvreKind, ManoeuvreShip};
use std::ffi::CString;
use std::ptr::null;

fmi2::declare_fmi2_functions!();

fn vr(name: &str) -> u32 {
    Fmu::variables()
        .iter()
        .position(|v| v.name == name)
        .unwrap_or_else(|| panic!("no variable {name}")) as u32
}

unsafe fn instantiate() -> fmi2Component {
    let guid = CString::new(fmi2_export::xml::guid::<Fmu>()).unwrap();
    let name = CString::new("ship").unwrap();
    let cb = fmi2CallbackFunctions {
        logger: None,
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: std::ptr::null_mut(),
    };
    let c = fmi2Instantiate(
        name.as_ptr(),
        fmi2CoSimulation,
        guid.as_ptr(),
        null(),
        &cb,
        0,
        0,
    );
    assert!(!c.is_null());
    assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), fmi2OK);
    assert_eq!(fmi2EnterInitializationMode(c), fmi2OK);
    c
}

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
        unsafe {
            let c = instantiate();
            assert_eq!(fmi2SetInteger(c, &vr("kind"), 1, &kind), fmi2OK);
            assert_eq!(fmi2SetReal(c, &vr("rudder_angle"), 1, &a), fmi2OK);
            if kind == 2 {
                assert_eq!(fmi2SetReal(c, &vr("check_angle"), 1, &b), fmi2OK);
            }
            assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
            let mut ship = make();
            let ins = [vr("heading"), vr("yaw_rate")];
            for (k, expected) in rust.iter().enumerate().take(n) {
                let t = k as f64 * h;
                let s = ship.sample();
                assert_eq!(
                    fmi2SetReal(c, ins.as_ptr(), 2, [s.psi, s.r].as_ptr()),
                    fmi2OK
                );
                let mut cmd = 0.0;
                assert_eq!(fmi2GetReal(c, &vr("rudder_command"), 1, &mut cmd), fmi2OK);
                assert_eq!(cmd, expected.rudder_command, "kind {kind} step {k}");
                assert_eq!(fmi2DoStep(c, t, h, 1), fmi2OK);
                ship.advance(cmd, h);
            }
            assert_eq!(ship.sample(), {
                let mut last = rust[n];
                last.rudder_command = 0.0;
                last
            });
            assert_eq!(fmi2Terminate(c), fmi2OK);
            fmi2FreeInstance(c);
        }
        if kind == 2 {
            assert!(
                rust.iter().any(|s| s.rudder_command < 0.0),
                "zig-zag switched"
            );
        }
    }
}

#[test]
fn variable_table_passes_the_layer_checks() {
    fmi2_export::variables::check_table(Fmu::variables()).unwrap();
}
