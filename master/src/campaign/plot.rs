//! Plots of a campaign's run table (PNG), for `shipsim campaign plot`:
//!
//! - [`line_band()`]: a KPI against one factor, the mean over the runs of each design point
//!   (the seeds) with its 5–95 % band, one coloured series per value of a group column;
//! - [`heatmap()`]: the mean of a KPI over two factors, on the viridis colour map, with a colour
//!   bar;
//! - [`polar()`]: a KPI against a direction on polar axes (e.g. roll reduction over wave heading);
//! - [`histogram()`]: the distribution of a KPI over the runs (e.g. a Monte-Carlo robustness
//!   study), on [`Bins`] chosen by the Freedman–Diaconis rule, with its mean and 5 % / 95 %
//!   percentiles, one semi-transparent histogram per value of a group column.
//!
//! Every plot reduces the rows that share a design point to their [`Stats`]: the mean, and the
//! 5 % and 95 % empirical percentiles (numpy's default definition). A row is skipped when one of
//! its plotted values is not finite (a failed run's KPIs are NaN); [`PlotSummary`] returns the
//! count, and the figure's caption prints it. Bad input (a missing or text column, no finite
//! row, a path that cannot be written) is an [`Error`](crate::Error) that names it, never a
//! panic.
//!
//! One file per concern: `stats` (percentiles, bins, the reduction of the run table's rows, and
//! their unit tests), `figure` (canvas, title, caption, legend, numbers on axes), and one per
//! chart: `line_band`, `heatmap`, `polar`, `histogram`.
//!
//! Rendering shares the time-series plotter's setup ([`crate::plot`]): plotters' bitmap
//! backend and DejaVu Sans embedded, so no system font or graphics library is needed, its series
//! colours and its drawing error.

mod figure;
mod heatmap;
mod histogram;
mod line_band;
mod polar;
mod stats;

pub use heatmap::{heatmap, viridis, Cells};
pub use histogram::histogram;
pub use line_band::line_band;
pub use polar::polar;
pub use stats::{
    aggregate, distribution, grid, Aggregate, BinRule, Bins, Distribution, Grid, GroupCounts,
    SeriesStats, Stats,
};

use std::path::PathBuf;

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
    /// The first column's label: `x` of [`line_band()`] and [`heatmap()`], the angle of
    /// [`polar()`].
    pub x_label: Option<String>,
    /// The second column's label: `y` of [`line_band()`] and [`heatmap()`], the radius of
    /// [`polar()`].
    pub y_label: Option<String>,
    /// The colour bar's label ([`heatmap()`]'s `z`).
    pub z_label: Option<String>,
    /// The group column's name in the legend (`"H_s [m]"` gives entries `H_s [m] = 2`).
    pub group_label: Option<String>,
    /// Width and height in pixels (default 900 x 700; at least 400 x 300).
    pub size: (u32, u32),
    /// The unit of [`polar()`]'s angle column (default degrees).
    pub angle_unit: AngleUnit,
    /// [`polar()`]: compass-like (default) or mathematical.
    pub orientation: Orientation,
    /// [`heatmap()`]: print each cell's mean in the cell (default true; left out where the
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
    /// [`line_band()`] and [`histogram()`] (`y` in runs): the data ranges `x` and `y` span the
    /// pixel rectangle `left..=right`, `bottom..=top` (y grows upwards in the data).
    Cartesian {
        left: i32,
        top: i32,
        right: i32,
        bottom: i32,
        x: (f64, f64),
        y: (f64, f64),
    },
    /// [`heatmap()`]: the cells, and the colour range `z` (viridis(0) to viridis(1)).
    Cells { cells: Cells, z: (f64, f64) },
    /// [`polar()`]: the radius `r.0` is at `centre`, `r.1` on the outer ring, `radius_px` away.
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
