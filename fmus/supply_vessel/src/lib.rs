//! `SupplyVessel` FMU: the 3-DOF low-frequency DP model of the supply vessel Northern Clipper
//! (`models::hull::supply_vessel`, [Fossen1999, sec. 2]) as an FMI 2.0 co-simulation FMU. No
//! physics here: the variable table maps the model onto FMI variables.

use fmi2_export::{passes, FmuModel};
use models::error::check_positive;
use models::hull::supply_vessel::{
    SupplyVessel, SupplyVesselInputs, SupplyVesselOutputs, NORTHERN_CLIPPER_D, NORTHERN_CLIPPER_M,
};
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SupplyVesselFmu {
    mass: [[f64; 3]; 3],
    damping: [[f64; 3]; 3],
    max_substep: f64,
    inputs: SupplyVesselInputs,
    vessel: SupplyVessel,
    /// The model's outputs, computed once wherever the model changes (initialize, do_step,
    /// calculate_outputs) instead of in every getter; `None` (after a deserialized restore)
    /// means compute them. Not part of the state.
    #[serde(skip)]
    outputs: Option<SupplyVesselOutputs>,
}

/// Start value of `surge_force` [N]: a small thrust so that the default experiment moves
/// (steady surge X/D11 = 1.0 m/s).
pub const DEFAULT_SURGE_FORCE: f64 = 5.0e4;

impl Default for SupplyVesselFmu {
    fn default() -> Self {
        let vessel = SupplyVessel::northern_clipper();
        SupplyVesselFmu {
            mass: NORTHERN_CLIPPER_M,
            damping: NORTHERN_CLIPPER_D,
            max_substep: vessel.max_substep,
            inputs: SupplyVesselInputs {
                tau: [DEFAULT_SURGE_FORCE, 0.0, 0.0],
                ..Default::default()
            },
            vessel,
            outputs: None,
        }
    }
}

impl SupplyVesselFmu {
    fn model_outputs(&self) -> SupplyVesselOutputs {
        self.vessel.outputs()
    }

    fn out(&self) -> SupplyVesselOutputs {
        self.outputs.unwrap_or_else(|| self.model_outputs())
    }

    /// Keeps the outputs of the model as it is now (the getters read them).
    fn keep_outputs(&mut self) {
        self.outputs = Some(self.model_outputs());
    }
}

fmi2_export::fmu! {
    SupplyVesselFmu => "SupplyVessel",
    description: "Supply vessel Northern Clipper: 3-DOF low-frequency DP \
        model M nu' + D nu = tau + J^T(psi) b with wave-frequency motion superposed on the \
        measurement (Fossen & Strand 1999)",
    experiment: (0.0, 600.0, 0.1),
    // Every output is a function of the state: no direct feedthrough from the inputs.
    direct_feedthrough: false,
    documentation: "documentation.html",
    variables: {
        fixed real "m11" (mass[0][0]),
            "Inertia matrix M (eq. 56), entry (1, 1), SI (kg, kg.m, kg.m2 by row/column)";
        fixed real "m12" (mass[0][1]),
            "Inertia matrix M (eq. 56), entry (1, 2), SI (kg, kg.m, kg.m2 by row/column)";
        fixed real "m13" (mass[0][2]),
            "Inertia matrix M (eq. 56), entry (1, 3), SI (kg, kg.m, kg.m2 by row/column)";
        fixed real "m21" (mass[1][0]),
            "Inertia matrix M (eq. 56), entry (2, 1), SI (kg, kg.m, kg.m2 by row/column)";
        fixed real "m22" (mass[1][1]),
            "Inertia matrix M (eq. 56), entry (2, 2), SI (kg, kg.m, kg.m2 by row/column)";
        fixed real "m23" (mass[1][2]),
            "Inertia matrix M (eq. 56), entry (2, 3), SI (kg, kg.m, kg.m2 by row/column)";
        fixed real "m31" (mass[2][0]),
            "Inertia matrix M (eq. 56), entry (3, 1), SI (kg, kg.m, kg.m2 by row/column)";
        fixed real "m32" (mass[2][1]),
            "Inertia matrix M (eq. 56), entry (3, 2), SI (kg, kg.m, kg.m2 by row/column)";
        fixed real "m33" (mass[2][2]),
            "Inertia matrix M (eq. 56), entry (3, 3), SI (kg, kg.m, kg.m2 by row/column)";
        fixed real "d11" (damping[0][0]),
            "Damping matrix D (eq. 57), entry (1, 1), SI (N.s/m, N.s, N.m.s by row/column)";
        fixed real "d12" (damping[0][1]),
            "Damping matrix D (eq. 57), entry (1, 2), SI (N.s/m, N.s, N.m.s by row/column)";
        fixed real "d13" (damping[0][2]),
            "Damping matrix D (eq. 57), entry (1, 3), SI (N.s/m, N.s, N.m.s by row/column)";
        fixed real "d21" (damping[1][0]),
            "Damping matrix D (eq. 57), entry (2, 1), SI (N.s/m, N.s, N.m.s by row/column)";
        fixed real "d22" (damping[1][1]),
            "Damping matrix D (eq. 57), entry (2, 2), SI (N.s/m, N.s, N.m.s by row/column)";
        fixed real "d23" (damping[1][2]),
            "Damping matrix D (eq. 57), entry (2, 3), SI (N.s/m, N.s, N.m.s by row/column)";
        fixed real "d31" (damping[2][0]),
            "Damping matrix D (eq. 57), entry (3, 1), SI (N.s/m, N.s, N.m.s by row/column)";
        fixed real "d32" (damping[2][1]),
            "Damping matrix D (eq. 57), entry (3, 2), SI (N.s/m, N.s, N.m.s by row/column)";
        fixed real "d33" (damping[2][2]),
            "Damping matrix D (eq. 57), entry (3, 3), SI (N.s/m, N.s, N.m.s by row/column)";
        fixed real "max_substep" ["s"] (max_substep).min(0.0),
            "Largest RK4 sub-step (default 0.1 s; the fastest open-loop time constant is 8.40 s)";
        input real "surge_force" ["N"] (inputs.tau[0]),
            "Thrust tau_1: surge force, body frame (start value 5e4 N so that the default experiment moves)";
        input real "sway_force" ["N"] (inputs.tau[1]),
            "Thrust tau_2: sway force, body frame (to starboard)";
        input real "yaw_moment" ["N.m"] (inputs.tau[2]),
            "Thrust tau_3: yaw moment (positive to starboard)";
        input real "bias_north" ["N"] (inputs.bias[0]),
            "Earth-fixed bias force b_1, north (current, wind, second-order waves; eq. 3, rotated by J^T(psi))";
        input real "bias_east" ["N"] (inputs.bias[1]), "Earth-fixed bias force b_2, east";
        input real "bias_yaw" ["N.m"] (inputs.bias[2]), "Earth-fixed bias moment b_3, yaw";
        input real "wave_motion_north" ["m"] (inputs.wave_motion[0]),
            "Wave-frequency motion eta_w,1 (north) superposed on the measured position \
             (e.g. Waves.wf_motion_surge)";
        input real "wave_motion_east" ["m"] (inputs.wave_motion[1]),
            "Wave-frequency motion eta_w,2 (east) (e.g. Waves.wf_motion_sway)";
        input real "wave_motion_yaw" ["rad"] (inputs.wave_motion[2]),
            "Wave-frequency yaw motion eta_w,3 (e.g. Waves.wf_motion_yaw)";
        output real "x" ["m"] (|m| m.out().eta[0]), "LF north position";
        output real "y" ["m"] (|m| m.out().eta[1]), "LF east position";
        output real "heading" ["rad"] (|m| m.out().eta[2]),
            "LF heading psi from north, clockwise, continuous (not wrapped)";
        output real "heading_wrapped" ["rad"] (|m| m.out().heading_wrapped),
            "LF heading wrapped to (-pi, pi]";
        output real "surge_velocity" ["m/s"] (|m| m.out().nu[0]), "LF body velocity u";
        output real "sway_velocity" ["m/s"] (|m| m.out().nu[1]), "LF body velocity v";
        output real "yaw_rate" ["rad/s"] (|m| m.out().nu[2]), "LF yaw rate r";
        output real "measured_x" ["m"] (|m| m.out().measured[0]),
            "Measured north position y_1 = x + eta_w,1 (wave input of the last step)";
        output real "measured_y" ["m"] (|m| m.out().measured[1]),
            "Measured east position y_2 = y + eta_w,2";
        output real "measured_heading" ["rad"] (|m| m.out().measured[2]),
            "Measured heading y_3 = psi + eta_w,3";
    }
}

impl FmuModel for SupplyVesselFmu {
    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.outputs = None;
        let mut vessel = SupplyVessel::new(self.mass, self.damping).map_err(|e| e.to_string())?;
        check_positive("max_substep", self.max_substep)?;
        vessel.max_substep = self.max_substep;
        self.vessel = vessel;
        self.keep_outputs();
        Ok(())
    }

    fn calculate_outputs(&mut self) {
        self.keep_outputs();
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        self.vessel.step(&self.inputs, h);
        self.keep_outputs();
        Ok(())
    }

    fn internal_steps(&self, _t: f64, h: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        let max_substep = self.vessel.max_substep;
        each("max_substep", max_substep, passes(h, max_substep));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_the_fmu_parameter_and_value() {
        let mut m = SupplyVesselFmu::default();
        m.mass[1][1] = -2.0;
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
