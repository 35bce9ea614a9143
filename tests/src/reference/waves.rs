//! Waves reference cases: the model of `models::disturbances::waves` driven with the inputs the
//! Python tests give the `Waves` FMU (parameters as start values: `roll_gain` = 1e6,
//! `yaw_gain` = 3e5, `wave_direction` = 0.4 rad, `seed` = 5; the shaping case also
//! `realisation` = 2, `shaping_form` = 1).

use models::disturbances::waves::{encounter_angle, Realisation, ShapingForm, WaveParams, Waves};
use std::io::Write;

/// Ship speed and heading inputs of the cases.
pub fn inputs(t: f64) -> (f64, f64) {
    (6.0 + 0.01 * t, 0.3 * (0.05 * t).sin())
}

fn run(out: &mut dyn Write, p: WaveParams) -> std::io::Result<()> {
    let h = 0.1;
    let n = 3000;
    let mut w = Waves::new(p, 0.0).expect("valid parameters");
    writeln!(
        out,
        "time,ship_speed,heading,wave_elevation,roll_moment,yaw_moment,wf_motion_surge,wf_motion_yaw"
    )?;
    // inputs at the start time are applied before initialization; afterwards an importer samples
    // the outputs (direct feedthrough of the held inputs of the previous row), then sets the row's
    // inputs and steps.
    let (u0, psi0) = inputs(0.0);
    w.set_inputs(u0, encounter_angle(0.4, psi0));
    for k in 0..=n {
        let t = k as f64 * h;
        let (u, psi) = inputs(t);
        let m = w.wf_motion();
        writeln!(
            out,
            "{t:?},{u:?},{psi:?},{:?},{:?},{:?},{:?},{:?}",
            w.elevation(),
            w.roll_moment(),
            w.yaw_moment(),
            m[0],
            m[2]
        )?;
        w.set_inputs(u, encounter_angle(0.4, psi));
        let next = (k + 1) as f64 * h;
        w.advance_to(next);
    }
    Ok(())
}

fn base() -> WaveParams {
    WaveParams {
        seed: 5,
        roll_gain: 1.0e6,
        yaw_gain: 3.0e5,
        ..WaveParams::default()
    }
}

/// Sum of sinusoids (default realisation), 300 s at h = 0.1 s.
pub fn sum_of_sinusoids(out: &mut dyn Write) -> std::io::Result<()> {
    run(out, base())
}

/// Shaping filter, low-pass form [Klugt1987, Fig. 2.10], 300 s at h = 0.1 s.
pub fn shaping_filter(out: &mut dyn Write) -> std::io::Result<()> {
    run(
        out,
        WaveParams {
            realisation: Realisation::ShapingFilter,
            shaping_form: ShapingForm::LowPass,
            ..base()
        },
    )
}
