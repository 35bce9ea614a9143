//! Calls the `fmi2*` symbols that `export_fmu!` emitted for NomotoShip (linked from this crate's
//! rlib), as a C importer would, and checks them against the model bit for bit.

use fmi2::*;
use fmi2_export::FmuModel;
use models::hull::nomoto::{NomotoInputs, NomotoOutputs, NomotoShip};
use nomoto_ship_fmu::NomotoShipFmu as Fmu;
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

const OUTPUTS: [&str; 10] = [
    "sway_velocity",
    "sway_velocity_prime",
    "yaw_rate",
    "yaw_rate_prime",
    "heading",
    "heading_wrapped",
    "x",
    "y",
    "speed_over_ground",
    "time_prime",
];

fn expected(o: &NomotoOutputs) -> [f64; 10] {
    [
        o.sway_velocity,
        o.v_prime,
        o.yaw_rate,
        o.r_prime,
        o.heading,
        o.heading_wrapped,
        o.x,
        o.y,
        o.speed_over_ground,
        o.time_prime,
    ]
}

unsafe fn check(model_preset: i32, mut model: NomotoShip, h: f64) {
    let c = instantiate();
    assert_eq!(fmi2SetInteger(c, &vr("model"), 1, &model_preset), fmi2OK);
    assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
    let ins: Vec<u32> = [
        "rudder_angle",
        "current_speed",
        "current_direction",
        "yaw_disturbance",
    ]
    .iter()
    .map(|n| vr(n))
    .collect();
    let outs: Vec<u32> = OUTPUTS.iter().map(|n| vr(n)).collect();
    for k in 0..1000 {
        let t = k as f64 * h;
        let u = [
            0.1 * (0.05 * t).sin(),
            0.5,
            1.0 + 0.001 * t,
            0.02 * (0.4 * t).cos(),
        ];
        assert_eq!(fmi2SetReal(c, ins.as_ptr(), 4, u.as_ptr()), fmi2OK);
        assert_eq!(fmi2DoStep(c, t, h, 1), fmi2OK);
        model.step(
            &NomotoInputs {
                rudder: u[0],
                current_speed: u[1],
                current_direction: u[2],
                yaw_disturbance: u[3],
            },
            h,
        );
        let mut v = [0.0; 10];
        assert_eq!(fmi2GetReal(c, outs.as_ptr(), 10, v.as_mut_ptr()), fmi2OK);
        assert_eq!(
            v,
            expected(&model.outputs()),
            "model {model_preset} step {k}"
        );
    }
    assert!(model.outputs().heading.abs() > 1e-3);
    assert_eq!(fmi2Terminate(c), fmi2OK);
    fmi2FreeInstance(c);
}

#[test]
fn exported_api_reproduces_both_models() {
    unsafe {
        check(1, NomotoShip::ddg51(), 0.1);
        check(2, NomotoShip::esso_osaka(), 0.5);
    }
}

#[test]
fn bad_parameter_is_refused() {
    unsafe {
        let c = instantiate();
        let zero = 0.0;
        assert_eq!(fmi2SetReal(c, &vr("t_prime"), 1, &zero), fmi2OK);
        assert_eq!(fmi2ExitInitializationMode(c), fmi2Error);
        fmi2FreeInstance(c);
    }
}

#[test]
fn variable_table_passes_the_layer_checks() {
    fmi2_export::variables::check_table(Fmu::variables()).unwrap();
}
