//! Issue 19, "steps that end", on the export layer with a small model: the bound on the work of
//! one `fmi2DoStep`, the finiteness check of the outputs after initialization and after each
//! step, and the validation of restored FMU states (`fmi2SetFMUstate`,
//! `fmi2DeSerializeFMUstate`). No test is timed: a step that would run for hours without the
//! bound ends with the bound's error, which is what the tests assert.

use fmi2::*;
use fmi2_export::testing::{functions, Harness};
use fmi2_export::{passes, FmuModel};
use serde::{Deserialize, Serialize};

/// x' = 1 integrated in sub-steps of at most `dt` (a copy of `max_substep` taken at
/// initialization, as the models keep their grids' steps); `ratio` = 1 / divisor (inf for the
/// declared minimum 0); `y` becomes NaN in a step that starts at or after `nan_at`.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct Stepper {
    max_substep: f64,
    divisor: f64,
    nan_at: f64,
    dt: f64,
    x: f64,
    substeps: f64,
    y: f64,
}

impl Default for Stepper {
    fn default() -> Self {
        Stepper {
            max_substep: 1e-3,
            divisor: 1.0,
            nan_at: 1e9,
            dt: 1e-3,
            x: 0.0,
            substeps: 0.0,
            y: 0.0,
        }
    }
}

fmi2_export::fmu_description! {
    Stepper => "Stepper",
    description: "sub-stepping test model",
    experiment: (0.0, 10.0, 0.1),
    documentation_html: "<p>test</p>",
    variables: {
        fixed real "max_substep" ["s"] (max_substep).min(1e-4), "largest sub-step";
        fixed real "divisor" (divisor).min(0.0), "ratio = 1 / divisor";
        tunable real "nan_at" ["s"] (nan_at), "y is NaN from a step starting at or after this";
        output real "x" ["s"] (x), "integral of 1";
        output real "substeps" (substeps), "sub-steps taken so far";
        output real "ratio" (|m| 1.0 / m.divisor), "1 / divisor";
        output real "y" (y), "NaN after nan_at";
    }
}

impl FmuModel for Stepper {
    fn initialize(&mut self, _t: f64) -> Result<(), String> {
        self.dt = self.max_substep;
        Ok(())
    }
    fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        let n = (h / self.dt).ceil().max(1.0);
        let mut k = 0.0;
        while k < n {
            self.x += h / n;
            self.substeps += 1.0;
            k += 1.0;
        }
        if t >= self.nan_at {
            self.y = f64::NAN;
        }
        Ok(())
    }
    fn internal_steps(&self, _t: f64, h: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        each("max_substep", self.dt, passes(h, self.dt));
    }
}

fn stepper() -> Harness<Stepper> {
    Harness::instantiate(functions::<Stepper>(), "s")
}

#[test]
fn a_step_of_more_than_a_million_sub_steps_is_refused_and_the_instance_keeps_going() {
    let mut fmu = stepper();
    fmu.initialize(0.0);
    // 1e9 s in sub-steps of 1 ms: 1e12 passes (hours of work) is refused before it starts.
    assert_eq!(fmu.try_step(0.0, 1e9), fmi2Error);
    assert_eq!(
        fmu.log().last(),
        "fmi2DoStep at t = 0, h = 1000000000: instance \"s\": communicationStepSize = \
         1000000000 s would take 1.000e12 internal steps (1.000e12 of max_substep = 0.001 s); \
         at most 1e6 per fmi2DoStep: use a smaller communication step size or a larger \
         max_substep"
    );
    assert_eq!(fmu.reals(&["x", "substeps"]), [0.0, 0.0]);
    // The refusal left the instance in Step Mode at t = 0: exactly 1e6 passes are allowed.
    fmu.step(0.0, 1000.0);
    assert_eq!(fmu.real("substeps"), 1e6);
    assert_eq!(fmu.try_step(1000.0, 1000.1), fmi2Error);
    fmu.step(1000.0, 0.5);
    assert_eq!(fmu.real("substeps"), 1e6 + 500.0);
}

#[test]
fn a_non_finite_output_after_initialization_or_a_step_is_an_error_naming_it() {
    // The declared minimum divisor = 0 gives ratio = inf at initialization.
    let mut fmu = stepper();
    fmu.set("divisor", 0.0);
    assert_eq!(fmu.setup(0.0, None), fmi2OK);
    assert_eq!(fmu.enter_initialization(), fmi2OK);
    assert_eq!(fmu.exit_initialization(), fmi2Error);
    assert_eq!(
        fmu.log().last(),
        "fmi2ExitInitializationMode at t = 0: instance \"s\": output \"ratio\" = inf is not a \
         finite number (parameters or inputs outside what the model can handle?)"
    );
    assert_eq!(fmu.try_step(0.0, 0.1), fmi2Error);
    assert!(fmu.log().last().contains("not allowed in state Error"));
    // y turns NaN in the step from t = 0.2.
    let mut fmu = stepper();
    fmu.set("nan_at", 0.2).initialize(0.0);
    fmu.step(0.0, 0.1).step(0.1, 0.1);
    assert_eq!(fmu.try_step(0.2, 0.1), fmi2Error);
    assert_eq!(
        fmu.log().last(),
        "fmi2DoStep at t = 0.2, h = 0.1: instance \"s\": output \"y\" = NaN is not a finite \
         number (parameters or inputs outside what the model can handle?)"
    );
    assert_eq!(fmu.terminate(), fmi2Error);
}

/// The serialized state after two steps, and the byte offsets of every copy of `x` in it.
fn serialized(fmu: &mut Harness<Stepper>, x: f64) -> (Vec<u8>, Vec<usize>) {
    fmu.initialize(0.0).step(0.0, 0.1).step(0.1, 0.1);
    let state = fmu.get_state();
    let bytes = fmu.serialize(state);
    fmu.free_state(state);
    let at = (0..bytes.len() - 7)
        .filter(|&i| bytes[i..i + 8] == x.to_le_bytes())
        .collect();
    (bytes, at)
}

fn patched(bytes: &[u8], at: usize, x: f64) -> Vec<u8> {
    let mut b = bytes.to_vec();
    b[at..at + 8].copy_from_slice(&x.to_le_bytes());
    b
}

#[test]
fn a_deserialized_state_is_checked_like_the_setters_and_the_step() {
    let mut fmu = stepper();
    let (bytes, at) = serialized(&mut fmu, 1e-3);
    // max_substep (the parameter) and dt (its copy), in field order.
    assert_eq!(at.len(), 2, "{at:?}");
    for (offset, value, message) in [
        (
            at[0],
            1.5e-40,
            "\"max_substep\" = 1.5e-40 is not a finite number in [0.0001, inf]",
        ),
        (
            at[0],
            f64::NAN,
            "\"max_substep\" = NaN is not a finite number in [0.0001, inf]",
        ),
        (
            at[1],
            1.5e-40,
            "internal step max_substep = 1.5e-40 s is below its declared minimum 0.0001 s",
        ),
        (
            at[1],
            0.0,
            "internal step max_substep = 0.0 s is not a positive number",
        ),
        (
            at[1],
            -1.0,
            "internal step max_substep = -1.0 s is not a positive number",
        ),
    ] {
        let (status, state) = fmu.deserialize(&patched(&bytes, offset, value));
        assert_eq!(status, fmi2Error, "{value} at {offset}");
        assert!(state.0.is_null());
        let expected =
            format!("fmi2DeSerializeFMUstate: instance \"s\": the FMU state is refused: {message}");
        assert_eq!(fmu.log().last(), expected);
    }
    // The time: fmi2DoStep would take a NaN communication point from it.
    let (_, at) = serialized(&mut stepper(), 0.2);
    for value in [f64::NAN, f64::INFINITY] {
        let (status, _) = fmu.deserialize(&patched(&bytes, *at.last().unwrap(), value));
        assert_eq!(status, fmi2Error);
        assert!(
            fmu.log()
                .last()
                .ends_with(&format!("time = {value} is not finite")),
            "{}",
            fmu.log().last()
        );
    }
    // The unchanged bytes are accepted and restore the state exactly.
    let (status, state) = fmu.deserialize(&bytes);
    assert_eq!(status, fmi2OK);
    let x = fmu.real("x");
    fmu.step(0.2, 0.1);
    assert_eq!(fmu.set_state(state), fmi2OK);
    assert_eq!(fmu.reals(&["x", "substeps"]), [x, 200.0]);
    fmu.free_state(state);
}

#[test]
fn a_state_pointer_written_over_is_checked_by_set_fmu_state() {
    let mut fmu = stepper();
    fmu.initialize(0.0).step(0.0, 0.1);
    let x = fmu.real("x");
    let state = fmu.get_state();
    // What an importer that writes through the opaque pointer (or a memory error) could leave:
    // max_substep and its copy inside the state box, found by their value, set to 1e-300.
    let size = std::mem::size_of::<u64>() + 2 * std::mem::size_of::<Stepper>();
    let copies = unsafe {
        let p = state.0 as *mut u8;
        let found: Vec<usize> = (0..size)
            .filter(|&i| std::slice::from_raw_parts(p.add(i), 8) == 1e-3f64.to_le_bytes())
            .collect();
        for &i in &found {
            std::ptr::copy_nonoverlapping(1e-300f64.to_le_bytes().as_ptr(), p.add(i), 8);
        }
        found.len()
    };
    assert_eq!(copies, 2);
    assert_eq!(fmu.set_state(state), fmi2Error);
    assert!(
        fmu.log().last().contains(
            "fmi2SetFMUstate: instance \"s\": the FMU state is refused: \"max_substep\" = 1e-300"
        ),
        "{}",
        fmu.log().last()
    );
    // The instance is as it was.
    assert_eq!(fmu.real("x"), x);
    fmu.step(0.1, 0.1);
    fmu.free_state(state);
}
