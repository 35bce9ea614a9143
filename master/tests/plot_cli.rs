//! `shipsim plot` (issue 18, point 7): a factor per column, x-y tracks with equal axes, several
//! CSV files overlaid, a time window, and the last time label drawn whole. The PNGs are decoded
//! and their pixels checked.

use image::{Rgb, RgbImage};
use shipsim::plot::{parse_window, Request};
use shipsim::results::ResultsTable;
use std::path::Path;
use std::process::Command;

/// plot's first two series colours (matplotlib's tab10 blue and red).
const BLUE: Rgb<u8> = Rgb([31, 119, 180]);
const RED: Rgb<u8> = Rgb([214, 39, 40]);

fn shipsim_plot(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_shipsim"))
        .arg("plot")
        .args(args)
        .output()
        .unwrap()
}

fn write_csv(path: &Path, header: &str, rows: impl Iterator<Item = String>) {
    let mut text = format!("{header}\n");
    for r in rows {
        text.push_str(&r);
        text.push('\n');
    }
    std::fs::write(path, text).unwrap();
}

fn decode(path: &Path) -> RgbImage {
    let bytes = std::fs::read(path).unwrap();
    image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
        .unwrap()
        .to_rgb8()
}

/// The pixels of colour `c` with x < `x_max` (left of the legends).
fn pixels(img: &RgbImage, c: Rgb<u8>, x_max: u32) -> Vec<(u32, u32)> {
    img.enumerate_pixels()
        .filter(|(x, _, p)| *x < x_max && **p == c)
        .map(|(x, y, _)| (x, y))
        .collect()
}

/// Two CSVs overlaid (--label off,on): "off" (0) in blue at the bottom of the panel, "on" (1)
/// in red at the top; the figure is 1100 x (60 + 260) px; and nothing is drawn in the last 8
/// pixel columns (the old 10-px right margin cut the last time label "10.0" there).
#[test]
fn overlay_draws_each_file_in_its_colour_and_the_last_label_whole() {
    let d = tempfile::tempdir().unwrap();
    let (a, b) = (d.path().join("a.csv"), d.path().join("b.csv"));
    write_csv(&a, "time,g.s", (0..=10).map(|t| format!("{t},0")));
    write_csv(&b, "time,g.s", (0..=10).map(|t| format!("{t},1")));
    let png = d.path().join("o.png");
    let o = shipsim_plot(&[
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--label",
        "off,on",
        "--panel",
        "s=g.s",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let img = decode(&png);
    assert_eq!(img.dimensions(), (1100, 320));
    let (blue, red) = (pixels(&img, BLUE, 700), pixels(&img, RED, 700));
    // Two pixels thick over ~600 px of the plotting area each.
    assert!(
        blue.len() > 1000 && red.len() > 1000,
        "{} {}",
        blue.len(),
        red.len()
    );
    let top_of_blue = blue.iter().map(|p| p.1).min().unwrap();
    let bottom_of_red = red.iter().map(|p| p.1).max().unwrap();
    assert!(
        top_of_blue > bottom_of_red + 150,
        "{top_of_blue} {bottom_of_red}"
    );
    for x in 1092..1100 {
        for y in 0..320 {
            assert_eq!(*img.get_pixel(x, y), Rgb([255, 255, 255]), "({x}, {y})");
        }
    }
    // --label needs one name per file.
    let o = shipsim_plot(&[
        a.to_str().unwrap(),
        "--label",
        "x,y",
        "--panel",
        "s=g.s",
        "-o",
        "x.png",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("--label has 2 names for 1 CSV files"), "{err}");
}

/// --xy draws y over x with the same metres per pixel on both axes: an ellipse 400 m wide and
/// 100 m high is 4 times wider than high on the image (±3 %; the line is 2 px thick), in a
/// figure of 1100 x (60 + 620) px.
#[test]
fn xy_track_has_equal_axes() {
    let d = tempfile::tempdir().unwrap();
    let csv = d.path().join("track.csv");
    write_csv(
        &csv,
        "time,ship.x,ship.y",
        (0..=360).map(|deg| {
            let th = (deg as f64).to_radians();
            format!("{deg},{},{}", 50.0 * th.sin(), 200.0 * th.cos())
        }),
    );
    let png = d.path().join("t.png");
    let o = shipsim_plot(&[
        csv.to_str().unwrap(),
        "--xy",
        "ship.y,ship.x",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let img = decode(&png);
    assert_eq!(img.dimensions(), (1100, 680));
    let blue = pixels(&img, BLUE, 1100);
    let (x0, x1) = (
        blue.iter().map(|p| p.0).min().unwrap(),
        blue.iter().map(|p| p.0).max().unwrap(),
    );
    let (y0, y1) = (
        blue.iter().map(|p| p.1).min().unwrap(),
        blue.iter().map(|p| p.1).max().unwrap(),
    );
    let ratio = f64::from(x1 - x0) / f64::from(y1 - y0);
    assert!(
        (ratio - 4.0).abs() < 0.12,
        "{x0}..{x1} x {y0}..{y1}: ratio {ratio}"
    );
    // The ellipse fills the width of the plotting area (the wide axis sets the scale).
    assert!(x1 - x0 > 850, "{x0}..{x1}");
}

fn ramp_table() -> ResultsTable {
    let d = tempfile::tempdir().unwrap();
    let csv = d.path().join("r.csv");
    write_csv(&csv, "time,g.s,g.r", (0..=10).map(|t| format!("{t},{t},1")));
    ResultsTable::read(&csv).unwrap()
}

/// A column's *F applies to that column only; --scale to the others; --window keeps the rows
/// with T0 <= t <= T1 of every panel and track.
#[test]
fn scale_per_column_and_window() {
    let files = [("run".to_string(), ramp_table())];
    let (panels, tracks) = (
        ["deg=g.s*2,g.r".to_string(), "other=g.s".to_string()],
        ["g.s,g.r*3".to_string()],
    );
    let req = Request {
        files: &files,
        panels: &panels,
        tracks: &tracks,
        scale: 10.0,
        window: Some(parse_window("2:5").unwrap()),
    };
    let (p, t) = req.figure().unwrap();
    assert_eq!(p[0].y_label, "deg");
    assert_eq!(p[0].series[0].t, [2.0, 3.0, 4.0, 5.0]);
    assert_eq!(p[0].series[0].y, [4.0, 6.0, 8.0, 10.0]);
    assert_eq!(p[0].series[1].y, [10.0, 10.0, 10.0, 10.0]);
    assert_eq!(p[1].series[0].y, [20.0, 30.0, 40.0, 50.0]);
    assert_eq!(
        (t[0].x_label.as_str(), t[0].y_label.as_str()),
        ("g.s", "g.r*3")
    );
    assert_eq!(t[0].series[0].t, [20.0, 30.0, 40.0, 50.0]);
    assert_eq!(t[0].series[0].y, [3.0, 3.0, 3.0, 3.0]);
    assert_eq!(parse_window(":4").unwrap(), (f64::NEG_INFINITY, 4.0));
    assert_eq!(parse_window("-1:").unwrap(), (-1.0, f64::INFINITY));
    for bad in ["5:2", "3", "a:b"] {
        let e = parse_window(bad).unwrap_err().to_string();
        assert!(e.contains("expected T0:T1"), "{bad}: {e}");
    }
    let bad = ["x=g.s*deg".to_string()];
    let req = Request {
        panels: &bad,
        tracks: &[],
        ..req
    };
    let e = req.figure().unwrap_err().to_string();
    assert!(
        e.contains("\"g.s*deg\": expected COLUMN or COLUMN*FACTOR"),
        "{e}"
    );
}

/// The window reaches the image: a step from 0 to 1 at t = 5 s plotted over 0:10 and over 6:10.
/// Over 6:10 only the level 1 is left, so the line is flat (all its pixels on one or two rows);
/// over 0:10 it spans the panel's height.
#[test]
fn window_on_the_command_line() {
    let d = tempfile::tempdir().unwrap();
    let csv = d.path().join("step.csv");
    write_csv(
        &csv,
        "time,g.s",
        (0..=10).map(|t| format!("{t},{}", u8::from(t > 5))),
    );
    let mut spans = Vec::new();
    for w in ["0:10", "6:10"] {
        let png = d.path().join("w.png");
        let o = shipsim_plot(&[
            csv.to_str().unwrap(),
            "--panel",
            "s=g.s",
            "--window",
            w,
            "-o",
            png.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let blue = pixels(&decode(&png), BLUE, 700);
        let rows = blue.iter().map(|p| p.1);
        spans.push(rows.clone().max().unwrap() - rows.min().unwrap());
    }
    assert!(spans[0] > 150 && spans[1] <= 2, "{spans:?}");
}
