//! A test fixture for the export layer (issue 19: "panics are reported through the FMU's
//! logger, not printed to the host's stderr"): an FMU whose output getter panics when its input
//! is 13 and whose step panics when it is 14. Built as a `cdylib` like every FMU, it has its own copy of the standard library and
//! its own panic hook, which is what `tests/cdylib_panic.rs` loads and checks. It is not an FMU
//! of the catalogue (no `[package.metadata.fmu]`: `cargo xtask build-fmus` leaves it out).

use fmi2_export::FmuModel;
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct PanicProbe {
    pub u: f64,
}

/// `u`, or a panic when `u` is 13 (the fixture's planted fault, in a getter: the export layer's
/// most frequent call).
fn echo(m: &PanicProbe) -> f64 {
    if m.u == 13.0 {
        panic!("planted panic in a getter: u = 13");
    }
    m.u
}

fmi2_export::fmu! {
    PanicProbe => "PanicProbe",
    description: "Test fixture: y = u, and a panic in fmi2GetReal of y when u = 13 and in fmi2DoStep when u = 14",
    experiment: (0.0, 1.0, 0.1),
    documentation_html: "<p>Test fixture of the export layer's panic hook.</p>",
    variables: {
        input real "u" (u), "Input";
        output real "y" (|m| echo(m)).depends_on(&["u"]), "u; a panic when u = 13";
    }
}

impl FmuModel for PanicProbe {
    fn initialize(&mut self, _start_time: f64) -> Result<(), String> {
        Ok(())
    }

    /// A panic when `u` is 14 (the planted fault of a call the export layer marks).
    fn do_step(&mut self, _t: f64, _h: f64) -> Result<(), String> {
        if self.u == 14.0 {
            panic!("planted panic in a step: u = 14");
        }
        Ok(())
    }
}
