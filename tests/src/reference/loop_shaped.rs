//! HeadingAutopilot and TrackController reference cases.

use models::controllers::loop_shaped::{
    HeadingAutopilot, HeadingDesign, HeadingReference, TrackChange, TrackController, TrackDesign,
};
use std::io::Write;

/// HeadingAutopilot, reference_mode = 1 (track change: turn_angle −π/2, turn_rate 0.05 rad/s,
/// leg_time 60 s, turn_start 10 s); the `heading` input is a lagging pseudo-response
/// 0.9·ψ_ref(t − 5 s) + 0.01 sin(0.7 t) (so both the ±30° limit and the linear range occur).
/// h = 0.05 s, 200 s. Columns: `time`, `heading` (set at `time`, held), then `rudder_command`,
/// `unlimited_command`, `heading_reference_used` as sampled before that row's input (row 0 after
/// initialization, which sees the row-0 input as FMPy applies it in initialization mode).
pub fn heading_track_change(out: &mut dyn Write) -> std::io::Result<()> {
    let h = 0.05;
    let n = 4000;
    let tc = TrackChange {
        start: 10.0,
        angle: -std::f64::consts::FRAC_PI_2,
        turn_rate: 0.05,
        leg: 60.0,
    };
    let heading = |t: f64| 0.9 * tc.heading(t - 5.0) + 0.01 * (0.7 * t).sin();
    let mut ap = HeadingAutopilot::new(HeadingDesign::default()).expect("valid design");
    ap.reference = HeadingReference::TrackChange;
    ap.track_change = tc;
    ap.start(heading(0.0), 0.0);
    writeln!(
        out,
        "time,heading,rudder_command,unlimited_command,heading_reference_used"
    )?;
    for k in 0..=n {
        let t = k as f64 * h;
        let psi = heading(t);
        writeln!(
            out,
            "{t:?},{psi:?},{:?},{:?},{:?}",
            ap.command(),
            ap.unlimited_command(),
            ap.heading_reference()
        )?;
        let next = (k + 1) as f64 * h;
        ap.step(psi, 0.0, next - t);
    }
    Ok(())
}

/// TrackController, reference_mode = 0: `cross_track_reference` = 20 m from 5 s (a step),
/// `cross_track` = 15 (1 − e^(−t/30)) + 0.5 sin(0.9 t) m. h = 0.05 s, 200 s. Columns: `time`,
/// `cross_track`, `cross_track_reference`, then `rudder_command`, `unlimited_command`.
pub fn track_offset(out: &mut dyn Write) -> std::io::Result<()> {
    let h = 0.05;
    let n = 4000;
    let reference = |t: f64| if t >= 5.0 { 20.0 } else { 0.0 };
    let y = |t: f64| 15.0 * (1.0 - (-t / 30.0).exp()) + 0.5 * (0.9 * t).sin();
    let mut tc = TrackController::new(TrackDesign::default()).expect("valid design");
    tc.start(reference(0.0));
    writeln!(
        out,
        "time,cross_track,cross_track_reference,rudder_command,unlimited_command"
    )?;
    for k in 0..=n {
        let t = k as f64 * h;
        let (yy, r) = (y(t), reference(t));
        writeln!(
            out,
            "{t:?},{yy:?},{r:?},{:?},{:?}",
            tc.command(),
            tc.unlimited_command()
        )?;
        let next = (k + 1) as f64 * h;
        tc.step(yy, r, next - t);
    }
    Ok(())
}
