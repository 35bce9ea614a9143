//! `FirstOrderLag`: the minimal example FMU of `docs/ADDING_AN_FMU.md`, a first-order lag
//! `T dy/dt = K u - y` advanced exactly for an input held over the step (zero-order hold):
//! `y(t + h) = a y(t) + (1 - a) K u` with `a = exp(-h/T)`.
//!
//! A real FMU keeps its equations in `models/` and only maps them onto FMI variables here; the
//! model is inline in this example to keep it in one file.

use fmi2_export::FmuModel;
use serde::{Deserialize, Serialize};

/// Parameters, input and state of one instance; `Default` holds the start values.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FirstOrderLag {
    gain: f64,
    time_constant: f64,
    initial_output: f64,
    input: f64,
    output: f64,
}

impl Default for FirstOrderLag {
    fn default() -> Self {
        FirstOrderLag {
            gain: 1.0,
            time_constant: 2.0,
            initial_output: 0.0,
            input: 0.0,
            output: 0.0,
        }
    }
}

fmi2_export::fmu! {
    FirstOrderLag => "FirstOrderLag",
    description: "First-order lag T dy/dt = K u - y (the minimal example FMU)",
    experiment: (0.0, 10.0, 0.1),
    // y is the state: it does not depend directly on u.
    direct_feedthrough: false,
    documentation: "documentation.html",
    variables: {
        tunable real "gain" (gain), "Static gain K";
        tunable real "time_constant" ["s"] (time_constant).min(0.0), "Time constant T (> 0)";
        fixed real "initial_output" (initial_output), "Output y at the start time";
        input real "u" (input), "Input u";
        output real "y" (output), "Output y";
    }
}

impl FirstOrderLag {
    fn check(&self) -> Result<(), String> {
        match self.time_constant > 0.0 {
            true => Ok(()),
            false => Err(format!(
                "time_constant = {} must be > 0",
                self.time_constant
            )),
        }
    }
}

impl FmuModel for FirstOrderLag {
    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        self.check()?;
        self.output = self.initial_output;
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.check()
    }

    fn do_step(&mut self, _t: f64, h: f64) -> Result<(), String> {
        let a = (-h / self.time_constant).exp();
        self.output = a * self.output + (1.0 - a) * self.gain * self.input;
        Ok(())
    }
}
