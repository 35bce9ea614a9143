//! SteeringGear reference case.

use models::steering_gear::{SteeringGear, SteeringGearParams};
use std::io::Write;

/// Columns: `time`; `rudder_command`, the input set at `time` and held until the next row;
/// the outputs at `time` as an importer samples them before setting that row's input (FMPy's
/// order: sample, apply input, step). Row 0 holds the outputs after initialization.
pub fn sine(out: &mut dyn Write) -> std::io::Result<()> {
    let h = 0.01;
    let n = 3000;
    let command = |t: f64| 0.5 * (0.8 * t).sin();
    let mut gear = SteeringGear::new(SteeringGearParams::default(), 0.0).expect("valid preset");
    writeln!(
        out,
        "time,rudder_command,rudder_angle,rudder_rate,rate_saturated_time"
    )?;
    gear.set_command(command(0.0));
    for k in 0..=n {
        let t = k as f64 * h;
        let cmd = command(t);
        writeln!(
            out,
            "{t:?},{cmd:?},{:?},{:?},{:?}",
            gear.angle(),
            gear.rate(),
            gear.rate_saturated_time()
        )?;
        let next = (k + 1) as f64 * h;
        gear.step(cmd, next - t);
    }
    Ok(())
}
