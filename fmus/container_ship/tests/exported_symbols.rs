//! Calls the `fmi2*` symbols that `export_fmu!` emitted for ContainerShip (linked from this
//! crate's rlib), as a C importer would, and checks them against the model bit for bit.

use container_ship_fmu::ContainerShipFmu as Fmu;
use fmi2::*;
use fmi2_export::FmuModel;
use models::hull::container_ship::{
    ContainerShip, ContainerShipInputs, ContainerShipOutputs, LinearContainerShip,
    LinearContainerShipInputs,
};
use std::ffi::CString;
use std::ptr::null;

fmi2::declare_fmi2_functions!();

fn vr(name: &str) -> u32 {
    Fmu::variables()
        .iter()
        .position(|v| v.name == name)
        .unwrap_or_else(|| panic!("no variable {name}")) as u32
}

const OUTPUTS: [&str; 16] = [
    "surge_velocity",
    "sway_velocity",
    "yaw_rate",
    "roll_rate",
    "roll",
    "heading",
    "heading_wrapped",
    "x",
    "y",
    "rudder_angle",
    "shaft_speed",
    "speed",
    "drift_angle",
    "sway_velocity_prime",
    "yaw_rate_prime",
    "roll_rate_prime",
];

fn expected(o: &ContainerShipOutputs) -> [f64; 16] {
    [
        o.u,
        o.v,
        o.r,
        o.p,
        o.roll,
        o.heading,
        o.heading_wrapped,
        o.x,
        o.y,
        o.rudder,
        o.shaft_rpm,
        o.speed,
        o.drift_angle,
        o.v_prime,
        o.r_prime,
        o.p_prime,
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

#[test]
fn exported_api_reproduces_the_nonlinear_model() {
    unsafe {
        let c = instantiate();
        assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
        let mut model = ContainerShip::at_equilibrium(80.0).unwrap();
        let ins = [
            vr("rudder_command"),
            vr("shaft_speed_command"),
            vr("sway_force"),
            vr("roll_moment"),
            vr("yaw_moment"),
        ];
        let outs: Vec<u32> = OUTPUTS.iter().map(|n| vr(n)).collect();
        let h = 0.1;
        for k in 0..1000 {
            let t = k as f64 * h;
            let u = [
                0.3 * (0.05 * t).sin(),
                80.0 - 10.0 * (0.01 * t).sin(),
                1e5 * (0.1 * t).sin(),
                2e6 * (0.5 * t).sin(),
                -1e6 * (0.02 * t).cos(),
            ];
            assert_eq!(fmi2SetReal(c, ins.as_ptr(), 5, u.as_ptr()), fmi2OK);
            assert_eq!(fmi2DoStep(c, t, h, 1), fmi2OK);
            model.step(
                &ContainerShipInputs {
                    rudder_command: u[0],
                    shaft_command_rpm: u[1],
                    sway_force_ext: u[2],
                    roll_moment_ext: u[3],
                    yaw_moment_ext: u[4],
                },
                h,
            );
            let mut v = [0.0; 16];
            assert_eq!(fmi2GetReal(c, outs.as_ptr(), 16, v.as_mut_ptr()), fmi2OK);
            assert_eq!(v, expected(&model.outputs()), "step {k}");
        }
        assert!(model.outputs().heading.abs() > 0.1);
        assert_eq!(fmi2Terminate(c), fmi2OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn exported_api_reproduces_the_linear_model() {
    unsafe {
        let c = instantiate();
        let two = 2;
        assert_eq!(fmi2SetInteger(c, &vr("variant"), 1, &two), fmi2OK);
        assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
        let mut model = LinearContainerShip::mss_default();
        let outs: Vec<u32> = OUTPUTS.iter().map(|n| vr(n)).collect();
        let h = 0.25;
        for k in 0..400 {
            let t = k as f64 * h;
            let cmd = 0.2 * (0.03 * t).sin();
            assert_eq!(fmi2SetReal(c, &vr("rudder_command"), 1, &cmd), fmi2OK);
            assert_eq!(fmi2DoStep(c, t, h, 1), fmi2OK);
            model.step(
                &LinearContainerShipInputs {
                    rudder_command: cmd,
                },
                h,
            );
            let mut v = [0.0; 16];
            assert_eq!(fmi2GetReal(c, outs.as_ptr(), 16, v.as_mut_ptr()), fmi2OK);
            assert_eq!(v, expected(&model.outputs()), "step {k}");
        }
        assert_eq!(fmi2Terminate(c), fmi2OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn bad_parameter_is_refused() {
    unsafe {
        let c = instantiate();
        let bad = -1.0;
        assert_eq!(fmi2SetReal(c, &vr("initial_shaft_speed"), 1, &bad), fmi2OK);
        assert_eq!(fmi2ExitInitializationMode(c), fmi2Error);
        fmi2FreeInstance(c);
    }
}

#[test]
fn variable_table_passes_the_layer_checks() {
    fmi2_export::variables::check_table(Fmu::variables()).unwrap();
    let xml = fmi2_export::xml::model_description::<Fmu>();
    assert!(xml.contains(r#"name="rudder_command""#));
}
