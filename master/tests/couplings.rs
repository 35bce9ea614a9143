//! `check` warns when a declared coupling has no effect: Waves declares (in its model
//! description's `shipsim` vendor annotations) that `roll_moment` is scaled by `roll_gain` and
//! `yaw_moment` by `yaw_gain`; a connected output whose gain is 0 (its default, or set so) is a
//! warning in `Plan::warnings`, and a nonzero gain or an unconnected output is not.
//! Uses our FMUs from $SHIPSIM_FMU_DIR (`cargo xtask build-fmus`); fails, never skips, without them.
mod common;
use common::*;
use shipsim::run::prepare;
use shipsim::system::System;

/// Waves driving a SteeringGear's rudder_command (any Real input will do) from `output`, with
/// `parameters` on the Waves instance; the warnings of the validated plan.
fn warnings(output: &str, parameters: &str) -> Vec<String> {
    let d = tempfile::tempdir().unwrap();
    for m in ["Waves", "SteeringGear"] {
        std::fs::copy(our_fmu(m), d.path().join(format!("{m}.fmu"))).unwrap();
    }
    let p = write_system(
        d.path(),
        "coupled.toml",
        &format!(
            r#"
[simulation]
stop_time = 1.0
step_size = 0.1
[[instances]]
name = "waves"
fmu = "Waves.fmu"
parameters = {{ {parameters} }}
[[instances]]
name = "gear"
fmu = "SteeringGear.fmu"
[[connections]]
from = "waves.{output}"
to = "gear.rudder_command"
convert = true
"#
        ),
    );
    let system = System::load(&p).unwrap();
    let (plan, _) = prepare(&system).unwrap();
    plan.warnings
}

fn about(warnings: &[String], gain: &str) -> Vec<String> {
    warnings
        .iter()
        .filter(|w| w.contains(&format!("'waves.{gain}' is 0")))
        .cloned()
        .collect()
}

#[test]
fn connected_output_with_a_zero_default_gain_warns() {
    let w = warnings("roll_moment", "seed = 1");
    let roll = about(&w, "roll_gain");
    assert_eq!(roll.len(), 1, "{w:?}");
    assert!(
        roll[0].contains(
            "'waves.roll_moment' is connected (waves.roll_moment -> gear.rudder_command) but its gain 'waves.roll_gain' is 0 (its default), so the connection carries only zeros; set roll_gain"
        ),
        "{}",
        roll[0]
    );
    // the line of the instance ([[instances]] of waves)
    assert!(roll[0].contains("coupled.toml:5:"), "{}", roll[0]);
    assert!(
        about(&w, "yaw_gain").is_empty(),
        "yaw_moment is not connected: {w:?}"
    );
}

#[test]
fn connected_output_with_a_gain_set_to_zero_warns() {
    let w = warnings("yaw_moment", "yaw_gain = 0.0");
    let yaw = about(&w, "yaw_gain");
    assert_eq!(yaw.len(), 1, "{w:?}");
    assert!(!yaw[0].contains("(its default)"), "{}", yaw[0]);
}

#[test]
fn nonzero_gain_or_unconnected_output_does_not_warn() {
    let w = warnings("roll_moment", "roll_gain = 0.03");
    assert!(about(&w, "roll_gain").is_empty(), "{w:?}");
    // wave_elevation is not gated: no coupling warning although both gains are 0
    let w = warnings("wave_elevation", "seed = 1");
    assert!(w.iter().all(|w| !w.contains("carries only zeros")), "{w:?}");
}
