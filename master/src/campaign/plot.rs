//! Plots of a campaign's run table (PNG), for `shipsim campaign plot`:
//!
//! - [`line_band`]: a KPI against one factor, the mean over the runs of each design point
//!   (the seeds) with its 5–95 % band, one coloured series per value of a group column;
//! - [`heatmap`]: the mean of a KPI over two factors, on the viridis colour map, with a colour bar;
//! - [`polar`]: a KPI against a direction on polar axes (e.g. roll reduction over wave heading);
//! - [`histogram`]: the distribution of a KPI over the runs (e.g. a Monte-Carlo robustness
//!   study), on [`bins`] chosen by the Freedman–Diaconis rule, with its mean and 5 % / 95 %
//!   percentiles, one semi-transparent histogram per value of a group column.
//!
//! Every plot reduces the rows that share a design point to their [`Stats`]: the mean, and the
//! 5 % and 95 % empirical percentiles of [`percentile`]. A row is skipped when one of its
//! plotted values is not finite (a failed run's KPIs are NaN); [`PlotSummary`] returns the
//! count, and the figure's caption prints it. Bad input (a missing or text column, no finite
//! row, a path that cannot be written) is an [`Error`] that names it, never a panic.
//!
//! Rendering shares the time-series plotter's setup ([`crate::plot`]): plotters' bitmap
//! backend and DejaVu Sans embedded, so no system font or graphics library is needed, its series
//! colours and its drawing error.

use crate::campaign::table::{ColumnData, Table};
use crate::error::{suggest, Error, Result};
use crate::plot::{color, create_parent_dir, drawing_error, register_font, Area};
use plotters::coord::types::{RangedCoordf64, RangedCoordu32};
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::PathBuf;

const FONT: &str = "sans-serif";
const TEXT: RGBColor = RGBColor(30, 30, 30);
/// The colour of axes, the polar frame and tick marks.
const AXIS: RGBColor = RGBColor(40, 40, 40);
/// Rings, spokes and grid lines.
const GRID: RGBColor = RGBColor(205, 205, 205);
/// A heat-map cell without any finite run.
const EMPTY_CELL: RGBColor = RGBColor(225, 225, 225);
/// Opacity of a 5–95 % band over its series colour.
const BAND_ALPHA: f64 = 0.2;
/// The percentiles of the band.
const BAND: (f64, f64) = (5.0, 95.0);

/// The unit of a direction column.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AngleUnit {
    #[default]
    Degrees,
    Radians,
}

/// Where 0 lies on polar axes, and which way angles grow.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Orientation {
    /// 0 at the top, angles growing clockwise, as on a compass card.
    #[default]
    Compass,
    /// 0 to the right, angles growing counter-clockwise.
    Mathematical,
}

/// What to draw and where. Labels default to the column names; put units in them
/// (`"roll reduction [%]"`).
#[derive(Clone, Debug)]
pub struct PlotOptions {
    /// The PNG to write (its folder is created).
    pub path: PathBuf,
    /// The title above the figure (default: the KPI against the factors).
    pub title: Option<String>,
    /// The first column's label: `x` of [`line_band`] and [`heatmap`], the angle of [`polar`].
    pub x_label: Option<String>,
    /// The second column's label: `y` of [`line_band`] and [`heatmap`], the radius of [`polar`].
    pub y_label: Option<String>,
    /// The colour bar's label ([`heatmap`]'s `z`).
    pub z_label: Option<String>,
    /// The group column's name in the legend (`"H_s [m]"` gives entries `H_s [m] = 2`).
    pub group_label: Option<String>,
    /// Width and height in pixels (default 900 x 700; at least 400 x 300).
    pub size: (u32, u32),
    /// The unit of [`polar`]'s angle column (default degrees).
    pub angle_unit: AngleUnit,
    /// [`polar`]: compass-like (default) or mathematical.
    pub orientation: Orientation,
    /// [`heatmap`]: print each cell's mean in the cell (default true; left out where the
    /// cells are too small for the text).
    pub annotate: bool,
}

impl PlotOptions {
    pub fn new(path: impl Into<PathBuf>) -> Self {
        PlotOptions {
            path: path.into(),
            title: None,
            x_label: None,
            y_label: None,
            z_label: None,
            group_label: None,
            size: (900, 700),
            angle_unit: AngleUnit::Degrees,
            orientation: Orientation::Compass,
            annotate: true,
        }
    }
}

/// What a plot drew: the rows used and skipped, the series, and where the data lie in the image.
#[derive(Clone, Debug, PartialEq)]
pub struct PlotSummary {
    /// Rows whose plotted values are all finite.
    pub rows_used: usize,
    /// Rows left out because a plotted value (usually a failed run's KPI) is NaN or infinite.
    pub rows_skipped: usize,
    /// Series drawn (groups; 1 for a heat map).
    pub series: usize,
    pub frame: Frame,
}

/// The mapping from data to pixels (image coordinates: x to the right, y down).
#[derive(Clone, Debug, PartialEq)]
pub enum Frame {
    /// [`line_band`] and [`histogram`] (`y` in runs): the data ranges `x` and `y` span the
    /// pixel rectangle `left..=right`, `bottom..=top` (y grows upwards in the data).
    Cartesian {
        left: i32,
        top: i32,
        right: i32,
        bottom: i32,
        x: (f64, f64),
        y: (f64, f64),
    },
    /// [`heatmap`]: the cells, and the colour range `z` (viridis(0) to viridis(1)).
    Cells { cells: Cells, z: (f64, f64) },
    /// [`polar`]: the radius `r.0` is at `centre`, `r.1` on the outer ring, `radius_px` away.
    Polar {
        centre: (i32, i32),
        radius_px: f64,
        r: (f64, f64),
    },
}

impl Frame {
    /// Cartesian axes whose data ranges `x` and `y` span the pixels from `top_left` to
    /// `bottom_right`.
    fn cartesian(
        (left, top): (i32, i32),
        (right, bottom): (i32, i32),
        x: (f64, f64),
        y: (f64, f64),
    ) -> Frame {
        Frame::Cartesian {
            left,
            top,
            right,
            bottom,
            x,
            y,
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Statistics

/// The `p`-th percentile (0 ≤ p ≤ 100) of `values`, by linear interpolation between order
/// statistics: with the values sorted, x₀ ≤ … ≤ xₙ₋₁, and h = (n − 1) p / 100, it is
/// x⌊h⌋ + (h − ⌊h⌋)(x⌊h⌋₊₁ − x⌊h⌋). This is definition 7 of Hyndman and Fan (*Sample quantiles in
/// statistical packages*, The American Statistician 50 (1996) 361–365), the default of numpy's
/// `percentile` (`method="linear"`) and of R's `quantile`; the interpolation is evaluated as
/// numpy does (from the upper neighbour when the fraction is at least 0.5).
/// `None` for no values, a NaN among them, or `p` outside 0..=100.
pub fn percentile(values: &[f64], p: f64) -> Option<f64> {
    if values.is_empty() || values.iter().any(|v| v.is_nan()) || !(0.0..=100.0).contains(&p) {
        return None;
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    Some(percentile_sorted(&sorted, p))
}

/// [`percentile`] of values sorted ascending (not empty, no NaN, `p` in 0..=100).
fn percentile_sorted(sorted: &[f64], p: f64) -> f64 {
    let h = (sorted.len() - 1) as f64 * (p / 100.0);
    let i = (h.floor() as usize).min(sorted.len() - 1);
    let Some(&b) = sorted.get(i + 1) else {
        return sorted[i];
    };
    let (a, t) = (sorted[i], h - i as f64);
    if t >= 0.5 {
        b - (b - a) * (1.0 - t)
    } else {
        a + (b - a) * t
    }
}

/// The runs of one design point: their number, mean and 5 % / 95 % percentiles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stats {
    pub n: usize,
    pub mean: f64,
    pub p05: f64,
    pub p95: f64,
}

impl Stats {
    /// The statistics of finite values; `None` when there are none or one is not finite.
    pub fn of(values: &[f64]) -> Option<Stats> {
        if values.is_empty() || values.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let mut sorted = values.to_vec();
        sorted.sort_by(f64::total_cmp);
        Some(Stats {
            n: values.len(),
            mean: values.iter().sum::<f64>() / values.len() as f64,
            p05: percentile_sorted(&sorted, BAND.0),
            p95: percentile_sorted(&sorted, BAND.1),
        })
    }
}

/// One group's points: for every distinct x (ascending), the statistics of its rows.
#[derive(Clone, Debug, PartialEq)]
pub struct SeriesStats {
    /// The group's value as text (`None` without a group column).
    pub group: Option<String>,
    pub points: Vec<(f64, Stats)>,
}

/// A KPI reduced over the rows of each (group, x).
#[derive(Clone, Debug, PartialEq)]
pub struct Aggregate {
    pub series: Vec<SeriesStats>,
    pub rows_used: usize,
    pub rows_skipped: usize,
}

/// The statistics of KPI `y` for every distinct value of factor `x`, per value of `group`
/// (numbers in ascending order, text in order of first appearance). Rows with a non-finite
/// `x` or `y` (or a NaN group value) are skipped and counted.
pub fn aggregate(table: &Table, x: &str, y: &str, group: Option<&str>) -> Result<Aggregate> {
    aggregate_by(table, [("x", x), ("y", y)], group, |v| v)
}

/// [`aggregate`] with the x values mapped by `key` first (polar: angles into [0°, 360°)).
fn aggregate_by(
    table: &Table,
    cols: [(&str, &str); 2],
    group: Option<&str>,
    key: impl Fn(f64) -> f64,
) -> Result<Aggregate> {
    let data = [
        numeric(table, cols[0].1, cols[0].0)?,
        numeric(table, cols[1].1, cols[1].0)?,
    ];
    let groups = Groups::of(table, group)?;
    let (rows, skipped) = finite_rows(table, data, &groups);
    no_rows_error(table, rows.len(), &[cols[0].1, cols[1].1])?;
    let mut per_group = vec![Vec::new(); groups.labels.len()];
    for (g, [x, y]) in &rows {
        per_group[*g].push((key(*x), *y));
    }
    let series = groups
        .labels
        .iter()
        .zip(per_group)
        .filter(|(_, pairs)| !pairs.is_empty())
        .map(|(label, pairs)| SeriesStats {
            group: group.map(|_| label.clone()),
            points: reduce(pairs),
        })
        .collect();
    Ok(Aggregate {
        series,
        rows_used: rows.len(),
        rows_skipped: skipped,
    })
}

/// The statistics of the values sharing each distinct key, keys ascending.
fn reduce(mut pairs: Vec<(f64, f64)>) -> Vec<(f64, Stats)> {
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    pairs
        .chunk_by(|a, b| a.0 == b.0)
        .filter_map(|chunk| {
            let values: Vec<f64> = chunk.iter().map(|p| p.1).collect();
            Stats::of(&values).map(|s| (chunk[0].0, s))
        })
        .collect()
}

/// The mean of a KPI in every cell of a two-factor grid.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    /// Distinct x values, ascending.
    pub xs: Vec<f64>,
    /// Distinct y values, ascending.
    pub ys: Vec<f64>,
    /// Cell (i, j) at `j * xs.len() + i`; `None` where no row with finite values falls.
    pub cells: Vec<Option<Stats>>,
    pub rows_used: usize,
    pub rows_skipped: usize,
}

/// The statistics of KPI `z` over the rows of every (x, y) cell.
pub fn grid(table: &Table, x: &str, y: &str, z: &str) -> Result<Grid> {
    let data = [
        numeric(table, x, "x")?,
        numeric(table, y, "y")?,
        numeric(table, z, "z")?,
    ];
    let (rows, skipped) = finite_rows(table, data, &Groups::of(table, None)?);
    no_rows_error(table, rows.len(), &[x, y, z])?;
    let distinct = |k: usize| {
        let mut v: Vec<f64> = rows.iter().map(|(_, r)| r[k]).collect();
        v.sort_by(f64::total_cmp);
        v.dedup();
        v
    };
    let (xs, ys) = (distinct(0), distinct(1));
    let mut values = vec![Vec::new(); xs.len() * ys.len()];
    for (_, [xv, yv, zv]) in &rows {
        let i = xs.partition_point(|v| v < xv);
        let j = ys.partition_point(|v| v < yv);
        values[j * xs.len() + i].push(*zv);
    }
    Ok(Grid {
        cells: values.iter().map(|v| Stats::of(v)).collect(),
        xs,
        ys,
        rows_used: rows.len(),
        rows_skipped: skipped,
    })
}

/// The most bins [`bins`] makes.
pub const MAX_BINS: usize = 100;

/// The rule by which [`bins`] chose the bins.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinRule {
    /// Freedman and Diaconis: width 2 IQR n^(-1/3).
    FreedmanDiaconis,
    /// Sturges: ceil(log₂ n) + 1 bins (the interquartile range is 0).
    Sturges,
    /// All values are equal: one bin centred on them.
    SingleValue,
}

/// Bins of equal width over the values' range and the values in each.
#[derive(Clone, Debug, PartialEq)]
pub struct Bins {
    /// Ascending, one more than the bins: bin `i` is `edges[i] <= v < edges[i + 1]`, the last
    /// one closed (`v <= edges[n]`), as in numpy's `histogram`.
    pub edges: Vec<f64>,
    /// The values in each bin.
    pub counts: Vec<usize>,
    pub rule: BinRule,
    /// The rule asked for more than [`MAX_BINS`] bins; there are [`MAX_BINS`].
    pub capped: bool,
}

impl Bins {
    /// The number of bins.
    pub fn len(&self) -> usize {
        self.edges.len().saturating_sub(1)
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The width of every bin.
    pub fn width(&self) -> f64 {
        match (self.edges.first(), self.edges.last()) {
            (Some(a), Some(b)) if !self.is_empty() => (b - a) / self.len() as f64,
            _ => f64::NAN,
        }
    }

    /// The bin holding `v`; `None` outside the edges (or for NaN).
    pub fn index(&self, v: f64) -> Option<usize> {
        let n = self.len();
        if n == 0 || !(self.edges[0]..=self.edges[n]).contains(&v) {
            return None;
        }
        Some((self.edges.partition_point(|e| *e <= v).saturating_sub(1)).min(n - 1))
    }

    /// The number of `values` in each bin (values outside the edges are not counted): a
    /// group's histogram on bins chosen for all runs.
    pub fn count(&self, values: &[f64]) -> Vec<usize> {
        let mut counts = vec![0; self.len()];
        for i in values.iter().filter_map(|v| self.index(*v)) {
            counts[i] += 1;
        }
        counts
    }
}

/// Bins for a histogram of `values`: equal widths from the smallest value to the largest, as
/// many as the rule of Freedman and Diaconis asks for (D. Freedman and P. Diaconis, *On the
/// histogram as a density estimator: L₂ theory*, Zeitschrift für Wahrscheinlichkeitstheorie
/// und verwandte Gebiete 57 (1981) 453–476): width 2 IQR n^(-1/3), with the
/// interquartile range IQR from [`percentile`] (75 % minus 25 %); the count is the range over
/// that width rounded up, and the width is then the range over the count. This is numpy's
/// `histogram_bin_edges(values, "fd")`, edges and all.
///
/// - When the IQR is 0 (most runs share one value), the width would be 0: Sturges' rule gives
///   ceil(log₂ n) + 1 bins instead (H. A. Sturges, *The choice of a class interval*, Journal of
///   the American Statistical Association 21 (1926) 65–66). numpy makes one bin there.
/// - At most [`MAX_BINS`] bins (a few outliers far out would ask for thousands).
/// - A single distinct value v gets one bin centred on it, v ± |v|/10 (± 1 for 0; numpy:
///   ± 0.5).
///
/// `None` for no values, a value that is not finite, or a range too wide for an `f64`.
pub fn bins(values: &[f64]) -> Option<Bins> {
    if values.is_empty() || values.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let (lo, hi) = (sorted[0], sorted[sorted.len() - 1]);
    let n = sorted.len() as f64;
    let iqr = percentile_sorted(&sorted, 75.0) - percentile_sorted(&sorted, 25.0);
    let (rule, wanted, (first, last)) = if hi == lo {
        (BinRule::SingleValue, 1.0, widen(lo, hi))
    } else if iqr > 0.0 {
        let width = 2.0 * iqr * n.powf(-1.0 / 3.0);
        (
            BinRule::FreedmanDiaconis,
            ((hi - lo) / width).ceil(),
            (lo, hi),
        )
    } else {
        (BinRule::Sturges, n.log2().ceil() + 1.0, (lo, hi))
    };
    if !(last - first).is_finite() {
        return None;
    }
    // `as` saturates: an infinite count (a width that underflowed) is capped too.
    let count = (wanted as usize).clamp(1, MAX_BINS);
    let step = (last - first) / count as f64;
    let mut edges: Vec<f64> = (0..count).map(|i| i as f64 * step + first).collect();
    edges.push(last);
    let mut bins = Bins {
        edges,
        counts: Vec::new(),
        rule,
        capped: wanted > MAX_BINS as f64,
    };
    bins.counts = bins.count(values);
    Some(bins)
}

/// One group's histogram on the shared [`Bins`], and its statistics.
#[derive(Clone, Debug, PartialEq)]
pub struct GroupCounts {
    /// The group's value as text (`None` without a group column).
    pub group: Option<String>,
    pub counts: Vec<usize>,
    pub stats: Stats,
}

/// The distribution of a KPI over the runs: bins chosen for all of them, and each group's
/// counts on those bins.
#[derive(Clone, Debug, PartialEq)]
pub struct Distribution {
    pub bins: Bins,
    /// Groups with at least one finite value, in [`aggregate`]'s order.
    pub groups: Vec<GroupCounts>,
    pub rows_used: usize,
    pub rows_skipped: usize,
}

/// The [`bins`] of KPI `x` over the rows with a finite value, and the counts and [`Stats`] of
/// each value of `group` on them. Rows with a non-finite `x` (or a NaN group value) are
/// skipped and counted.
pub fn distribution(table: &Table, x: &str, group: Option<&str>) -> Result<Distribution> {
    let groups = Groups::of(table, group)?;
    let (rows, skipped) = finite_rows(table, [numeric(table, x, "x")?], &groups);
    no_rows_error(table, rows.len(), &[x])?;
    let all: Vec<f64> = rows.iter().map(|(_, [v])| *v).collect();
    let bins = bins(&all).ok_or_else(|| {
        let (lo, hi) = all
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(*v), b.max(*v))
            });
        Error::Other(format!(
            "plot x: the values of {x:?} run from {lo:e} to {hi:e}, a range too wide to bin"
        ))
    })?;
    let mut per_group = vec![Vec::new(); groups.labels.len()];
    for (g, [v]) in &rows {
        per_group[*g].push(*v);
    }
    let groups = groups
        .labels
        .iter()
        .zip(per_group)
        .filter_map(|(label, values)| {
            Some(GroupCounts {
                group: group.map(|_| label.clone()),
                counts: bins.count(&values),
                stats: Stats::of(&values)?,
            })
        })
        .collect();
    Ok(Distribution {
        bins,
        groups,
        rows_used: rows.len(),
        rows_skipped: skipped,
    })
}

// ---------------------------------------------------------------------------------------------
// Columns

/// The column `name` for the plot's `role`; the error lists the table's columns.
fn column<'a>(table: &'a Table, name: &str, role: &str) -> Result<&'a ColumnData> {
    let col = table.column(name).ok_or_else(|| {
        let near = suggest(name, table.names.iter().map(String::as_str));
        let hint = if near.is_empty() {
            String::new()
        } else {
            format!(" (did you mean {}?)", near.join(", "))
        };
        let list = if table.names.is_empty() {
            "none".to_string()
        } else {
            table.names.join(", ")
        };
        Error::Other(format!(
            "plot {role}: no column {name:?} in the run table{hint}; columns: {list}"
        ))
    })?;
    if col.len() != table.rows() {
        return Err(Error::Other(format!(
            "plot {role}: column {name:?} has {} values, the run table {} rows",
            col.len(),
            table.rows()
        )));
    }
    Ok(col)
}

/// A numeric (Float, Int or Bool) column.
fn numeric<'a>(table: &'a Table, name: &str, role: &str) -> Result<&'a ColumnData> {
    let col = column(table, name, role)?;
    if let ColumnData::Text(_) = col {
        let numeric: Vec<&str> = table
            .names
            .iter()
            .zip(&table.columns)
            .filter(|(_, c)| !matches!(c, ColumnData::Text(_)))
            .map(|(n, _)| n.as_str())
            .collect();
        return Err(Error::Other(format!(
            "plot {role}: column {name:?} holds text, not numbers; numeric columns: {}",
            numeric.join(", ")
        )));
    }
    Ok(col)
}

/// The rows with all of `cols` finite and a known group, as (group, values); and the count of
/// the others.
fn finite_rows<const N: usize>(
    table: &Table,
    cols: [&ColumnData; N],
    groups: &Groups,
) -> (Vec<(usize, [f64; N])>, usize) {
    let mut rows = Vec::with_capacity(table.rows());
    for r in 0..table.rows() {
        let values = cols.map(|c| c.number(r));
        match groups.of_row[r] {
            Some(g) if values.iter().all(|v| v.is_finite()) => rows.push((g, values)),
            _ => {}
        }
    }
    let skipped = table.rows() - rows.len();
    (rows, skipped)
}

fn no_rows_error(table: &Table, used: usize, names: &[&str]) -> Result<()> {
    if used > 0 {
        return Ok(());
    }
    Err(Error::Other(format!(
        "plot: no row has finite values in all of {} ({} rows, all skipped: failed runs have NaN KPIs)",
        names
            .iter()
            .map(|n| format!("{n:?}"))
            .collect::<Vec<_>>()
            .join(", "),
        table.rows()
    )))
}

/// The group of every row, and the groups' labels in plotting order.
struct Groups {
    labels: Vec<String>,
    of_row: Vec<Option<usize>>,
}

impl Groups {
    fn of(table: &Table, name: Option<&str>) -> Result<Groups> {
        let Some(name) = name else {
            return Ok(Groups {
                labels: vec![String::new()],
                of_row: vec![Some(0); table.rows()],
            });
        };
        if let ColumnData::Text(v) = column(table, name, "group")? {
            let mut labels: Vec<String> = Vec::new();
            let of_row = v
                .iter()
                .map(|s| {
                    Some(labels.iter().position(|l| l == s).unwrap_or_else(|| {
                        labels.push(s.clone());
                        labels.len() - 1
                    }))
                })
                .collect();
            return Ok(Groups { labels, of_row });
        }
        let col = column(table, name, "group")?;
        let values: Vec<f64> = (0..table.rows()).map(|r| col.number(r)).collect();
        let mut distinct: Vec<f64> = values.iter().copied().filter(|v| !v.is_nan()).collect();
        distinct.sort_by(f64::total_cmp);
        distinct.dedup();
        Ok(Groups {
            labels: distinct.iter().map(|v| group_value(col, *v)).collect(),
            of_row: values
                .iter()
                .map(|v| (!v.is_nan()).then(|| distinct.partition_point(|d| d < v)))
                .collect(),
        })
    }
}

fn group_value(col: &ColumnData, v: f64) -> String {
    match col {
        ColumnData::Bool(_) => (v != 0.0).to_string(),
        _ => plain(v),
    }
}

// ---------------------------------------------------------------------------------------------
// Numbers on axes, colours

/// A round step (1, 2, 2.5 or 5 times a power of ten) giving about `target` steps over `span`.
fn nice_step(span: f64, target: f64) -> f64 {
    let raw = (span / target).max(f64::MIN_POSITIVE);
    let mag = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 2.5, 5.0, 10.0]
        .into_iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw * (1.0 - 1e-9))
        .unwrap_or(10.0 * mag)
}

/// The multiples of `step` within `lo..=hi` (to a millionth of a step).
fn ticks(lo: f64, hi: f64, step: f64) -> Vec<f64> {
    let first = (lo / step - 1e-6).ceil() as i64;
    let last = (hi / step + 1e-6).floor() as i64;
    (first..=last).map(|k| k as f64 * step).collect()
}

/// A tick value printed with as many decimals as its step needs.
fn tick_label(v: f64, step: f64) -> String {
    let decimals = (0..8)
        .find(|d| {
            let s = step * 10f64.powi(*d);
            (s - s.round()).abs() < 1e-6 * s.max(1.0)
        })
        .unwrap_or(8) as usize;
    let s = format!("{v:.decimals$}");
    if s.trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        s.trim_start_matches('-').to_string()
    } else {
        s
    }
}

/// A value with 3 significant digits (cell annotations).
fn short_value(v: f64) -> String {
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        return format!("{v:.2e}");
    }
    let digits = if a == 0.0 {
        0
    } else {
        a.log10().floor() as i32
    };
    let decimals = (2 - digits).clamp(0, 4) as usize;
    format!("{v:.decimals$}")
}

/// A value as [`plain`] writes it when that is no longer than [`short_value`] (4 rather than
/// 4.00, 19.8 rather than 19.80; 1.17 rather than 1.169607).
fn compact(v: f64) -> String {
    let (p, s) = (plain(v), short_value(v));
    if p.len() <= s.len() {
        p
    } else {
        s
    }
}

/// `(lo, hi)` widened when empty (a single value) so that it can be mapped onto pixels.
fn widen(lo: f64, hi: f64) -> (f64, f64) {
    if hi > lo {
        return (lo, hi);
    }
    let d = if (lo.abs() * 0.1).is_normal() {
        lo.abs() * 0.1
    } else {
        1.0
    };
    (lo - d, hi + d)
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

// ---------------------------------------------------------------------------------------------
// Figure: canvas, title, caption, legend

fn font(size: u32) -> TextStyle<'static> {
    (FONT, size).into_font().color(&TEXT)
}

fn anchored(size: u32, h: HPos, v: VPos) -> TextStyle<'static> {
    font(size).pos(Pos::new(h, v))
}

/// Text with a hair space (U+200A) after each space. plotters 0.3.7 draws each glyph of the
/// embedded font without its left side bearing (plotters-rs/plotters#576), which closes up word
/// gaps ("of runs" reads "ofruns"); the hair space restores them.
fn typeset(text: &str) -> String {
    text.replace(' ', " \u{200A}")
}

/// A text element, typeset.
fn words(
    text: impl AsRef<str>,
    pos: (i32, i32),
    style: TextStyle<'static>,
) -> Text<'static, (i32, i32), String> {
    Text::new(typeset(text.as_ref()), pos, style)
}

/// `text` broken at spaces into lines no wider than `width` pixels (a longer word stands alone).
fn wrap(area: &Area, text: &str, size: u32, width: u32) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for word in text.split(' ') {
        match lines.last_mut() {
            Some(line) if text_width(area, &format!("{line} {word}"), size) <= width => {
                line.push(' ');
                line.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    lines
}

fn text_width(area: &Area, text: &str, size: u32) -> u32 {
    area.estimate_text_size(&typeset(text), &font(size))
        .map_or(text.chars().count() as u32 * size * 6 / 10, |(w, _)| w)
}

/// Checks the options and the output path, creating its folder; then calls `draw` on a white
/// canvas and writes the PNG.
fn render(
    opts: &PlotOptions,
    draw: impl FnOnce(&Area) -> Result<PlotSummary>,
) -> Result<PlotSummary> {
    let path = opts.path.as_path();
    let (w, h) = opts.size;
    if !(400..=8000).contains(&w) || !(300..=8000).contains(&h) {
        return Err(Error::Other(format!(
            "plot {}: size {w}x{h} pixels is outside 400x300 ..= 8000x8000",
            path.display()
        )));
    }
    let png = path.extension().and_then(|e| e.to_str());
    if !png.is_some_and(|e| e.eq_ignore_ascii_case("png")) {
        return Err(Error::Other(format!(
            "plot {}: the output must be a .png file",
            path.display()
        )));
    }
    create_parent_dir(path)?;
    std::fs::File::create(path)
        .map_err(|e| Error::io(format!("plot: cannot write {}", path.display()), e))?;
    register_font();
    let in_path = |e: Error| Error::Other(format!("plot {}: {e}", path.display()));
    let root = BitMapBackend::new(path, opts.size).into_drawing_area();
    root.fill(&WHITE).map_err(drawing_error).map_err(in_path)?;
    let summary = draw(&root).map_err(in_path)?;
    root.present().map_err(drawing_error).map_err(in_path)?;
    Ok(summary)
}

/// Draws the title and the caption lines and returns the area between them.
fn figure<'a>(root: &Area<'a>, title: &str, caption: &[String]) -> Result<Area<'a>> {
    let body = root
        .titled(&typeset(title), font(22))
        .map_err(drawing_error)?;
    let (w, h) = body.dim_in_pixel();
    let caption: Vec<String> = caption
        .iter()
        .flat_map(|c| wrap(root, c, 14, w - 24))
        .collect();
    let foot_h = 10 + 18 * caption.len() as u32;
    let (body, foot) = body.split_vertically(h.saturating_sub(foot_h));
    for (i, line) in caption.iter().enumerate() {
        foot.draw(&words(line.as_str(), (12, 2 + 18 * i as i32), font(14)))
            .map_err(drawing_error)?;
    }
    Ok(body)
}

/// The caption's first line: runs used and skipped, runs per point, and the band's definition.
fn caption(runs_per_point: (usize, usize), used: usize, skipped: usize, band: bool) -> Vec<String> {
    let mut first = match runs_per_point {
        (1, 1) => "One run per point".to_string(),
        (a, b) if a == b => format!("Mean of {a} runs per point"),
        (a, b) => format!("Mean of {a} to {b} runs per point"),
    };
    if band {
        first.push_str("; band: 5 to 95 % percentiles (linear interpolation, numpy's default)");
    }
    vec![first, runs_line(used, skipped)]
}

/// The caption's line of runs used and skipped.
fn runs_line(used: usize, skipped: usize) -> String {
    match skipped {
        0 => format!("{used} runs"),
        s => format!("{used} runs; {s} skipped (a plotted value is not finite, as in failed runs)"),
    }
}

fn runs_per_point(series: &[SeriesStats]) -> (usize, usize) {
    let n = series.iter().flat_map(|s| s.points.iter().map(|p| p.1.n));
    (n.clone().min().unwrap_or(0), n.max().unwrap_or(0))
}

/// One legend line.
struct Entry {
    label: String,
    color: RGBColor,
    mark: Mark,
}

/// How a legend entry shows its colour.
#[derive(Clone, Copy)]
enum Mark {
    /// A line with a marker: a series of means.
    Series,
    /// A swatch in the band's tint.
    Band,
    /// A bar filled with the colour at this opacity, outlined in the colour.
    Bar(f64),
    /// A plain line.
    Line,
    /// A dashed line.
    Dashed,
}

/// The legend's entries for `series` (labelled by `group_label = value`), and the band swatch.
fn entries(series: &[SeriesStats], group_label: &str, y_label: &str, band: bool) -> Vec<Entry> {
    let mut out: Vec<Entry> = series
        .iter()
        .enumerate()
        .map(|(i, s)| Entry {
            label: match &s.group {
                Some(g) => format!("{group_label} = {g}"),
                None => format!("mean {y_label}"),
            },
            color: color(i),
            mark: Mark::Series,
        })
        .collect();
    if band {
        let color = if series.len() == 1 {
            color(0)
        } else {
            RGBColor(120, 120, 120)
        };
        out.push(Entry {
            label: "5 to 95 % of runs".into(),
            color,
            mark: Mark::Band,
        });
    }
    out
}

/// The width of the legend panel at the right of the figure: the widest entry (the notes are
/// wrapped to it), at least 210 and at most 2/5 of the figure's width.
fn legend_width(area: &Area, entries: &[Entry]) -> u32 {
    let widest = entries
        .iter()
        .map(|e| text_width(area, &e.label, 15) + 44)
        .max()
        .unwrap_or(0);
    (widest + 36).max(210).min(area.dim_in_pixel().0 * 2 / 5)
}

/// Draws a boxed legend at the top of `area`, and `notes` under it (as many lines as fit).
fn draw_legend(area: &Area, entries: &[Entry], notes: &[String]) -> Result<()> {
    let (w, h) = area.dim_in_pixel();
    let (x0, y0, row) = (8, 24, 24);
    let box_h = 10 + row * entries.len() as i32;
    let x1 = w as i32 - 12;
    area.draw(&Rectangle::new(
        [(x0, y0), (x1, y0 + box_h)],
        AXIS.stroke_width(1),
    ))
    .map_err(drawing_error)?;
    for (k, e) in entries.iter().enumerate() {
        let y = y0 + 17 + row * k as i32;
        draw_mark(area, e, (x0 + 8, y))?;
        let label = words(
            e.label.as_str(),
            (x0 + 44, y),
            anchored(15, HPos::Left, VPos::Center),
        );
        area.draw(&label).map_err(drawing_error)?;
    }
    let notes: Vec<String> = notes
        .iter()
        .flat_map(|n| wrap(area, n, 14, w - 20))
        .collect();
    for (k, note) in notes.iter().enumerate() {
        let y = y0 + box_h + 22 + 20 * k as i32;
        if y + 10 > h as i32 {
            break;
        }
        area.draw(&words(
            note.as_str(),
            (x0, y),
            anchored(14, HPos::Left, VPos::Center),
        ))
        .map_err(drawing_error)?;
    }
    Ok(())
}

/// An entry's mark, 28 pixels wide from `(x, y)` (the middle of its left side).
fn draw_mark(area: &Area, e: &Entry, (x, y): (i32, i32)) -> Result<()> {
    let line = vec![(x, y), (x + 28, y)];
    match e.mark {
        Mark::Series => {
            area.draw(&PathElement::new(line, e.color.stroke_width(2)))
                .map_err(drawing_error)?;
            area.draw(&Circle::new((x + 14, y), 4, e.color.filled()))
                .map_err(drawing_error)
        }
        Mark::Band => {
            let style = e.color.mix(BAND_ALPHA * 1.5).filled();
            area.draw(&Rectangle::new([(x, y - 7), (x + 28, y + 7)], style))
                .map_err(drawing_error)
        }
        Mark::Bar(alpha) => {
            let corners = [(x + 4, y - 7), (x + 24, y + 7)];
            area.draw(&Rectangle::new(corners, e.color.mix(alpha).filled()))
                .map_err(drawing_error)?;
            area.draw(&Rectangle::new(corners, e.color.stroke_width(1)))
                .map_err(drawing_error)
        }
        Mark::Line => area
            .draw(&PathElement::new(line, e.color.stroke_width(2)))
            .map_err(drawing_error),
        Mark::Dashed => area
            .draw(&DashedPathElement::new(line, 6, 5, e.color.stroke_width(2)))
            .map_err(drawing_error),
    }
}

/// Splits off the legend panel at the right and draws it; returns the plotting part.
fn with_legend<'a>(body: &Area<'a>, entries: &[Entry], notes: &[String]) -> Result<Area<'a>> {
    let (w, _) = body.dim_in_pixel();
    let (plot, side) = body.split_horizontally(w - legend_width(body, entries));
    draw_legend(&side, entries, notes)?;
    Ok(plot)
}

fn label_or<'a>(label: &'a Option<String>, column: &'a str) -> &'a str {
    label.as_deref().unwrap_or(column)
}

// ---------------------------------------------------------------------------------------------
// KPI against one factor

/// Draws KPI `y` against factor `x`: for every distinct x (and value of `group`, one colour
/// each), the mean over the rows as points joined by a line, and the band from the 5 % to the
/// 95 % percentile ([`percentile`]) shaded where a point has two or more rows.
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

/// Whether a series has a design point with two or more runs (a band to draw).
fn spread(s: &SeriesStats) -> bool {
    s.points.iter().any(|p| p.1.n > 1)
}

/// The figure of [`line_band`] and [`polar`]: title (`labels.0` unless the options give one),
/// caption, legend (series of KPI `labels.1` per `group`, the band, then `notes`), and `draw`
/// for the plot beside the legend.
fn series_figure(
    agg: &Aggregate,
    opts: &PlotOptions,
    labels: (String, &str),
    group: Option<&str>,
    notes: &[String],
    draw: impl FnOnce(&Area) -> Result<Frame>,
) -> Result<PlotSummary> {
    let band = agg.series.iter().any(spread);
    let group_label = label_or(&opts.group_label, group.unwrap_or(""));
    let legend = entries(&agg.series, group_label, labels.1, band);
    let title = opts.title.clone().unwrap_or(labels.0);
    let per_point = runs_per_point(&agg.series);
    let caption = caption(per_point, agg.rows_used, agg.rows_skipped, band);
    render(opts, |root| {
        let body = figure(root, &title, &caption)?;
        let plot = with_legend(&body, &legend, notes)?;
        Ok(PlotSummary {
            rows_used: agg.rows_used,
            rows_skipped: agg.rows_skipped,
            series: agg.series.len(),
            frame: draw(&plot)?,
        })
    })
}

/// The data range of `values`, padded by `pad` of its span on both sides.
fn padded_range(values: impl Iterator<Item = f64>, pad: f64) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    let (lo, hi) = widen(lo, hi);
    let d = (hi - lo) * pad;
    (lo - d, hi + d)
}

/// The step between the 8 (at most) labels that plotters puts on an axis over `range`.
fn label_step(range: (f64, f64)) -> f64 {
    label_step_of(range, 8)
}

/// The step between the `n` (at most) labels that plotters puts on an axis over `range`.
fn label_step_of(range: (f64, f64), n: usize) -> f64 {
    let points = RangedCoordf64::from(range.0..range.1).key_points(n);
    let step = points
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(f64::INFINITY, f64::min);
    if step.is_finite() && step > 0.0 {
        step
    } else {
        range.1 - range.0
    }
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

/// A factor value as written in a campaign file: the fewest decimals (up to 6) that give it
/// back to 1e-9 (so that a linspace's 0.30000000000000004 reads 0.3).
fn plain(v: f64) -> String {
    for d in 0..=6usize {
        let s = format!("{v:.d$}");
        if s.parse::<f64>()
            .is_ok_and(|p| (p - v).abs() <= 1e-9 * v.abs().max(1.0))
        {
            return s;
        }
    }
    format!("{v:.3e}")
}

// ---------------------------------------------------------------------------------------------
// KPI over two factors

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

// ---------------------------------------------------------------------------------------------
// KPI against a direction

/// Draws the mean of KPI `r` against the direction `angle` on polar axes: concentric rings
/// labelled with their radius, spokes every 30° labelled with their angle, one series per
/// value of `group` (mean points joined by a line interpolated linearly in angle and radius),
/// and the 5–95 % band shaded where a direction has two or more rows.
///
/// - Directions are taken modulo 360° (2π), so 0° and 360° pool; values equal to within
///   1e-9° are one direction.
/// - A series is closed when its directions go round the whole circle: no gap between
///   neighbouring directions (the one across 0° included) wider than 1.5 times their median
///   gap. Otherwise it is open, running from the end of its widest gap round to its start.
/// - The centre is radius 0, or the lowest value rounded down to a ring when a value is
///   negative; the radius labels run along the middle of the widest gap between directions.
pub fn polar(
    table: &Table,
    angle: &str,
    r: &str,
    group: Option<&str>,
    opts: &PlotOptions,
) -> Result<PlotSummary> {
    let unit = opts.angle_unit;
    let cols = [("angle", angle), ("radius", r)];
    let agg = aggregate_by(table, cols, group, |a| direction(a, unit))?;
    let (a_label, r_label) = (label_or(&opts.x_label, angle), label_or(&opts.y_label, r));
    let notes = [
        format!("radius: {r_label}"),
        format!("angle: {a_label}"),
        match opts.orientation {
            Orientation::Compass => "0 at the top, clockwise".to_string(),
            Orientation::Mathematical => "0 to the right, counter-clockwise".to_string(),
        },
    ];
    let title = format!("{r_label} over {a_label}");
    series_figure(&agg, opts, (title, r_label), group, &notes, |plot| {
        draw_polar(plot, &agg.series, opts)
    })
}

/// A direction in degrees in [0, 360), rounded to 1e-9°.
fn direction(a: f64, unit: AngleUnit) -> f64 {
    let deg = match unit {
        AngleUnit::Degrees => a,
        AngleUnit::Radians => a.to_degrees(),
    };
    let d = (deg.rem_euclid(360.0) * 1e9).round() / 1e9;
    if d >= 360.0 {
        0.0
    } else {
        d + 0.0 // no -0.0
    }
}

/// The gaps between neighbouring directions (ascending in [0, 360)): gap `k` runs from
/// direction `k` to the next, the last one across 0°.
fn gaps(angles: &[f64]) -> Vec<f64> {
    let m = angles.len();
    (0..m)
        .map(|k| {
            let next = if k + 1 < m {
                angles[k + 1]
            } else {
                angles[0] + 360.0
            };
            next - angles[k]
        })
        .collect()
}

fn widest_gap(angles: &[f64]) -> usize {
    let g = gaps(angles);
    (0..g.len()).fold(0, |best, k| if g[k] > g[best] { k } else { best })
}

fn goes_round(angles: &[f64]) -> bool {
    if angles.len() < 3 {
        return false;
    }
    let mut g = gaps(angles);
    g.sort_by(f64::total_cmp);
    let median = g[g.len() / 2];
    g[g.len() - 1] <= 1.5 * median + 1e-9
}

/// Polar axes in the coordinates of their drawing area.
struct PolarAxes {
    centre: (f64, f64),
    radius: f64,
    r: (f64, f64),
    orientation: Orientation,
}

impl PolarAxes {
    /// The pixel `rho` pixels from the centre in direction `deg`.
    fn at(&self, deg: f64, rho: f64) -> (i32, i32) {
        let (s, c) = deg.to_radians().sin_cos();
        let (dx, dy) = match self.orientation {
            Orientation::Compass => (rho * s, -rho * c),
            Orientation::Mathematical => (rho * c, -rho * s),
        };
        (
            (self.centre.0 + dx).round() as i32,
            (self.centre.1 + dy).round() as i32,
        )
    }
    /// The pixel of the data point (direction `deg`, value `r`), clamped to the axes.
    fn point(&self, deg: f64, r: f64) -> (i32, i32) {
        let f = ((r - self.r.0) / (self.r.1 - self.r.0)).clamp(0.0, 1.0);
        self.at(deg, f * self.radius)
    }
}

fn draw_polar(area: &Area, series: &[SeriesStats], opts: &PlotOptions) -> Result<Frame> {
    let values = series
        .iter()
        .flat_map(|s| s.points.iter())
        .flat_map(|p| [p.1.p05, p.1.mean, p.1.p95]);
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    let (lo, hi) = widen(if lo >= 0.0 { 0.0 } else { lo }, hi);
    let step = nice_step(hi - lo, 5.0);
    let r = ((lo / step).floor() * step, (hi / step).ceil() * step);
    let labels = angle_labels(opts.angle_unit);
    let label_w = labels
        .iter()
        .map(|l| text_width(area, l, 14))
        .max()
        .unwrap_or(0) as f64;
    let (w, h) = area.dim_in_pixel();
    let radius = ((w as f64 - 2.0 * label_w - 40.0).min(h as f64 - 70.0) / 2.0).max(20.0);
    let axes = PolarAxes {
        centre: (w as f64 / 2.0, h as f64 / 2.0),
        radius,
        r,
        orientation: opts.orientation,
    };
    let mut all: Vec<f64> = series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.0))
        .collect();
    all.sort_by(f64::total_cmp);
    all.dedup();
    let k = widest_gap(&all);
    let middle = all[k] + gaps(&all)[k] / 2.0;
    let label_dir = ((middle - 15.0) / 30.0).round() * 30.0 + 15.0;
    draw_polar_grid(area, &axes, &labels)?;
    draw_ring_labels(area, &axes, step, label_dir)?;
    for (i, s) in series.iter().enumerate() {
        draw_polar_series(area, &axes, s, color(i))?;
    }
    let (bx, by) = area.get_base_pixel();
    Ok(Frame::Polar {
        centre: (
            bx + axes.centre.0.round() as i32,
            by + axes.centre.1.round() as i32,
        ),
        radius_px: radius,
        r,
    })
}

/// The labels of the spokes at 0°, 30°, … 330°.
fn angle_labels(unit: AngleUnit) -> Vec<String> {
    const PI: [&str; 12] = [
        "0", "π/6", "π/3", "π/2", "2π/3", "5π/6", "π", "7π/6", "4π/3", "3π/2", "5π/3", "11π/6",
    ];
    (0..12)
        .map(|k| match unit {
            AngleUnit::Degrees => format!("{}°", 30 * k),
            AngleUnit::Radians => PI[k].to_string(),
        })
        .collect()
}

fn draw_polar_grid(area: &Area, axes: &PolarAxes, labels: &[String]) -> Result<()> {
    for (k, label) in labels.iter().enumerate() {
        let deg = 30.0 * k as f64;
        let spoke = PathElement::new(
            vec![axes.at(deg, 0.0), axes.at(deg, axes.radius)],
            GRID.stroke_width(1),
        );
        area.draw(&spoke).map_err(drawing_error)?;
        let (x, y) = axes.at(deg, axes.radius + 8.0);
        let (dx, dy) = (x as f64 - axes.centre.0, y as f64 - axes.centre.1);
        let side = |d: f64| {
            if d > 0.3 * axes.radius {
                1
            } else if d < -0.3 * axes.radius {
                -1
            } else {
                0
            }
        };
        let h = [HPos::Right, HPos::Center, HPos::Left][(side(dx) + 1) as usize];
        let v = [VPos::Bottom, VPos::Center, VPos::Top][(side(dy) + 1) as usize];
        area.draw(&words(label.as_str(), (x, y), anchored(14, h, v)))
            .map_err(drawing_error)?;
    }
    let step = nice_step(axes.r.1 - axes.r.0, 5.0);
    for v in ticks(axes.r.0, axes.r.1, step).into_iter().skip(1) {
        let rho = (v - axes.r.0) / (axes.r.1 - axes.r.0) * axes.radius;
        let outer = v >= axes.r.1 - 1e-6 * step;
        let style = if outer {
            AXIS.stroke_width(1)
        } else {
            GRID.stroke_width(1)
        };
        let centre = axes.at(0.0, 0.0);
        area.draw(&Circle::new(centre, rho.round() as u32, style))
            .map_err(drawing_error)?;
    }
    Ok(())
}

fn draw_ring_labels(area: &Area, axes: &PolarAxes, step: f64, deg: f64) -> Result<()> {
    for v in ticks(axes.r.0, axes.r.1, step) {
        let rho = (v - axes.r.0) / (axes.r.1 - axes.r.0) * axes.radius;
        if rho == 0.0 && v == 0.0 {
            continue;
        }
        let text = tick_label(v, step);
        let (x, y) = axes.at(deg, rho);
        let half = text_width(area, &text, 13) as i32 / 2 + 3;
        let bg = Rectangle::new(
            [(x - half, y - 9), (x + half, y + 8)],
            WHITE.mix(0.85).filled(),
        );
        area.draw(&bg).map_err(drawing_error)?;
        let style = (FONT, 13)
            .into_font()
            .color(&RGBColor(70, 70, 70))
            .pos(Pos::new(HPos::Center, VPos::Center));
        area.draw(&words(text, (x, y), style))
            .map_err(drawing_error)?;
    }
    Ok(())
}

/// The series' points in drawing order (closed: back to the first; open: from the end of the
/// widest gap), each as (direction, stats).
fn polar_order(s: &SeriesStats) -> Vec<(f64, Stats)> {
    let angles: Vec<f64> = s.points.iter().map(|p| p.0).collect();
    let m = angles.len();
    if goes_round(&angles) {
        let mut v = s.points.clone();
        v.push(s.points[0]);
        return v;
    }
    let start = (widest_gap(&angles) + 1) % m;
    (0..m).map(|k| s.points[(start + k) % m]).collect()
}

/// The path through `values` at the directions of `order`, linear in angle and radius between
/// neighbours (at most 2° per piece).
fn polar_path(
    axes: &PolarAxes,
    order: &[(f64, Stats)],
    value: impl Fn(&Stats) -> f64,
) -> Vec<(i32, i32)> {
    let mut path = vec![axes.point(order[0].0, value(&order[0].1))];
    for pair in order.windows(2) {
        let ((a0, s0), (a1, s1)) = (pair[0], pair[1]);
        let d = (a1 - a0).rem_euclid(360.0);
        let pieces = (d / 2.0).ceil().max(1.0) as usize;
        for p in 1..=pieces {
            let f = p as f64 / pieces as f64;
            let (v0, v1) = (value(&s0), value(&s1));
            path.push(axes.point(a0 + f * d, v0 + f * (v1 - v0)));
        }
    }
    path
}

fn draw_polar_series(
    area: &Area,
    axes: &PolarAxes,
    s: &SeriesStats,
    color: RGBColor,
) -> Result<()> {
    let order = polar_order(s);
    if spread(s) {
        let mut band = polar_path(axes, &order, |st| st.p95);
        band.extend(polar_path(axes, &order, |st| st.p05).into_iter().rev());
        area.draw(&Polygon::new(band, color.mix(BAND_ALPHA).filled()))
            .map_err(drawing_error)?;
    }
    let mean = polar_path(axes, &order, |st| st.mean);
    area.draw(&PathElement::new(mean, color.stroke_width(2)))
        .map_err(drawing_error)?;
    for (deg, st) in &s.points {
        area.draw(&Circle::new(axes.point(*deg, st.mean), 4, color.filled()))
            .map_err(drawing_error)?;
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Distribution of a KPI

/// Opacity of a group's bars where groups overlay.
const OVERLAY_ALPHA: f64 = 0.45;
/// The mean and percentile lines of a histogram without groups.
const STAT_INK: RGBColor = RGBColor(20, 20, 20);
/// The height of a row of line tags above the bars, in pixels.
const TAG_ROW: i32 = 19;

/// Draws the distribution of KPI `x` over the rows (e.g. the Monte-Carlo runs of a robustness
/// study): bars of the runs in each of the [`bins`] (Freedman–Diaconis, or Sturges when the
/// interquartile range is 0), a solid line at the mean and dashed lines at the 5 % and 95 %
/// percentiles ([`percentile`]), tagged above the bars, with their values in the legend.
///
/// With `group`, each value of the group column gets its own semi-transparent histogram
/// (outlined in its colour) on the bins chosen for all rows, and its own mean and percentile
/// lines, so that the arms or variants of a study compare bin by bin.
pub fn histogram(
    table: &Table,
    x: &str,
    group: Option<&str>,
    opts: &PlotOptions,
) -> Result<PlotSummary> {
    let d = distribution(table, x, group)?;
    let x_label = label_or(&opts.x_label, x);
    let group_label = label_or(&opts.group_label, group.unwrap_or(""));
    let title = opts
        .title
        .clone()
        .unwrap_or_else(|| format!("Distribution of {x_label}"));
    let caption = [
        bins_caption(&d.bins, d.rows_used, d.groups.len()),
        runs_line(d.rows_used, d.rows_skipped),
    ];
    let (legend, notes) = histogram_legend(&d, group_label);
    render(opts, |root| {
        let body = figure(root, &title, &caption)?;
        let plot = with_legend(&body, &legend, &notes)?;
        Ok(PlotSummary {
            rows_used: d.rows_used,
            rows_skipped: d.rows_skipped,
            series: d.groups.len(),
            frame: draw_histogram(&plot, &d, x_label)?,
        })
    })
}

/// The caption's line on the bins: the rule, its numbers, and the percentiles' definition.
fn bins_caption(b: &Bins, n: usize, groups: usize) -> String {
    let (k, w) = (b.len(), compact(b.width()));
    let mut line = match b.rule {
        BinRule::FreedmanDiaconis => format!(
            "Bins: Freedman–Diaconis rule, width 2 IQR n^(-1/3) with n = {n}, rounded to {k} bins of {w}"
        ),
        BinRule::Sturges => format!(
            "Bins: Sturges' rule (the interquartile range is 0), ceil(log2 {n}) + 1 = {k} bins of {w}"
        ),
        BinRule::SingleValue => format!(
            "All runs have the value {}: one bin centred on it",
            compact((b.edges[0] + b.edges[1]) / 2.0)
        ),
    };
    if b.capped {
        line.push_str(&format!(" (capped at {MAX_BINS} bins)"));
    }
    if groups > 1 {
        line.push_str("; the groups share the bins");
    }
    line.push_str("; percentiles: linear interpolation (numpy's default)");
    line
}

/// The colour of group `i`'s bars and lines, and the opacity of its bars.
fn bar_style(i: usize, groups: usize) -> (RGBColor, RGBColor, f64) {
    match groups {
        1 => (color(0), STAT_INK, 1.0),
        _ => (color(i), color(i), OVERLAY_ALPHA),
    }
}

/// The legend (bars, mean, percentiles) and its notes. Without groups the entries carry the
/// values; with groups the notes give each group's mean and percentiles.
fn histogram_legend(d: &Distribution, group_label: &str) -> (Vec<Entry>, Vec<String>) {
    let many = d.groups.len();
    let mut entries: Vec<Entry> = d
        .groups
        .iter()
        .enumerate()
        .map(|(i, g)| {
            let (color, _, alpha) = bar_style(i, many);
            Entry {
                label: match &g.group {
                    Some(v) => format!("{group_label} = {v} ({} runs)", g.stats.n),
                    None => format!("runs per bin ({} runs)", g.stats.n),
                },
                color,
                mark: Mark::Bar(alpha),
            }
        })
        .collect();
    let (mean, band, ink) = match &d.groups[..] {
        [one] => (
            format!("mean {}", compact(one.stats.mean)),
            format!(
                "5 % {} and 95 % {}",
                compact(one.stats.p05),
                compact(one.stats.p95)
            ),
            STAT_INK,
        ),
        _ => (
            "mean (group colour)".to_string(),
            "5 % and 95 % (group colour)".to_string(),
            RGBColor(110, 110, 110),
        ),
    };
    for (label, mark) in [(mean, Mark::Line), (band, Mark::Dashed)] {
        entries.push(Entry {
            label,
            color: ink,
            mark,
        });
    }
    let mut notes = Vec::new();
    for g in d.groups.iter().filter(|_| many > 1) {
        let (s, v) = (g.stats, g.group.as_deref().unwrap_or(""));
        notes.push(format!("{group_label} = {v}: mean {}", compact(s.mean)));
        notes.push(format!("5 % {}, 95 % {}", compact(s.p05), compact(s.p95)));
    }
    (entries, notes)
}

/// A line at a statistic of a group, and its tag above the bars.
struct Tag {
    value: f64,
    text: String,
    color: RGBColor,
    dashed: bool,
    group: usize,
}

fn tags(d: &Distribution) -> Vec<Tag> {
    let many = d.groups.len();
    let mut out = Vec::new();
    for (i, g) in d.groups.iter().enumerate() {
        let (_, color, _) = bar_style(i, many);
        for (value, text, dashed) in [
            (g.stats.p05, "5 %", true),
            (g.stats.mean, "mean", false),
            (g.stats.p95, "95 %", true),
        ] {
            out.push(Tag {
                value,
                text: text.to_string(),
                color,
                dashed,
                group: i,
            });
        }
    }
    out
}

/// The tags with their pixel columns `xs`, those of a group within 2 pixels of each other
/// merged into one ("5 %, mean, 95 %" when all runs are equal), solid if one of them is.
fn merge_tags(tags: Vec<Tag>, xs: &[i32]) -> (Vec<Tag>, Vec<i32>) {
    let (mut kept, mut kept_xs): (Vec<Tag>, Vec<i32>) = (Vec::new(), Vec::new());
    for (t, x) in tags.into_iter().zip(xs) {
        let same = kept
            .iter()
            .zip(&kept_xs)
            .position(|(k, kx)| k.group == t.group && (kx - x).abs() <= 2);
        match same {
            Some(k) => {
                kept[k].text = format!("{}, {}", kept[k].text, t.text);
                kept[k].dashed &= t.dashed;
            }
            None => {
                kept.push(t);
                kept_xs.push(*x);
            }
        }
    }
    (kept, kept_xs)
}

/// Rows for tags centred at `xs` (pixels) and `widths` wide: each tag goes to the first row
/// (from the top) where it clears the tags already there, taking them from left to right.
/// Returns each tag's row and the number of rows.
fn tag_rows(xs: &[i32], widths: &[i32]) -> (Vec<usize>, usize) {
    let mut order: Vec<usize> = (0..xs.len()).collect();
    order.sort_by_key(|&k| xs[k]);
    let mut ends: Vec<i32> = Vec::new();
    let mut rows = vec![0; xs.len()];
    for k in order {
        let left = xs[k] - widths[k] / 2;
        let row = ends
            .iter()
            .position(|e| left > *e + 4)
            .unwrap_or(ends.len());
        if row == ends.len() {
            ends.push(0);
        }
        ends[row] = left + widths[k];
        rows[k] = row;
    }
    (rows, ends.len())
}

type HistogramChart<'a, 'b> =
    ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordu32>>;

/// The chart of a histogram: `x` over the data range, counts 0 to `y_top` (integers, so that
/// the axis has no fractional runs).
fn histogram_chart<'a, 'b>(
    area: &'a Area<'b>,
    x: (f64, f64),
    y_top: u32,
) -> Result<HistogramChart<'a, 'b>> {
    ChartBuilder::on(area)
        .margin_top(16)
        .margin_left(12)
        .margin_right(16)
        .x_label_area_size(56)
        .y_label_area_size(78)
        .build_cartesian_2d(x.0..x.1, 0..y_top)
        .map_err(drawing_error)
}

fn draw_histogram(area: &Area, d: &Distribution, x_label: &str) -> Result<Frame> {
    let b = &d.bins;
    let pad = if b.rule == BinRule::SingleValue {
        0.5
    } else {
        0.04
    };
    let xr = padded_range([b.edges[0], b.edges[b.len()]].into_iter(), pad);
    let tags = tags(d);
    // The chart's pixels along x do not depend on the count axis: lay the tags out on a probe
    // chart, then leave room above the tallest bar for their rows.
    let probe = histogram_chart(area, xr, 1)?;
    let (px, py) = probe.plotting_area().get_pixel_range();
    let xs: Vec<i32> = tags
        .iter()
        .map(|t| probe.backend_coord(&(t.value, 0)).0)
        .collect();
    let (tags, xs) = merge_tags(tags, &xs);
    let widths: Vec<i32> = tags
        .iter()
        .map(|t| text_width(area, &t.text, 13) as i32 + 8)
        .collect();
    let xs: Vec<i32> = xs
        .iter()
        .zip(&widths)
        .map(|(x, w)| (*x).clamp(px.start + w / 2, (px.end - w / 2).max(px.start + w / 2)))
        .collect();
    let (rows, n_rows) = tag_rows(&xs, &widths);
    let height = (py.end - py.start) as f64;
    let free = (height - (n_rows as i32 * TAG_ROW + 24) as f64).max(0.3 * height);
    let tallest = d.groups.iter().flat_map(|g| g.counts.iter()).max().copied();
    let tallest = tallest.unwrap_or(1).max(1) as u32;
    let y_top = ((tallest as f64 * height / free).ceil() as u32).max(tallest + 1);
    let mut chart = histogram_chart(area, xr, y_top)?;
    let n_labels = x_labels_that_fit(area, xr, px.end - px.start);
    let x_step = label_step_of(xr, n_labels);
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_desc(typeset(x_label))
        .y_desc("runs")
        .x_labels(n_labels)
        .y_labels(8)
        .x_label_formatter(&|v| tick_label(*v, x_step))
        .label_style(font(14))
        .axis_desc_style(font(17))
        .bold_line_style(RGBColor(225, 225, 225))
        // Counts are whole: no lines between the labelled ones (and `max_light_lines(0)` hangs
        // plotters 0.3.7).
        .light_line_style(TRANSPARENT)
        .axis_style(AXIS)
        .draw()
        .map_err(drawing_error)?;
    draw_bars(&mut chart, d)?;
    let (bx, by) = area.get_base_pixel();
    let base = chart.backend_coord(&(xr.0, 0)).1 - by;
    let placed: Vec<(i32, i32)> = xs
        .iter()
        .zip(&rows)
        .map(|(x, r)| (*x - bx, py.start - by + 4 + *r as i32 * TAG_ROW))
        .collect();
    draw_tags(area, &chart, &tags, &placed, base)?;
    let top_left = chart.backend_coord(&(xr.0, y_top));
    let bottom_right = chart.backend_coord(&(xr.1, 0));
    Ok(Frame::cartesian(
        top_left,
        bottom_right,
        xr,
        (0.0, y_top as f64),
    ))
}

/// The most labels (2 to 8) along `range` whose widest label, 12 pixels apart, fits `width`.
fn x_labels_that_fit(area: &Area, range: (f64, f64), width: i32) -> usize {
    (2..=8)
        .rev()
        .find(|&n| {
            let step = label_step_of(range, n);
            let widest = ticks(range.0, range.1, step)
                .iter()
                .map(|v| text_width(area, &tick_label(*v, step), 14) as i32)
                .max()
                .unwrap_or(0);
            let count = ((range.1 - range.0) / step).floor() as i32 + 1;
            count * (widest + 12) <= width
        })
        .unwrap_or(2)
}

/// Each group's bars: without groups solid, with white lines between bins; with groups
/// semi-transparent, each outlined by its steps.
fn draw_bars(chart: &mut HistogramChart, d: &Distribution) -> Result<()> {
    let e = &d.bins.edges;
    let many = d.groups.len();
    for (i, g) in d.groups.iter().enumerate() {
        let (color, _, alpha) = bar_style(i, many);
        let bars = g.counts.iter().enumerate().filter(|(_, c)| **c > 0);
        chart
            .draw_series(bars.map(|(k, c)| {
                Rectangle::new(
                    [(e[k], 0), (e[k + 1], *c as u32)],
                    color.mix(alpha).filled(),
                )
            }))
            .map_err(drawing_error)?;
        if many == 1 {
            let between = (1..g.counts.len()).map(|k| {
                let h = g.counts[k - 1].max(g.counts[k]) as u32;
                PathElement::new(vec![(e[k], 0), (e[k], h)], WHITE.stroke_width(1))
            });
            chart.draw_series(between).map_err(drawing_error)?;
        } else {
            chart
                .draw_series(
                    outlines(e, &g.counts)
                        .into_iter()
                        .map(|steps| PathElement::new(steps, color.stroke_width(2))),
                )
                .map_err(drawing_error)?;
        }
    }
    Ok(())
}

/// The outlines of the runs of non-empty bins, each up from the base, along the bins' tops and
/// back down (not along the base under another group's bars).
fn outlines(edges: &[f64], counts: &[usize]) -> Vec<Vec<(f64, u32)>> {
    let mut out = Vec::new();
    let mut k = 0;
    while k < counts.len() {
        if counts[k] == 0 {
            k += 1;
            continue;
        }
        let mut path = vec![(edges[k], 0)];
        while k < counts.len() && counts[k] > 0 {
            let c = counts[k] as u32;
            path.extend([(edges[k], c), (edges[k + 1], c)]);
            k += 1;
        }
        path.push((edges[k], 0));
        out.push(path);
    }
    out
}

/// The lines from the bars' base (`base`, area pixels) up to their tags, dashed ones first,
/// then the tags at `placed` (the top middle of each, area pixels) on white.
fn draw_tags(
    area: &Area,
    chart: &HistogramChart,
    tags: &[Tag],
    placed: &[(i32, i32)],
    base: i32,
) -> Result<()> {
    let (bx, _) = area.get_base_pixel();
    for dashed in [true, false] {
        for (t, (_, y)) in tags.iter().zip(placed).filter(|(t, _)| t.dashed == dashed) {
            let x = chart.backend_coord(&(t.value, 0)).0 - bx;
            let line = vec![(x, base), (x, y + TAG_ROW - 2)];
            let style = t.color.stroke_width(2);
            if dashed {
                area.draw(&DashedPathElement::new(line, 7, 5, style))
            } else {
                area.draw(&PathElement::new(line, style))
            }
            .map_err(drawing_error)?;
        }
    }
    for (t, (x, y)) in tags.iter().zip(placed) {
        let half = text_width(area, &t.text, 13) as i32 / 2 + 4;
        let bg = Rectangle::new(
            [(x - half, y + 1), (x + half, y + TAG_ROW - 2)],
            WHITE.mix(0.9).filled(),
        );
        area.draw(&bg).map_err(drawing_error)?;
        let style = (FONT, 13)
            .into_font()
            .color(&t.color)
            .pos(Pos::new(HPos::Center, VPos::Center));
        area.draw(&words(&t.text, (*x, y + TAG_ROW / 2), style))
            .map_err(drawing_error)?;
    }
    Ok(())
}
