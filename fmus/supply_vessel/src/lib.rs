//! `SupplyVessel` FMU: the 3-DOF low-frequency DP model of the supply vessel Northern Clipper
//! (`models::hull::supply_vessel`, Fossen & Strand 1999) as an FMI 2.0 co-simulation FMU. No
//! physics here: the variable table maps the model onto FMI variables.

use fmi2_export::{export_fmu, DefaultExperiment, FmuModel, Variable};
use models::hull::supply_vessel::{
    SupplyVessel, SupplyVesselInputs, SupplyVesselOutputs, NORTHERN_CLIPPER_D, NORTHERN_CLIPPER_M,
};
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SupplyVesselFmu {
    m: [[f64; 3]; 3],
    d: [[f64; 3]; 3],
    max_substep: f64,
    inputs: SupplyVesselInputs,
    vessel: SupplyVessel,
}

/// Start value of `surge_force` [N]: a small thrust so that the default experiment moves
/// (steady surge X/D11 = 1.0 m/s).
pub const DEFAULT_SURGE_FORCE: f64 = 5.0e4;

impl Default for SupplyVesselFmu {
    fn default() -> Self {
        let vessel = SupplyVessel::northern_clipper();
        SupplyVesselFmu {
            m: NORTHERN_CLIPPER_M,
            d: NORTHERN_CLIPPER_D,
            max_substep: vessel.max_substep,
            inputs: SupplyVesselInputs {
                tau: [DEFAULT_SURGE_FORCE, 0.0, 0.0],
                ..Default::default()
            },
            vessel,
        }
    }
}

impl SupplyVesselFmu {
    fn out(&self) -> SupplyVesselOutputs {
        self.vessel.outputs()
    }
}

type V = Variable<SupplyVesselFmu>;

static VARIABLES: &[V] = &[
    V::real_parameter(
        "m11",
        None,
        false,
        "Inertia matrix M (eq. 56), entry (1, 1), SI (kg, kg.m, kg.m2 by row/column)",
        |m| m.m[0][0],
        |m, v| m.m[0][0] = v,
    ),
    V::real_parameter(
        "m12",
        None,
        false,
        "Inertia matrix M (eq. 56), entry (1, 2), SI (kg, kg.m, kg.m2 by row/column)",
        |m| m.m[0][1],
        |m, v| m.m[0][1] = v,
    ),
    V::real_parameter(
        "m13",
        None,
        false,
        "Inertia matrix M (eq. 56), entry (1, 3), SI (kg, kg.m, kg.m2 by row/column)",
        |m| m.m[0][2],
        |m, v| m.m[0][2] = v,
    ),
    V::real_parameter(
        "m21",
        None,
        false,
        "Inertia matrix M (eq. 56), entry (2, 1), SI (kg, kg.m, kg.m2 by row/column)",
        |m| m.m[1][0],
        |m, v| m.m[1][0] = v,
    ),
    V::real_parameter(
        "m22",
        None,
        false,
        "Inertia matrix M (eq. 56), entry (2, 2), SI (kg, kg.m, kg.m2 by row/column)",
        |m| m.m[1][1],
        |m, v| m.m[1][1] = v,
    ),
    V::real_parameter(
        "m23",
        None,
        false,
        "Inertia matrix M (eq. 56), entry (2, 3), SI (kg, kg.m, kg.m2 by row/column)",
        |m| m.m[1][2],
        |m, v| m.m[1][2] = v,
    ),
    V::real_parameter(
        "m31",
        None,
        false,
        "Inertia matrix M (eq. 56), entry (3, 1), SI (kg, kg.m, kg.m2 by row/column)",
        |m| m.m[2][0],
        |m, v| m.m[2][0] = v,
    ),
    V::real_parameter(
        "m32",
        None,
        false,
        "Inertia matrix M (eq. 56), entry (3, 2), SI (kg, kg.m, kg.m2 by row/column)",
        |m| m.m[2][1],
        |m, v| m.m[2][1] = v,
    ),
    V::real_parameter(
        "m33",
        None,
        false,
        "Inertia matrix M (eq. 56), entry (3, 3), SI (kg, kg.m, kg.m2 by row/column)",
        |m| m.m[2][2],
        |m, v| m.m[2][2] = v,
    ),
    V::real_parameter(
        "d11",
        None,
        false,
        "Damping matrix D (eq. 57), entry (1, 1), SI (N.s/m, N.s, N.m.s by row/column)",
        |m| m.d[0][0],
        |m, v| m.d[0][0] = v,
    ),
    V::real_parameter(
        "d12",
        None,
        false,
        "Damping matrix D (eq. 57), entry (1, 2), SI (N.s/m, N.s, N.m.s by row/column)",
        |m| m.d[0][1],
        |m, v| m.d[0][1] = v,
    ),
    V::real_parameter(
        "d13",
        None,
        false,
        "Damping matrix D (eq. 57), entry (1, 3), SI (N.s/m, N.s, N.m.s by row/column)",
        |m| m.d[0][2],
        |m, v| m.d[0][2] = v,
    ),
    V::real_parameter(
        "d21",
        None,
        false,
        "Damping matrix D (eq. 57), entry (2, 1), SI (N.s/m, N.s, N.m.s by row/column)",
        |m| m.d[1][0],
        |m, v| m.d[1][0] = v,
    ),
    V::real_parameter(
        "d22",
        None,
        false,
        "Damping matrix D (eq. 57), entry (2, 2), SI (N.s/m, N.s, N.m.s by row/column)",
        |m| m.d[1][1],
        |m, v| m.d[1][1] = v,
    ),
    V::real_parameter(
        "d23",
        None,
        false,
        "Damping matrix D (eq. 57), entry (2, 3), SI (N.s/m, N.s, N.m.s by row/column)",
        |m| m.d[1][2],
        |m, v| m.d[1][2] = v,
    ),
    V::real_parameter(
        "d31",
        None,
        false,
        "Damping matrix D (eq. 57), entry (3, 1), SI (N.s/m, N.s, N.m.s by row/column)",
        |m| m.d[2][0],
        |m, v| m.d[2][0] = v,
    ),
    V::real_parameter(
        "d32",
        None,
        false,
        "Damping matrix D (eq. 57), entry (3, 2), SI (N.s/m, N.s, N.m.s by row/column)",
        |m| m.d[2][1],
        |m, v| m.d[2][1] = v,
    ),
    V::real_parameter(
        "d33",
        None,
        false,
        "Damping matrix D (eq. 57), entry (3, 3), SI (N.s/m, N.s, N.m.s by row/column)",
        |m| m.d[2][2],
        |m, v| m.d[2][2] = v,
    ),
    V::real_parameter(
        "max_substep",
        Some("s"),
        false,
        "Largest RK4 sub-step (default 0.1 s; the fastest open-loop time constant is 8.40 s)",
        |m| m.max_substep,
        |m, v| m.max_substep = v,
    )
    .with_range(Some(0.0), None),
    V::real_input(
        "surge_force",
        Some("N"),
        "Thrust tau_1: surge force, body frame (start value 5e4 N so that the default experiment moves)",
        |m| m.inputs.tau[0],
        |m, v| m.inputs.tau[0] = v,
    ),
    V::real_input(
        "sway_force",
        Some("N"),
        "Thrust tau_2: sway force, body frame (to starboard)",
        |m| m.inputs.tau[1],
        |m, v| m.inputs.tau[1] = v,
    ),
    V::real_input(
        "yaw_moment",
        Some("N.m"),
        "Thrust tau_3: yaw moment (positive to starboard)",
        |m| m.inputs.tau[2],
        |m, v| m.inputs.tau[2] = v,
    ),
    V::real_input(
        "bias_north",
        Some("N"),
        "Earth-fixed bias force b_1, north (current, wind, second-order waves; eq. 3, rotated by J^T(psi))",
        |m| m.inputs.bias[0],
        |m, v| m.inputs.bias[0] = v,
    ),
    V::real_input(
        "bias_east",
        Some("N"),
        "Earth-fixed bias force b_2, east",
        |m| m.inputs.bias[1],
        |m, v| m.inputs.bias[1] = v,
    ),
    V::real_input(
        "bias_yaw",
        Some("N.m"),
        "Earth-fixed bias moment b_3, yaw",
        |m| m.inputs.bias[2],
        |m, v| m.inputs.bias[2] = v,
    ),
    V::real_input(
        "wave_motion_north",
        Some("m"),
        "Wave-frequency motion eta_w,1 (north) superposed on the measured position \
         (e.g. Waves.wf_motion_surge)",
        |m| m.inputs.wave_motion[0],
        |m, v| m.inputs.wave_motion[0] = v,
    ),
    V::real_input(
        "wave_motion_east",
        Some("m"),
        "Wave-frequency motion eta_w,2 (east) (e.g. Waves.wf_motion_sway)",
        |m| m.inputs.wave_motion[1],
        |m, v| m.inputs.wave_motion[1] = v,
    ),
    V::real_input(
        "wave_motion_yaw",
        Some("rad"),
        "Wave-frequency yaw motion eta_w,3 (e.g. Waves.wf_motion_yaw)",
        |m| m.inputs.wave_motion[2],
        |m, v| m.inputs.wave_motion[2] = v,
    ),
    V::real_output("x", Some("m"), "LF north position", |m| m.out().eta[0]),
    V::real_output("y", Some("m"), "LF east position", |m| m.out().eta[1]),
    V::real_output(
        "heading",
        Some("rad"),
        "LF heading psi from north, clockwise, continuous (not wrapped)",
        |m| m.out().eta[2],
    ),
    V::real_output(
        "heading_wrapped",
        Some("rad"),
        "LF heading wrapped to (-pi, pi]",
        |m| m.out().heading_wrapped,
    ),
    V::real_output(
        "surge_velocity",
        Some("m/s"),
        "LF body velocity u",
        |m| m.out().nu[0],
    ),
    V::real_output(
        "sway_velocity",
        Some("m/s"),
        "LF body velocity v",
        |m| m.out().nu[1],
    ),
    V::real_output("yaw_rate", Some("rad/s"), "LF yaw rate r", |m| m.out().nu[2]),
    V::real_output(
        "measured_x",
        Some("m"),
        "Measured north position y_1 = x + eta_w,1 (wave input of the last step)",
        |m| m.out().measured[0],
    ),
    V::real_output(
        "measured_y",
        Some("m"),
        "Measured east position y_2 = y + eta_w,2",
        |m| m.out().measured[1],
    ),
    V::real_output(
        "measured_heading",
        Some("rad"),
        "Measured heading y_3 = psi + eta_w,3",
        |m| m.out().measured[2],
    ),
];

impl FmuModel for SupplyVesselFmu {
    const MODEL_IDENTIFIER: &'static str = "SupplyVessel";
    /// Every output is a function of the state: no direct feedthrough from the inputs.
    const DIRECT_FEEDTHROUGH: bool = false;
    const DESCRIPTION: &'static str = "Supply vessel Northern Clipper: 3-DOF low-frequency DP \
        model M nu' + D nu = tau + J^T(psi) b with wave-frequency motion superposed on the \
        measurement (Fossen & Strand 1999)";
    const DEFAULT_EXPERIMENT: DefaultExperiment = DefaultExperiment {
        start_time: 0.0,
        stop_time: 600.0,
        step_size: 0.1,
    };

    fn variables() -> &'static [Variable<Self>] {
        VARIABLES
    }

    fn documentation_html() -> &'static str {
        include_str!("documentation.html")
    }

    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        let mut vessel = SupplyVessel::new(self.m, self.d).map_err(|e| e.to_string())?;
        if !(self.max_substep.is_finite() && self.max_substep > 0.0) {
            return Err(format!(
                "parameter max_substep = {} must be finite and > 0",
                self.max_substep
            ));
        }
        vessel.max_substep = self.max_substep;
        self.vessel = vessel;
        Ok(())
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        self.vessel.step(&self.inputs, h);
        Ok(())
    }
}

export_fmu!(SupplyVesselFmu);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_the_fmu_parameter_and_value() {
        let mut m = SupplyVesselFmu::default();
        m.m[1][1] = -2.0;
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("m22 = -2"), "{e}");
        let mut m = SupplyVesselFmu {
            max_substep: 0.0,
            ..Default::default()
        };
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("max_substep = 0"), "{e}");
    }
}
