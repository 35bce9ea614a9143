//! The statistics of the campaign plots: percentiles, the [`Stats`] of a design point's runs,
//! histogram [`Bins`], and the reduction of a run table's rows to them ([`aggregate`],
//! [`grid`], [`distribution`]), reading its columns and groups.

use super::figure::{plain, widen};
use crate::campaign::table::{ColumnData, Table};
use crate::error::{suggest, Error, Result};

/// The percentiles of the band.
const BAND: (f64, f64) = (5.0, 95.0);

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
pub(super) fn aggregate_by(
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
// The run table's columns and groups

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
