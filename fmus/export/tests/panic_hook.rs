//! Issue 19: a panic inside an FMI call goes to the instance's logger, not to the host's
//! stderr. The FMU's panic hook stays silent for a panic inside an FMI call of its library and
//! hands every other panic to the hook it replaced. One test in its own binary: a panic hook is
//! process-wide, so the order (host hook first, then the FMU's) must be this test's alone.

use fmi2::*;
use fmi2_export::testing::{functions, Harness};
use fmi2_export::FmuModel;
use serde::{Deserialize, Serialize};
use std::panic::catch_unwind;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

#[derive(Clone, Debug, Default, Serialize, Deserialize)]
struct Panicky {
    panic_at: f64,
    y: f64,
}

fmi2_export::fmu_description! {
    Panicky => "Panicky",
    description: "panics in do_step",
    experiment: (0.0, 1.0, 0.1),
    documentation_html: "<p>test</p>",
    variables: {
        tunable real "panic_at" ["s"] (panic_at), "panic in a step starting at or after this";
        output real "y" (y), "steps taken";
    }
}

impl FmuModel for Panicky {
    fn initialize(&mut self, _t: f64) -> Result<(), String> {
        Ok(())
    }
    fn do_step(&mut self, t: f64, _h: f64) -> Result<(), String> {
        if t >= self.panic_at {
            panic!("deliberate panic at t = {t}");
        }
        self.y += 1.0;
        Ok(())
    }
}

#[test]
fn a_panic_in_an_fmi_call_is_logged_and_kept_off_the_host_hook() {
    // The host's hook, counting the panics it sees (in place of printing them to stderr).
    let host_saw = Arc::new(AtomicUsize::new(0));
    let seen = host_saw.clone();
    std::panic::set_hook(Box::new(move |_| {
        seen.fetch_add(1, Ordering::SeqCst);
    }));
    let mut fmu = Harness::<Panicky>::instantiate(functions::<Panicky>(), "p");
    fmu.set("panic_at", 0.1).initialize(0.0);
    fmu.step(0.0, 0.1);
    assert_eq!(fmu.try_step(0.1, 0.1), fmi2Error);
    let line = fmu.log().last();
    let expected = "fmi2DoStep: internal error (panic: deliberate panic at t = 0.1) at \
                    fmus/export/tests/panic_hook.rs:";
    assert!(line.starts_with(expected), "{line}");
    assert!(
        line.ends_with(
            "; the instance is in the Error state (fmi2Reset, fmi2SetFMUstate or fmi2FreeInstance)"
        ),
        "{line}"
    );
    assert_eq!(fmu.log().lines().last().map(|l| l.0), Some(fmi2Error));
    assert_eq!(
        host_saw.load(Ordering::SeqCst),
        0,
        "the host's hook saw the FMU's panic"
    );
    // A panic outside an FMI call (here the host's own) still reaches the host's hook, also on
    // the thread that made FMI calls.
    assert!(catch_unwind(|| panic!("the host's own panic")).is_err());
    assert_eq!(host_saw.load(Ordering::SeqCst), 1);
    // And inside the next FMI call the FMU's hook is silent again.
    assert_eq!(fmu.reset(), fmi2OK);
    fmu.set("panic_at", 0.0).initialize(0.0);
    assert_eq!(fmu.try_step(0.0, 0.1), fmi2Error);
    assert!(fmu.log().last().contains("deliberate panic at t = 0"));
    assert_eq!(host_saw.load(Ordering::SeqCst), 1);
}
