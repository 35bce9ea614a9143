//! SupplyVessel through the `fmi2*` symbols its crate exports, as a C importer calls them: the
//! checks every FMU runs, and the FMU against `models::hull::supply_vessel` bit for bit, by
//! variable name.

use fmi2_export::fmi2::{fmi2Error, fmi2OK};
use models::hull::supply_vessel::{SupplyVessel, SupplyVesselInputs, SupplyVesselOutputs};

fmi2_export::fmu_tests!(supply_vessel_fmu::SupplyVesselFmu);

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

fn expected(o: &SupplyVesselOutputs) -> Vec<f64> {
    vec![
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
    let mut fmu = fmu();
    fmu.initialize(0.0);
    let mut model = SupplyVessel::northern_clipper();
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
        for (name, value) in INPUTS.iter().zip(u) {
            fmu.set(name, value);
        }
        fmu.step(t, h);
        model.step(
            &SupplyVesselInputs {
                tau: [u[0], u[1], u[2]],
                bias: [u[3], u[4], u[5]],
                wave_motion: [u[6], u[7], u[8]],
            },
            h,
        );
        assert_eq!(fmu.reals(&OUTPUTS), expected(&model.outputs()), "step {k}");
    }
    assert!(model.outputs().eta[0].abs() > 1.0);
    assert_eq!(fmu.terminate(), fmi2OK);
}

#[test]
fn singular_mass_matrix_is_refused() {
    let mut fmu = fmu();
    assert_eq!(fmu.setup(0.0, None), fmi2OK);
    assert_eq!(fmu.enter_initialization(), fmi2OK);
    fmu.set("m33", 0.0);
    assert_eq!(fmu.exit_initialization(), fmi2Error);
}
