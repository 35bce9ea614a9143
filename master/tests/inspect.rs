//! `shipsim inspect` (issue 18, point 3): variables grouped by causality with description,
//! range, unit, display unit and declared type, in 100 columns; `--doc` prints the FMU's
//! documentation/index.html as text and `--doc --html DIR` copies its documentation out.

mod common;

use common::*;
use std::path::Path;
use std::process::{Command, Output};

fn shipsim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_shipsim"))
        .args(args)
        .output()
        .unwrap()
}

fn ok_stdout(o: &Output) -> String {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout.clone()).unwrap()
}

const MD: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="Doc" guid="{doc}" description="A model to inspect">
  <CoSimulation modelIdentifier="doc"/>
  <UnitDefinitions>
    <Unit name="rad"><BaseUnit rad="1"/><DisplayUnit name="deg" factor="57.29577951308232"/></Unit>
    <Unit name="K"><BaseUnit K="1"/><DisplayUnit name="degC" offset="-273.15"/></Unit>
    <Unit name="m"><BaseUnit m="1"/></Unit>
  </UnitDefinitions>
  <TypeDefinitions><SimpleType name="Angle"><Real unit="rad" displayUnit="deg"/></SimpleType></TypeDefinitions>
  <ModelVariables>
    <ScalarVariable name="angle" valueReference="0" causality="input" description="Commanded angle, positive to starboard"><Real declaredType="Angle" start="0.17453292519943295" min="-0.6108652381980153" max="0.6108652381980153"/></ScalarVariable>
    <ScalarVariable name="y" valueReference="1" causality="output" initial="calculated"><Real unit="m"/></ScalarVariable>
    <ScalarVariable name="gain" valueReference="2" causality="parameter" variability="tunable" description="Gain of the coupling; 0 (the default) switches the coupling off, so a connected input has no effect until it is set"><Real start="0" min="0" max="10"/></ScalarVariable>
    <ScalarVariable name="mode" valueReference="0" causality="parameter" variability="fixed"><Integer start="2" min="1" max="3"/></ScalarVariable>
    <ScalarVariable name="a_name_that_is_longer_than_the_name_column" valueReference="3" causality="local"><Real unit="K" displayUnit="degC" start="300"/></ScalarVariable>
  </ModelVariables>
  <ModelStructure><Outputs><Unknown index="2" dependencies=""/></Outputs></ModelStructure>
</fmiModelDescription>"#;

const HTML: &str = "<!DOCTYPE html><html><head><title>Doc</title><style>h1{color:red}</style></head><body>\
<h1>Doc</h1><p>Angles are positive to starboard;\n  <code>gain</code> = 0 switches the coupling off &amp; is the default.</p>\
<h2>Variables</h2><table><tr><th>name</th><th>unit</th></tr><tr><td>angle</td><td>rad</td></tr></table>\
<pre>\ny = gain * angle   (x &lt; 1)\n</pre></body></html>";

/// An FMU of the model description above (no binary: inspect does not load it), with a
/// documentation folder when `doc` is true.
fn doc_fmu(dir: &Path, doc: bool) -> std::path::PathBuf {
    let p = dir.join(if doc { "doc.fmu" } else { "nodoc.fmu" });
    let mut entries = vec![("modelDescription.xml", MD.as_bytes().to_vec())];
    if doc {
        entries.push(("documentation/index.html", HTML.as_bytes().to_vec()));
        entries.push(("documentation/img/fig.svg", b"<svg/>".to_vec()));
    }
    zip_files(&p, &entries);
    p
}

/// The variables by causality, each with its unit, display unit (start, min and max also in
/// it), range, declared type and description: the whole section, written out by hand.
#[test]
fn variables_are_grouped_with_description_range_and_display_unit() {
    let d = tempfile::tempdir().unwrap();
    let fmu = doc_fmu(d.path(), false);
    let out = ok_stdout(&shipsim(&["inspect", fmu.to_str().unwrap()]));
    let section = &out[out.find("variables (5)").expect(&out)..];
    let expected = "\
variables (5), by causality:

parameters (2):
  name                           vr type        variab.    initial    start        unit
  gain                            2 Real        tunable    exact      0
      range 0 .. 10
      Gain of the coupling; 0 (the default) switches the coupling off, so a connected input has no
      effect until it is set
  mode                            0 Integer     fixed      exact      2
      range 1 .. 3

inputs (1):
  name                           vr type        variab.    initial    start        unit
  angle                           0 Real        continuous            0.17453292519943295 rad
      display unit deg, start 0.174533 rad (10 deg); range -0.610865 rad (-35 deg) .. 0.610865 rad
      (35 deg); declared type Angle
      Commanded angle, positive to starboard

outputs (1):
  name                           vr type        variab.    initial    start        unit
  y                               1 Real        continuous calculated              m

locals (1):
  name                           vr type        variab.    initial    start        unit
  a_name_that_is_longer_than_the_name_column
                                  3 Real        continuous calculated 300          K
      display unit degC, start 300 K (26.85 degC)
";
    assert_eq!(section, expected);
    assert!(out.contains("description    A model to inspect\n"), "{out}");
}

/// Every line of `inspect` of each of our FMUs fits in 100 columns, and the Waves FMU shows the
/// convention of its wave direction and its display unit.
#[test]
fn our_fmus_fit_in_100_columns() {
    let mut n = 0;
    for e in std::fs::read_dir(fmu_dir()).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_none_or(|x| x != "fmu") {
            continue;
        }
        n += 1;
        let out = ok_stdout(&shipsim(&["inspect", p.to_str().unwrap()]));
        for line in out.lines() {
            assert!(line.chars().count() <= 100, "{}: {line}", p.display());
        }
    }
    assert!(n >= 20, "{n} FMUs in {}", fmu_dir().display());
    let waves = ok_stdout(&shipsim(&["inspect", our_fmu("Waves").to_str().unwrap()]));
    let at = waves.find("  wave_direction ").expect(&waves);
    let block: Vec<&str> = waves[at..].lines().take(4).collect();
    assert!(
        block[0].ends_with(" Real        tunable    exact      0            rad"),
        "{block:?}"
    );
    assert_eq!(block[1], "      display unit deg, start 0 rad (0 deg)");
    assert!(
        block[2..]
            .join(" ")
            .contains("0 following, +-pi/2 beam, pi head seas"),
        "{block:?}"
    );
}

/// --doc prints the page as text: no tags, references decoded, headings marked, table cells
/// joined, <pre> kept.
#[test]
fn doc_prints_the_html_as_text() {
    let d = tempfile::tempdir().unwrap();
    let fmu = doc_fmu(d.path(), true);
    let out = ok_stdout(&shipsim(&["inspect", fmu.to_str().unwrap(), "--doc"]));
    assert_eq!(
        out,
        "# Doc\n\nAngles are positive to starboard; gain = 0 switches the coupling off & is the default.\n\n\
         ## Variables\n\nname | unit\nangle | rad\n\ny = gain * angle   (x < 1)\n"
    );
    let waves = ok_stdout(&shipsim(&[
        "inspect",
        our_fmu("Waves").to_str().unwrap(),
        "--doc",
    ]));
    assert!(waves.contains("gamma = 0 is following seas"), "{waves}");
    assert!(!waves.contains("<p>") && !waves.contains("&amp;") && !waves.contains("font-family"));
}

/// --doc --html DIR copies the documentation folder byte for byte; an FMU without one is an
/// error that says so.
#[test]
fn doc_html_extracts_the_folder() {
    let d = tempfile::tempdir().unwrap();
    let fmu = doc_fmu(d.path(), true);
    let out_dir = d.path().join("html");
    let out = ok_stdout(&shipsim(&[
        "inspect",
        fmu.to_str().unwrap(),
        "--doc",
        "--html",
        out_dir.to_str().unwrap(),
    ]));
    assert_eq!(
        out,
        format!(
            "wrote 2 files; open {}\n",
            out_dir.join("index.html").display()
        )
    );
    assert_eq!(
        std::fs::read(out_dir.join("index.html")).unwrap(),
        HTML.as_bytes()
    );
    assert_eq!(
        std::fs::read(out_dir.join("img/fig.svg")).unwrap(),
        b"<svg/>"
    );
    let none = doc_fmu(d.path(), false);
    let o = shipsim(&["inspect", none.to_str().unwrap(), "--doc"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        err.contains("nodoc.fmu")
            && err.contains("no documentation/index.html; it has no documentation/ folder"),
        "{err}"
    );
    // --html needs --doc.
    assert!(!shipsim(&["inspect", fmu.to_str().unwrap(), "--html", "x"])
        .status
        .success());
}
