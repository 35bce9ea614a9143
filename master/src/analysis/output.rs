//! The analysis's files: tables (CSV and Parquet, the campaign tables' writers) and plots (a
//! Bode plot over a logarithmic frequency axis, a Nyquist plot with equal axes, the describing
//! function over a logarithmic amplitude axis), into one folder.

use super::bode::{bode, chart, Curve, Marker};
use super::{DescribingPoint, LoopPoint, Margins, OutputResponse, ResponsePoint};
use crate::campaign::table::{ColumnData, Table};
use crate::error::{Error, Result};
use crate::plot::{plot_figure, Series, Track};
use num_complex::Complex64;
use std::path::{Path, PathBuf};

/// The files written.
#[derive(Debug, Clone)]
pub struct Written {
    pub table: PathBuf,
    pub parquet: PathBuf,
    pub plots: Vec<PathBuf>,
}

/// Unwrapped phase in degrees along a sorted sequence.
fn unwrapped(values: impl Iterator<Item = Complex64>) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::new();
    for v in values {
        let p = v.arg().to_degrees();
        let p = match out.last() {
            Some(prev) => p + 360.0 * ((prev - p) / 360.0).round(),
            None => p,
        };
        out.push(p);
    }
    out
}

fn db(x: Complex64) -> f64 {
    20.0 * x.norm().log10()
}

fn write_table(dir: &Path, stem: &str, table: &Table) -> Result<(PathBuf, PathBuf)> {
    std::fs::create_dir_all(dir)
        .map_err(|e| Error::io(format!("cannot create {}", dir.display()), e))?;
    let csv = dir.join(format!("{stem}.csv"));
    let parquet = dir.join(format!("{stem}.parquet"));
    table.write_csv(&csv)?;
    table.write_parquet(&parquet)?;
    Ok((csv, parquet))
}

fn optional(v: impl Iterator<Item = Option<f64>>) -> ColumnData {
    ColumnData::Float(v.map(|x| x.unwrap_or(f64::NAN)).collect())
}

/// The Bode curves of named ratios over ω.
fn curves(series: &[(String, Vec<f64>, Vec<Complex64>)]) -> Vec<Curve> {
    series
        .iter()
        .map(|(name, w, v)| Curve {
            name: name.clone(),
            omega: w.clone(),
            gain_db: v.iter().map(|x| db(*x)).collect(),
            phase_deg: unwrapped(v.iter().copied()),
        })
        .collect()
}

/// The response table: one row per frequency and output.
pub fn response_table(points: &[ResponsePoint]) -> Table {
    let rows: Vec<(f64, &OutputResponse)> = points
        .iter()
        .flat_map(|p| p.outputs.iter().map(move |o| (p.omega, o)))
        .collect();
    let names: Vec<String> = points
        .first()
        .map(|p| p.outputs.iter().map(|o| o.name.clone()).collect())
        .unwrap_or_default();
    let phases: Vec<Vec<f64>> = names
        .iter()
        .enumerate()
        .map(|(i, _)| unwrapped(points.iter().map(|p| p.outputs[i].ratio)))
        .collect();
    let mut t = Table::default();
    t.push(
        "omega_rad_s",
        ColumnData::Float(rows.iter().map(|r| r.0).collect()),
    );
    t.push(
        "output",
        ColumnData::Text(rows.iter().map(|r| r.1.name.clone()).collect()),
    );
    t.push(
        "gain_db",
        ColumnData::Float(rows.iter().map(|r| db(r.1.ratio)).collect()),
    );
    let phase = (0..points.len()).flat_map(|k| phases.iter().map(move |p| p[k]));
    t.push("phase_deg", ColumnData::Float(phase.collect()));
    push_common(&mut t, &rows);
    t
}

/// The response table (one row per frequency and output) and its Bode plot.
pub fn write_response(dir: &Path, points: &[ResponsePoint], title: &str) -> Result<Written> {
    let (table, parquet) = write_table(dir, "response", &response_table(points))?;
    let names: Vec<String> = points
        .first()
        .map(|p| p.outputs.iter().map(|o| o.name.clone()).collect())
        .unwrap_or_default();
    let series: Vec<(String, Vec<f64>, Vec<Complex64>)> = names
        .iter()
        .enumerate()
        .map(|(i, n)| {
            let w = points.iter().map(|p| p.omega).collect();
            (
                n.clone(),
                w,
                points.iter().map(|p| p.outputs[i].ratio).collect(),
            )
        })
        .collect();
    let bode_png = dir.join("bode.png");
    bode(&bode_png, title, &curves(&series), &[])?;
    Ok(Written {
        table,
        parquet,
        plots: vec![bode_png],
    })
}

/// re, im, distortion and the linearity check of response rows.
fn push_common(t: &mut Table, rows: &[(f64, &OutputResponse)]) {
    t.push(
        "re",
        ColumnData::Float(rows.iter().map(|r| r.1.ratio.re).collect()),
    );
    t.push(
        "im",
        ColumnData::Float(rows.iter().map(|r| r.1.ratio.im).collect()),
    );
    t.push(
        "distortion",
        ColumnData::Float(rows.iter().map(|r| r.1.distortion).collect()),
    );
    t.push(
        "gain_change_db",
        optional(rows.iter().map(|r| r.1.gain_change_db)),
    );
    t.push(
        "phase_change_deg",
        optional(rows.iter().map(|r| r.1.phase_change_deg)),
    );
}

/// The loop's table: one row per measured frequency.
pub fn loop_table(points: &[LoopPoint]) -> Table {
    let mut t = Table::default();
    t.push(
        "omega_rad_s",
        ColumnData::Float(points.iter().map(|p| p.omega).collect()),
    );
    t.push(
        "gain_db",
        ColumnData::Float(points.iter().map(|p| db(p.l)).collect()),
    );
    t.push(
        "phase_deg",
        ColumnData::Float(unwrapped(points.iter().map(|p| p.l))),
    );
    t.push(
        "re",
        ColumnData::Float(points.iter().map(|p| p.l.re).collect()),
    );
    t.push(
        "im",
        ColumnData::Float(points.iter().map(|p| p.l.im).collect()),
    );
    t.push(
        "distortion",
        ColumnData::Float(points.iter().map(|p| p.distortion).collect()),
    );
    t.push(
        "gain_change_db",
        optional(points.iter().map(|p| p.gain_change_db)),
    );
    t.push(
        "phase_change_deg",
        optional(points.iter().map(|p| p.phase_change_deg)),
    );
    t
}

/// The loop's table, its Bode and Nyquist plots.
pub fn write_margins(
    dir: &Path,
    points: &[LoopPoint],
    m: &Margins,
    title: &str,
) -> Result<Written> {
    let w: Vec<f64> = points.iter().map(|p| p.omega).collect();
    let (table, parquet) = write_table(dir, "loop", &loop_table(points))?;
    let shown = |x: Option<f64>, unit: &str| x.map_or("none".into(), |v| format!("{v:.2} {unit}"));
    let title = format!(
        "{title}: GM {} at {}, PM {} at {}",
        shown(m.gain_margin_db, "dB"),
        shown(m.gain_margin_rad_s, "rad/s"),
        shown(m.phase_margin_deg, "deg"),
        shown(m.crossover_rad_s, "rad/s")
    );
    let series = vec![("L".to_string(), w, points.iter().map(|p| p.l).collect())];
    let bode_png = dir.join("bode.png");
    let mut markers = Vec::new();
    if let (Some(w), Some(pm)) = (m.crossover_rad_s, m.phase_margin_deg) {
        markers.push(Marker {
            omega: w,
            label: format!("crossover, PM {pm:.2} deg"),
        });
    }
    if let (Some(w), Some(gm)) = (m.gain_margin_rad_s, m.gain_margin_db) {
        markers.push(Marker {
            omega: w,
            label: format!("phase -180 deg, GM {gm:.2} dB"),
        });
    }
    bode(&bode_png, &title, &curves(&series), &markers)?;
    let nyquist_png = dir.join("nyquist.png");
    plot_figure(&nyquist_png, &title, &[], &[nyquist(points)])?;
    Ok(Written {
        table,
        parquet,
        plots: vec![bode_png, nyquist_png],
    })
}

/// L in the complex plane, with the unit circle and the critical point −1.
fn nyquist(points: &[LoopPoint]) -> Track {
    // Far from −1 the curve only squeezes the region that matters: clipped to |L| <= 4.
    let near: Vec<&LoopPoint> = points.iter().filter(|p| p.l.norm() <= 4.0).collect();
    let circle: Vec<f64> = (0..=180)
        .map(|i| f64::from(i) * std::f64::consts::TAU / 180.0)
        .collect();
    Track {
        x_label: "Re L".into(),
        y_label: "Im L".into(),
        series: vec![
            Series {
                label: "L(jw), |L| <= 4".into(),
                t: near.iter().map(|p| p.l.re).collect(),
                y: near.iter().map(|p| p.l.im).collect(),
            },
            Series {
                label: "unit circle".into(),
                t: circle.iter().map(|a| a.cos()).collect(),
                y: circle.iter().map(|a| a.sin()).collect(),
            },
            Series {
                label: "-1".into(),
                t: vec![-1.05, -0.95, -1.0, -1.0, -1.0],
                y: vec![0.0, 0.0, 0.0, 0.05, -0.05],
            },
        ],
    }
}

/// The describing function's table: one row per amplitude.
pub fn describing_table(points: &[DescribingPoint]) -> Table {
    let rows: Vec<(f64, &OutputResponse)> = points
        .iter()
        .flat_map(|p| p.outputs.iter().map(move |o| (p.amplitude, o)))
        .collect();
    let mut t = Table::default();
    t.push(
        "amplitude",
        ColumnData::Float(rows.iter().map(|r| r.0).collect()),
    );
    t.push(
        "omega_rad_s",
        ColumnData::Float(
            points
                .iter()
                .flat_map(|p| p.outputs.iter().map(|_| p.omega))
                .collect(),
        ),
    );
    t.push(
        "output",
        ColumnData::Text(rows.iter().map(|r| r.1.name.clone()).collect()),
    );
    t.push(
        "gain",
        ColumnData::Float(rows.iter().map(|r| r.1.ratio.norm()).collect()),
    );
    t.push(
        "gain_db",
        ColumnData::Float(rows.iter().map(|r| db(r.1.ratio)).collect()),
    );
    t.push(
        "phase_deg",
        ColumnData::Float(rows.iter().map(|r| r.1.ratio.arg().to_degrees()).collect()),
    );
    push_common(&mut t, &rows);
    t
}

/// The describing function's table and plot (gain and phase against the amplitude).
pub fn write_describing(dir: &Path, points: &[DescribingPoint], title: &str) -> Result<Written> {
    let (table, parquet) = write_table(dir, "describing", &describing_table(points))?;
    let rows: Vec<(f64, &OutputResponse)> = points
        .iter()
        .flat_map(|p| p.outputs.iter().map(move |o| (p.amplitude, o)))
        .collect();
    let name = rows.first().map(|r| r.1.name.clone()).unwrap_or_default();
    let ratios: Vec<Complex64> = points.iter().map(|p| p.outputs[0].ratio).collect();
    let curve = Curve {
        name,
        omega: points.iter().map(|p| p.amplitude).collect(),
        gain_db: ratios.iter().map(|x| db(*x)).collect(),
        phase_deg: unwrapped(ratios.iter().copied()),
    };
    let png = dir.join("describing.png");
    chart(&png, title, "amplitude of the sinusoid", &[curve], &[])?;
    Ok(Written {
        table,
        parquet,
        plots: vec![png],
    })
}
