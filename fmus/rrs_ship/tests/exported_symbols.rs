//! Calls the `fmi2*` symbols that `export_fmu!` emitted for RrsShip (linked from this crate's
//! rlib), as a C importer would, and checks them against the model bit for bit.

use fmi2::*;
use fmi2_export::FmuModel;
use models::hull::rrs_ship::{RrsShip, RrsShipInputs, RrsShipOutputs};
use rrs_ship_fmu::RrsShipFmu as Fmu;
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

const OUTPUTS: [&str; 11] = [
    "roll",
    "roll_rate",
    "sway",
    "yaw_rate",
    "heading",
    "heading_wrapped",
    "x",
    "y",
    "wave_sway",
    "wave_yaw",
    "wave_roll",
];

fn expected(o: &RrsShipOutputs) -> [f64; 11] {
    [
        o.roll,
        o.roll_rate,
        o.sway,
        o.yaw_rate,
        o.heading,
        o.heading_wrapped,
        o.x,
        o.y,
        o.wave_sway,
        o.wave_yaw,
        o.wave_roll,
    ]
}

unsafe fn check(model_preset: i32, mut model: RrsShip, h: f64) {
    let c = instantiate();
    assert_eq!(fmi2SetInteger(c, &vr("model"), 1, &model_preset), fmi2OK);
    assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
    let ins: Vec<u32> = [
        "rudder_angle",
        "speed",
        "roll_disturbance",
        "yaw_disturbance",
        "wave_elevation",
    ]
    .iter()
    .map(|n| vr(n))
    .collect();
    let outs: Vec<u32> = OUTPUTS.iter().map(|n| vr(n)).collect();
    for k in 0..1000 {
        let t = k as f64 * h;
        let u = [
            0.1 * (0.3 * t).sin(),
            6.0 + 0.05 * t,
            0.01 * (0.2 * t).sin(),
            0.005 * (0.1 * t).cos(),
            0.5 * (0.64 * t).sin(),
        ];
        assert_eq!(fmi2SetReal(c, ins.as_ptr(), 5, u.as_ptr()), fmi2OK);
        assert_eq!(fmi2DoStep(c, t, h, 1), fmi2OK);
        model.step(
            &RrsShipInputs {
                rudder: u[0],
                speed: u[1],
                roll_disturbance: u[2],
                yaw_disturbance: u[3],
                wave_elevation: u[4],
            },
            h,
        );
        let mut v = [0.0; 11];
        assert_eq!(fmi2GetReal(c, outs.as_ptr(), 11, v.as_mut_ptr()), fmi2OK);
        assert_eq!(
            v,
            expected(&model.outputs()),
            "model {model_preset} step {k}"
        );
    }
    assert!(model.outputs().roll.abs() > 1e-4);
    assert_eq!(fmi2Terminate(c), fmi2OK);
    fmi2FreeInstance(c);
}

#[test]
fn exported_api_reproduces_the_three_models() {
    unsafe {
        check(1, RrsShip::simulation_22kn(), 0.1);
        check(2, RrsShip::control_model(), 0.05);
        check(3, RrsShip::control_model_table_2_5(), 0.2);
    }
}

#[test]
fn variable_table_passes_the_layer_checks() {
    fmi2_export::variables::check_table(Fmu::variables()).unwrap();
}

/// The second (wind) disturbance channel adds to the first: w_phi = 0.01 + 0.02 through both
/// inputs gives bit-for-bit the same motion as 0.03 through roll_disturbance alone (and
/// likewise for yaw).
#[test]
fn wind_disturbance_inputs_add_to_the_first_channel() {
    unsafe fn run(split: bool) -> Vec<f64> {
        let c = instantiate();
        let model = 2;
        assert_eq!(fmi2SetInteger(c, &vr("model"), 1, &model), fmi2OK);
        assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
        let (names, values): (Vec<&str>, Vec<f64>) = if split {
            (
                vec![
                    "roll_disturbance",
                    "wind_roll_disturbance",
                    "yaw_disturbance",
                    "wind_yaw_disturbance",
                ],
                vec![0.01, 0.02, 0.001, 0.002],
            )
        } else {
            (
                vec!["roll_disturbance", "yaw_disturbance"],
                vec![0.03, 0.003],
            )
        };
        let vrs: Vec<u32> = names.iter().map(|n| vr(n)).collect();
        assert_eq!(
            fmi2SetReal(c, vrs.as_ptr(), vrs.len(), values.as_ptr()),
            fmi2OK
        );
        for k in 0..200 {
            assert_eq!(fmi2DoStep(c, k as f64 * 0.1, 0.1, 1), fmi2OK);
        }
        let outs: Vec<u32> = OUTPUTS.iter().map(|n| vr(n)).collect();
        let mut v = vec![0.0; outs.len()];
        assert_eq!(
            fmi2GetReal(c, outs.as_ptr(), outs.len(), v.as_mut_ptr()),
            fmi2OK
        );
        assert_eq!(fmi2Terminate(c), fmi2OK);
        fmi2FreeInstance(c);
        v
    }
    let (a, b) = unsafe { (run(true), run(false)) };
    assert!(a[0].abs() > 1e-3, "the disturbance rolls the ship");
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() <= 1e-15 * y.abs().max(1.0), "{x} vs {y}");
    }
}
