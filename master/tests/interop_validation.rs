//! The interop defects of issue 18 at the library level, on the model descriptions of the fixture
//! FMUs (tests/fixtures/fmus; their binaries are built and run by tests/python/test_fixture_fmus.py):
//!
//! - unit mismatches in an OSP file are warnings unless `System::strict_units` is set; in the
//!   native TOML they stay errors; a difference in the rad exponent alone is a warning either way;
//! - two different FMU files with one GUID give a warning in `Plan::warnings`;
//! - an Integer declared continuous gives a warning;
//! - `export-osp` leaves Enumeration initial values out of the file (libcosim ignores Enumeration
//!   variables), with a warning.

mod common;

use shipsim::format::{osp, toml};
use shipsim::model_description::ModelDescription;
use shipsim::system::System;
use std::path::{Path, PathBuf};

fn fixture_dir(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/fixtures/fmus")
        .join(name)
}

fn md_text(name: &str) -> String {
    std::fs::read_to_string(fixture_dir(name).join("modelDescription.xml")).unwrap()
}

fn md(name: &str) -> ModelDescription {
    ModelDescription::parse(&md_text(name)).unwrap()
}

/// The OSP file of the units case (tests/fixtures/fmus/systems), also run by
/// tests/python/test_fixture_fmus.py in shipsim and libcosim.
fn units_osp() -> String {
    std::fs::read_to_string(fixture_dir("systems/units_OspSystemStructure.xml")).unwrap()
}

fn units_mds() -> [ModelDescription; 2] {
    [md("RadianSource"), md("RadSink")]
}

fn unit_warnings(warnings: &[String]) -> Vec<&String> {
    warnings
        .iter()
        .filter(|w| w.contains("incompatible units"))
        .collect()
}

#[test]
fn osp_unit_mismatches_are_warnings_unless_strict() {
    let sys = osp::parse(Path::new("/sys/OspSystemStructure.xml"), &units_osp()).unwrap();
    assert!(
        !sys.strict_units,
        "the OSP reader does not ask for strict units"
    );
    let [a, b] = units_mds();
    let plan = sys.validate(&[&a, &b]).unwrap();
    assert_eq!(plan.connections.len(), 2);
    let w = unit_warnings(&plan.warnings);
    assert_eq!(w.len(), 2, "{:?}", plan.warnings);
    assert!(w[0].contains("'src.angle' is in radian but 'sink.angle_in' is in rad"));
    assert!(w[0].contains("only in the rad exponent"));
    assert!(w[1].contains("'src.work' is in dimensionless but 'sink.energy_in' is in kg.m2/s2"));
    assert!(w[1].contains("--strict-units"));

    let mut strict = sys.clone();
    strict.strict_units = true;
    let e = strict.validate(&[&a, &b]).unwrap_err().to_string();
    assert!(
        e.contains("'src.work' is in dimensionless but 'sink.energy_in' is in kg.m2/s2"),
        "{e}"
    );
    assert!(
        !e.contains("src.angle"),
        "the rad-only difference is no error: {e}"
    );
    assert!(!e.contains("convert"), "an OSP file has no convert: {e}");
}

#[test]
fn toml_unit_mismatches_stay_errors_with_the_convert_hint() {
    let text = std::fs::read_to_string(fixture_dir("systems/units.toml")).unwrap();
    let sys = toml::parse(Path::new("/sys/units.toml"), &text).unwrap();
    assert!(sys.strict_units);
    let [a, b] = units_mds();
    let e = sys.validate(&[&a, &b]).unwrap_err().to_string();
    assert!(e.contains("/sys/units.toml:4"), "{e}");
    assert!(
        e.contains("incompatible units: 'src.work' is in dimensionless but 'sink.energy_in' is in kg.m2/s2; if the gain converts between these quantities, set convert = true"),
        "{e}"
    );
    assert!(!e.contains("src.angle"), "{e}");
    let converted = text.replace(
        "\"src.work -> sink.energy_in\"",
        "{ from = \"src.work\", to = \"sink.energy_in\", convert = true }",
    );
    let sys = toml::parse(Path::new("/sys/units.toml"), &converted).unwrap();
    let plan = sys.validate(&[&a, &b]).unwrap();
    let w = unit_warnings(&plan.warnings);
    assert_eq!(w.len(), 1, "{:?}", plan.warnings);
    assert!(w[0].contains("only in the rad exponent"));
}

/// A system of two instances of the given FMU files (paths need not exist: validation reads no
/// file).
fn two_instances(a: &str, b: &str) -> System {
    let text = format!(
        "[simulation]\nstop_time = 1.0\nstep_size = 0.0625\n\
         [[instances]]\nname = \"a\"\nfmu = \"{a}\"\n[[instances]]\nname = \"b\"\nfmu = \"{b}\"\n"
    );
    toml::parse(Path::new("/sys/two.toml"), &text).unwrap()
}

fn guid_warnings(sys: &System, mds: [&ModelDescription; 2]) -> Vec<String> {
    let plan = sys.validate(&mds).unwrap();
    plan.warnings
        .into_iter()
        .filter(|w| w.contains("GUID"))
        .collect()
}

#[test]
fn different_models_sharing_a_guid_warn() {
    let (a, b) = (md("SharedGuidA"), md("SharedGuidB"));
    assert_eq!(a.guid, b.guid);
    let w = guid_warnings(&two_instances("A.fmu", "B.fmu"), [&a, &b]);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(w[0].contains("model 'SharedGuidA'") && w[0].contains("model 'SharedGuidB'"));
    assert!(w[0].contains("{shipsim-fixture-shared-guid}") && w[0].contains("libcosim"));
    // One FMU twice, and two copies of one model: nothing to confuse.
    assert!(guid_warnings(&two_instances("A.fmu", "A.fmu"), [&a, &a]).is_empty());
    assert!(guid_warnings(&two_instances("A.fmu", "copy/A.fmu"), [&a, &a]).is_empty());
    // Different GUIDs: no warning.
    let (c, d) = (md("RadSink"), md("Feedthrough"));
    assert!(guid_warnings(&two_instances("C.fmu", "D.fmu"), [&c, &d]).is_empty());
}

#[test]
fn integer_declared_continuous_warns_once_per_fmu() {
    let (src, ft) = (md("RadianSource"), md("Feedthrough"));
    let sys = two_instances("RadianSource.fmu", "RadianSource.fmu");
    let plan = sys.validate(&[&src, &src]).unwrap();
    let w: Vec<_> = plan
        .warnings
        .iter()
        .filter(|w| w.contains("continuous"))
        .collect();
    assert_eq!(w.len(), 1, "{:?}", plan.warnings);
    assert!(w[0].contains("'count' (Integer)") && w[0].contains("sec. 2.2.7"));
    let sys = two_instances("Feedthrough.fmu", "RadSink.fmu");
    let rad_sink = md("RadSink");
    let plan = sys.validate(&[&ft, &rad_sink]).unwrap();
    assert!(
        !plan.warnings.iter().any(|w| w.contains("continuous")),
        "{:?}",
        plan.warnings
    );
}

#[test]
fn export_osp_leaves_enumeration_values_out() {
    let dir = tempfile::tempdir().unwrap();
    // export-osp reads model descriptions only: an archive without a binary is enough.
    common::zip_files(
        &dir.path().join("Feedthrough.fmu"),
        &[("modelDescription.xml", md_text("Feedthrough").into_bytes())],
    );
    let toml_path = dir.path().join("ft.toml");
    let text = "connections = [\"m.enumeration_output -> n.enumeration_input\", \
                \"m.integer_output -> n.integer_input\"]\n\
                [simulation]\nstop_time = 1.0\nstep_size = 0.0625\n[[instances]]\nname = \"m\"\n\
                fmu = \"Feedthrough.fmu\"\nparameters = { enumeration_input = 2, integer_input = 3 }\n\
                [[instances]]\nname = \"n\"\nfmu = \"Feedthrough.fmu\"\n";
    let sys = toml::parse(&toml_path, text).unwrap();
    let out = dir.path().join("osp/OspSystemStructure.xml");
    let warnings = osp::write(&sys, &out).unwrap();
    let xml = std::fs::read_to_string(&out).unwrap();
    assert!(!xml.contains("enumeration_input"), "{xml}");
    assert!(
        xml.contains(
            r#"<InitialValue variable="integer_input"><Integer value="3"/></InitialValue>"#
        ),
        "{xml}"
    );
    let w: Vec<_> = warnings
        .iter()
        .filter(|w| w.contains("Enumeration"))
        .collect();
    assert_eq!(w.len(), 1, "{warnings:?}");
    assert!(
        w[0].contains("the value of m.enumeration_input, the connection m.enumeration_output -> n.enumeration_input"),
        "{}",
        w[0]
    );
    // The Integer connection stays, the Enumeration one is left out.
    assert!(xml.contains(r#"<Variable simulator="m" name="integer_output" causality="output"/>"#));
    assert!(!xml.contains("enumeration_output"), "{xml}");
    // What is left reads back as the same system without the Enumeration value.
    let back = osp::parse(&out, &xml).unwrap();
    let values: Vec<_> = back.instances[0]
        .values
        .iter()
        .map(|v| v.variable.as_str())
        .collect();
    assert_eq!(values, ["integer_input"]);
}
