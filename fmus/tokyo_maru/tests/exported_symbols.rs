//! Calls the `fmi2*` symbols that `export_fmu!` emitted for TokyoMaru (linked from this crate's
//! rlib), as a C importer would, and checks them against the model bit for bit.

use fmi2::*;
use fmi2_export::FmuModel;
use models::hull::tokyo_maru::{TokyoMaru, TokyoMaruInputs, TokyoMaruOutputs};
use std::ffi::CString;
use std::ptr::null;
use tokyo_maru_fmu::TokyoMaruFmu as Fmu;

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

const OUTPUTS: [&str; 12] = [
    "heading",
    "heading_wrapped",
    "yaw_rate",
    "yaw_rate_prime",
    "drift_angle",
    "sway_velocity",
    "cross_track",
    "cross_track_prime",
    "x",
    "y",
    "rudder_angle_actual",
    "time_prime",
];

fn expected(o: &TokyoMaruOutputs) -> [f64; 12] {
    [
        o.heading,
        o.heading_wrapped,
        o.yaw_rate,
        o.yaw_rate_prime,
        o.drift_angle,
        o.sway_velocity,
        o.cross_track,
        o.cross_track_prime,
        o.x,
        o.y,
        o.rudder,
        o.time_prime,
    ]
}

/// Runs `steps` steps from `k0` with the same inputs into the FMU and the model.
unsafe fn run(
    c: fmi2Component,
    model: &mut TokyoMaru,
    gear: bool,
    k0: usize,
    steps: usize,
    h: f64,
) {
    let rudder = if gear {
        "rudder_command"
    } else {
        "rudder_angle"
    };
    let ins: Vec<u32> = [
        rudder,
        "yaw_moment_prime",
        "sway_force_prime",
        "current_lateral",
    ]
    .iter()
    .map(|n| vr(n))
    .collect();
    let outs: Vec<u32> = OUTPUTS.iter().map(|n| vr(n)).collect();
    for k in k0..k0 + steps {
        let t = k as f64 * h;
        let u = [
            0.1 * (0.02 * t).sin(),
            1e-4 * (0.01 * t).sin(),
            2e-3 * (0.015 * t).cos(),
            0.2 * (0.005 * t).cos(),
        ];
        assert_eq!(fmi2SetReal(c, ins.as_ptr(), 4, u.as_ptr()), fmi2OK);
        assert_eq!(fmi2DoStep(c, t, h, 1), fmi2OK);
        model.step(
            &TokyoMaruInputs {
                rudder: u[0],
                yaw_moment_prime: u[1],
                sway_force_prime: u[2],
                current_lateral: u[3],
            },
            h,
        );
        let mut v = [0.0; 12];
        assert_eq!(fmi2GetReal(c, outs.as_ptr(), 12, v.as_mut_ptr()), fmi2OK);
        assert_eq!(v, expected(&model.outputs()), "step {k}");
    }
}

#[test]
fn exported_api_reproduces_the_model_and_a_depth_change() {
    unsafe {
        let c = instantiate();
        assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
        let mut model = TokyoMaru::design_depth();
        run(c, &mut model, false, 0, 300, 1.0);
        // tunable H/T in step mode
        let ht = 1.4;
        assert_eq!(fmi2SetReal(c, &vr("depth_ratio"), 1, &ht), fmi2OK);
        model.depth_ratio = ht;
        run(c, &mut model, false, 300, 300, 1.0);
        let deep = 1;
        assert_eq!(fmi2SetBoolean(c, &vr("deep_water"), 1, &deep), fmi2OK);
        model.depth_ratio = f64::INFINITY;
        run(c, &mut model, false, 600, 300, 1.0);
        assert!(model.outputs().cross_track.abs() > 1.0);
        assert_eq!(fmi2Terminate(c), fmi2OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn exported_api_reproduces_the_internal_gear_and_euler() {
    unsafe {
        let c = instantiate();
        let t = 1;
        assert_eq!(
            fmi2SetBoolean(c, &vr("internal_steering_gear"), 1, &t),
            fmi2OK
        );
        let two = 2;
        assert_eq!(fmi2SetInteger(c, &vr("integration"), 1, &two), fmi2OK);
        assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
        let mut model = TokyoMaru::design_depth();
        model.internal_steering_gear = true;
        model.integration = models::hull::tokyo_maru::TokyoMaruIntegration::Euler {
            max_substep_prime: 0.005,
        };
        run(c, &mut model, true, 0, 400, 0.5);
        assert_eq!(fmi2Terminate(c), fmi2OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn bad_depth_ratio_in_step_mode_is_refused_and_the_old_value_kept() {
    unsafe {
        let c = instantiate();
        assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
        let bad = 0.0;
        assert_eq!(fmi2SetReal(c, &vr("depth_ratio"), 1, &bad), fmi2Error);
        let mut v = 0.0;
        assert_eq!(fmi2GetReal(c, &vr("depth_ratio"), 1, &mut v), fmi2OK);
        assert_eq!(v, 1.89);
        fmi2FreeInstance(c);
    }
}

#[test]
fn variable_table_passes_the_layer_checks() {
    fmi2_export::variables::check_table(Fmu::variables()).unwrap();
}
