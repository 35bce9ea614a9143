//! Waves through the `fmi2*` symbols its crate exports, as a C importer calls them: the checks
//! every FMU runs, and the FMU against `models::disturbances::waves` by variable name, with a
//! state snapshot restored.

use fmi2_export::fmi2::fmi2OK;
use models::disturbances::waves::{encounter_angle, WaveParams, Waves};

fmi2_export::fmu_tests!(waves_fmu::WavesFmu);

const OUTPUTS: [&str; 4] = [
    "wave_elevation",
    "roll_moment",
    "yaw_moment",
    "wf_motion_yaw",
];

/// Ship speed and heading at step `k`.
fn inputs(k: usize, h: f64) -> [f64; 2] {
    let t = k as f64 * h;
    [6.0 + 0.01 * k as f64, 0.3 * (0.05 * t).sin()]
}

#[test]
fn exported_api_reproduces_the_model_and_restores_states() {
    let mut fmu = fmu();
    assert_eq!(fmu.setup(0.0, None), fmi2OK);
    assert_eq!(fmu.enter_initialization(), fmi2OK);
    fmu.set("seed", 99i32)
        .set("roll_gain", 1.0e6)
        .set("yaw_gain", 3.0e5)
        .set("wave_direction", 0.4);
    assert_eq!(fmu.exit_initialization(), fmi2OK);

    let p = WaveParams {
        seed: 99,
        roll_gain: 1.0e6,
        yaw_gain: 3.0e5,
        ..WaveParams::default()
    };
    let mut model = Waves::new(p, 0.0).unwrap();
    let h = 0.1;
    // the state of t = 20 s restored and the rest repeated: bit-identical
    fmu.check_replay(400, 200, |fmu, k, replaying| {
        let t = k as f64 * h;
        let u = inputs(k, h);
        fmu.set("ship_speed", u[0]).set("heading", u[1]).step(t, h);
        let v = fmu.reals(&OUTPUTS);
        if !replaying {
            model.set_inputs(u[0], encounter_angle(0.4, u[1]));
            model.advance_to(t + h);
            let m = model.wf_motion();
            let expected = [
                model.elevation(),
                model.roll_moment(),
                model.yaw_moment(),
                m[2],
            ];
            assert_eq!(v, expected);
        }
        v
    });
    assert_eq!(fmu.terminate(), fmi2OK);
}

#[test]
fn model_identifier_and_elevation_are_declared() {
    let xml = fmi2_export::xml::model_description::<waves_fmu::WavesFmu>();
    assert!(xml.contains(r#"name="wave_elevation""#));
    assert!(xml.contains(r#"modelIdentifier="Waves""#));
}

/// The model description declares, for the tool "shipsim", that roll_moment is scaled by
/// roll_gain and yaw_moment by yaw_gain (FMI 2.0, sec. 2.2.6), between DefaultExperiment and
/// ModelVariables as the schema orders them; the master reads them back.
#[test]
fn couplings_are_annotated() {
    let xml = fmi2_export::xml::model_description::<waves_fmu::WavesFmu>();
    assert!(xml.contains(
        "  <VendorAnnotations>\n    <Tool name=\"shipsim\">\n      <Couplings>\n        \
         <Coupling output=\"roll_moment\" gain=\"roll_gain\"/>\n        \
         <Coupling output=\"yaw_moment\" gain=\"yaw_gain\"/>\n      </Couplings>\n    </Tool>\n  \
         </VendorAnnotations>\n  <ModelVariables>"
    ));
    let de = xml.find("<DefaultExperiment").unwrap();
    assert!(de < xml.find("<VendorAnnotations>").unwrap());
    let md = shipsim::model_description::ModelDescription::parse(&xml).unwrap();
    let pairs: Vec<(&str, &str)> = md
        .couplings()
        .iter()
        .map(|c| (c.output.as_str(), c.gain.as_str()))
        .collect();
    assert_eq!(
        pairs,
        [("roll_moment", "roll_gain"), ("yaw_moment", "yaw_gain")]
    );
}
