//! `shipsim stats`: window statistics of a CSV's columns. The CSV is written here with values
//! whose statistics are known in closed form.

use std::f64::consts::TAU;
use std::path::Path;
use std::process::{Command, Output};

/// t = k/100 for k = 0..=1000 (0 .. 10 s);
/// ship.a = 2 + 3 sin(2 pi t) (period 1 s), ship.b = 0 before t = 5 s and 1 from it,
/// gear.c = t.
fn write_csv(path: &Path) {
    let mut s = String::from("time,ship.a,ship.b,gear.c\n");
    for k in 0..=1000 {
        let t = k as f64 / 100.0;
        let a = 2.0 + 3.0 * (TAU * t).sin();
        let b = if k >= 500 { 1.0 } else { 0.0 };
        s.push_str(&format!("{t},{a},{b},{t}\n"));
    }
    std::fs::write(path, s).unwrap();
}

fn stats(csv: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_shipsim"))
        .arg("stats")
        .arg(csv)
        .args(args)
        .output()
        .unwrap()
}

/// `shipsim stats` fails with a message containing every part.
fn refused(csv: &Path, args: &[&str], parts: &[&str]) {
    let out = stats(csv, args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} passed");
    for part in parts {
        assert!(err.contains(part), "{part} not in: {err}");
    }
}

fn json(csv: &Path, args: &[&str]) -> serde_json::Value {
    let mut a = args.to_vec();
    a.push("--json");
    let out = stats(csv, &a);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn column<'a>(j: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    j["columns"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == name)
        .unwrap_or_else(|| panic!("no {name} in {j}"))
}

fn assert_close(j: &serde_json::Value, stat: &str, expected: f64, tol: f64) {
    let x = j[stat].as_f64().unwrap();
    assert!((x - expected).abs() <= tol, "{stat}: {x} vs {expected}");
}

#[test]
fn a_sine_over_whole_periods_and_a_ramp() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("x.csv");
    write_csv(&csv);
    // Window 2 .. 4.99 s: 300 samples, three whole periods of the sine.
    let j = json(&csv, &["--window", "2:4.99"]);
    assert_eq!(j["samples"], 300);
    assert_eq!(
        (j["t0"].as_f64(), j["t1"].as_f64()),
        (Some(2.0), Some(4.99))
    );
    // Sampled sine (100 points per period): mean 2, population variance 3^2/2 = 4.5,
    // RMS sqrt(2^2 + 4.5); the samples include the peaks (t = k + 1/4, k + 3/4): min -1, max 5.
    let a = column(&j, "ship.a");
    assert_close(a, "mean", 2.0, 1e-12);
    assert_close(a, "variance", 4.5, 1e-12);
    assert_close(a, "std", 4.5f64.sqrt(), 1e-12);
    assert_close(a, "rms", 8.5f64.sqrt(), 1e-12);
    assert_close(a, "min", -1.0, 1e-12);
    assert_close(a, "max", 5.0, 1e-12);
    assert_close(a, "max_abs", 5.0, 1e-12);
    // The ramp t over 300 points spaced h = 0.01 from 2: mean (2 + 4.99)/2 = 3.495, variance
    // h^2 (n^2 - 1)/12 (discrete uniform), RMS sqrt(variance + mean^2).
    let c = column(&j, "gear.c");
    let var = 1e-4 * (300.0 * 300.0 - 1.0) / 12.0;
    assert_close(c, "mean", 3.495, 1e-12);
    assert_close(c, "variance", var, 1e-12);
    assert_close(c, "rms", (var + 3.495 * 3.495).sqrt(), 1e-12);
    assert_close(c, "min", 2.0, 0.0);
    assert_close(c, "max", 4.99, 0.0);
    // ship.b is 0 over the window.
    assert_close(column(&j, "ship.b"), "max_abs", 0.0, 0.0);

    // Without a window: all 1001 samples; b = 1 on 501 of them: mean p = 501/1001,
    // variance p (1 - p).
    let j = json(&csv, &[]);
    assert_eq!(j["samples"], 1001);
    let p = 501.0 / 1001.0;
    let b = column(&j, "ship.b");
    assert_close(b, "mean", p, 1e-14);
    assert_close(b, "variance", p * (1.0 - p), 1e-14);
    assert_close(b, "rms", p.sqrt(), 1e-14);
    // Open-ended windows: from 5 s on, b is 1 everywhere.
    let j = json(&csv, &["--window", "5:"]);
    assert_eq!(j["samples"], 501);
    assert_close(column(&j, "ship.b"), "min", 1.0, 0.0);
    let j = json(&csv, &["--window", ":0.5"]);
    assert_eq!(j["samples"], 51);
}

#[test]
fn columns_by_name_and_glob_and_the_table() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("x.csv");
    write_csv(&csv);
    let names = |j: &serde_json::Value| -> Vec<String> {
        j["columns"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c["name"].as_str().unwrap().to_string())
            .collect()
    };
    assert_eq!(names(&json(&csv, &[])), ["ship.a", "ship.b", "gear.c"]);
    assert_eq!(
        names(&json(&csv, &["--columns", "ship.*"])),
        ["ship.a", "ship.b"]
    );
    assert_eq!(
        names(&json(&csv, &["--columns", "gear.c,ship.?"])),
        ["gear.c", "ship.a", "ship.b"]
    );
    assert_eq!(
        names(&json(&csv, &["--columns", "*.a, ship.*"])),
        ["ship.a", "ship.b"]
    );

    // The table: a header with every statistic, one row per column, aligned.
    let out = stats(&csv, &["--window", "2:4.99", "--columns", "ship.a,gear.c"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert!(lines[0].contains("300 samples, t = 2 .. 4.99 s"), "{text}");
    let header: Vec<&str> = lines[1].split_whitespace().collect();
    assert_eq!(
        header,
        ["column", "mean", "variance", "std", "rms", "min", "max", "max_abs"]
    );
    assert_eq!(lines.len(), 4, "{text}");
    assert!(
        lines[2].starts_with("ship.a") && lines[3].starts_with("gear.c"),
        "{text}"
    );
    assert!(
        lines[1..].iter().all(|l| l.len() == lines[1].len()),
        "not aligned:\n{text}"
    );
    let row: Vec<f64> = lines[2]
        .split_whitespace()
        .skip(1)
        .map(|x| x.parse().unwrap())
        .collect();
    assert!(
        (row[0] - 2.0).abs() < 1e-6 && (row[1] - 4.5).abs() < 1e-5,
        "{text}"
    );

    // Errors: an unknown column (with a suggestion), an empty window, a bad window.
    refused(
        &csv,
        &["--columns", "ship.aa"],
        &["no column matches 'ship.aa'", "'ship.a'"],
    );
    let empty = ["no sample in the window [20, 30]", "t = 0 .. 10"];
    refused(&csv, &["--window", "20:30"], &empty);
    assert!(!stats(&csv, &["--window", "5"]).status.success());
    assert!(!stats(&csv, &["--window", "6:5"]).status.success());
}

/// A CSV with a recorded String variable and RFC 4180 quoting (a name with a comma, a text
/// field with a comma and doubled quotes): the numbers are read by column, the text column is
/// left out, and asking for it says it is text. (Before, the reader split lines at every
/// comma: "3 values, header has 4".)
#[test]
fn quoted_fields_and_text_columns_are_read() {
    let d = tempfile::tempdir().unwrap();
    let csv = d.path().join("text.csv");
    std::fs::write(
        &csv,
        "time,m.mode,\"a,b.y\",m.x\n0,\"on, \"\"fast\"\"\",1,10\n0.5,off,3,20\n1,off,5,30\n",
    )
    .unwrap();
    let j = json(&csv, &[]);
    let names: Vec<&str> = j["columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["a,b.y", "m.x"]);
    // mean of 1, 3, 5 and of 10, 20, 30, written out by hand
    assert_eq!(column(&j, "a,b.y")["mean"], 3.0);
    assert_eq!(column(&j, "m.x")["mean"], 20.0);
    refused(
        &csv,
        &["--columns", "m.mode"],
        &["column 'm.mode' is text (a String variable)"],
    );
}

/// An FMU archive with only a model description (no binaries: `stats --system` reads the
/// descriptions and loads nothing): Real variables with units, one through a declaredType, one
/// without a unit, and an Integer.
fn description_only_fmu(path: &Path, name: &str, variables: &str) {
    let xml = format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="{name}" guid="{{stats-{name}}}">
  <CoSimulation modelIdentifier="{name}"/>
  <UnitDefinitions>
    <Unit name="m"><BaseUnit m="1"/></Unit>
    <Unit name="m/s"><BaseUnit m="1" s="-1"/></Unit>
  </UnitDefinitions>
  <TypeDefinitions>
    <SimpleType name="Speed"><Real quantity="Velocity" unit="m/s"/></SimpleType>
  </TypeDefinitions>
  <ModelVariables>
{variables}
  </ModelVariables>
  <ModelStructure/>
</fmiModelDescription>"#
    );
    let f = std::fs::File::create(path).unwrap();
    let mut z = zip::ZipWriter::new(f);
    z.start_file(
        "modelDescription.xml",
        zip::write::SimpleFileOptions::default(),
    )
    .unwrap();
    std::io::Write::write_all(&mut z, xml.as_bytes()).unwrap();
    z.finish().unwrap();
}

/// The system that "wrote" x.csv: `ship` (a in m, b a Speed: m/s through its declaredType) and
/// `gear` (c without a unit), two instances of one FMU for `ship`.
fn write_system(dir: &Path) -> std::path::PathBuf {
    description_only_fmu(
        &dir.join("Ship.fmu"),
        "Ship",
        r#"    <ScalarVariable name="a" valueReference="0" causality="output"><Real unit="m"/></ScalarVariable>
    <ScalarVariable name="b" valueReference="1" causality="output"><Real declaredType="Speed"/></ScalarVariable>"#,
    );
    description_only_fmu(
        &dir.join("Gear.fmu"),
        "Gear",
        r#"    <ScalarVariable name="c" valueReference="0" causality="output"><Real/></ScalarVariable>
    <ScalarVariable name="n" valueReference="1" causality="output"><Integer/></ScalarVariable>"#,
    );
    let system = dir.join("sys.toml");
    std::fs::write(
        &system,
        r#"[simulation]
stop_time = 10.0
step_size = 0.01
[[instances]]
name = "ship"
fmu = "Ship.fmu"
[[instances]]
name = "other_ship"
fmu = "Ship.fmu"
[[instances]]
name = "gear"
fmu = "Gear.fmu"
"#,
    )
    .unwrap();
    system
}

/// `--system FILE`: every column gets the unit its FMU declares (following declaredType; "-"
/// for none), the variance its square; without `--system`, the header says how to get units.
/// (Before, `stats` printed no units and had no --system.)
#[test]
fn units_from_the_system_file() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("x.csv");
    write_csv(&csv);
    let system = write_system(dir.path());
    let sys = system.to_str().unwrap();

    let j = json(&csv, &["--system", sys]);
    assert_eq!(j["system"], sys);
    let units = |name: &str| {
        let c = column(&j, name);
        (c["unit"].clone(), c["variance_unit"].clone())
    };
    assert_eq!(units("ship.a"), ("m".into(), "m^2".into()));
    assert_eq!(units("ship.b"), ("m/s".into(), "(m/s)^2".into()));
    assert_eq!(
        units("gear.c"),
        (serde_json::Value::Null, serde_json::Value::Null)
    );
    // the statistics themselves do not change
    assert_eq!(
        column(&j, "ship.a")["mean"],
        column(&json(&csv, &[]), "ship.a")["mean"]
    );

    // The table: a unit column after the name, the header says the variance is in unit^2.
    let out = stats(&csv, &["--system", sys, "--window", "2:4.99"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert!(
        lines[0].contains("300 samples, t = 2 .. 4.99 s")
            && lines[0].contains(&format!(
                "units from the FMUs of {sys} (variance in unit^2)"
            )),
        "{text}"
    );
    let header: Vec<&str> = lines[1].split_whitespace().collect();
    assert_eq!(
        header,
        ["column", "unit", "mean", "variance", "std", "rms", "min", "max", "max_abs"]
    );
    let row = |name: &str| -> Vec<&str> {
        lines
            .iter()
            .find(|l| l.starts_with(name))
            .unwrap_or_else(|| panic!("no {name} in {text}"))
            .split_whitespace()
            .collect()
    };
    assert_eq!(row("ship.a")[1], "m");
    assert_eq!(row("ship.b")[1], "m/s");
    assert_eq!(row("gear.c")[1], "-");
    assert_eq!(row("ship.a").len(), header.len(), "{text}");
    assert!(
        lines[1..].iter().all(|l| l.len() == lines[1].len()),
        "not aligned:\n{text}"
    );

    // Without --system: no unit column, and the header says how to get units.
    let out = stats(&csv, &[]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.lines().next().unwrap().contains(
            "no units (a CSV has none): give --system FILE, the system file that wrote it"
        ),
        "{text}"
    );
    assert_eq!(
        text.lines().nth(1).unwrap().split_whitespace().nth(1),
        Some("mean")
    );
    let j = json(&csv, &[]);
    assert_eq!(j["system"], serde_json::Value::Null);
    assert_eq!(column(&j, "ship.a")["unit"], serde_json::Value::Null);

    // A column the system does not have: "?" and a warning; none of them: an error.
    let other = dir.path().join("other.csv");
    std::fs::write(&other, "time,ship.a,tug.x\n0,1,2\n1,3,4\n").unwrap();
    let out = stats(&other, &["--system", sys]);
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("column 'tug.x' is not a variable of") && err.contains("unit is unknown"),
        "{err}"
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let tug: Vec<&str> = text.lines().last().unwrap().split_whitespace().collect();
    assert_eq!(tug[..2], ["tug.x", "?"], "{text}");
    refused(
        &other,
        &["--system", sys, "--columns", "tug.x"],
        &[
            "none of the columns is a variable of its instances",
            "'tug.x'",
        ],
    );
    // A system whose FMU is missing: the system file's error.
    std::fs::remove_file(dir.path().join("Gear.fmu")).unwrap();
    refused(&csv, &["--system", sys], &["Gear.fmu", "not found"]);
}
