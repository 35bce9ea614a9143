//! Time-series plots (PNG) of recorded results ([`ResultsTable`]), for `shipsim plot`,
//! `cargo xtask demo` and the validation report.
//!
//! Rendering is pure Rust (plotters' bitmap backend with the DejaVu Sans font embedded through
//! the `dejavu` crate), so no system font or graphics library is needed. The setup, the series
//! colours and the drawing error are shared with the campaign plots ([`crate::campaign::plot`]).

use crate::error::{Error, Result};
use crate::results::ResultsTable;
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

/// A plotted column as written on the command line: `COL` or `COL*FACTOR` (the factor applies
/// to this column only, e.g. `ship.roll*57.29578` for degrees).
pub fn parse_column(spec: &str) -> Result<(String, Option<f64>)> {
    let bad = || Error::Other(format!("{spec:?}: expected COLUMN or COLUMN*FACTOR"));
    match spec.rsplit_once('*') {
        None if !spec.trim().is_empty() => Ok((spec.trim().to_string(), None)),
        None => Err(bad()),
        Some((col, f)) => {
            let f = f.trim().parse::<f64>().ok().filter(|f| f.is_finite());
            match (col.trim(), f) {
                ("", _) | (_, None) => Err(bad()),
                (c, f) => Ok((c.to_string(), f)),
            }
        }
    }
}

/// A time window `T0:T1` in seconds; either side may be left out (`200:`, `:600`).
pub fn parse_window(spec: &str) -> Result<(f64, f64)> {
    let bad = || {
        Error::Other(format!(
            "--window {spec:?}: expected T0:T1 in seconds (either may be empty)"
        ))
    };
    let (a, b) = spec.split_once(':').ok_or_else(bad)?;
    let side = |x: &str, open: f64| match x.trim() {
        "" => Ok(open),
        x => x
            .parse::<f64>()
            .ok()
            .filter(|v| !v.is_nan())
            .ok_or_else(bad),
    };
    let (t0, t1) = (side(a, f64::NEG_INFINITY)?, side(b, f64::INFINITY)?);
    if t0 >= t1 {
        return Err(bad());
    }
    Ok((t0, t1))
}

/// What `shipsim plot` draws: from one CSV, or several overlaid (each series once per file,
/// labelled `LABEL: column`), time panels and x-y tracks, within a time window.
pub struct Request<'a> {
    /// Each file's label and table.
    pub files: &'a [(String, ResultsTable)],
    /// `Y LABEL=COL[*F],COL[*F],...`, one per time panel.
    pub panels: &'a [String],
    /// `XCOL[*F],YCOL[*F]`, one per track panel (equal axes).
    pub tracks: &'a [String],
    /// The factor of a column without its own `*F`.
    pub scale: f64,
    /// Only the rows with t0 <= t <= t1.
    pub window: Option<(f64, f64)>,
}

impl Request<'_> {
    /// The time panels and track panels; an unknown column is an error that lists the columns.
    pub fn figure(&self) -> Result<(Vec<Panel>, Vec<Track>)> {
        let mut panels = Vec::new();
        for spec in self.panels {
            let (label, cols) = spec.split_once('=').ok_or_else(|| {
                Error::Other(format!(
                    "--panel {spec:?}: expected LABEL=COL[*F][,COL[*F]...]"
                ))
            })?;
            let mut series = Vec::new();
            for col in cols.split(',').filter(|c| !c.trim().is_empty()) {
                let (name, f) = parse_column(col)?;
                for (file, table) in self.files {
                    let (t, y) = self.values(table, &name, f)?;
                    series.push(Series {
                        label: self.label(file, &name),
                        t,
                        y,
                    });
                }
            }
            panels.push(Panel {
                y_label: label.to_string(),
                series,
            });
        }
        let mut tracks = Vec::new();
        for spec in self.tracks {
            let bad = || Error::Other(format!("--xy {spec:?}: expected XCOL[*F],YCOL[*F]"));
            let (x, y) = spec.split_once(',').ok_or_else(bad)?;
            let ((xn, xf), (yn, yf)) = (parse_column(x)?, parse_column(y)?);
            let mut series = Vec::new();
            for (file, table) in self.files {
                let (_, xs) = self.values(table, &xn, xf)?;
                let (_, ys) = self.values(table, &yn, yf)?;
                series.push(Series {
                    label: self.label(file, &format!("{yn} over {xn}")),
                    t: xs,
                    y: ys,
                });
            }
            tracks.push(Track {
                x_label: x.trim().to_string(),
                y_label: y.trim().to_string(),
                series,
            });
        }
        Ok((panels, tracks))
    }

    /// The times and scaled values of a column within the window.
    fn values(
        &self,
        table: &ResultsTable,
        name: &str,
        factor: Option<f64>,
    ) -> Result<(Vec<f64>, Vec<f64>)> {
        let f = factor.unwrap_or(self.scale);
        let (t0, t1) = self.window.unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
        let rows = table.time().iter().zip(table.column(name)?);
        Ok(rows
            .filter(|(t, _)| (t0..=t1).contains(*t))
            .map(|(t, v)| (*t, v * f))
            .unzip())
    }

    fn label(&self, file: &str, name: &str) -> String {
        match self.files.len() {
            1 => name.to_string(),
            _ => format!("{file}: {name}"),
        }
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
const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(90, 90, 90),
];

/// The error of a failed plotters call, in every PNG plot of the crate; the caller names the
/// file (`plot PATH: drawing failed: ...`).
pub(crate) fn drawing_error<E: std::fmt::Debug>(e: E) -> Error {
    Error::Other(format!("drawing failed: {e:?}"))
}

/// The drawing area of a PNG plot (in pixels).
pub(crate) type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

/// Creates the folder that will hold `path` (and its parents) when it does not exist.
pub(crate) fn create_parent_dir(path: &Path) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| Error::io(format!("cannot create {}", dir.display()), e))?;
    }
    Ok(())
}

/// The margin right of every chart, wide enough for the last time-axis label (such as "400.0")
/// to be drawn whole: plotters centres a tick label on its tick, so half of it lies right of
/// the plotting area.
const RIGHT_MARGIN: u32 = 30;
/// The other margins of a chart, and the heights and widths of its axis label areas [px].
const MARGIN: u32 = 10;
const X_LABEL_AREA: u32 = 35;
const Y_LABEL_AREA: u32 = 70;

/// Draws the panels one above the other against time and writes a PNG.
pub fn plot_panels(path: &Path, title: &str, panels: &[Panel]) -> Result<()> {
    plot_figure(path, title, panels, &[])
}

/// One x-y panel with equal scales on both axes (a ship's track: metres per pixel are the same
/// across and up). Each series is a curve of `y` over `x`; [`Series::t`] holds the x values.
#[derive(Clone, Debug)]
pub struct Track {
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
}

/// Heights of a time panel and of a track panel [px]; the figure is 1100 px wide.
const PANEL_HEIGHT: u32 = 260;
const TRACK_HEIGHT: u32 = 620;

/// Draws the time panels one above the other, then the track panels, and writes a PNG of
/// 1100 px by 60 px (title) + 260 px per time panel + 620 px per track panel.
pub fn plot_figure(path: &Path, title: &str, panels: &[Panel], tracks: &[Track]) -> Result<()> {
    if panels.is_empty() && tracks.is_empty() {
        return Err(Error::Other("nothing to plot".into()));
    }
    register_font();
    let path = &crate::output_path::writable(path)?;
    create_parent_dir(path)?;
    draw_figure(path, title, panels, tracks)
        .map_err(|e| Error::Other(format!("plot {}: {e}", path.display())))
}

/// The figure of [`plot_figure`], written to `path`.
fn draw_figure(path: &Path, title: &str, panels: &[Panel], tracks: &[Track]) -> Result<()> {
    let height = 60 + PANEL_HEIGHT * panels.len() as u32 + TRACK_HEIGHT * tracks.len() as u32;
    let root = BitMapBackend::new(path, (1100, height)).into_drawing_area();
    root.fill(&WHITE).map_err(drawing_error)?;
    let root = root
        .titled(title, ("sans-serif", 22))
        .map_err(drawing_error)?;
    // The height below the title, shared in proportion (all of it without tracks).
    let (time_px, track_px) = (
        PANEL_HEIGHT * panels.len() as u32,
        TRACK_HEIGHT * tracks.len() as u32,
    );
    let below_title = root.dim_in_pixel().1;
    let split = below_title * time_px / (time_px + track_px);
    let (time_area, track_area) = root.split_vertically(split);
    if !panels.is_empty() {
        let areas = time_area.split_evenly((panels.len(), 1));
        let (t0, t1) = bounds(
            panels
                .iter()
                .flat_map(|p| p.series.iter())
                .flat_map(|s| &s.t),
        );
        for (panel, area) in panels.iter().zip(areas.iter()) {
            draw_time_panel(area, panel, (t0, t1))?;
        }
    }
    if !tracks.is_empty() {
        for (track, area) in tracks
            .iter()
            .zip(track_area.split_evenly((tracks.len(), 1)).iter())
        {
            draw_track(area, track)?;
        }
    }
    root.present().map_err(drawing_error)?;
    Ok(())
}

/// The smallest and largest finite value ((0, 1) when there are none or they are equal).
fn bounds<'v>(values: impl Iterator<Item = &'v f64>) -> (f64, f64) {
    let (lo, hi) = values
        .copied()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if lo < hi {
        (lo, hi)
    } else if lo == hi {
        (lo - 0.5, hi + 0.5)
    } else {
        (0.0, 1.0)
    }
}

/// The colour of series `i` of a panel (or of a campaign plot's group), in [`COLORS`] order.
pub(crate) fn color(i: usize) -> RGBColor {
    COLORS[i % COLORS.len()]
}

fn draw_time_panel(area: &Area, panel: &Panel, (t0, t1): (f64, f64)) -> Result<()> {
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
    let desc = ("time [s]", panel.y_label.as_str());
    draw_chart(area, (t0, t1), (lo - pad, hi + pad), desc, &panel.series)
}

/// One chart: the mesh with the axis descriptions, the series as lines in [`COLORS`] order,
/// the legend.
fn draw_chart(
    area: &Area,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
    (x_desc, y_desc): (&str, &str),
    series: &[Series],
) -> Result<()> {
    let mut chart = ChartBuilder::on(area)
        .margin(MARGIN)
        .margin_right(RIGHT_MARGIN)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(Y_LABEL_AREA)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(drawing_error)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(drawing_error)?;
    for (i, s) in series.iter().enumerate() {
        let c = color(i);
        chart
            .draw_series(LineSeries::new(
                s.t.iter().copied().zip(s.y.iter().copied()),
                c.stroke_width(2),
            ))
            .map_err(drawing_error)?
            .label(s.label.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
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

/// Ranges for an x-y plot with equal scales in a plotting area of `w` by `h` pixels: the
/// data's box padded by 5 %, the axis with fewer units per pixel widened about its centre.
pub fn equal_axes(x: (f64, f64), y: (f64, f64), w: u32, h: u32) -> ((f64, f64), (f64, f64)) {
    let pad = |(a, b): (f64, f64)| ((b - a) * 0.05, (a + b) / 2.0, b - a);
    let (px, cx, wx) = pad(x);
    let (py, cy, wy) = pad(y);
    let (wx, wy) = (wx + 2.0 * px, wy + 2.0 * py);
    let per_px = (wx / w.max(1) as f64).max(wy / h.max(1) as f64);
    let (hx, hy) = (per_px * w as f64 / 2.0, per_px * h as f64 / 2.0);
    ((cx - hx, cx + hx), (cy - hy, cy + hy))
}

fn draw_track(area: &Area, track: &Track) -> Result<()> {
    let (w, h) = area.dim_in_pixel();
    let plot_w = w.saturating_sub(MARGIN + RIGHT_MARGIN + Y_LABEL_AREA);
    let plot_h = h.saturating_sub(2 * MARGIN + X_LABEL_AREA);
    let xs = bounds(track.series.iter().flat_map(|s| &s.t));
    let ys = bounds(track.series.iter().flat_map(|s| &s.y));
    let (x, y) = equal_axes(xs, ys, plot_w, plot_h);
    let desc = (track.x_label.as_str(), track.y_label.as_str());
    draw_chart(area, x, y, desc, &track.series)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plots_a_recorder_csv() {
        let dir = tempfile::tempdir().unwrap();
        let csv = dir.path().join("r.csv");
        std::fs::write(&csv, "time,g.a,g.flag\n0,1.5,true\n0.1,2.5,false\n").unwrap();
        let t = ResultsTable::read(&csv).unwrap();
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
    }
}
