//! SupplyVessel reference case (models::hull::supply_vessel).

use models::hull::supply_vessel::{SupplyVessel, SupplyVesselInputs};
use std::io::Write;

/// Northern Clipper with time-varying thrust, constant bias and wave-frequency motion;
/// h = 0.2 s, 600 s.
pub fn thrust(out: &mut dyn Write) -> std::io::Result<()> {
    let h = 0.2;
    let n = 3000;
    let mut vessel = SupplyVessel::northern_clipper();
    writeln!(
        out,
        "time,surge_force,sway_force,yaw_moment,bias_north,bias_east,bias_yaw,wave_motion_north,\
         wave_motion_east,wave_motion_yaw,x,y,heading,surge_velocity,sway_velocity,yaw_rate,\
         measured_x,measured_y,measured_heading"
    )?;
    for k in 0..=n {
        let t = k as f64 * h;
        let u = SupplyVesselInputs {
            tau: [
                1e5 * (0.01 * t).sin(),
                5e4 * (0.02 * t).cos(),
                1e6 * (0.015 * t).sin(),
            ],
            bias: [2e4, -1e4, 5e5],
            wave_motion: [
                0.5 * (0.8 * t).sin(),
                0.3 * (0.7 * t).cos(),
                0.02 * (0.9 * t).sin(),
            ],
        };
        let o = vessel.outputs();
        write!(out, "{t:?}")?;
        for v in u.tau.iter().chain(&u.bias).chain(&u.wave_motion) {
            write!(out, ",{v:?}")?;
        }
        for v in o.eta.iter().chain(&o.nu).chain(&o.measured) {
            write!(out, ",{v:?}")?;
        }
        writeln!(out)?;
        let next = (k + 1) as f64 * h;
        vessel.step(&u, next - t);
    }
    Ok(())
}
