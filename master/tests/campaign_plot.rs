//! The campaign plots (`shipsim::campaign::plot`): the statistics they draw, the PNGs they
//! write (decoded here: size, colours, where the data land), and their errors. The statistics'
//! building blocks (percentiles, bins) have their unit tests in `src/campaign/plot/stats.rs`.
//!
//! The run tables are built by hand: a synthetic roll-reduction study,
//! r = 50 + 30 sin(direction) + 5 (H_s - 3) + e, with three seeds e = -4, 0, +4 per design
//! point, so that every point's mean is the noise-free value, and its 5 % and 95 %
//! percentiles (numpy's default) are the mean -3.6 and +3.6 (h = 0.1 and 1.9 of 2 gaps of 4).
//!
//! Set CAMPAIGN_PLOT_DIR to keep the PNGs there (to look at them).

use image::{Rgb, RgbImage};
use shipsim::campaign::plot::{
    aggregate, distribution, grid, heatmap, histogram, line_band, polar, viridis, AngleUnit,
    BinRule, Cells, Frame, Orientation, PlotOptions,
};
use shipsim::campaign::table::{ColumnData, Table};
use std::path::PathBuf;

const DIRECTIONS: [f64; 9] = [30.0, 45.0, 60.0, 75.0, 90.0, 105.0, 120.0, 135.0, 150.0];
const HEIGHTS: [f64; 3] = [2.0, 3.0, 4.0];
const NOISE: [f64; 3] = [-4.0, 0.0, 4.0];
/// The series colours, in order (matplotlib's tab10 blue, red, green).
const SERIES: [Rgb<u8>; 3] = [Rgb([31, 119, 180]), Rgb([214, 39, 40]), Rgb([44, 160, 44])];

fn expected_mean(deg: f64, hs: f64) -> f64 {
    50.0 + 30.0 * deg.to_radians().sin() + 5.0 * (hs - 3.0)
}

/// The study's run table (directions x heights x seeds) and one failed run (NaN KPI).
fn rrs_table() -> Table {
    let (mut dir, mut hs, mut seed, mut arm, mut kpi) = (vec![], vec![], vec![], vec![], vec![]);
    for d in DIRECTIONS {
        for h in HEIGHTS {
            for (s, e) in NOISE.iter().enumerate() {
                dir.push(d);
                hs.push(h);
                seed.push(s as i64);
                arm.push("on".to_string());
                kpi.push(expected_mean(d, h) + e);
            }
        }
    }
    dir.push(90.0);
    hs.push(3.0);
    seed.push(3);
    arm.push("on".to_string());
    kpi.push(f64::NAN);
    let mut t = Table::default();
    t.push("wave_dir", ColumnData::Float(dir));
    t.push("H_s", ColumnData::Float(hs));
    t.push("seed", ColumnData::Int(seed));
    t.push("arm", ColumnData::Text(arm));
    t.push("roll_reduction", ColumnData::Float(kpi));
    t
}

/// A folder for the PNGs: CAMPAIGN_PLOT_DIR when set, else a temporary one.
fn out_dir() -> (Option<tempfile::TempDir>, PathBuf) {
    match std::env::var_os("CAMPAIGN_PLOT_DIR") {
        Some(d) => (None, PathBuf::from(d)),
        None => {
            let t = tempfile::tempdir().unwrap();
            let p = t.path().to_path_buf();
            (Some(t), p)
        }
    }
}

/// Options with the study's labels and units.
fn study_options(path: PathBuf) -> PlotOptions {
    let mut opts = PlotOptions::new(path);
    opts.x_label = Some("wave direction [deg]".into());
    opts.y_label = Some("roll reduction [%]".into());
    opts.group_label = Some("H_s [m]".into());
    opts
}

/// Decodes the PNG at `path`, checks its size and that it is a real figure (many colours).
fn decode(path: &std::path::Path, size: (u32, u32)) -> RgbImage {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{}", path.display());
    let img = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
        .unwrap()
        .to_rgb8();
    assert_eq!(img.dimensions(), size, "{}", path.display());
    let mut colours: Vec<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    colours.sort_unstable();
    colours.dedup();
    assert!(
        colours.len() > 60,
        "{}: {} colours",
        path.display(),
        colours.len()
    );
    img
}

fn count(img: &RgbImage, c: Rgb<u8>) -> usize {
    img.pixels().filter(|p| **p == c).count()
}

/// Whether a pixel within `r` pixels of (x, y) satisfies `f`.
fn near(img: &RgbImage, (x, y): (i32, i32), r: i32, f: impl Fn(Rgb<u8>) -> bool) -> bool {
    (-r..=r).any(|dy| {
        (-r..=r).any(|dx| {
            let (px, py) = (x + dx, y + dy);
            px >= 0
                && py >= 0
                && (px as u32) < img.width()
                && (py as u32) < img.height()
                && f(*img.get_pixel(px as u32, py as u32))
        })
    })
}

fn close(a: Rgb<u8>, b: [u8; 3], tol: u8) -> bool {
    a.0.iter().zip(b).all(|(x, y)| x.abs_diff(y) <= tol)
}

#[test]
fn aggregate_reduces_the_seeds_of_each_design_point() {
    let agg = aggregate(&rrs_table(), "wave_dir", "roll_reduction", Some("H_s")).unwrap();
    assert_eq!((agg.rows_used, agg.rows_skipped), (81, 1));
    let groups: Vec<_> = agg
        .series
        .iter()
        .map(|s| s.group.clone().unwrap())
        .collect();
    assert_eq!(groups, ["2", "3", "4"]);
    for (s, h) in agg.series.iter().zip(HEIGHTS) {
        let xs: Vec<f64> = s.points.iter().map(|p| p.0).collect();
        assert_eq!(xs, DIRECTIONS);
        for (d, st) in &s.points {
            let m = expected_mean(*d, h);
            // The three seeds m-4, m, m+4: mean m, p5 = m-4 + 0.1*4, p95 = m + 0.9*4.
            assert_eq!(st.n, 3);
            assert!((st.mean - m).abs() < 1e-12, "{d} {h}: {}", st.mean);
            assert!((st.p05 - (m - 3.6)).abs() < 1e-12, "{d} {h}: {}", st.p05);
            assert!((st.p95 - (m + 3.6)).abs() < 1e-12, "{d} {h}: {}", st.p95);
        }
    }
    let one = aggregate(&rrs_table(), "H_s", "roll_reduction", None).unwrap();
    assert_eq!(one.series.len(), 1);
    assert_eq!(one.series[0].group, None);
    // H_s = 3: 27 runs of 9 directions (the failed one left out).
    assert_eq!(one.series[0].points[1].1.n, 27);
    let g = grid(&rrs_table(), "wave_dir", "H_s", "roll_reduction").unwrap();
    assert_eq!((g.xs.len(), g.ys.len(), g.rows_skipped), (9, 3, 1));
    let cell = g.cells[2 * 9 + 4].unwrap(); // 90 deg, H_s = 4
    assert_eq!(cell.n, 3);
    assert!((cell.mean - 85.0).abs() < 1e-12);
}

#[test]
fn viridis_follows_matplotlibs_table() {
    // matplotlib _viridis_data[0], [128], [255], scaled to 8 bits.
    for (t, want) in [
        (0.0, [68, 1, 84]),
        (128.0 / 255.0, [33, 145, 140]),
        (1.0, [253, 231, 37]),
    ] {
        let c = viridis(t);
        assert!(
            close(Rgb([c.0, c.1, c.2]), want, 4),
            "viridis({t}) = {c:?}, want {want:?}"
        );
    }
    assert_eq!(viridis(-3.0), viridis(0.0));
    assert_eq!(viridis(f64::NAN), viridis(0.0));
}

#[test]
fn line_band_draws_means_bands_and_groups() {
    let (_keep, dir) = out_dir();
    let opts = study_options(dir.join("line_band.png"));
    let s = line_band(
        &rrs_table(),
        "wave_dir",
        "roll_reduction",
        Some("H_s"),
        &opts,
    )
    .unwrap();
    assert_eq!((s.rows_used, s.rows_skipped, s.series), (81, 1, 3));
    let img = decode(&opts.path, (900, 700));
    for c in SERIES {
        assert!(
            count(&img, c) > 300,
            "series colour {c:?}: {} pixels",
            count(&img, c)
        );
    }
    let Frame::Cartesian {
        left,
        top,
        right,
        bottom,
        x,
        y,
    } = s.frame
    else {
        panic!("{:?}", s.frame)
    };
    assert!(
        x.0 <= 30.0 && x.1 >= 150.0 && y.0 <= 56.0 && y.1 >= 89.0,
        "{x:?} {y:?}"
    );
    let px = |xv: f64, yv: f64| {
        let fx = (xv - x.0) / (x.1 - x.0);
        let fy = (yv - y.0) / (y.1 - y.0);
        let col = left as f64 + fx * (right - left) as f64;
        let row = bottom as f64 - fy * (bottom - top) as f64;
        (col.round() as i32, row.round() as i32)
    };
    for (d, h, c) in [
        (30.0, 2.0, SERIES[0]),
        (90.0, 3.0, SERIES[1]),
        (150.0, 4.0, SERIES[2]),
    ] {
        let at = px(d, expected_mean(d, h));
        assert!(
            near(&img, at, 2, |p| p == c),
            "no {c:?} marker at {at:?} ({d}, {h})"
        );
    }
    // Inside the top group's band (mean + 2.5 of +3.6), away from the line: tinted green.
    let inside = px(90.0, expected_mean(90.0, 4.0) + 2.5);
    let p = img.get_pixel(inside.0 as u32, inside.1 as u32).0;
    assert!(
        p[1] > p[0] + 10 && p[1] > p[2] + 10 && p[1] > 200,
        "band at {inside:?}: {p:?}"
    );
    // Above all bands: white (or a light grid line).
    let above = px(90.0, expected_mean(90.0, 4.0) + 4.5);
    let p = img.get_pixel(above.0 as u32, above.1 as u32).0;
    assert!(
        p.iter().all(|c| *c >= 220) && p[0] == p[1],
        "above the band at {above:?}: {p:?}"
    );
}

#[test]
fn heatmap_colours_cells_by_their_mean() {
    let (_keep, dir) = out_dir();
    let mut opts = PlotOptions::new(dir.join("heatmap.png"));
    opts.size = (1000, 600);
    opts.x_label = Some("wave direction [deg]".into());
    opts.y_label = Some("H_s [m]".into());
    opts.z_label = Some("roll reduction [%]".into());
    let s = heatmap(&rrs_table(), "wave_dir", "H_s", "roll_reduction", &opts).unwrap();
    assert_eq!((s.rows_used, s.rows_skipped), (81, 1));
    let img = decode(&opts.path, (1000, 600));
    let Frame::Cells { cells, z } = s.frame else {
        panic!("{:?}", s.frame)
    };
    let Cells {
        left,
        top,
        right,
        bottom,
        nx,
        ny,
    } = cells;
    assert_eq!((nx, ny), (9, 3));
    // Lowest mean: 30 deg (and 150), H_s = 2: 60; highest: 90 deg, H_s = 4: 85.
    assert!(
        (z.0 - 60.0).abs() < 1e-9 && (z.1 - 85.0).abs() < 1e-9,
        "{z:?}"
    );
    // A pixel a quarter into cell (i, j) from its bottom-left corner (away from the value text).
    let cell = |i: usize, j: usize| {
        let (w, h) = (
            (right - left) as f64 / nx as f64,
            (bottom - top) as f64 / ny as f64,
        );
        let x = left as f64 + w * (i as f64 + 0.25);
        let y = bottom as f64 - h * (j as f64 + 0.25);
        *img.get_pixel(x as u32, y as u32)
    };
    assert!(close(cell(0, 0), [68, 1, 84], 5), "{:?}", cell(0, 0));
    assert!(close(cell(8, 0), [68, 1, 84], 5), "{:?}", cell(8, 0));
    assert!(close(cell(4, 2), [253, 231, 37], 5), "{:?}", cell(4, 2));
    // 90 deg, H_s = 3: 80, at 20/25 of the range: matplotlib's viridis(0.8) = _viridis_data[204].
    assert!(close(cell(4, 1), [122, 209, 81], 6), "{:?}", cell(4, 1));
    // The colour bar right of the cells runs from viridis(0) at the bottom to viridis(1) on top.
    let bar = |y: i32, want: [u8; 3]| {
        (right + 5..img.width() as i32).any(|x| close(*img.get_pixel(x as u32, y as u32), want, 5))
    };
    assert!(
        bar(top + 2, [253, 231, 37]),
        "no yellow at the top of the colour bar"
    );
    assert!(
        bar(bottom - 2, [68, 1, 84]),
        "no purple at the bottom of the colour bar"
    );
    assert!(
        bar((top + bottom) / 2, [33, 145, 140]),
        "no viridis(0.5) half-way up the colour bar"
    );
}

/// The pixel of (direction, value) on polar axes from the frame, computed here.
fn polar_px(frame: &Frame, deg: f64, value: f64, compass: bool) -> (i32, i32) {
    let Frame::Polar {
        centre,
        radius_px,
        r,
    } = frame
    else {
        panic!("{frame:?}")
    };
    let rho = (value - r.0) / (r.1 - r.0) * radius_px;
    let th = deg.to_radians();
    let (dx, dy) = if compass {
        (rho * th.sin(), -rho * th.cos())
    } else {
        (rho * th.cos(), -rho * th.sin())
    };
    (
        (centre.0 as f64 + dx).round() as i32,
        (centre.1 as f64 + dy).round() as i32,
    )
}

#[test]
fn polar_puts_directions_where_the_orientation_says() {
    let (_keep, dir) = out_dir();
    let mut opts = study_options(dir.join("polar.png"));
    opts.x_label = Some("wave direction (0 = following, 90 = beam, 180 = head) [deg]".into());
    opts.title = Some("Roll reduction by RRS over wave direction".into());
    let s = polar(
        &rrs_table(),
        "wave_dir",
        "roll_reduction",
        Some("H_s"),
        &opts,
    )
    .unwrap();
    assert_eq!((s.rows_used, s.rows_skipped, s.series), (81, 1, 3));
    let img = decode(&opts.path, (900, 700));
    let Frame::Polar {
        centre,
        radius_px,
        r,
    } = s.frame.clone()
    else {
        panic!("{:?}", s.frame)
    };
    assert_eq!(r.0, 0.0, "all values are positive: the centre is 0");
    assert!(r.1 >= 89.0 && r.1 < 150.0, "{r:?}");
    for (d, h, c) in [
        (90.0, 4.0, SERIES[2]),
        (30.0, 2.0, SERIES[0]),
        (135.0, 3.0, SERIES[1]),
    ] {
        let at = polar_px(&s.frame, d, expected_mean(d, h), true);
        assert!(
            near(&img, at, 3, |p| p == c),
            "no {c:?} at {at:?} for ({d}, {h})"
        );
    }
    // The outer ring crosses straight above the centre (0 deg, no data there): axis colour.
    let ring = (centre.0, centre.1 - radius_px.round() as i32);
    assert!(
        near(&img, ring, 1, |p| close(p, [40, 40, 40], 30)),
        "ring at {ring:?}"
    );
    // The spokes meet at the centre (grey, not white).
    let c = img.get_pixel(centre.0 as u32, centre.1 as u32).0;
    assert!(c.iter().all(|v| *v < 235), "centre {centre:?}: {c:?}");
    // 30..150 deg is less than the circle: the curves are open, nothing drawn at 270 deg.
    let gap = polar_px(&s.frame, 270.0, expected_mean(30.0, 2.0), true);
    assert!(
        !near(&img, gap, 6, |p| SERIES.contains(&p)),
        "a series crosses {gap:?}"
    );

    // The same directions in radians, mathematical orientation: 90 deg is straight up.
    let mut t = rrs_table();
    if let ColumnData::Float(v) = &mut t.columns[0] {
        v.iter_mut().for_each(|a| *a = a.to_radians());
    }
    let mut math = PlotOptions::new(dir.join("polar_math_radians.png"));
    math.angle_unit = AngleUnit::Radians;
    math.orientation = Orientation::Mathematical;
    let s = polar(&t, "wave_dir", "roll_reduction", Some("H_s"), &math).unwrap();
    let img = decode(&math.path, (900, 700));
    let Frame::Polar { centre, .. } = s.frame else {
        panic!()
    };
    let up = polar_px(&s.frame, 90.0, 85.0, false);
    assert_eq!(up.0, centre.0);
    assert!(
        near(&img, up, 3, |p| p == SERIES[2]),
        "no H_s = 4 point above the centre at {up:?}"
    );
}

#[test]
fn polar_closes_a_full_circle_and_allows_negative_values() {
    let (_keep, dir) = out_dir();
    let angles: Vec<f64> = (0..12).map(|k| 30.0 * k as f64).collect();
    let kpi: Vec<f64> = angles.iter().map(|a| 50.0 * a.to_radians().cos()).collect();
    let mut t = Table::default();
    t.push("heading", ColumnData::Float(angles));
    t.push("sway", ColumnData::Float(kpi));
    let opts = PlotOptions::new(dir.join("nested/polar_closed.png"));
    let s = polar(&t, "heading", "sway", None, &opts).unwrap();
    assert_eq!((s.rows_used, s.rows_skipped, s.series), (12, 0, 1));
    let img = decode(&opts.path, (900, 700));
    let Frame::Polar { r, .. } = s.frame.clone() else {
        panic!()
    };
    assert!(
        r.0 <= -50.0 && r.0 > -100.0 && r.1 >= 50.0,
        "the centre is below 0: {r:?}"
    );
    // Every gap is drawn: between 330 deg (43.3) and 0 deg (50) the closed curve passes 345 deg
    // at r = 46.65, and between 0 and 30 deg (43.3) it passes 15 deg at the same r.
    let r_mid = (50.0 * 30f64.to_radians().cos() + 50.0) / 2.0;
    for (deg, r) in [(345.0, r_mid), (15.0, r_mid), (195.0, -r_mid)] {
        let at = polar_px(&s.frame, deg, r, true);
        assert!(
            near(&img, at, 3, |p| p == SERIES[0]),
            "no curve at {deg} deg, {at:?}"
        );
    }
}

#[test]
fn errors_name_the_problem() {
    let (_keep, dir) = out_dir();
    let t = rrs_table();
    let opts = PlotOptions::new(dir.join("e.png"));
    let err = |r: shipsim::Result<_>| r.unwrap_err().to_string();

    let e = err(line_band(
        &t,
        "wave_direction",
        "roll_reduction",
        None,
        &opts,
    ));
    assert!(e.contains("no column \"wave_direction\""), "{e}");
    assert!(e.contains("did you mean wave_dir"), "{e}");
    assert!(
        e.contains("columns: wave_dir, H_s, seed, arm, roll_reduction"),
        "{e}"
    );
    let e = err(polar(&t, "wave_dir", "roll_reduction", Some("Hs_m"), &opts));
    assert!(e.contains("plot group: no column \"Hs_m\""), "{e}");
    let e = err(heatmap(&t, "wave_dir", "arm", "roll_reduction", &opts));
    assert!(e.contains("column \"arm\" holds text, not numbers"), "{e}");
    assert!(
        e.contains("numeric columns: wave_dir, H_s, seed, roll_reduction"),
        "{e}"
    );

    let mut failed = Table::default();
    failed.push("x", ColumnData::Float(vec![1.0, 2.0]));
    failed.push("kpi", ColumnData::Float(vec![f64::NAN, f64::NAN]));
    let e = err(line_band(&failed, "x", "kpi", None, &opts));
    assert!(
        e.contains("no row has finite values in all of \"x\", \"kpi\" (2 rows"),
        "{e}"
    );

    let ragged = Table {
        names: vec!["x".into(), "kpi".into()],
        columns: vec![
            ColumnData::Float(vec![1.0, 2.0]),
            ColumnData::Float(vec![1.0]),
        ],
    };
    let e = err(line_band(&ragged, "x", "kpi", None, &opts));
    assert!(
        e.contains("column \"kpi\" has 1 values, the run table 2 rows"),
        "{e}"
    );

    std::fs::write(dir.join("file"), "").unwrap();
    let blocked = PlotOptions::new(dir.join("file/p.png"));
    let e = err(line_band(&t, "wave_dir", "roll_reduction", None, &blocked));
    assert!(e.contains("cannot create") && e.contains("file"), "{e}");
    std::fs::create_dir_all(dir.join("d.png")).unwrap();
    let e = err(line_band(
        &t,
        "wave_dir",
        "roll_reduction",
        None,
        &PlotOptions::new(dir.join("d.png")),
    ));
    // an output that exists and is not a regular file is refused (issue 38, item 2)
    assert!(
        e.contains("d.png is a directory; an output must be a regular file"),
        "{e}"
    );
    let e = err(line_band(
        &t,
        "wave_dir",
        "roll_reduction",
        None,
        &PlotOptions::new(dir.join("p.svg")),
    ));
    assert!(e.contains("p.svg: the output must be a .png file"), "{e}");
    let mut tiny = PlotOptions::new(dir.join("tiny.png"));
    tiny.size = (100, 80);
    let e = err(polar(&t, "wave_dir", "roll_reduction", None, &tiny));
    assert!(e.contains("size 100x80 pixels"), "{e}");
    assert!(!dir.join("tiny.png").exists() && !dir.join("e.png").exists());
}

/// Small and odd tables: one row, one x value, text and Bool groups, empty heat-map cells,
/// the smallest figure. Each still draws (and counts what it skipped).
#[test]
fn degenerate_tables_still_plot() {
    let (_keep, dir) = out_dir();
    let mut t = Table::default();
    t.push("speed", ColumnData::Int(vec![5, 5, 10, 10, 15]));
    t.push(
        "dir",
        ColumnData::Float(vec![180.0, 180.0, 180.0, 90.0, 90.0]),
    );
    t.push(
        "arm",
        ColumnData::Text(["off", "on", "off", "on", "off"].map(String::from).to_vec()),
    );
    t.push(
        "rrs",
        ColumnData::Bool(vec![false, true, false, true, true]),
    );
    t.push(
        "kpi",
        ColumnData::Float(vec![1.0, 2.0, f64::INFINITY, -4.0, 0.5]),
    );

    let mut small = PlotOptions::new(dir.join("small_line.png"));
    small.size = (400, 300);
    let s = line_band(&t, "speed", "kpi", Some("arm"), &small).unwrap();
    assert_eq!((s.rows_used, s.rows_skipped, s.series), (4, 1, 2));
    decode(&small.path, (400, 300));

    let one = PlotOptions::new(dir.join("one_x.png"));
    let s = line_band(&t, "dir", "kpi", Some("rrs"), &one).unwrap();
    assert_eq!((s.rows_used, s.series), (4, 2));
    let Frame::Cartesian { x, .. } = s.frame else {
        panic!()
    };
    assert!(x.0 < 90.0 && x.1 > 180.0, "{x:?}");
    decode(&one.path, (900, 700));

    let heat = PlotOptions::new(dir.join("sparse_heatmap.png"));
    let s = heatmap(&t, "speed", "dir", "kpi", &heat).unwrap();
    assert_eq!((s.rows_used, s.rows_skipped), (4, 1));
    let img = decode(&heat.path, (900, 700));
    let Frame::Cells { cells, .. } = s.frame else {
        panic!()
    };
    let Cells {
        left,
        top,
        right,
        bottom,
        nx,
        ny,
    } = cells;
    assert_eq!((nx, ny), (3, 2));
    // (speed 5, dir 90) has no run: the grey of an empty cell.
    let (x, y) = (left + (right - left) / 12, bottom - (bottom - top) / 8);
    assert_eq!(img.get_pixel(x as u32, y as u32).0, [225, 225, 225]);

    let polar_one = PlotOptions::new(dir.join("polar_one.png"));
    let s = polar(&t, "dir", "kpi", Some("arm"), &polar_one).unwrap();
    assert_eq!((s.rows_used, s.series), (4, 2));
    let Frame::Polar { r, .. } = s.frame else {
        panic!()
    };
    assert!(r.0 <= -4.0 && r.1 >= 2.0, "{r:?}");
    decode(&polar_one.path, (900, 700));
}

// ---------------------------------------------------------------------------------------------
// Histogram
//
// A robustness study's KPI, peak roll [deg], over 40 Monte-Carlo runs: the values 1 to 7 with
// the multiplicities 2, 4, 8, 12, 8, 4, 2, and one failed run (NaN). Sorted, x0..x39:
// 1 at 0-1, 2 at 2-5, 3 at 6-13, 4 at 14-25, 5 at 26-33, 6 at 34-37, 7 at 38-39.
// - p25: h = 39 * 0.25 = 9.75, x9 = x10 = 3; p75: h = 29.25, x29 = x30 = 5; IQR = 2.
// - Freedman-Diaconis width 2 * 2 * 40^(-1/3) = 1.1696; range 6 / 1.1696 = 5.13, so 6 bins of
//   6/6 = 1: edges 1, 2, ..., 7; counts [1,2) 2, [2,3) 4, [3,4) 8, [4,5) 12, [5,6) 8, and
//   [6,7] (closed) 4 + 2 = 6.
// - mean 160 / 40 = 4; p5: h = 1.95, x1 + 0.95 (x2 - x1) = 1.95; p95: h = 37.05, 6.05.
// numpy 2.4.6 agrees: np.histogram(v, "fd") and np.percentile(v, [5, 25, 75, 95]).
//
// Hull "A" holds the 20 smallest runs (1 x2, 2 x4, 3 x8, 4 x6), hull "B" the other 20
// (4 x6, 5 x8, 6 x4, 7 x2) and the failed run. On the shared bins: A [2, 4, 8, 6, 0, 0],
// B [0, 0, 0, 6, 8, 6]. A: mean 58/20 = 2.9, p5 (h = 0.95) 1, p95 (h = 18.05) 4.
// B: mean 102/20 = 5.1, p5 4, p95 7.

const MULTIPLICITY: [usize; 7] = [2, 4, 8, 12, 8, 4, 2];

fn mc_table() -> Table {
    let mut kpi: Vec<f64> = (1..=7)
        .zip(MULTIPLICITY)
        .flat_map(|(v, m)| std::iter::repeat_n(v as f64, m))
        .collect();
    let mut hull: Vec<String> = (0..40)
        .map(|i| if i < 20 { "A" } else { "B" }.to_string())
        .collect();
    kpi.push(f64::NAN);
    hull.push("B".into());
    let mut t = Table::default();
    t.push("seed", ColumnData::Int((0..41).collect()));
    t.push("hull", ColumnData::Text(hull));
    t.push("peak_roll", ColumnData::Float(kpi));
    t
}

/// The pixel of data (x, count) in a Cartesian frame, computed here.
fn cart_px(frame: &Frame, xv: f64, yv: f64) -> (i32, i32) {
    let Frame::Cartesian {
        left,
        top,
        right,
        bottom,
        x,
        y,
    } = frame
    else {
        panic!("{frame:?}")
    };
    let fx = (xv - x.0) / (x.1 - x.0);
    let fy = (yv - y.0) / (y.1 - y.0);
    (
        (*left as f64 + fx * (right - left) as f64).round() as i32,
        (*bottom as f64 - fy * (bottom - top) as f64).round() as i32,
    )
}

fn px_at(img: &RgbImage, (x, y): (i32, i32)) -> Rgb<u8> {
    *img.get_pixel(x as u32, y as u32)
}

/// Of the pixel rows from count `y0` to `y1` at data x `xv`, the fraction with a pixel within
/// one column of it satisfying `f`.
fn column_fraction(
    img: &RgbImage,
    frame: &Frame,
    xv: f64,
    (y0, y1): (f64, f64),
    f: impl Fn(Rgb<u8>) -> bool,
) -> f64 {
    let (x, r0) = cart_px(frame, xv, y0);
    let (_, r1) = cart_px(frame, xv, y1);
    let rows = r1..=r0;
    let n = rows.clone().count();
    let hit = rows
        .filter(|r| (-1..=1).any(|dx| f(px_at(img, (x + dx, *r)))))
        .count();
    hit as f64 / n as f64
}

const BLUE: [u8; 3] = [31, 119, 180];
const RED: [u8; 3] = [214, 39, 40];
/// The mean and percentile lines without groups.
fn ink(p: Rgb<u8>) -> bool {
    close(p, [20, 20, 20], 12)
}

#[test]
fn histogram_draws_bins_mean_and_percentiles() {
    let (_keep, dir) = out_dir();
    let mut opts = PlotOptions::new(dir.join("histogram.png"));
    opts.size = (1000, 650);
    opts.x_label = Some("peak roll [deg]".into());
    opts.title = Some("Peak roll over 40 Monte-Carlo runs (hull coefficients ±20 %)".into());
    let s = histogram(&mc_table(), "peak_roll", None, &opts).unwrap();
    assert_eq!((s.rows_used, s.rows_skipped, s.series), (40, 1, 1));
    let img = decode(&opts.path, (1000, 650));
    let f = &s.frame;
    let Frame::Cartesian { x, y, .. } = f.clone() else {
        panic!("{f:?}")
    };
    assert!(x.0 < 1.0 && x.0 > 0.5 && x.1 > 7.0 && x.1 < 7.5, "{x:?}");
    assert_eq!(y.0, 0.0);
    assert!(
        y.1 >= 13.0 && y.1 <= 30.0,
        "room above the tallest bar: {y:?}"
    );
    // The tallest bin, [4, 5) with 12 runs: blue up to 12, not above (+-0.4 of a run, more
    // than 10 pixels here).
    assert_eq!(px_at(&img, cart_px(f, 4.5, 6.5)).0, BLUE);
    assert_eq!(px_at(&img, cart_px(f, 4.5, 11.6)).0, BLUE);
    let above = px_at(&img, cart_px(f, 4.5, 12.4));
    assert!(
        above.0.iter().all(|c| *c >= 220),
        "above the tallest bar: {above:?}"
    );
    // [2, 3): 4 runs; [6, 7] (closed): 6 runs.
    for (xv, n) in [(1.5, 2.0), (2.5, 4.0), (3.5, 8.0), (5.5, 8.0), (6.5, 6.0)] {
        assert_eq!(px_at(&img, cart_px(f, xv, n - 0.4)).0, BLUE, "bin at {xv}");
        let p = px_at(&img, cart_px(f, xv, n + 0.4));
        assert!(p.0 != BLUE && p.0[0] >= 200, "above the bin at {xv}: {p:?}");
    }
    // The mean (4) is a solid line from the base up past the bars; the 5 % (1.95) and 95 %
    // (6.05) percentiles are dashed (7 px on, 5 off: about 60 % of the rows); none at 3.
    let mean = column_fraction(&img, f, 4.0, (0.2, 12.3), ink);
    assert_eq!(mean, 1.0, "mean line");
    for p in [1.95, 6.05] {
        let frac = column_fraction(&img, f, p, (0.2, 12.3), ink);
        assert!((0.4..0.8).contains(&frac), "dashed line at {p}: {frac}");
    }
    assert_eq!(column_fraction(&img, f, 3.0, (0.2, 12.3), ink), 0.0);
}

#[test]
fn histogram_overlays_groups_on_shared_bins() {
    let d = distribution(&mc_table(), "peak_roll", Some("hull")).unwrap();
    assert_eq!((d.rows_used, d.rows_skipped), (40, 1));
    assert_eq!(d.bins.counts, [2, 4, 8, 12, 8, 6]);
    let [a, b] = &d.groups[..] else {
        panic!("{:?}", d.groups)
    };
    assert_eq!(
        (a.group.as_deref(), b.group.as_deref()),
        (Some("A"), Some("B"))
    );
    assert_eq!(
        (&a.counts[..], &b.counts[..]),
        (&[2, 4, 8, 6, 0, 0][..], &[0, 0, 0, 6, 8, 6][..])
    );
    for (g, want) in [(a, (20, 2.9, 1.0, 4.0)), (b, (20, 5.1, 4.0, 7.0))] {
        let s = g.stats;
        assert_eq!(s.n, want.0);
        assert!((s.mean - want.1).abs() < 1e-12, "{s:?}");
        assert!(
            (s.p05 - want.2).abs() < 1e-12 && (s.p95 - want.3).abs() < 1e-12,
            "{s:?}"
        );
    }

    let (_keep, dir) = out_dir();
    let mut opts = PlotOptions::new(dir.join("histogram_groups.png"));
    opts.x_label = Some("peak roll [deg]".into());
    opts.group_label = Some("hull".into());
    let s = histogram(&mc_table(), "peak_roll", Some("hull"), &opts).unwrap();
    assert_eq!((s.rows_used, s.rows_skipped, s.series), (40, 1, 2));
    let img = decode(&opts.path, (900, 700));
    let f = &s.frame;
    // Bars at 45 % opacity on white: c' = 255 - 0.45 (255 - c); B over A: 0.55 A' + 0.45 B.
    // A alone: (154.2, 193.8, 221.3); B alone: (236.6, 157.8, 158.3); both: (181.1, 124.1, 139.7).
    // Tolerance 3 (plotters blends with 115/256 and truncates).
    for (xv, yv, want) in [
        (1.5, 1.5, [154, 194, 221]),
        (3.5, 6.5, [154, 194, 221]),
        (5.5, 4.5, [237, 158, 158]),
        (4.5, 3.5, [181, 124, 140]),
    ] {
        let p = px_at(&img, cart_px(f, xv, yv));
        assert!(close(p, want, 3), "({xv}, {yv}): {p:?}, want {want:?}");
    }
    // Each group's steps outline its bars in its colour: A's top of [3, 4) at 8, B's of [5, 6).
    assert!(near(&img, cart_px(f, 3.5, 8.0), 1, |p| p.0 == BLUE));
    assert!(near(&img, cart_px(f, 5.5, 8.0), 1, |p| p.0 == RED));
    // Above A's [1, 2) (2 runs): nothing.
    let p = px_at(&img, cart_px(f, 1.5, 2.5));
    assert!(p.0.iter().all(|c| *c >= 220), "{p:?}");
    // Solid mean lines in the groups' colours: A at 2.9, B at 5.1.
    let full = |c: [u8; 3]| move |p: Rgb<u8>| p.0 == c;
    assert_eq!(column_fraction(&img, f, 2.9, (0.2, 8.5), full(BLUE)), 1.0);
    assert_eq!(column_fraction(&img, f, 5.1, (0.2, 8.5), full(RED)), 1.0);
    // A's 95 % (4) and B's 5 % (4) share a column: dashed in both colours.
    assert!(column_fraction(&img, f, 4.0, (0.2, 8.5), full(RED)) > 0.2);
}

/// 200 runs of a skewed KPI, the quantiles of an exponential distribution (mean 2) shifted by 1:
/// x_i = 1 - 2 ln(1 - u_i), u_i = (i + 0.5) / 200. numpy 2.4.6, `np.histogram(x, "fd")`: 17 bins
/// (range / FD width = 16.04) from 1.005006260436237, the next edge 1.7095899565409294, the
/// last 12.982929094216006, with the counts below; mean 2.996536347427496,
/// `np.percentile(x, [5, 95])` = 1.1073303670466839, 6.9038925646248135.
#[test]
fn histogram_of_200_skewed_runs_matches_numpy() {
    let x: Vec<f64> = (0..200)
        .map(|i| 1.0 - 2.0 * (-(i as f64 + 0.5) / 200.0).ln_1p())
        .collect();
    let mut t = Table::default();
    t.push("settling_time", ColumnData::Float(x));
    let d = distribution(&t, "settling_time", None).unwrap();
    let b = &d.bins;
    assert_eq!((b.rule, b.len()), (BinRule::FreedmanDiaconis, 17));
    for (got, want) in [
        (b.edges[0], 1.005006260436237),
        (b.edges[1], 1.7095899565409294),
        (b.edges[17], 12.982929094216006),
    ] {
        assert!((got - want).abs() < 1e-12 * want, "{got} vs numpy {want}");
    }
    assert_eq!(
        b.counts,
        [60, 41, 30, 20, 15, 10, 7, 5, 4, 2, 2, 1, 1, 1, 0, 0, 1]
    );
    let s = d.groups[0].stats;
    assert!((s.mean - 2.996536347427496).abs() < 1e-12, "{s:?}");
    assert!((s.p05 - 1.1073303670466839).abs() < 1e-12, "{s:?}");
    assert!((s.p95 - 6.9038925646248135).abs() < 1e-12, "{s:?}");

    let (_keep, dir) = out_dir();
    let mut opts = PlotOptions::new(dir.join("histogram_200.png"));
    opts.x_label = Some("heading settling time [s]".into());
    let s = histogram(&t, "settling_time", None, &opts).unwrap();
    let img = decode(&opts.path, (900, 700));
    let f = &s.frame;
    // The first bin (60 runs) up to 60, and the empty 15th bin white.
    let mid = |k: usize| (b.edges[k] + b.edges[k + 1]) / 2.0;
    assert_eq!(px_at(&img, cart_px(f, mid(0), 59.0)).0, BLUE);
    assert!(px_at(&img, cart_px(f, mid(0), 61.5)).0[0] > 200);
    assert!(px_at(&img, cart_px(f, mid(14), 0.5)).0[0] > 200);
    assert_eq!(px_at(&img, cart_px(f, mid(16), 0.5)).0, BLUE);
}

#[test]
fn histogram_of_a_constant_column_draws_one_bin() {
    let (_keep, dir) = out_dir();
    let mut t = Table::default();
    t.push("runs_failed", ColumnData::Int(vec![3; 5]));
    let opts = PlotOptions::new(dir.join("histogram_constant.png"));
    let s = histogram(&t, "runs_failed", None, &opts).unwrap();
    assert_eq!((s.rows_used, s.rows_skipped, s.series), (5, 0, 1));
    let d = distribution(&t, "runs_failed", None).unwrap();
    assert_eq!(
        (d.bins.edges.clone(), d.bins.counts.clone()),
        (vec![2.7, 3.3], vec![5])
    );
    let img = decode(&opts.path, (900, 700));
    let f = &s.frame;
    let Frame::Cartesian { x, y, .. } = f.clone() else {
        panic!()
    };
    // The bin is centred: the axis pads it by half its width on both sides.
    assert!(
        (x.0 - 2.4).abs() < 1e-9 && (x.1 - 3.6).abs() < 1e-9,
        "{x:?}"
    );
    assert!(y.1 >= 6.0, "{y:?}");
    assert_eq!(px_at(&img, cart_px(f, 2.85, 2.5)).0, BLUE);
    assert_eq!(px_at(&img, cart_px(f, 3.15, 4.5)).0, BLUE);
    assert!(
        px_at(&img, cart_px(f, 2.55, 2.5)).0[0] > 220,
        "left of the bin"
    );
    // Mean and percentiles all at 3: one solid line in the middle of the bar.
    assert_eq!(column_fraction(&img, f, 3.0, (0.2, 4.8), ink), 1.0);

    let mut one = Table::default();
    one.push("kpi", ColumnData::Float(vec![f64::NAN, -0.25]));
    let opts = PlotOptions::new(dir.join("histogram_one_run.png"));
    let s = histogram(&one, "kpi", None, &opts).unwrap();
    assert_eq!((s.rows_used, s.rows_skipped), (1, 1));
    decode(&opts.path, (900, 700));
}

/// The smallest figure, 100 bins (capped), a Bool group, and a group whose runs all failed.
#[test]
fn histogram_odd_inputs_still_plot() {
    let (_keep, dir) = out_dir();
    // 0..=999 and an outlier at 1e6 (capped at 100 bins, as in the unit tests of the bins); the
    // group "rrs" is true for the even values; the group "arm" is "broken" for three failed runs.
    let mut kpi: Vec<f64> = (0..1000).map(f64::from).collect();
    kpi.extend([1e6, f64::NAN, f64::NAN, f64::NAN]);
    let rrs: Vec<bool> = (0..1004).map(|i| i % 2 == 0).collect();
    let arm: Vec<String> = (0..1004)
        .map(|i| if i > 1000 { "broken" } else { "ok" }.to_string())
        .collect();
    let mut t = Table::default();
    t.push("kpi", ColumnData::Float(kpi));
    t.push("rrs", ColumnData::Bool(rrs));
    t.push("arm", ColumnData::Text(arm));

    let mut small = PlotOptions::new(dir.join("histogram_small.png"));
    small.size = (400, 300);
    let s = histogram(&t, "kpi", Some("rrs"), &small).unwrap();
    assert_eq!((s.rows_used, s.rows_skipped, s.series), (1001, 3, 2));
    decode(&small.path, (400, 300));
    let d = distribution(&t, "kpi", Some("rrs")).unwrap();
    assert_eq!(d.bins.len(), 100);
    let groups: Vec<_> = d.groups.iter().map(|g| g.group.clone().unwrap()).collect();
    assert_eq!(groups, ["false", "true"]);
    // The first bin [0, 1e4) holds 0..=999: 500 odd (false) and 500 even (true); the outlier
    // 1e6 (row 1000) is even.
    assert_eq!((d.groups[0].counts[0], d.groups[1].counts[0]), (500, 500));
    assert_eq!((d.groups[0].counts[99], d.groups[1].counts[99]), (0, 1));

    // The group of failed runs has no finite value: no histogram for it.
    let opts = PlotOptions::new(dir.join("histogram_failed_group.png"));
    let s = histogram(&t, "kpi", Some("arm"), &opts).unwrap();
    assert_eq!((s.rows_used, s.rows_skipped, s.series), (1001, 3, 1));
    let img = decode(&opts.path, (900, 700));
    // One group: drawn like a histogram without groups (solid bars).
    assert_eq!(px_at(&img, cart_px(&s.frame, 5e3, 500.0)).0, BLUE);
}

#[test]
fn histogram_errors_name_the_problem() {
    let (_keep, dir) = out_dir();
    let opts = PlotOptions::new(dir.join("h.png"));
    let err = |r: shipsim::Result<_>| r.unwrap_err().to_string();
    let t = mc_table();
    let e = err(histogram(&t, "peak_rol", None, &opts));
    assert!(e.contains("plot x: no column \"peak_rol\""), "{e}");
    assert!(e.contains("did you mean peak_roll"), "{e}");
    assert!(e.contains("columns: seed, hull, peak_roll"), "{e}");
    let e = err(histogram(&t, "hull", None, &opts));
    assert!(
        e.contains("column \"hull\" holds text, not numbers; numeric columns: seed, peak_roll"),
        "{e}"
    );
    let e = err(histogram(&t, "peak_roll", Some("arm"), &opts));
    assert!(e.contains("plot group: no column \"arm\""), "{e}");

    let mut failed = Table::default();
    failed.push("kpi", ColumnData::Float(vec![f64::NAN, f64::INFINITY]));
    let e = err(histogram(&failed, "kpi", None, &opts));
    assert!(
        e.contains("no row has finite values in all of \"kpi\" (2 rows"),
        "{e}"
    );

    let mut wide = Table::default();
    wide.push("kpi", ColumnData::Float(vec![-1e308, 1e308]));
    let e = err(histogram(&wide, "kpi", None, &opts));
    assert!(
        e.contains("\"kpi\" run from -1e308 to 1e308, a range too wide to bin"),
        "{e}"
    );
    let mut tiny = PlotOptions::new(dir.join("tiny_h.png"));
    tiny.size = (300, 300);
    let e = err(histogram(&t, "peak_roll", None, &tiny));
    assert!(e.contains("size 300x300 pixels"), "{e}");
    assert!(!dir.join("h.png").exists() && !dir.join("tiny_h.png").exists());
}
