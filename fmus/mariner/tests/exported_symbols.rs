//! Calls the `fmi2*` symbols that `export_fmu!` emitted for Mariner (linked from this
//! crate's rlib), as a C importer would, and checks them against the model bit for bit.

use fmi2::*;
use fmi2_export::FmuModel;
use mariner_fmu::MarinerFmu as Fmu;
use models::hull::mariner::{Mariner, MarinerInputs, MarinerOutputs, U0_DEFAULT};
use std::ffi::CString;
use std::ptr::null;

fmi2::declare_fmi2_functions!();

fn vr(name: &str) -> u32 {
    Fmu::variables()
        .iter()
        .position(|v| v.name == name)
        .unwrap_or_else(|| panic!("no variable {name}")) as u32
}

const OUTPUTS: [&str; 14] = [
    "surge_velocity",
    "surge_perturbation",
    "sway_velocity",
    "yaw_rate",
    "heading",
    "heading_wrapped",
    "x",
    "y",
    "rudder_angle",
    "speed",
    "drift_angle",
    "surge_perturbation_prime",
    "sway_velocity_prime",
    "yaw_rate_prime",
];

fn expected(o: &MarinerOutputs) -> [f64; 14] {
    [
        o.u,
        o.delta_u,
        o.v,
        o.r,
        o.heading,
        o.heading_wrapped,
        o.x,
        o.y,
        o.rudder,
        o.speed,
        o.drift_angle,
        o.u_prime,
        o.v_prime,
        o.r_prime,
    ]
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

unsafe fn run(c: fmi2Component, mut model: Mariner, h: f64, steps: usize) -> Mariner {
    let outs: Vec<u32> = OUTPUTS.iter().map(|n| vr(n)).collect();
    for k in 0..steps {
        let t = k as f64 * h;
        let cmd = 0.5 * (0.04 * t).sin();
        assert_eq!(fmi2SetReal(c, &vr("rudder_command"), 1, &cmd), fmi2OK);
        assert_eq!(fmi2DoStep(c, t, h, 1), fmi2OK);
        model.step(
            &MarinerInputs {
                rudder_command: cmd,
            },
            h,
        );
        let mut v = [0.0; 14];
        assert_eq!(fmi2GetReal(c, outs.as_ptr(), 14, v.as_mut_ptr()), fmi2OK);
        assert_eq!(v, expected(&model.outputs()), "step {k}");
    }
    model
}

#[test]
fn exported_api_reproduces_the_trimmed_model() {
    unsafe {
        let c = instantiate();
        assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
        let mut trim = 0.0;
        assert_eq!(
            fmi2GetReal(c, &vr("trim_rudder_command"), 1, &mut trim),
            fmi2OK
        );
        assert_eq!(trim, Mariner::trim_input(U0_DEFAULT));
        let model = run(c, Mariner::trimmed(U0_DEFAULT).unwrap(), 0.1, 1500);
        assert!(model.outputs().heading.abs() > 0.1);
        assert_eq!(fmi2Terminate(c), fmi2OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn exported_api_reproduces_the_mss_start() {
    unsafe {
        let c = instantiate();
        let f = 0;
        assert_eq!(fmi2SetBoolean(c, &vr("trimmed"), 1, &f), fmi2OK);
        assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
        run(c, Mariner::mss_default(), 0.3, 500);
        assert_eq!(fmi2Terminate(c), fmi2OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn bad_parameter_is_refused() {
    unsafe {
        let c = instantiate();
        let bad = -1.0;
        assert_eq!(fmi2SetReal(c, &vr("rudder_max"), 1, &bad), fmi2Error);
        let bad = 0.0;
        assert_eq!(fmi2SetReal(c, &vr("max_substep"), 1, &bad), fmi2OK);
        assert_eq!(fmi2ExitInitializationMode(c), fmi2Error);
        fmi2FreeInstance(c);
    }
}

#[test]
fn variable_table_passes_the_layer_checks() {
    fmi2_export::variables::check_table(Fmu::variables()).unwrap();
    let xml = fmi2_export::xml::model_description::<Fmu>();
    assert!(xml.contains(r#"causality="calculatedParameter""#));
}
