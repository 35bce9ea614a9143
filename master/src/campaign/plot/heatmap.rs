//! The mean of a KPI over two factors: a heat map of equal cells on the viridis colour map.

use super::figure::{
    anchored, caption, figure, label_or, nice_step, render, short_value, text_width, tick_label,
    ticks, words, AXIS, FONT, TEXT,
};
use super::stats::{grid, plain, widen, Grid};
use super::{Frame, PlotOptions, PlotSummary};
use crate::campaign::table::Table;
use crate::error::Result;
use crate::plot::{drawing_error, Area};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// A heat-map cell without any finite run.
const EMPTY_CELL: RGBColor = RGBColor(225, 225, 225);

/// Draws the mean of KPI `z` in every (x, y) cell of two factors as a heat map on the
/// [`viridis`] colour map, with a colour bar, and (with `opts.annotate`) each cell's mean in
/// the cell. The cells are of equal size whatever the spacing of the factors' values, which the
/// tick labels give; a cell without a finite run is grey.
pub fn heatmap(
    table: &Table,
    x: &str,
    y: &str,
    z: &str,
    opts: &PlotOptions,
) -> Result<PlotSummary> {
    let g = grid(table, x, y, z)?;
    let labels = [
        label_or(&opts.x_label, x),
        label_or(&opts.y_label, y),
        label_or(&opts.z_label, z),
    ];
    let means = || g.cells.iter().flatten().map(|s| s.mean);
    let range = means().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    let range = widen(range.0, range.1);
    let title = opts
        .title
        .clone()
        .unwrap_or_else(|| format!("{} over {} and {}", labels[2], labels[0], labels[1]));
    let n = || g.cells.iter().flatten().map(|s| s.n);
    let mut caption = caption(
        (n().min().unwrap_or(0), n().max().unwrap_or(0)),
        g.rows_used,
        g.rows_skipped,
        false,
    );
    caption[0] = caption[0].replace("point", "cell");
    if g.cells.iter().any(Option::is_none) {
        caption[0].push_str("; grey: no finite run");
    }
    render(opts, |root| {
        let body = figure(root, &title, &caption)?;
        let frame = draw_heatmap(&body, &g, labels, range, opts.annotate)?;
        Ok(PlotSummary {
            rows_used: g.rows_used,
            rows_skipped: g.rows_skipped,
            series: 1,
            frame,
        })
    })
}

/// The cells of a heat map: `nx` x `ny` cells of equal size fill the pixel rectangle
/// `left..=right`, `top..=bottom`; column `i` holds the `i`-th smallest x, row `j` (from the
/// bottom) the `j`-th smallest y.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cells {
    pub left: i32,
    pub top: i32,
    pub right: i32,
    pub bottom: i32,
    pub nx: usize,
    pub ny: usize,
}

impl Cells {
    /// Column `i`'s left and right edges.
    fn x(&self, i: usize) -> (i32, i32) {
        let w = (self.right - self.left) as f64 / self.nx as f64;
        (
            self.left + (w * i as f64) as i32,
            self.left + (w * (i + 1) as f64) as i32,
        )
    }
    /// Row `j`'s top and bottom edges (row 0 at the bottom).
    fn y(&self, j: usize) -> (i32, i32) {
        let h = (self.bottom - self.top) as f64 / self.ny as f64;
        (
            self.bottom - (h * (j + 1) as f64) as i32,
            self.bottom - (h * j as f64) as i32,
        )
    }
}

fn draw_heatmap(
    area: &Area,
    g: &Grid,
    labels: [&str; 3],
    z: (f64, f64),
    annotate: bool,
) -> Result<Frame> {
    let (w, h) = area.dim_in_pixel();
    let y_ticks: Vec<String> = g.ys.iter().map(|v| plain(*v)).collect();
    let z_step = nice_step(z.1 - z.0, 6.0);
    let z_ticks: Vec<(f64, String)> = ticks(z.0, z.1, z_step)
        .into_iter()
        .map(|v| (v, tick_label(v, z_step)))
        .collect();
    let widest = |labels: &mut dyn Iterator<Item = &String>| {
        labels.map(|l| text_width(area, l, 14)).max().unwrap_or(0) as i32
    };
    let bar = widest(&mut z_ticks.iter().map(|t| &t.1)) + 100;
    let cells = Cells {
        left: 54 + widest(&mut y_ticks.iter()),
        top: 16,
        right: w as i32 - bar,
        bottom: h as i32 - 66,
        nx: g.xs.len(),
        ny: g.ys.len(),
    };
    draw_cells(area, g, cells, z, annotate)?;
    draw_cell_axes(area, g, cells, &y_ticks, labels)?;
    draw_colour_bar(area, cells, z, &z_ticks, labels[2])?;
    let (bx, by) = area.get_base_pixel();
    let cells = Cells {
        left: bx + cells.left,
        top: by + cells.top,
        right: bx + cells.right,
        bottom: by + cells.bottom,
        ..cells
    };
    Ok(Frame::Cells { cells, z })
}

fn draw_cells(area: &Area, g: &Grid, c: Cells, z: (f64, f64), annotate: bool) -> Result<()> {
    for j in 0..c.ny {
        for i in 0..c.nx {
            let ((x0, x1), (y0, y1)) = (c.x(i), c.y(j));
            let stats = g.cells[j * c.nx + i];
            let fill = stats.map_or(EMPTY_CELL, |s| viridis((s.mean - z.0) / (z.1 - z.0)));
            area.draw(&Rectangle::new([(x0, y0), (x1, y1)], fill.filled()))
                .map_err(drawing_error)?;
            if let Some(s) = stats.filter(|_| annotate) {
                annotate_cell(area, ((x0, y0), (x1, y1)), s.mean, fill)?;
            }
        }
    }
    let frame = Rectangle::new([(c.left, c.top), (c.right, c.bottom)], AXIS.stroke_width(1));
    area.draw(&frame).map_err(drawing_error)
}

/// Prints `value` in the middle of a cell, in black or white by the fill's luminance
/// (ITU-R BT.709 weights), 13 to 18 px by the cell's height; not at all where it does not fit.
fn annotate_cell(
    area: &Area,
    ((x0, y0), (x1, y1)): ((i32, i32), (i32, i32)),
    value: f64,
    fill: RGBColor,
) -> Result<()> {
    let text = short_value(value);
    let size = ((y1 - y0) / 5).clamp(13, 18) as u32;
    let Some(size) = (13..=size)
        .rev()
        .find(|s| text_width(area, &text, *s) as i32 + 6 <= x1 - x0)
    else {
        return Ok(());
    };
    if y1 - y0 < size as i32 + 6 {
        return Ok(());
    }
    let luminance = 0.2126 * fill.0 as f64 + 0.7152 * fill.1 as f64 + 0.0722 * fill.2 as f64;
    let ink = if luminance > 128.0 { BLACK } else { WHITE };
    let style = (FONT, size)
        .into_font()
        .color(&ink)
        .pos(Pos::new(HPos::Center, VPos::Center));
    area.draw(&words(text, ((x0 + x1) / 2, (y0 + y1) / 2), style))
        .map_err(drawing_error)
}

/// Every `k`-th label, so that labels of `size` pixels fit cells of `cell` pixels.
fn label_stride(size: i32, cell: i32) -> usize {
    ((size as f64 / cell.max(1) as f64).ceil() as usize).max(1)
}

fn draw_cell_axes(
    area: &Area,
    g: &Grid,
    c: Cells,
    y_ticks: &[String],
    labels: [&str; 3],
) -> Result<()> {
    let x_ticks: Vec<String> = g.xs.iter().map(|v| plain(*v)).collect();
    let widest = x_ticks
        .iter()
        .map(|t| text_width(area, t, 14))
        .max()
        .unwrap_or(0) as i32;
    let col_w = (c.right - c.left) / c.nx as i32;
    for (i, t) in x_ticks
        .iter()
        .enumerate()
        .step_by(label_stride(widest + 12, col_w))
    {
        let (x0, x1) = c.x(i);
        let x = (x0 + x1) / 2;
        let tick = PathElement::new(vec![(x, c.bottom), (x, c.bottom + 5)], AXIS.stroke_width(1));
        area.draw(&tick).map_err(drawing_error)?;
        let label = words(
            t.as_str(),
            (x, c.bottom + 9),
            anchored(14, HPos::Center, VPos::Top),
        );
        area.draw(&label).map_err(drawing_error)?;
    }
    let row_h = (c.bottom - c.top) / c.ny as i32;
    for (j, t) in y_ticks.iter().enumerate().step_by(label_stride(22, row_h)) {
        let (y0, y1) = c.y(j);
        let y = (y0 + y1) / 2;
        let tick = PathElement::new(vec![(c.left - 5, y), (c.left, y)], AXIS.stroke_width(1));
        area.draw(&tick).map_err(drawing_error)?;
        let label = words(
            t.as_str(),
            (c.left - 9, y),
            anchored(14, HPos::Right, VPos::Center),
        );
        area.draw(&label).map_err(drawing_error)?;
    }
    let x_title = words(
        labels[0],
        ((c.left + c.right) / 2, c.bottom + 36),
        anchored(17, HPos::Center, VPos::Top),
    );
    area.draw(&x_title).map_err(drawing_error)?;
    let y_title = words(labels[1], (20, (c.top + c.bottom) / 2), vertical(17));
    area.draw(&y_title).map_err(drawing_error)
}

/// Text turned to read upwards, centred on its position.
fn vertical(size: u32) -> TextStyle<'static> {
    (FONT, size)
        .into_font()
        .transform(FontTransform::Rotate270)
        .color(&TEXT)
        .pos(Pos::new(HPos::Center, VPos::Center))
}

fn draw_colour_bar(
    area: &Area,
    c: Cells,
    z: (f64, f64),
    z_ticks: &[(f64, String)],
    label: &str,
) -> Result<()> {
    let (x0, x1) = (c.right + 24, c.right + 46);
    let span = (c.bottom - c.top).max(1);
    for py in c.top..=c.bottom {
        let t = (c.bottom - py) as f64 / span as f64;
        // A filled rectangle needs a height: each row overlaps the next by a pixel.
        area.draw(&Rectangle::new(
            [(x0, py), (x1, py + 1)],
            viridis(t).filled(),
        ))
        .map_err(drawing_error)?;
    }
    area.draw(&Rectangle::new(
        [(x0, c.top), (x1, c.bottom)],
        AXIS.stroke_width(1),
    ))
    .map_err(drawing_error)?;
    let mut label_x = x1 + 10;
    for (v, text) in z_ticks {
        let y = c.bottom - ((v - z.0) / (z.1 - z.0) * span as f64).round() as i32;
        let tick = PathElement::new(vec![(x1, y), (x1 + 5, y)], AXIS.stroke_width(1));
        area.draw(&tick).map_err(drawing_error)?;
        let style = anchored(14, HPos::Left, VPos::Center);
        area.draw(&words(text.as_str(), (x1 + 8, y), style))
            .map_err(drawing_error)?;
        label_x = label_x.max(x1 + 8 + text_width(area, text, 14) as i32 + 16);
    }
    let title = words(label, (label_x, (c.top + c.bottom) / 2), vertical(17));
    area.draw(&title).map_err(drawing_error)
}

/// The viridis colour map at `t` in [0, 1] (clamped): matplotlib's default perceptually
/// uniform map (S. van der Walt and N. Smith, 2015; 256-entry table in matplotlib's
/// `_cm_listed.py`), by the degree-6 polynomial fit of M. Zucker ("Colormap polynomial
/// approximations", Shadertoy WlfXRN, 2019, CC0). The fit is within 3.3/255 of matplotlib's
/// table in every channel (we compared entry 0 and entries 12 to 255).
pub fn viridis(t: f64) -> RGBColor {
    const C: [[f64; 3]; 7] = [
        [
            0.277_727_327_223_417_7,
            0.005_407_344_544_966_578,
            0.334_099_805_335_306_1,
        ],
        [
            0.105_093_043_108_577_4,
            1.404_613_529_898_575,
            1.384_590_162_594_685,
        ],
        [
            -0.330_861_828_725_556_3,
            0.214_847_559_468_213,
            0.095_095_163_028_236_59,
        ],
        [
            -4.634_230_498_983_486,
            -5.799_100_973_351_585,
            -19.332_440_956_279_87,
        ],
        [
            6.228_269_936_347_081,
            14.179_933_366_805_09,
            56.690_552_600_681_05,
        ],
        [
            4.776_384_997_670_288,
            -13.745_145_377_746_01,
            -65.353_032_633_372_34,
        ],
        [
            -5.435_455_855_934_631,
            4.645_852_612_178_535,
            26.312_435_249_583_2,
        ],
    ];
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let channel = |k: usize| {
        let v = C.iter().rev().fold(0.0, |acc, c| acc * t + c[k]);
        (v.clamp(0.0, 1.0) * 255.0).round() as u8
    };
    RGBColor(channel(0), channel(1), channel(2))
}
