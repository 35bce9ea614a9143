//! The Bode chart: gain [dB] and unwrapped phase [deg] over a logarithmic frequency axis, one
//! curve per named response, with the margins marked when given.

use crate::error::{Error, Result};
use crate::plot::{color, create_parent_dir, drawing_error, register_font, Area};
use plotters::prelude::*;
use std::path::Path;

/// A named response over ω (or over the amplitude, for a describing function): (name, x,
/// gain [dB], phase [deg]).
pub struct Curve {
    pub name: String,
    pub omega: Vec<f64>,
    pub gain_db: Vec<f64>,
    pub phase_deg: Vec<f64>,
}

/// A vertical marker (a crossover) on both panels.
pub struct Marker {
    pub omega: f64,
    pub label: String,
}

/// Writes the chart (1100 × 760 px) to `path`, over frequency [rad/s].
pub fn bode(path: &Path, title: &str, curves: &[Curve], markers: &[Marker]) -> Result<()> {
    chart(path, title, "frequency [rad/s]", curves, markers)
}

/// The same chart over another logarithmic axis (`x_desc`: the amplitude of a describing
/// function).
pub fn chart(
    path: &Path,
    title: &str,
    x_desc: &str,
    curves: &[Curve],
    markers: &[Marker],
) -> Result<()> {
    register_font();
    let path = &crate::output_path::writable(path)?;
    create_parent_dir(path)?;
    draw(path, (title, x_desc), curves, markers)
        .map_err(|e| Error::Other(format!("plot {}: {e}", path.display())))
}

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    match lo < hi {
        true => (lo, hi),
        false => (lo - 1.0, lo + 1.0),
    }
}

fn draw(
    path: &Path,
    (title, x_desc): (&str, &str),
    curves: &[Curve],
    markers: &[Marker],
) -> Result<()> {
    let root = BitMapBackend::new(path, (1100, 760)).into_drawing_area();
    root.fill(&WHITE).map_err(drawing_error)?;
    let root = root
        .titled(title, ("sans-serif", 20))
        .map_err(drawing_error)?;
    let (top, bottom) = root.split_vertically(root.dim_in_pixel().1 / 2);
    let w = range(curves.iter().flat_map(|c| c.omega.iter().copied()));
    let gain = |c: &Curve| c.gain_db.clone();
    let phase = |c: &Curve| c.phase_deg.clone();
    panel(&top, w, (x_desc, "gain [dB]"), curves, gain, markers)?;
    panel(&bottom, w, (x_desc, "phase [deg]"), curves, phase, markers)?;
    root.present().map_err(drawing_error)?;
    Ok(())
}

fn panel(
    area: &Area,
    (w0, w1): (f64, f64),
    (x_desc, y_desc): (&str, &str),
    curves: &[Curve],
    y: impl Fn(&Curve) -> Vec<f64>,
    markers: &[Marker],
) -> Result<()> {
    let (lo, hi) = range(curves.iter().flat_map(|c| y(c).into_iter()));
    let pad = (hi - lo) * 0.08;
    let mut chart = ChartBuilder::on(area)
        .margin(10)
        .margin_right(20)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d((w0..w1).log_scale(), (lo - pad)..(hi + pad))
        .map_err(drawing_error)?;
    chart
        .configure_mesh()
        .x_label_formatter(&|v| short(*v))
        .x_desc(x_desc)
        .y_desc(y_desc)
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(drawing_error)?;
    for (i, c) in curves.iter().enumerate() {
        let col = color(i);
        chart
            .draw_series(LineSeries::new(
                c.omega.iter().copied().zip(y(c)),
                col.stroke_width(2),
            ))
            .map_err(drawing_error)?
            .label(c.name.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2)));
    }
    for (i, m) in markers.iter().enumerate() {
        let col = color(curves.len() + i);
        chart
            .draw_series(LineSeries::new(
                [(m.omega, lo - pad), (m.omega, hi + pad)],
                col.stroke_width(1),
            ))
            .map_err(drawing_error)?
            .label(m.label.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(1)));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(drawing_error)?;
    Ok(())
}

/// A tick value with three significant digits and no trailing zeros (0.3, not
/// 0.30000000000000004).
fn short(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let decimals = (2 - v.abs().log10().floor() as i32).clamp(0, 12) as usize;
    let s = format!("{v:.decimals$}");
    match s.contains('.') {
        true => s.trim_end_matches('0').trim_end_matches('.').to_string(),
        false => s,
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn ticks_are_short() {
        assert_eq!(super::short(0.30000000000000004), "0.3");
        assert_eq!(super::short(0.00123456), "0.00123");
        assert_eq!(super::short(20.0), "20");
        assert_eq!(super::short(1.5), "1.5");
    }
}
