//! Calls the `fmi2*` symbols that `export_fmu!` emitted for SupplyVessel (linked from this crate's
//! rlib), as a C importer would, and checks them against the model bit for bit.

use fmi2::*;
use fmi2_export::FmuModel;
use models::hull::supply_vessel::{SupplyVessel, SupplyVesselInputs, SupplyVesselOutputs};
use std::ffi::CString;
use std::ptr::null;
use supply_vessel_fmu::SupplyVesselFmu as Fmu;

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

const INPUTS: [&str; 9] = [
    "surge_force",
    "sway_force",
    "yaw_moment",
    "bias_north",
    "bias_east",
    "bias_yaw",
    "wave_motion_north",
    "wave_motion_east",
    "wave_motion_yaw",
];

const OUTPUTS: [&str; 10] = [
    "x",
    "y",
    "heading",
    "heading_wrapped",
    "surge_velocity",
    "sway_velocity",
    "yaw_rate",
    "measured_x",
    "measured_y",
    "measured_heading",
];

fn expected(o: &SupplyVesselOutputs) -> [f64; 10] {
    [
        o.eta[0],
        o.eta[1],
        o.eta[2],
        o.heading_wrapped,
        o.nu[0],
        o.nu[1],
        o.nu[2],
        o.measured[0],
        o.measured[1],
        o.measured[2],
    ]
}

#[test]
fn exported_api_reproduces_the_model() {
    unsafe {
        let c = instantiate();
        assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
        let mut model = SupplyVessel::northern_clipper();
        let ins: Vec<u32> = INPUTS.iter().map(|n| vr(n)).collect();
        let outs: Vec<u32> = OUTPUTS.iter().map(|n| vr(n)).collect();
        let h = 0.5;
        for k in 0..2000 {
            let t = k as f64 * h;
            let u = [
                1e5 * (0.01 * t).sin(),
                5e4 * (0.02 * t).cos(),
                1e6 * (0.015 * t).sin(),
                2e4,
                -1e4,
                5e5,
                0.5 * (0.8 * t).sin(),
                0.3 * (0.7 * t).cos(),
                0.02 * (0.9 * t).sin(),
            ];
            assert_eq!(fmi2SetReal(c, ins.as_ptr(), 9, u.as_ptr()), fmi2OK);
            assert_eq!(fmi2DoStep(c, t, h, 1), fmi2OK);
            model.step(
                &SupplyVesselInputs {
                    tau: [u[0], u[1], u[2]],
                    bias: [u[3], u[4], u[5]],
                    wave_motion: [u[6], u[7], u[8]],
                },
                h,
            );
            let mut v = [0.0; 10];
            assert_eq!(fmi2GetReal(c, outs.as_ptr(), 10, v.as_mut_ptr()), fmi2OK);
            assert_eq!(v, expected(&model.outputs()), "step {k}");
        }
        assert!(model.outputs().eta[0].abs() > 1.0);
        assert_eq!(fmi2Terminate(c), fmi2OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn singular_mass_matrix_is_refused() {
    unsafe {
        let c = instantiate();
        let zero = 0.0;
        assert_eq!(fmi2SetReal(c, &vr("m33"), 1, &zero), fmi2OK);
        assert_eq!(fmi2ExitInitializationMode(c), fmi2Error);
        fmi2FreeInstance(c);
    }
}

#[test]
fn variable_table_passes_the_layer_checks() {
    fmi2_export::variables::check_table(Fmu::variables()).unwrap();
}
