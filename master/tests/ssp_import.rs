//! SSP 1.0 import on hand-written files (tests/fixtures/ssp, written from the standard's text,
//! not by shipsim) with the Feedthrough fixture FMU (tests/fixtures/fmus/Feedthrough, built with
//! gcc here). Expected values come from the FMU's equations:
//!
//!   real_continuous_output = real_continuous_input + real_tunable_parameter * t
//!   integer_output = integer_input + steps,  boolean_output = boolean_input xor (steps odd)
//!   enumeration_output = the item `steps` places after enumeration_input (1, 2, 3, 1, ...)
//!
//! and the master's Jacobi exchange (an input at row n holds the source's output of row n-1;
//! at row 0 the initial outputs). Tolerance 1e-12 absolute on values of order 10.
//! Then one test per refusal and malformed file: each error names the file, line and element.
mod common;
use common::{read_csv, zip_files};
use shipsim::run::{load_fmus, run as run_plan, run_system, Output, RunOptions};
use shipsim::system::System;
use std::alloc::{GlobalAlloc, Layout, System as SysAlloc};
use std::cell::Cell;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Counts the heap allocations of the current thread (the tests run in parallel threads; a run
/// is single-threaded).
struct Counting;
thread_local! {
    static ALLOCS: Cell<usize> = const { Cell::new(0) };
}
fn count() -> usize {
    ALLOCS.with(Cell::get)
}
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        SysAlloc.alloc(l)
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        SysAlloc.dealloc(p, l)
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        SysAlloc.realloc(p, l, n)
    }
}
#[global_allocator]
static A: Counting = Counting;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The Feedthrough fixture FMU, compiled and zipped into `dir/Feedthrough.fmu`.
fn feedthrough(dir: &Path) -> PathBuf {
    let src = root().join("tests/fixtures/fmus/Feedthrough");
    let so = dir.join("Feedthrough.so");
    let st = Command::new("gcc")
        .args([
            "-shared",
            "-fPIC",
            "-O2",
            "-std=c99",
            "-fvisibility=hidden",
            "-I",
        ])
        .arg(root().join("tests/fixtures/fmus/include"))
        .arg("-o")
        .arg(&so)
        .arg(src.join("Feedthrough.c"))
        .arg("-lm")
        .status()
        .expect("gcc must be installed to build the fixture FMU");
    assert!(st.success());
    let fmu = dir.join("Feedthrough.fmu");
    zip_files(
        &fmu,
        &[
            (
                "modelDescription.xml",
                std::fs::read(src.join("modelDescription.xml")).unwrap(),
            ),
            (
                "binaries/linux64/Feedthrough.so",
                std::fs::read(so).unwrap(),
            ),
        ],
    );
    fmu
}

/// A fixture case copied into a temporary directory, with resources/Feedthrough.fmu.
fn case(name: &str) -> tempfile::TempDir {
    let d = tempfile::tempdir().unwrap();
    let from = root().join("tests/fixtures/ssp").join(name);
    for e in std::fs::read_dir(&from).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), d.path().join(e.file_name())).unwrap();
    }
    std::fs::create_dir(d.path().join("resources")).unwrap();
    let fmu = feedthrough(d.path());
    std::fs::rename(fmu, d.path().join("resources/Feedthrough.fmu")).unwrap();
    d
}

/// The case packed as an `.ssp` (every file of the directory, FMU under resources/).
fn pack(d: &Path) -> PathBuf {
    let mut entries = Vec::new();
    let mut names = Vec::new();
    for e in std::fs::read_dir(d).unwrap() {
        let p = e.unwrap().path();
        if p.extension()
            .is_some_and(|x| x == "ssd" || x == "ssv" || x == "ssm")
        {
            names.push(p.file_name().unwrap().to_string_lossy().into_owned());
        }
    }
    names.push("resources/Feedthrough.fmu".into());
    for n in &names {
        entries.push((n.as_str(), std::fs::read(d.join(n)).unwrap()));
    }
    let out = d.join("system.ssp");
    zip_files(&out, &entries);
    out
}

type Table = (Vec<String>, Vec<Vec<f64>>);

fn run(path: &Path) -> Table {
    let sys = System::load(path).unwrap_or_else(|e| panic!("{e}"));
    let out = path.with_extension("csv");
    run_system(&sys, Output::File(out.clone()), &RunOptions::default())
        .unwrap_or_else(|e| panic!("{e}"));
    read_csv(&out)
}

fn column<'t>(t: &'t Table, name: &str) -> Vec<f64> {
    let c =
        t.0.iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("no column {name} in {:?}", t.0));
    t.1.iter().map(|r| r[c]).collect()
}

const H: f64 = 0.0625;

fn close(got: &[f64], want: impl Fn(usize) -> f64, what: &str) {
    assert_eq!(got.len(), 17, "{what}");
    for (n, g) in got.iter().enumerate() {
        let w = want(n);
        assert!((g - w).abs() <= 1e-12, "{what} row {n}: got {g}, want {w}");
    }
}

#[test]
fn linear_transformation() {
    let d = case("linear");
    let t = run(&d.path().join("SystemStructure.ssd"));
    let a = |n: usize| 3.0 * n as f64 * H;
    close(&column(&t, "A.real_continuous_output"), a, "A");
    close(
        &column(&t, "B.real_continuous_output"),
        |n| 2.5 * a(n.saturating_sub(1)) - 1.0,
        "B = 2.5 A - 1",
    );
}

#[test]
fn unit_conversion_km_per_h_to_m_per_s() {
    let d = case("units");
    let t = run(&d.path().join("SystemStructure.ssd"));
    let a = |n: usize| 36.0 * n as f64 * H; // km/h
    close(&column(&t, "A.real_continuous_output"), a, "A in km/h");
    close(
        &column(&t, "B.real_continuous_output"),
        |n| a(n.saturating_sub(1)) * 1000.0 / 3600.0,
        "B in m/s",
    );
}

#[test]
fn nested_systems_flattened_with_their_paths_and_system_bindings_first() {
    let d = case("nested");
    let t = run(&d.path().join("SystemStructure.ssd"));
    let a = |n: usize| 2.0 * n as f64 * H;
    // B's own binding says 9, the root system's 0.5: the system's wins.
    close(
        &column(&t, "outer/inner/B.real_continuous_output"),
        |n| a(n.saturating_sub(1)) + 0.5 * n as f64 * H,
        "outer/inner/B",
    );
}

#[test]
fn parameter_sets_in_ssv_files_with_an_ssm_mapping() {
    let d = case("params");
    let t = run(&d.path().join("SystemStructure.ssd"));
    close(
        &column(&t, "A.real_continuous_output"),
        |n| 1.25 * n as f64 * H,
        "A",
    );
    close(&column(&t, "A.integer_output"), |n| 7.0 + n as f64, "A int");
    b_from_gains(&t);
}

/// B's parameters from gains.ssv through the mapping: slope 0.75 -> real_tunable_parameter,
/// times 2; offset -4 -> integer_input.
fn b_from_gains(t: &Table) {
    close(
        &column(t, "B.real_continuous_output"),
        |n| 1.5 * n as f64 * H,
        "B",
    );
    close(&column(t, "B.integer_output"), |n| -4.0 + n as f64, "B int");
}

#[test]
fn mapping_transformations() {
    let d = case("mapping");
    let t = run(&d.path().join("SystemStructure.ssd"));
    let prev = |n: usize| n.saturating_sub(1) as f64;
    close(
        &column(&t, "B.integer_output"),
        |n| {
            let a = prev(n); // A.integer_output of the row before = its step count
            let mapped = match a as i64 {
                1 => 100.0,
                2 => 200.0,
                x => x as f64,
            };
            mapped + n as f64
        },
        "integer mapping",
    );
    close(
        &column(&t, "B.boolean_output"),
        |n| {
            let a = (n.saturating_sub(1) % 2) as f64; // false xor (steps odd)
            let mapped = 1.0 - a; // true <-> false
            ((mapped as i64) ^ (n as i64 % 2)) as f64
        },
        "boolean mapping",
    );
    close(
        &column(&t, "B.enumeration_output"),
        |n| {
            let a = (n.saturating_sub(1) % 3) as i64 + 1; // first, second, third, first, ...
            let mapped = match a {
                1 => 3,
                3 => 1,
                x => x,
            };
            ((mapped - 1 + n as i64) % 3 + 1) as f64
        },
        "enumeration mapping",
    );
}

#[test]
fn an_ssp_archive_runs_like_its_ssd() {
    for name in ["nested", "params", "mapping"] {
        let d = case(name);
        let ssd = run(&d.path().join("SystemStructure.ssd"));
        let ssp = run(&pack(d.path()));
        assert_eq!(ssd.0, ssp.0, "{name}");
        for (a, b) in ssd.1.iter().zip(&ssp.1) {
            let bits = |r: &Vec<f64>| r.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(a), bits(b), "{name}");
        }
    }
}

/// The error of loading the case after `edit` changed its SSD.
fn load_error(name: &str, edit: impl Fn(&str) -> String) -> String {
    let d = case(name);
    let p = d.path().join("SystemStructure.ssd");
    let text = std::fs::read_to_string(&p).unwrap();
    let changed = edit(&text);
    assert_ne!(changed, text, "the edit must change the file");
    std::fs::write(&p, changed).unwrap();
    match System::load(&p) {
        Ok(_) => panic!("{name}: loaded"),
        Err(e) => e.to_string(),
    }
}

fn has(msg: &str, parts: &[&str]) {
    for p in parts {
        assert!(msg.contains(p), "'{p}' not in: {msg}");
    }
}

#[test]
fn a_missing_fmu_is_named() {
    let e = load_error("linear", |t| {
        t.replacen("resources/Feedthrough.fmu", "resources/Missing.fmu", 1)
    });
    has(
        &e,
        &[
            "SystemStructure.ssd:",
            "component 'A'",
            "resources/Missing.fmu",
            "not found",
        ],
    );
}

#[test]
fn an_unknown_connector_is_named() {
    let e = load_error("linear", |t| {
        t.replace(
            "endConnector=\"real_continuous_input\"",
            "endConnector=\"real_input\"",
        )
    });
    has(
        &e,
        &[
            "SystemStructure.ssd:",
            "endConnector \"real_input\"",
            "'B' has no such connector",
        ],
    );
}

#[test]
fn a_unit_mismatch_without_conversion_is_an_error() {
    let e = load_error("units", |t| {
        t.replace(
            "<ssc:BaseUnit m=\"1\" s=\"-1\"/>",
            "<ssc:BaseUnit s=\"1\"/>",
        )
    });
    has(
        &e,
        &[
            "SystemStructure.ssd:",
            "A.real_continuous_output -> B.real_continuous_input",
            "unit mismatch without conversion",
            "km/h (m.s-1)",
            "m/s (s)",
        ],
    );
    // suppressUnitConversion connects them as written
    let d = case("units");
    let p = d.path().join("SystemStructure.ssd");
    let t = std::fs::read_to_string(&p)
        .unwrap()
        .replace(
            "<ssc:BaseUnit m=\"1\" s=\"-1\"/>",
            "<ssc:BaseUnit s=\"1\"/>",
        )
        .replace(
            "endConnector=\"real_continuous_input\"/>",
            "endConnector=\"real_continuous_input\" suppressUnitConversion=\"true\"/>",
        );
    std::fs::write(&p, t).unwrap();
    let t = run(&p);
    close(
        &column(&t, "B.real_continuous_output"),
        |n| 36.0 * n.saturating_sub(1) as f64 * H,
        "suppressed",
    );
}

#[test]
fn bad_xml_is_named_with_its_line() {
    let e = load_error("linear", |t| {
        t.replacen("</ssd:Elements>", "</ssd:Element>", 1)
    });
    has(&e, &["SystemStructure.ssd:", "not well-formed XML"]);
}

#[test]
fn bad_xml_in_an_ssv_names_the_ssv() {
    let d = case("params");
    std::fs::write(
        d.path().join("params.ssv"),
        "<ssv:ParameterSet version=\"1.0\" name=\"x\"><ssv:Parameters>",
    )
    .unwrap();
    let e = System::load(&d.path().join("SystemStructure.ssd"))
        .unwrap_err()
        .to_string();
    has(&e, &["params.ssv:", "<Parameters> is never closed"]);
}

#[test]
fn refused_elements_are_named() {
    let vs = load_error("linear", |t| {
        t.replace(
            "  </ssd:System>",
            "    <ssd:Annotations><ssc:Annotation type=\"org.openmodelica\"><oms:Annotations xmlns:oms=\"x\"><oms:SimulationInformation><oms:VariableStepMaster description=\"oms-ma\"/></oms:SimulationInformation></oms:Annotations></ssc:Annotation></ssd:Annotations>\n  </ssd:System>",
        )
    });
    has(
        &vs,
        &[
            "SystemStructure.ssd:",
            "<oms:VariableStepMaster>",
            "variable-step masters are not supported",
        ],
    );
    let sd = load_error("linear", |t| {
        t.replace(
            "  </ssd:System>",
            "    <ssd:SignalDictionaries><ssd:SignalDictionary name=\"d\"/></ssd:SignalDictionaries>\n  </ssd:System>",
        )
    });
    has(
        &sd,
        &[
            "SystemStructure.ssd:",
            "<SignalDictionaries> are not supported",
        ],
    );
    let v2 = load_error("linear", |t| {
        t.replace("version=\"1.0\">\n", "version=\"2.0\">\n")
    });
    has(&v2, &["SystemStructure.ssd:", "shipsim reads SSP 1.0"]);
    let sub = load_error("linear", |t| {
        t.replacen(
            "<ssd:Component name=\"B\" source",
            "<ssd:Component name=\"B\" type=\"application/x-ssp-package\" source",
            1,
        )
    });
    has(
        &sub,
        &[
            "SystemStructure.ssd:",
            "component 'B'",
            "application/x-ssp-package",
            "not supported",
        ],
    );
    let abs = load_error("linear", |t| {
        t.replacen(
            "source=\"resources/Feedthrough.fmu\"",
            "source=\"file:///tmp/Feedthrough.fmu\"",
            1,
        )
    });
    has(&abs, &["component 'A'", "use a relative path"]);
}

#[test]
fn oversized_and_deeply_nested_files_are_refused() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("big.ssd");
    let f = std::fs::File::create(&p).unwrap();
    f.set_len(33 << 20).unwrap();
    let e = System::load(&p).unwrap_err().to_string();
    has(&e, &["big.ssd", "larger than 32 MiB"]);
    let deep = d.path().join("deep.ssd");
    std::fs::write(&deep, "<a>".repeat(100_000)).unwrap();
    let e = System::load(&deep).unwrap_err().to_string();
    has(&e, &["deep.ssd:1", "nested deeper than 64"]);
}

#[test]
fn a_broken_archive_is_named() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("broken.ssp");
    std::fs::write(&p, b"not a zip").unwrap();
    let e = System::load(&p).unwrap_err().to_string();
    has(&e, &["broken.ssp", "not a valid SSP (zip) archive"]);
    let empty = d.path().join("empty.ssp");
    zip_files(&empty, &[("readme.txt", b"x".to_vec())]);
    let e = System::load(&empty).unwrap_err().to_string();
    has(&e, &["empty.ssp", "no SystemStructure.ssd"]);
}

#[test]
fn the_value_mappings_allocate_nothing_in_the_step_loop() {
    let d = case("mapping");
    let mut sys = System::load(&d.path().join("SystemStructure.ssd")).unwrap();
    let fmus = load_fmus(&sys).unwrap();
    let mds: Vec<_> = fmus.iter().map(|f| &f.model_description).collect();
    let mut counts = Vec::new();
    for stop in [1.0, 100.0] {
        sys.stop_time = Some(stop);
        let plan = sys.validate(&mds).unwrap();
        assert!(plan.connections.iter().all(|c| c.mapping.is_some()));
        let before = count();
        let s = run_plan(
            &plan,
            &fmus,
            Output::Writer(Box::new(std::io::sink())),
            &RunOptions::default(),
        )
        .unwrap();
        counts.push(count() - before);
        assert_eq!(s.macro_steps, (stop / H) as u64);
    }
    assert_eq!(counts[0], counts[1], "allocations for 16 vs 1600 steps");
}

#[test]
fn a_value_mapping_on_a_real_connection_is_refused() {
    let d = case("linear");
    let p = d.path().join("SystemStructure.ssd");
    let t = std::fs::read_to_string(&p).unwrap().replace(
        "<ssc:LinearTransformation factor=\"2.5\" offset=\"-1\"/>",
        "<ssc:IntegerMappingTransformation><ssc:MapEntry source=\"1\" target=\"2\"/></ssc:IntegerMappingTransformation>",
    );
    std::fs::write(&p, t).unwrap();
    let sys = System::load(&p).unwrap();
    let fmus = sys.unpack_fmus().unwrap();
    let mds: Vec<_> = fmus.iter().map(|f| &f.model_description).collect();
    let e = sys.validate(&mds).unwrap_err().to_string();
    has(
        &e,
        &[
            "SystemStructure.ssd:",
            "A.real_continuous_output -> B.real_continuous_input",
            "the value mapping does not apply",
            "Real",
        ],
    );
}

#[test]
fn a_missing_stop_time_asks_for_one() {
    let d = case("linear");
    let p = d.path().join("SystemStructure.ssd");
    let t = std::fs::read_to_string(&p)
        .unwrap()
        .replace(" stopTime=\"1\"", "");
    std::fs::write(&p, t).unwrap();
    let mut sys = System::load(&p).unwrap();
    let e = sys.require_stop_time().unwrap_err().to_string();
    has(&e, &["SystemStructure.ssd", "stopTime", "--stop-time"]);
    sys.stop_time = Some(0.5);
    sys.require_stop_time().unwrap();
}

/// SSP 1.0 defines no step size: an SSD without an OSP or OMSimulator fixed-step annotation
/// loads, and a run asks for one (issue 36, item 9: such a file could not be run from the
/// command line at all). Given by `--step-size`, the run equals the annotated file's.
#[test]
fn a_missing_step_size_asks_for_one_and_step_size_gives_it() {
    let d = case("linear");
    let p = d.path().join("SystemStructure.ssd");
    let annotated = run(&p);
    let t = std::fs::read_to_string(&p)
        .unwrap()
        .replace("<osp:FixedStepAlgorithm baseStepSize=\"0.0625\"/>", "");
    std::fs::write(&p, t).unwrap();
    let mut sys = System::load(&p).unwrap();
    let e = sys.apply_step_size(None).unwrap_err().to_string();
    has(
        &e,
        &[
            "SystemStructure.ssd",
            "gives no step size",
            "--step-size",
            "step_size = SECONDS",
        ],
    );
    sys.apply_step_size(Some(H)).unwrap();
    let shipsim = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_shipsim"))
            .current_dir(d.path())
            .args(["run", "SystemStructure.ssd", "-q", "-o", "cli.csv"])
            .args(args)
            .output()
            .unwrap()
    };
    let out = shipsim(&[]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("--step-size SECONDS"),
        "{err}"
    );
    let out = shipsim(&["--step-size", "0.0625"]);
    assert!(out.status.success(), "{out:?}");
    assert_eq!(read_csv(&d.path().join("cli.csv")), annotated);
    // `shipsim check` names what is missing.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_shipsim"))
        .args(["check"])
        .arg(&p)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("gives no step size"),
        "{err}"
    );
}

#[test]
fn a_system_binding_with_a_prefix_and_a_mapping_of_prefixed_names() {
    let d = case("params");
    let p = d.path().join("SystemStructure.ssd");
    let text = std::fs::read_to_string(&p).unwrap();
    // B's own binding moves to the root system, with prefix "B." (SSP 1.0: the prefix is
    // prepended before the mapping, so the mapping names "B.slope").
    let own = "          <ssd:ParameterBinding source=\"gains.ssv\">\n            <ssd:ParameterMapping source=\"gains.ssm\"/>\n          </ssd:ParameterBinding>\n";
    assert!(text.contains(own));
    let text = text.replace(own, "").replacen(
        "<ssd:System name=\"root\">\n",
        "<ssd:System name=\"root\">\n    <ssd:ParameterBindings>\n      <ssd:ParameterBinding source=\"gains.ssv\" prefix=\"B.\">\n        <ssd:ParameterMapping source=\"prefixed.ssm\"/>\n      </ssd:ParameterBinding>\n    </ssd:ParameterBindings>\n",
        1,
    );
    std::fs::write(&p, text).unwrap();
    let ssm = std::fs::read_to_string(d.path().join("gains.ssm"))
        .unwrap()
        .replace(
            "source=\"slope\" target=\"",
            "source=\"B.slope\" target=\"B.",
        )
        .replace(
            "source=\"offset\" target=\"",
            "source=\"B.offset\" target=\"B.",
        );
    std::fs::write(d.path().join("prefixed.ssm"), ssm).unwrap();
    let t = run(&p);
    b_from_gains(&t);
}
