//! Sensors reference case: `models::sensors` with the FMU's default parameters except
//! `seed` = 8 and `roll_sigma` = 0.3, driven with smooth true signals.

use models::sensors::{SensorParams, Sensors, CHANNELS, CHANNEL_NAMES};
use std::io::Write;

/// True value of channel `i` at `t`.
pub fn truth(t: f64) -> [f64; CHANNELS] {
    std::array::from_fn(|i| (i as f64 + 1.0) * (0.1 * t + 0.05 * i as f64).sin())
}

/// 60 s at h = 0.1 s (the 0.2349 s and 1 s sampling grids fall between communication points).
pub fn default_noise(out: &mut dyn Write) -> std::io::Result<()> {
    let h = 0.1;
    let n = 600;
    let mut p = SensorParams::default();
    p.seed = 8;
    p.channels[2].sigma = 0.3;
    let mut s = Sensors::new(p, 0.0, truth(0.0)).expect("valid parameters");
    let names = CHANNEL_NAMES.map(|(n, _)| n);
    let mut header = String::from("time");
    for n in names {
        header.push_str(&format!(",{n}"));
    }
    for n in names {
        header.push_str(&format!(",{n}_measured"));
    }
    writeln!(out, "{header}")?;
    for k in 0..=n {
        let t = k as f64 * h;
        let x = truth(t);
        // sampled before the row's inputs are set (importer order), then set, then step
        let mut row = format!("{t:?}");
        for v in x {
            row.push_str(&format!(",{v:?}"));
        }
        for i in 0..CHANNELS {
            row.push_str(&format!(",{:?}", s.measured(i)));
        }
        writeln!(out, "{row}")?;
        s.set_inputs(x);
        s.advance_to((k + 1) as f64 * h);
    }
    Ok(())
}
