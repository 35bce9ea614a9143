//! HeadingAutopilot through the `fmi2*` symbols its crate exports: the checks every FMU runs, and
//! the value references that system files use.

fmi2_export::fmu_tests!(heading_autopilot_fmu::HeadingAutopilotFmu);

#[test]
fn value_references_are_pinned() {
    let fmu = fmu();
    assert_eq!(fmu.vr("heading"), 14);
    assert_eq!(fmu.vr("rudder_command"), 16);
}

use fmi2_export::fmi2::fmi2OK;
use models::controllers::loop_shaped::presets::CONTAINER_SHIP_PRESET_SPEED;
use models::controllers::loop_shaped::{HeadingAutopilot, HeadingDesign};

/// `preset` is appended at the end of the table: the value references before it are unchanged.
#[test]
fn preset_is_the_last_variable() {
    let mut fmu = fmu();
    assert_eq!(fmu.vr("preset"), 19);
    assert_eq!(fmu.vr("heading_reference_used"), 18);
    fmu.setup(0.0, None);
    fmu.enter_initialization();
    assert_eq!(fmu.get::<i32>("preset"), 0);
}

/// Rudder commands of the FMU over 200 steps of 0.5 s on a heading that answers slowly, with
/// `preset` set to `preset` (None: not set).
fn commands(preset: Option<i32>) -> Vec<u64> {
    let mut fmu = fmu();
    assert_eq!(fmu.setup(0.0, None), fmi2OK);
    assert_eq!(fmu.enter_initialization(), fmi2OK);
    if let Some(p) = preset {
        fmu.set("preset", p);
    }
    fmu.set("heading_reference", 0.2);
    assert_eq!(fmu.exit_initialization(), fmi2OK);
    (0..200)
        .map(|k| {
            fmu.set("heading", 0.001 * k as f64);
            fmu.step(0.5 * k as f64, 0.5);
            fmu.real("rudder_command").to_bits()
        })
        .collect()
}

/// The same loop on the model directly.
fn model_commands(design: HeadingDesign) -> Vec<u64> {
    let mut ap = HeadingAutopilot::new(design).unwrap();
    ap.start(0.0, 0.2);
    (0..200)
        .map(|k| {
            ap.step(0.001 * k as f64, 0.2, 0.5);
            ap.command().to_bits()
        })
        .collect()
}

/// preset = 1 (DDG-51) gives the defaults' commands bit for bit; preset = 2 gives the model's
/// container-ship design bit for bit, and other commands than the DDG-51's.
#[test]
fn presets_give_their_designs() {
    let default = commands(None);
    assert_eq!(default, model_commands(HeadingDesign::default()));
    assert_eq!(commands(Some(0)), default);
    assert_eq!(commands(Some(1)), default);
    let container = commands(Some(2));
    let design = HeadingDesign::container_ship(CONTAINER_SHIP_PRESET_SPEED).unwrap();
    assert_eq!(container, model_commands(design));
    assert_ne!(container, default);
}

/// After initialization with preset = 2 the design parameters read the preset's values.
#[test]
fn preset_values_read_back() {
    let mut fmu = fmu();
    fmu.setup(0.0, None);
    fmu.enter_initialization();
    fmu.set("preset", 2);
    assert_eq!(fmu.exit_initialization(), fmi2OK);
    assert_eq!(fmu.real("ship_length"), 175.0);
    assert_eq!(fmu.real("ship_speed"), 7.0);
    assert_eq!(fmu.real("gear_pole"), 25.0);
    assert!((fmu.real("nomoto_k") - 2.920998).abs() < 1e-5);
    assert!((fmu.real("command_limit") - 10f64.to_radians()).abs() < 1e-15);
}

/// A design parameter set to neither its default nor the preset's value conflicts with the
/// preset: initialization is refused, whichever is set first; the preset's own value is
/// accepted.
#[test]
fn conflicting_design_parameter_is_refused() {
    for preset_first in [true, false] {
        let mut fmu = fmu();
        fmu.setup(0.0, None);
        fmu.enter_initialization();
        if preset_first {
            fmu.set("preset", 2);
            fmu.set("ship_speed", 8.0);
        } else {
            fmu.set("ship_speed", 8.0);
            fmu.set("preset", 2);
        }
        assert_ne!(fmu.exit_initialization(), fmi2OK);
        assert!(fmu.log().contains("preset = 2 sets ship_speed = 7"));
    }
    let mut fmu = fmu();
    fmu.setup(0.0, None);
    fmu.enter_initialization();
    fmu.set("preset", 2);
    fmu.set("ship_length", 175.0);
    assert_eq!(fmu.exit_initialization(), fmi2OK);
}
