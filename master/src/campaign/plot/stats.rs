//! The statistics of the campaign plots: percentiles, the [`Stats`] of a design point's runs,
//! histogram [`Bins`], and the reduction of a run table's rows to them ([`aggregate`],
//! [`grid`], [`distribution`]), reading its columns and groups.

use crate::campaign::table::{ColumnData, Table};
use crate::error::{suggest, Error, Result};

/// The percentiles of the band.
const BAND: (f64, f64) = (5.0, 95.0);

/// The `p`-th percentile (0 ≤ p ≤ 100) of values sorted ascending (not empty, no NaN), by
/// linear interpolation between order statistics: with the values x₀ ≤ … ≤ xₙ₋₁ and
/// h = (n − 1) p / 100, it is x⌊h⌋ + (h − ⌊h⌋)(x⌊h⌋₊₁ − x⌊h⌋). This is definition 7 of Hyndman and
/// Fan (*Sample quantiles in statistical packages*, The American Statistician 50 (1996)
/// 361–365), the default of numpy's `percentile` (`method="linear"`) and of R's `quantile`; the
/// interpolation is evaluated as numpy does (from the upper neighbour when the fraction is at
/// least 0.5).
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

/// The runs of one design point: their number, mean and 5 % / 95 % percentiles (linear
/// interpolation between order statistics, numpy's default: definition 7 of Hyndman and Fan).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stats {
    pub n: usize,
    pub mean: f64,
    pub p05: f64,
    pub p95: f64,
}

impl Stats {
    /// The statistics of finite values; `None` when there are none or one is not finite.
    fn of(values: &[f64]) -> Option<Stats> {
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
pub(super) const MAX_BINS: usize = 100;

/// The rule by which the [`Bins`] were chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinRule {
    /// Freedman and Diaconis: width 2 IQR n^(-1/3).
    FreedmanDiaconis,
    /// Sturges: ceil(log₂ n) + 1 bins (the interquartile range is 0).
    Sturges,
    /// All values are equal: one bin centred on them.
    SingleValue,
}

/// Bins of equal width over the values' range and the values in each; [`BinRule`] says how
/// many there are.
#[derive(Clone, Debug, PartialEq)]
pub struct Bins {
    /// Ascending, one more than the bins: bin `i` is `edges[i] <= v < edges[i + 1]`, the last
    /// one closed (`v <= edges[n]`), as in numpy's `histogram`.
    pub edges: Vec<f64>,
    /// The values in each bin.
    pub counts: Vec<usize>,
    pub rule: BinRule,
    /// The rule asked for more than 100 bins (the most there may be); there are 100.
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
    fn index(&self, v: f64) -> Option<usize> {
        let n = self.len();
        if n == 0 || !(self.edges[0]..=self.edges[n]).contains(&v) {
            return None;
        }
        Some((self.edges.partition_point(|e| *e <= v).saturating_sub(1)).min(n - 1))
    }

    /// The number of `values` in each bin (values outside the edges are not counted): a
    /// group's histogram on bins chosen for all runs.
    fn count(&self, values: &[f64]) -> Vec<usize> {
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
/// und verwandte Gebiete 57 (1981) 453–476): width 2 IQR n^(-1/3), with the interquartile
/// range IQR from [`percentile_sorted`] (75 % minus 25 %); the count is the range over that
/// width rounded up, and the width is then the range over the count. This is numpy's
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
fn bins(values: &[f64]) -> Option<Bins> {
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

/// The [`Bins`] of KPI `x` over the rows with a finite value, and the counts and [`Stats`] of
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

/// `(lo, hi)` widened when empty (a single value) so that it can be mapped onto pixels.
pub(super) fn widen(lo: f64, hi: f64) -> (f64, f64) {
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

/// A factor value as written in a campaign file: the fewest decimals (up to 6) that give it
/// back to 1e-9 (so that a linspace's 0.30000000000000004 reads 0.3).
pub(super) fn plain(v: f64) -> String {
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

#[cfg(test)]
mod tests {
    //! The statistics against values worked out by hand (the working is in the comments);
    //! where numpy (2.4.6) was asked too, it agrees.

    use super::*;

    fn close(got: f64, want: f64) -> bool {
        (got - want).abs() < 1e-12
    }

    /// A table of the given columns.
    fn table(columns: Vec<(&str, ColumnData)>) -> Table {
        let mut t = Table::default();
        for (name, data) in columns {
            t.push(name, data);
        }
        t
    }

    #[test]
    fn percentiles_interpolate_between_order_statistics() {
        // 1, 2, 3, 4: p5 at h = 3 * 0.05 = 0.15, 1 + 0.15 (2 - 1) = 1.15; p95 at h = 2.85,
        // 3 + 0.85 (4 - 3) = 3.85 (numpy: 3.8499999999999996, the bits we give too).
        let v = [1.0, 2.0, 3.0, 4.0];
        let (p5, p95) = (percentile_sorted(&v, 5.0), percentile_sorted(&v, 95.0));
        assert!(close(p5, 1.15), "{p5}");
        assert!(close(p95, 3.85), "{p95}");
        assert_eq!(p95, 3.8499999999999996);
        // -2, 0.25, 3.1, 7.5, 9 (n - 1 = 4):
        // p5: h = 0.2, -2 + 0.2 (0.25 + 2) = -1.55; p95: h = 3.8, 7.5 + 0.8 (9 - 7.5) = 8.7;
        // p37: h = 1.48, 0.25 + 0.48 (3.1 - 0.25) = 1.618; p50: h = 2, 3.1; p0 and p100 the ends.
        let v = [-2.0, 0.25, 3.1, 7.5, 9.0];
        for (p, want) in [
            (5.0, -1.55),
            (95.0, 8.7),
            (37.0, 1.618),
            (50.0, 3.1),
            (100.0, 9.0),
            (0.0, -2.0),
        ] {
            let got = percentile_sorted(&v, p);
            assert!(close(got, want), "p{p}: {got}, want {want}");
        }
        // One value is every percentile.
        assert_eq!(percentile_sorted(&[7.0], 95.0), 7.0);
        assert_eq!(percentile_sorted(&[7.0], 0.0), 7.0);
    }

    #[test]
    fn stats_are_the_mean_and_the_band_of_finite_values() {
        // 6, 10, 14: mean 10; p5 at h = 2 * 0.05 = 0.1, 6 + 0.1 * 4 = 6.4; p95 at h = 1.9,
        // 10 + 0.9 * 4 = 13.6. The order of the values does not matter.
        let s = Stats::of(&[14.0, 6.0, 10.0]).unwrap();
        assert_eq!(s.n, 3);
        assert!(
            close(s.mean, 10.0) && close(s.p05, 6.4) && close(s.p95, 13.6),
            "{s:?}"
        );
        let one = Stats::of(&[-2.5]).unwrap();
        assert_eq!((one.n, one.mean, one.p05, one.p95), (1, -2.5, -2.5, -2.5));
        assert_eq!(Stats::of(&[]), None);
        assert_eq!(Stats::of(&[1.0, f64::NAN]), None);
        assert_eq!(Stats::of(&[1.0, f64::INFINITY]), None);
    }

    #[test]
    fn reduce_pools_the_values_of_each_key() {
        // Key 1: 1 and 3, mean 2, p5 = 1 + 0.05 * 2 = 1.1, p95 = 1 + 0.95 * 2 = 2.9.
        // Key 2: 5 and 7, mean 6, p5 5.1, p95 6.9. Key 4: 4 alone.
        let r = reduce(vec![
            (2.0, 5.0),
            (4.0, 4.0),
            (1.0, 1.0),
            (2.0, 7.0),
            (1.0, 3.0),
        ]);
        let keys: Vec<f64> = r.iter().map(|p| p.0).collect();
        assert_eq!(keys, [1.0, 2.0, 4.0]);
        for ((_, s), (n, mean, p05, p95)) in
            r.iter()
                .zip([(2, 2.0, 1.1, 2.9), (2, 6.0, 5.1, 6.9), (1, 4.0, 4.0, 4.0)])
        {
            assert_eq!(s.n, n);
            assert!(
                close(s.mean, mean) && close(s.p05, p05) && close(s.p95, p95),
                "{s:?}"
            );
        }
    }

    /// 1 to 7 with the multiplicities 2, 4, 8, 12, 8, 4, 2 (40 values).
    fn study() -> Vec<f64> {
        (1..=7)
            .zip([2, 4, 8, 12, 8, 4, 2])
            .flat_map(|(v, m)| std::iter::repeat_n(v as f64, m))
            .collect()
    }

    #[test]
    fn bins_follow_freedman_diaconis() {
        // 0..=99: p25 at h = 99 * 0.25 = 24.75 is 24.75, p75 74.25, IQR 49.5; width
        // 2 * 49.5 * 100^(-1/3) = 21.33; 99 / 21.33 = 4.64, so 5 bins of 99 / 5 = 19.8 with 20
        // values each. The edges are i * 19.8 (3 * 19.8 rounds to 59.400000000000006), as
        // np.histogram_bin_edges(np.arange(100.), "fd") gives them.
        let v: Vec<f64> = (0..100).map(f64::from).collect();
        let b = bins(&v).unwrap();
        assert_eq!(b.edges, [0.0, 19.8, 39.6, 59.400000000000006, 79.2, 99.0]);
        assert_eq!(b.counts, [20; 5]);
        assert_eq!(
            (b.rule, b.capped, b.len(), b.is_empty()),
            (BinRule::FreedmanDiaconis, false, 5, false)
        );
        assert!(close(b.width(), 19.8), "{}", b.width());

        // The study, sorted x0..x39: 1 at 0-1, 2 at 2-5, 3 at 6-13, 4 at 14-25, 5 at 26-33, 6 at
        // 34-37, 7 at 38-39. p25 at h = 9.75: x9 = x10 = 3; p75 at h = 29.25: x29 = x30 = 5;
        // IQR 2; width 4 * 40^(-1/3) = 1.17; 6 / 1.17 = 5.13, so 6 bins of 1: [1, 2) 2, [2, 3) 4,
        // [3, 4) 8, [4, 5) 12, [5, 6) 8, and [6, 7] (closed) 4 + 2.
        let b = bins(&study()).unwrap();
        assert_eq!(b.edges, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]);
        assert_eq!(b.counts, [2, 4, 8, 12, 8, 6]);
    }

    #[test]
    fn bins_fall_back_to_sturges_a_cap_and_one_bin() {
        // 1, 5 (x17), 9, 13: p25 (h = 4.75) and p75 (h = 14.25) are both 5, IQR 0. Sturges:
        // ceil(log2 20) + 1 = 5 + 1 = 6 bins of 12 / 6 = 2 over [1, 13].
        let mut v = vec![1.0, 9.0, 13.0];
        v.extend([5.0; 17]);
        let b = bins(&v).unwrap();
        assert_eq!(b.rule, BinRule::Sturges);
        assert_eq!(b.edges, [1.0, 3.0, 5.0, 7.0, 9.0, 11.0, 13.0]);
        assert_eq!(b.counts, [1, 0, 17, 0, 1, 1]);

        // 0..=999 and one outlier at 1e6: IQR 750 - 250 = 500, width 1000 * 1001^(-1/3) = 99.97,
        // 1e6 / 99.97 = 10004 bins; capped at 100 bins of 1e4.
        let mut v: Vec<f64> = (0..1000).map(f64::from).collect();
        v.push(1e6);
        let b = bins(&v).unwrap();
        assert_eq!((b.len(), b.capped, MAX_BINS), (100, true, 100));
        assert_eq!((b.edges[0], b.edges[1], b.edges[100]), (0.0, 1e4, 1e6));
        assert_eq!((b.counts[0], b.counts[99]), (1000, 1));
        assert_eq!(b.counts[1..99].iter().sum::<usize>(), 0);

        // A single distinct value: one bin centred on it, +- a tenth of it (+- 1 at 0).
        let b = bins(&[2.5, 2.5, 2.5]).unwrap();
        assert_eq!(
            (b.rule, b.edges.clone(), b.counts),
            (BinRule::SingleValue, vec![2.25, 2.75], vec![3])
        );
        assert_eq!(bins(&[0.0]).unwrap().edges, [-1.0, 1.0]);
        assert_eq!(bins(&[-4.0]).unwrap().edges, [-4.4, -3.6]);

        assert_eq!(bins(&[]), None);
        assert_eq!(bins(&[1.0, f64::NAN]), None);
        assert_eq!(bins(&[1.0, f64::INFINITY]), None);
        assert_eq!(bins(&[-1e308, 1e308]), None, "the range overflows");
    }

    #[test]
    fn bins_are_half_open_and_the_last_is_closed() {
        let b = bins(&study()).unwrap(); // edges 1, 2, ..., 7
        assert_eq!(b.index(1.0), Some(0));
        assert_eq!(b.index(1.9999), Some(0));
        assert_eq!(b.index(2.0), Some(1));
        assert_eq!(b.index(7.0), Some(5));
        assert_eq!(
            (b.index(0.999), b.index(7.001), b.index(f64::NAN)),
            (None, None, None)
        );
        // Values outside the edges are not counted.
        assert_eq!(b.count(&[0.0, 1.5, 4.0, 4.5, 7.0, 8.0]), [1, 0, 0, 2, 0, 1]);
        let none = Bins {
            edges: vec![],
            counts: vec![],
            rule: BinRule::SingleValue,
            capped: false,
        };
        assert!(none.is_empty() && none.width().is_nan() && none.index(0.0).is_none());
    }

    #[test]
    fn aggregate_groups_text_in_order_of_appearance_and_numbers_ascending() {
        let x = ColumnData::Float(vec![1.0, 2.0, 1.0, 2.0, 1.0, 2.0, f64::NAN]);
        let y = ColumnData::Float(vec![10.0, 20.0, 14.0, 24.0, f64::NAN, 30.0, 5.0]);
        let arm = ColumnData::Text(["b", "b", "a", "a", "b", "a", "a"].map(String::from).into());
        let hs = ColumnData::Float(vec![3.0, 1.0, 3.0, 1.0, 3.0, f64::NAN, 1.0]);
        let rrs = ColumnData::Bool(vec![true, false, true, false, true, false, false]);
        let t = table(vec![
            ("x", x),
            ("y", y),
            ("arm", arm),
            ("hs", hs),
            ("rrs", rrs),
        ]);
        // Rows 4 (y NaN) and 6 (x NaN) are skipped. "b": x = 1 [10], x = 2 [20]; "a": x = 1
        // [14], x = 2 [24, 30] (mean 27, p5 24 + 0.05 * 6 = 24.3, p95 24 + 0.95 * 6 = 29.7).
        let a = aggregate(&t, "x", "y", Some("arm")).unwrap();
        assert_eq!((a.rows_used, a.rows_skipped), (5, 2));
        let groups: Vec<_> = a.series.iter().map(|s| s.group.as_deref()).collect();
        assert_eq!(groups, [Some("b"), Some("a")]);
        let means = |s: &SeriesStats| s.points.iter().map(|p| (p.0, p.1.mean)).collect::<Vec<_>>();
        assert_eq!(means(&a.series[0]), [(1.0, 10.0), (2.0, 20.0)]);
        assert_eq!(means(&a.series[1]), [(1.0, 14.0), (2.0, 27.0)]);
        let s = a.series[1].points[1].1;
        assert!(
            s.n == 2 && close(s.p05, 24.3) && close(s.p95, 29.7),
            "{s:?}"
        );

        // A number group: its values ascending, as written in a campaign file; a row whose
        // group is NaN (row 5) is skipped too. "1": x = 2 [20, 24]; "3": x = 1 [10, 14].
        let a = aggregate(&t, "x", "y", Some("hs")).unwrap();
        assert_eq!((a.rows_used, a.rows_skipped), (4, 3));
        let groups: Vec<_> = a.series.iter().map(|s| s.group.as_deref()).collect();
        assert_eq!(groups, [Some("1"), Some("3")]);
        assert_eq!(means(&a.series[0]), [(2.0, 22.0)]);
        assert_eq!(means(&a.series[1]), [(1.0, 12.0)]);

        // A Bool group reads false, true.
        let a = aggregate(&t, "x", "y", Some("rrs")).unwrap();
        let groups: Vec<_> = a.series.iter().map(|s| s.group.as_deref()).collect();
        assert_eq!(groups, [Some("false"), Some("true")]);

        // Without a group: one series without a name; x = 1 [10, 14], x = 2 [20, 24, 30].
        let a = aggregate(&t, "x", "y", None).unwrap();
        assert_eq!(a.series.len(), 1);
        assert_eq!(a.series[0].group, None);
        assert_eq!(
            means(&a.series[0]),
            [(1.0, 12.0), (2.0, 24.666666666666668)]
        );
    }

    #[test]
    fn grid_reduces_every_cell_and_leaves_empty_ones_empty() {
        // Cells (x, y): (1, 0.5) [1, 3], (2, 0.5) [2], (1, 1.5) [4]; (2, 1.5) has no run; the
        // last row's z is NaN.
        let t = table(vec![
            ("x", ColumnData::Int(vec![1, 2, 1, 1, 2])),
            ("y", ColumnData::Float(vec![0.5, 0.5, 1.5, 0.5, 1.5])),
            ("z", ColumnData::Float(vec![1.0, 2.0, 4.0, 3.0, f64::NAN])),
        ]);
        let g = grid(&t, "x", "y", "z").unwrap();
        assert_eq!(
            (g.xs.clone(), g.ys.clone()),
            (vec![1.0, 2.0], vec![0.5, 1.5])
        );
        assert_eq!((g.rows_used, g.rows_skipped), (4, 1));
        let cells: Vec<_> = g.cells.iter().map(|c| c.map(|s| (s.n, s.mean))).collect();
        assert_eq!(
            cells,
            [Some((2, 2.0)), Some((1, 2.0)), Some((1, 4.0)), None]
        );
    }

    #[test]
    fn distribution_counts_each_group_on_shared_bins() {
        // 0..=9: p25 at h = 2.25 is 2.25, p75 6.75, IQR 4.5; width 9 * 10^(-1/3) = 4.18;
        // 9 / 4.18 = 2.15, so 3 bins of 3: [0, 3) 3, [3, 6) 3, [6, 9] 4. Group "A" holds 0..=4,
        // [3, 2, 0], mean 2, p5 at h = 0.2: 0.2, p95 at h = 3.8: 3.8; "B" 5..=9 and a NaN,
        // [0, 1, 4], mean 7, p5 5.2, p95 8.8; "C" only a NaN: no histogram.
        let mut kpi: Vec<f64> = (0..10).map(f64::from).collect();
        kpi.extend([f64::NAN, f64::NAN]);
        let hull: Vec<String> = "AAAAABBBBBBC".chars().map(String::from).collect();
        let t = table(vec![
            ("kpi", ColumnData::Float(kpi)),
            ("hull", ColumnData::Text(hull)),
        ]);
        let d = distribution(&t, "kpi", Some("hull")).unwrap();
        assert_eq!((d.rows_used, d.rows_skipped), (10, 2));
        assert_eq!(d.bins.edges, [0.0, 3.0, 6.0, 9.0]);
        assert_eq!(
            (d.bins.rule, &d.bins.counts[..]),
            (BinRule::FreedmanDiaconis, &[3, 3, 4][..])
        );
        let [a, b] = &d.groups[..] else {
            panic!("{:?}", d.groups)
        };
        assert_eq!(
            (a.group.as_deref(), &a.counts[..]),
            (Some("A"), &[3, 2, 0][..])
        );
        assert_eq!(
            (b.group.as_deref(), &b.counts[..]),
            (Some("B"), &[0, 1, 4][..])
        );
        for (s, (n, mean, p05, p95)) in
            [(a.stats, (5, 2.0, 0.2, 3.8)), (b.stats, (5, 7.0, 5.2, 8.8))]
        {
            assert_eq!(s.n, n);
            assert!(
                close(s.mean, mean) && close(s.p05, p05) && close(s.p95, p95),
                "{s:?}"
            );
        }
    }
}
