//! `Manoeuvre` FMU: the rudder-command generator of the standard manoeuvres
//! (`models::manoeuvre::ManoeuvreGenerator`: step / turning circle, zig-zag, pull-out) as an
//! FMI 2.0 co-simulation FMU. No physics here: the variable table maps the generator onto FMI
//! variables.
//!
//! Timing: the output `rudder_command` at communication point t is the generator's command for
//! the step starting at t, from the heading and yaw rate *currently set* (direct feedthrough),
//! evaluated on a copy of the generator, so that it is a pure function of the committed state,
//! t and the inputs (getting it twice, or after setting new inputs, never changes the FMU state).
//! `fmi2DoStep(t, h)` commits the generator's decision at t with the inputs held over the step.

use fmi2_export::FmuModel;
use models::error::{check_finite, check_non_negative, check_positive};
use models::hull::DEG;
use models::manoeuvre::{ManoeuvreGenerator, ManoeuvreKind};
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one generator instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ManoeuvreFmu {
    /// 1: turning circle (rudder step); 2: zig-zag; 3: pull-out.
    kind: i32,
    rudder_angle: f64,
    check_angle: f64,
    hold_time: f64,
    execute_time: f64,
    initial_command: f64,
    heading: f64,
    yaw_rate: f64,
    /// Communication point of the outputs.
    time: f64,
    /// The committed generator (decisions up to the last completed step).
    generator: ManoeuvreGenerator,
    /// Outputs at `time` for the current inputs.
    command: f64,
    executed: bool,
    heading_change: f64,
}

impl Default for ManoeuvreFmu {
    fn default() -> Self {
        let mut m = ManoeuvreFmu {
            kind: 1,
            rudder_angle: 35.0 * DEG,
            check_angle: 10.0 * DEG,
            hold_time: 60.0,
            execute_time: 10.0,
            initial_command: 0.0,
            heading: 0.0,
            yaw_rate: 0.0,
            time: 0.0,
            generator: ManoeuvreGenerator::new(
                ManoeuvreKind::TurningCircle { rudder: 35.0 * DEG },
                10.0,
                0.0,
            ),
            command: 0.0,
            executed: false,
            heading_change: 0.0,
        };
        m.generator = m.build().expect("valid defaults");
        m.refresh();
        m
    }
}

impl ManoeuvreFmu {
    /// The generator the parameters describe; the error names the parameter and its value.
    pub fn build(&self) -> Result<ManoeuvreGenerator, String> {
        let (rudder, check, hold) = (self.rudder_angle, self.check_angle, self.hold_time);
        for (name, v) in [
            ("rudder_angle", rudder),
            ("execute_time", self.execute_time),
            ("initial_command", self.initial_command),
        ] {
            check_finite(name, v)?;
        }
        let kind = match self.kind {
            1 => ManoeuvreKind::TurningCircle { rudder },
            2 => {
                check_positive("check_angle", check)?;
                ManoeuvreKind::ZigZag { rudder, check }
            }
            3 => {
                check_non_negative("hold_time", hold)?;
                ManoeuvreKind::PullOut { rudder, hold }
            }
            v => Err(format!("parameter kind = {v} must be 1, 2 or 3"))?,
        };
        let (execute, initial) = (self.execute_time, self.initial_command);
        Ok(ManoeuvreGenerator::new(kind, execute, initial))
    }

    /// Outputs at `time` from the committed generator and the current inputs.
    fn refresh(&mut self) {
        let mut g = self.generator.clone();
        self.command = g.command(self.time, self.heading, self.yaw_rate);
        self.executed = g.psi_execute().is_some();
        self.heading_change = g.psi_execute().map_or(0.0, |p| self.heading - p);
    }
}

fmi2_export::fmu! {
    ManoeuvreFmu => "Manoeuvre",
    description: "Rudder-command generator of the standard manoeuvring \
        tests from the ship's heading: rudder step / turning circle, zig-zag a/b, pull-out \
        (IMO MSC.137(76), ITTC; MSS turncircle.m / zigzag.m)",
    experiment: (0.0, 300.0, 0.1),
    documentation: "documentation.html",
    variables: {
        fixed int(1, 3) "kind" (kind),
            "1: rudder step / turning circle (rudder_angle from execute_time on); 2: zig-zag a/b \
            (a = rudder_angle, b = check_angle); 3: pull-out (rudder_angle for hold_time, then 0)";
        fixed real "rudder_angle" ["rad"] (rudder_angle),
            "Rudder angle of the manoeuvre (zig-zag: a; negative for a port-first test); default 35 deg";
        fixed real "check_angle" ["rad"] (check_angle).min(0.0),
            "Zig-zag switching heading b (> 0): the rudder reverses when the heading change from the \
            execute heading reaches +-b with the yaw rate in the same direction; default 10 deg";
        fixed real "hold_time" ["s"] (hold_time).min(0.0),
            "Pull-out: time the rudder is held after execute before it returns to 0; default 60 s";
        fixed real "execute_time" ["s"] (execute_time),
            "Execute time t_e (the command switches at t >= t_e; the heading at t_e is latched as the \
            original course); default 10 s";
        fixed real "initial_command" ["rad"] (initial_command),
            "Command before execute (e.g. Mariner.trim_rudder_command for a run from the trimmed course)";
        input real "heading" ["rad"] (heading), "Ship heading psi, continuous (not wrapped)";
        input real "yaw_rate" ["rad/s"] (yaw_rate), "Ship yaw rate r";
        output real "rudder_command" ["rad"] (command),
            "Rudder command for the step starting at the current communication point (direct \
            feedthrough from heading and yaw_rate)";
        output real "heading_change" ["rad"] (heading_change),
            "Heading change psi - psi_e from the execute heading (0 before execute)";
        output bool "executed" (executed), "The manoeuvre has been executed (t >= execute_time)";
    }
}

impl FmuModel for ManoeuvreFmu {
    fn initialize(&mut self, start_time: f64) -> Result<(), String> {
        self.generator = self.build()?;
        self.time = start_time;
        self.refresh();
        Ok(())
    }

    fn calculate_outputs(&mut self) {
        self.refresh();
    }

    fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        self.generator.command(t, self.heading, self.yaw_rate);
        self.time = t + h;
        self.refresh();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_the_fmu_parameter_and_value() {
        let mut m = ManoeuvreFmu {
            kind: 2,
            check_angle: 0.0,
            ..Default::default()
        };
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("check_angle = 0"), "{e}");
        let mut m = ManoeuvreFmu {
            kind: 0,
            ..Default::default()
        };
        let e = m.initialize(0.0).unwrap_err();
        assert!(e.contains("kind = 0"), "{e}");
    }

    /// Getting the output (with any inputs) never changes the committed generator.
    #[test]
    fn output_is_a_pure_function_of_state_time_and_inputs() {
        let mut m = ManoeuvreFmu {
            kind: 2,
            ..Default::default()
        };
        m.initialize(0.0).unwrap();
        for k in 0..200 {
            m.do_step(k as f64 * 0.1, 0.1).unwrap();
        }
        let before = m.generator.clone();
        m.heading = 1.0;
        m.yaw_rate = 0.1;
        m.calculate_outputs();
        assert_eq!(m.command, -m.rudder_angle.abs());
        m.heading = 0.0;
        m.calculate_outputs();
        assert_eq!(m.command, m.rudder_angle);
        assert_eq!(m.generator, before);
    }
}
