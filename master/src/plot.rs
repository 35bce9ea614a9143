//! Time-series plots (PNG) of recorded results, for `shipsim plot`, `cargo xtask demo` and the
//! validation report.
//!
//! Rendering is pure Rust (plotters' bitmap backend with the DejaVu Sans font embedded through
//! the `dejavu` crate), so no system font or graphics library is needed.

use crate::error::{Error, Result};
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

/// One curve.
#[derive(Clone, Debug)]
pub struct Series {
    pub label: String,
    pub t: Vec<f64>,
    pub y: Vec<f64>,
}

/// One panel (subplot) sharing the time axis with the others.
#[derive(Clone, Debug)]
pub struct Panel {
    pub y_label: String,
    pub series: Vec<Series>,
}

/// A recorded CSV: header names and columns of numbers.
#[derive(Clone, Debug)]
pub struct Table {
    pub names: Vec<String>,
    pub columns: Vec<Vec<f64>>,
}

impl Table {
    /// Reads a CSV written by the recorder (first column time, header `instance.variable`).
    /// Booleans (`true`/`false`) read as 1/0.
    pub fn read(path: &Path) -> Result<Table> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| Error::io(format!("cannot read {}", path.display()), e))?;
        let mut lines = text.lines();
        let names: Vec<String> = lines
            .next()
            .ok_or_else(|| Error::Other(format!("{}: empty CSV file", path.display())))?
            .split(',')
            .map(|s| s.trim().trim_matches('"').to_string())
            .collect();
        let mut columns = vec![Vec::new(); names.len()];
        for (row, line) in lines.enumerate() {
            if line.trim().is_empty() {
                continue;
            }
            let cells: Vec<&str> = line.split(',').collect();
            if cells.len() != names.len() {
                return Err(Error::Other(format!(
                    "{}:{}: {} values, header has {}",
                    path.display(),
                    row + 2,
                    cells.len(),
                    names.len()
                )));
            }
            for (c, cell) in cells.iter().enumerate() {
                let cell = cell.trim();
                let v = match cell {
                    "true" | "True" => 1.0,
                    "false" | "False" => 0.0,
                    _ => cell.parse::<f64>().map_err(|_| {
                        Error::Other(format!(
                            "{}:{}: column {:?}: {cell:?} is not a number",
                            path.display(),
                            row + 2,
                            names[c]
                        ))
                    })?,
                };
                columns[c].push(v);
            }
        }
        Ok(Table { names, columns })
    }

    /// The column named `name`; the error lists the available columns.
    pub fn column(&self, name: &str) -> Result<&[f64]> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|i| self.columns[i].as_slice())
            .ok_or_else(|| {
                Error::Other(format!(
                    "no column {name:?}; columns: {}",
                    self.names.join(", ")
                ))
            })
    }

    /// The first column (time).
    pub fn time(&self) -> &[f64] {
        self.columns.first().map(Vec::as_slice).unwrap_or(&[])
    }
}

/// Registers the embedded DejaVu Sans as plotters' "sans-serif" (once per process). Every PNG
/// plot of the crate ([`plot_panels`], [`crate::campaign::plot`]) draws text with it.
pub(crate) fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The embedded font is valid; if registration failed, text would simply not render.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            dejavu::sans::regular(),
        );
    });
}

/// Series colours, in order: matplotlib's "tab10" blue, red, green, orange and purple, then grey.
pub(crate) const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(90, 90, 90),
];

fn draw_err<E: std::fmt::Debug>(path: &Path) -> impl Fn(E) -> Error + '_ {
    move |e| Error::Other(format!("drawing {}: {e:?}", path.display()))
}

/// Creates the folder that will hold `path` (and its parents) when it does not exist.
pub(crate) fn create_parent_dir(path: &Path) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| Error::io(format!("cannot create {}", dir.display()), e))?;
    }
    Ok(())
}

/// Draws the panels one above the other against time and writes a PNG.
pub fn plot_panels(path: &Path, title: &str, panels: &[Panel]) -> Result<()> {
    if panels.is_empty() {
        return Err(Error::Other("nothing to plot".into()));
    }
    register_font();
    create_parent_dir(path)?;
    let height = 60 + 260 * panels.len() as u32;
    let root = BitMapBackend::new(path, (1100, height)).into_drawing_area();
    let err = draw_err(path);
    root.fill(&WHITE).map_err(&err)?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(&err)?;
    let areas = root.split_evenly((panels.len(), 1));
    let (t0, t1) = panels
        .iter()
        .flat_map(|p| p.series.iter())
        .flat_map(|s| s.t.iter().copied())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), t| {
            (a.min(t), b.max(t))
        });
    let (t0, t1) = if t0 < t1 { (t0, t1) } else { (0.0, 1.0) };
    for (panel, area) in panels.iter().zip(areas.iter()) {
        let (mut lo, mut hi) = panel
            .series
            .iter()
            .flat_map(|s| s.y.iter().copied())
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| {
                (a.min(y), b.max(y))
            });
        if !(lo.is_finite() && hi.is_finite()) {
            (lo, hi) = (-1.0, 1.0);
        }
        let pad = ((hi - lo) * 0.08).max(1e-9);
        let mut chart = ChartBuilder::on(area)
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(70)
            .build_cartesian_2d(t0..t1, (lo - pad)..(hi + pad))
            .map_err(&err)?;
        chart
            .configure_mesh()
            .x_desc("time [s]")
            .y_desc(panel.y_label.as_str())
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(&err)?;
        for (i, s) in panel.series.iter().enumerate() {
            let color = COLORS[i % COLORS.len()];
            chart
                .draw_series(LineSeries::new(
                    s.t.iter().copied().zip(s.y.iter().copied()),
                    color.stroke_width(2),
                ))
                .map_err(&err)?
                .label(s.label.as_str())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                });
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .draw()
            .map_err(&err)?;
    }
    root.present().map_err(&err)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_a_recorder_csv_and_plots_it() {
        let dir = tempfile::tempdir().unwrap();
        let csv = dir.path().join("r.csv");
        std::fs::write(&csv, "time,g.a,g.flag\n0,1.5,true\n0.1,2.5,false\n").unwrap();
        let t = Table::read(&csv).unwrap();
        assert_eq!(t.column("g.a").unwrap(), &[1.5, 2.5]);
        assert_eq!(t.column("g.flag").unwrap(), &[1.0, 0.0]);
        assert!(t
            .column("g.b")
            .unwrap_err()
            .to_string()
            .contains("columns: time, g.a"));
        let png = dir.path().join("out/p.png");
        plot_panels(
            &png,
            "test",
            &[Panel {
                y_label: "a".into(),
                series: vec![Series {
                    label: "g.a".into(),
                    t: t.time().to_vec(),
                    y: t.column("g.a").unwrap().to_vec(),
                }],
            }],
        )
        .unwrap();
        let bytes = std::fs::read(&png).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
        std::fs::write(&csv, "time,x\n0,abc\n").unwrap();
        let e = Table::read(&csv).unwrap_err().to_string();
        assert!(
            e.contains("r.csv:2: column \"x\": \"abc\" is not a number"),
            "{e}"
        );
    }
}
