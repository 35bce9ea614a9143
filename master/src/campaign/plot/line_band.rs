//! The KPI against one factor: the mean over each design point's runs, and its 5–95 % band.

use super::figure::{
    font, label_or, label_step, padded_range, series_figure, spread, tick_label, typeset, AXIS,
    BAND_ALPHA,
};
use super::stats::{aggregate, SeriesStats};
use super::{Frame, PlotOptions, PlotSummary};
use crate::campaign::table::Table;
use crate::error::Result;
use crate::plot::{color, drawing_error, Area};
use plotters::prelude::*;

/// Draws KPI `y` against factor `x`: for every distinct x (and value of `group`, one colour
/// each), the mean over the rows as points joined by a line, and the band from the 5 % to the
/// 95 % percentile (see [`Stats`](super::Stats)) shaded where a point has two or more rows.
pub fn line_band(
    table: &Table,
    x: &str,
    y: &str,
    group: Option<&str>,
    opts: &PlotOptions,
) -> Result<PlotSummary> {
    let agg = aggregate(table, x, y, group)?;
    let (x_label, y_label) = (label_or(&opts.x_label, x), label_or(&opts.y_label, y));
    let title = format!("{y_label} against {x_label}");
    series_figure(&agg, opts, (title, y_label), group, &[], |plot| {
        draw_line_chart(plot, &agg.series, x_label, y_label)
    })
}

fn draw_line_chart(
    area: &Area,
    series: &[SeriesStats],
    x_label: &str,
    y_label: &str,
) -> Result<Frame> {
    let points = || series.iter().flat_map(|s| s.points.iter());
    let xr = padded_range(points().map(|p| p.0), 0.04);
    let yr = padded_range(points().flat_map(|p| [p.1.p05, p.1.p95, p.1.mean]), 0.08);
    let (x_step, y_step) = (label_step(xr), label_step(yr));
    let mut chart = ChartBuilder::on(area)
        .margin_top(16)
        .margin_left(12)
        .margin_right(16)
        .x_label_area_size(56)
        .y_label_area_size(78)
        .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
        .map_err(drawing_error)?;
    chart
        .configure_mesh()
        .x_desc(typeset(x_label))
        .y_desc(typeset(y_label))
        .x_labels(8)
        .y_labels(8)
        .x_label_formatter(&|v| tick_label(*v, x_step))
        .y_label_formatter(&|v| tick_label(*v, y_step))
        .label_style(font(14))
        .axis_desc_style(font(17))
        .bold_line_style(RGBColor(225, 225, 225))
        .light_line_style(RGBColor(245, 245, 245))
        .axis_style(AXIS)
        .draw()
        .map_err(drawing_error)?;
    for (i, s) in series.iter().enumerate() {
        if spread(s) {
            let upper = s.points.iter().map(|(x, st)| (*x, st.p95));
            let lower = s.points.iter().rev().map(|(x, st)| (*x, st.p05));
            let style = color(i).mix(BAND_ALPHA).filled();
            chart
                .draw_series(std::iter::once(Polygon::new(
                    upper.chain(lower).collect::<Vec<_>>(),
                    style,
                )))
                .map_err(drawing_error)?;
        }
    }
    for (i, s) in series.iter().enumerate() {
        let color = color(i);
        let means = s.points.iter().map(|(x, st)| (*x, st.mean));
        chart
            .draw_series(LineSeries::new(means.clone(), color.stroke_width(2)))
            .map_err(drawing_error)?;
        chart
            .draw_series(means.map(|p| Circle::new(p, 4, color.filled())))
            .map_err(drawing_error)?;
    }
    let top_left = chart.backend_coord(&(xr.0, yr.1));
    let bottom_right = chart.backend_coord(&(xr.1, yr.0));
    Ok(Frame::cartesian(top_left, bottom_right, xr, yr))
}
