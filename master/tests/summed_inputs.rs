//! Summed inputs in the native TOML (issue 17): several connections into one input are added
//! when each says `sum = true`, left to right in file order (libcosim's `Sum` order), with a
//! gain and offset per term, under both algorithms and with multi-rate instances; a double
//! connection without it stays an error; the step loop allocates nothing; the export to OSP
//! writes a `Sum` function that reads back to the same run.
//!
//! The test FMU (tests/c/testfmu.c) has the feed-through y2 = k*u, so an instance with k = 1
//! shows in y2 exactly the value its input u was set to. Expected values are written out in
//! the test as the additions the standard order prescribes; every comparison is exact (bits).
mod common;
use common::*;
use shipsim::run::{load_fmus, run, Output, RunOptions};
use shipsim::system::System;
use std::alloc::{GlobalAlloc, Layout, System as SysAlloc};
use std::cell::Cell;
use std::path::Path;

struct Counting;
thread_local! {
    /// Allocations of this thread (the tests of this file run in parallel threads).
    static ALLOCS: Cell<usize> = const { Cell::new(0) };
}
fn count() {
    let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
}
fn allocations() -> usize {
    ALLOCS.with(Cell::get)
}
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        count();
        SysAlloc.alloc(l)
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        SysAlloc.dealloc(p, l)
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        count();
        SysAlloc.realloc(p, l, n)
    }
}
#[global_allocator]
static A: Counting = Counting;

/// Sources a, b, c (y2 = u: 0.1, 0.2, 0.3 km) and the sink s (y2 = u), then `extra`.
fn system(algo: &str, connections: &str, extra: &str) -> String {
    format!(
        r#"{connections}
[simulation]
stop_time = 0.1
step_size = 0.01
algorithm = "{algo}"
[[instances]]
name = "a"
fmu = "testfmu.fmu"
parameters = {{ u = 0.1 }}
[[instances]]
name = "b"
fmu = "testfmu.fmu"
parameters = {{ u = 0.2 }}
[[instances]]
name = "c"
fmu = "testfmu.fmu"
parameters = {{ u = 0.3 }}
[[instances]]
name = "s"
fmu = "testfmu.fmu"
{extra}"#
    )
}

/// The check's error text for a system file.
fn check_error(path: &Path) -> String {
    load_plan(path).map(|_| ()).unwrap_err().to_string()
}

#[test]
fn three_terms_add_left_to_right_in_file_order() {
    // Floating-point addition is not associative: (0.1 + 0.2) + 0.3 = 0.6000000000000001,
    // (0.3 + 0.2) + 0.1 = 0.6. The file order picks the result.
    let forward: f64 = (0.1 + 0.2) + 0.3;
    let backward: f64 = (0.3 + 0.2) + 0.1;
    assert_ne!(forward.to_bits(), backward.to_bits());
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    for algo in ["jacobi", "gauss-seidel"] {
        for (names, expected) in [(["a", "b", "c"], forward), (["c", "b", "a"], backward)] {
            let list: Vec<String> = names
                .iter()
                .map(|n| format!("\"{n}.y2 -> s.u, sum, gain = 1.0, convert\""))
                .collect();
            let text = system(algo, &format!("connections = [{}]", list.join(", ")), "");
            let p = write_system(d.path(), "sum.toml", &text);
            let m = run_memory(&p);
            let got = m.column("s.y2").unwrap();
            assert_eq!(got.len(), 11);
            assert_eq!(
                bits(got),
                vec![expected.to_bits(); 11],
                "{algo}, order {names:?}: {got:?}"
            );
        }
    }
}

#[test]
fn each_term_has_its_gain_and_offset_and_the_table_form_works() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let connections = r#"[[connections]]
from = "a.y2"
to = "s.u"
gain = 1000.0
sum = true
[[connections]]
from = "b.y2"
to = "s.u"
gain = -3.0
offset = 0.25
convert = true
sum = true
[[connections]]
from = "c.y2"
to = "s.u"
offset = 7.0
convert = true
sum = true
"#;
    // TOML puts [[connections]] tables after the tables of the system.
    let text = system("jacobi", "", connections);
    let p = write_system(d.path(), "gains.toml", &text);
    let m = run_memory(&p);
    let expected: f64 = ((1000.0 * 0.1 + 0.0) + (-3.0 * 0.2 + 0.25)) + (1.0 * 0.3 + 7.0);
    assert_eq!(
        bits(m.column("s.y2").unwrap()),
        vec![expected.to_bits(); 11]
    );
}

#[test]
fn a_second_connection_without_sum_is_still_an_error() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let cases = [
        // neither says sum
        "connections = [\"a.y -> s.u\", \"b.y -> s.u\"]",
        // the first one does not
        "connections = [\"a.y -> s.u\", \"b.y -> s.u, sum\"]",
        // the second one does not
        "connections = [\"a.y -> s.u, sum\", \"b.y -> s.u\"]",
        // sum = false is no sum
        "connections = [\"a.y -> s.u, sum = false\", \"b.y -> s.u, sum = false\"]",
    ];
    for case in cases {
        let p = write_system(d.path(), "twice.toml", &system("jacobi", case, ""));
        let e = check_error(&p);
        assert!(
            e.contains("twice.toml:1:")
                && e.contains(
                    "input 's.u' is driven twice: by b.y -> s.u and by a.y -> s.u (line 1)"
                )
                && e.contains("to add them, set sum = true on every connection into it"),
            "{case}: {e}"
        );
    }
    // One line per connection: the error points at the second one.
    let p = write_system(
        d.path(),
        "lines.toml",
        &system(
            "jacobi",
            "connections = [\n\"a.y -> s.u\",\n\"b.y -> s.u\",\n]",
            "",
        ),
    );
    let e = check_error(&p);
    assert!(e.contains("lines.toml:3:") && e.contains("(line 2)"), "{e}");
}

#[test]
fn sums_are_of_real_inputs_only_and_the_keys_are_checked() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let p = write_system(
        d.path(),
        "int.toml",
        &system(
            "jacobi",
            "connections = [\"a.n_out -> s.n_in, sum\", \"b.n_out -> s.n_in, sum\"]",
            "",
        ),
    );
    let e = check_error(&p);
    assert!(
        e.contains(
            "connection a.n_out -> s.n_in: sum = true adds Real inputs only ('s.n_in' is Integer)"
        ),
        "{e}"
    );
    let p = write_system(
        d.path(),
        "bad.toml",
        &system("jacobi", "connections = [\"a.y -> s.u, sum = yes\"]", ""),
    );
    let e = System::load(&p).unwrap_err().to_string();
    assert!(e.contains("'sum = yes': sum is true or false"), "{e}");
}

/// Sources at step multiples 1, 2 and 3 summed into s, and each also alone into s1, s2, s3:
/// the sum is, row by row, (s1 + s2) + s3 of what the plain connections deliver (the plain
/// connections come first, so that under Gauss-Seidel every sink steps after the sources).
#[test]
fn multi_rate_terms_add_what_plain_connections_deliver() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    for algo in ["jacobi", "gauss-seidel"] {
        let connections = "connections = [\"a.y -> s1.u\", \"b.y -> s2.u\", \"c.y -> s3.u\", \"a.y -> s.u, sum\", \"b.y -> s.u, sum\", \"c.y -> s.u, sum\"]";
        let sinks: String = ["s1", "s2", "s3"]
            .iter()
            .map(|n| format!("[[instances]]\nname = \"{n}\"\nfmu = \"testfmu.fmu\"\n"))
            .collect();
        let text = system(algo, connections, &sinks)
            .replace("stop_time = 0.1", "stop_time = 0.6")
            .replace("name = \"b\"\n", "name = \"b\"\nstep_multiple = 2\n")
            .replace("name = \"c\"\n", "name = \"c\"\nstep_multiple = 3\n");
        assert_eq!(text.matches("step_multiple").count(), 2);
        let p = write_system(d.path(), "rates.toml", &text);
        let m = run_memory(&p);
        let col = |n: &str| m.column(n).unwrap().to_vec();
        let (s1, s2, s3) = (col("s1.y2"), col("s2.y2"), col("s3.y2"));
        let expected: Vec<f64> = (0..s1.len()).map(|k| (s1[k] + s2[k]) + s3[k]).collect();
        assert_eq!(bits(&col("s.y2")), bits(&expected), "{algo}");
        // the sources did move, each at its own rate (a change every 2 and 3 rows of 61)
        let changes = |xs: &[f64]| xs.windows(2).filter(|w| w[0] != w[1]).count();
        assert!(
            changes(&s2) >= 29 && changes(&s3) >= 19,
            "{algo}: {s2:?} {s3:?}"
        );
    }
}

#[test]
fn summed_inputs_allocate_nothing_per_step() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    for algo in ["jacobi", "gauss-seidel"] {
        let connections = "connections = [\"a.y -> s.u, sum\", \"b.y2 -> s.u, sum, gain = 2.0, convert\", \"c.y -> s.u, sum, offset = 1.0\"]";
        let p = write_system(
            d.path(),
            "alloc.toml",
            &system(algo, connections, "step_multiple = 2\n"),
        );
        let mut sys = System::load(&p).unwrap();
        let fmus = load_fmus(&sys).unwrap();
        let mds: Vec<_> = fmus.iter().map(|f| &f.model_description).collect();
        let mut counts = Vec::new();
        for stop in [1.0, 100.0] {
            sys.stop_time = Some(stop);
            let plan = sys.validate(&mds).unwrap();
            let before = allocations();
            let out = Output::Writer(Box::new(std::io::sink()));
            let s = run(&plan, &fmus, out, &RunOptions::default()).unwrap();
            counts.push(allocations() - before);
            assert_eq!(s.macro_steps, (stop * 100.0).round() as u64);
        }
        assert_eq!(
            counts[0], counts[1],
            "{algo}: allocations for 1e2 vs 1e4 steps"
        );
    }
}

#[test]
fn export_to_osp_writes_a_sum_that_reads_back_to_the_same_run() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let connections = "connections = [\"c.y2 -> s.u, sum, convert\", \"a.y2 -> s.u, sum, convert\", \"b.y2 -> s.u, sum, convert\", \"a.y -> e.u, gain = 2.0\"]";
    let e = "[[instances]]\nname = \"e\"\nfmu = \"testfmu.fmu\"\n";
    let p = write_system(d.path(), "exp.toml", &system("jacobi", connections, e));
    let sys = System::load(&p).unwrap();
    let osp = d.path().join("osp/OspSystemStructure.xml");
    shipsim::format::osp::write(&sys, &osp).unwrap();
    let xml = std::fs::read_to_string(&osp).unwrap();
    assert!(
        xml.contains("<Sum name=\"sum0\" inputCount=\"3\"/>"),
        "{xml}"
    );
    for (i, src) in ["c", "a", "b"].iter().enumerate() {
        let want = format!("<Variable simulator=\"{src}\" name=\"y2\"/>\n            <Signal function=\"sum0\" name=\"in[{i}]\"/>");
        assert!(xml.contains(&want), "{want}\n{xml}");
    }
    assert!(xml.contains("<Signal function=\"sum0\" name=\"out\"/>\n            <Variable simulator=\"s\" name=\"u\"/>"), "{xml}");
    let from_toml = run_memory(&p);
    let from_osp = run_memory(&osp);
    let expected: f64 = (0.3 + 0.1) + 0.2;
    for m in [&from_toml, &from_osp] {
        assert_eq!(
            bits(m.column("s.y2").unwrap()),
            vec![expected.to_bits(); 11]
        );
    }
    // the LinearTransformation beside the Sum: e.u = 2 a.y (a.y grows, so e.y does)
    assert!(xml.contains("<LinearTransformation name=\"lt3\" factor=\"2.0\" offset=\"0.0\"/>"));
    let e_y = from_toml.column("e.y").unwrap();
    assert!(e_y[10] > 0.0, "{e_y:?}");
    assert_eq!(bits(e_y), bits(from_osp.column("e.y").unwrap()));
}

#[test]
fn export_to_osp_refuses_a_summed_term_with_a_gain() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let connections = "connections = [\"a.y -> s.u, sum, gain = 2.0\", \"b.y -> s.u, sum\"]";
    let p = write_system(d.path(), "gain.toml", &system("jacobi", connections, ""));
    let sys = System::load(&p).unwrap();
    let osp = d.path().join("g/OspSystemStructure.xml");
    let e = shipsim::format::osp::write(&sys, &osp)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("gain.toml")
            && e.contains("cannot export to OSP: the summed connection(s) a.y -> s.u (gain 2, offset 0) have a gain or offset"),
        "{e}"
    );
    assert!(!osp.exists());
}

/// A plain connection passes -0.0 on as -0.0 (libcosim's VariableConnection transfers the value
/// as it is), and so do the terms of a sum (libcosim's Sum starts from in[0]); a connection with
/// a gain gives +0.0, as libcosim's LinearTransformation (offset + factor*in = 0.0 + -0.0).
#[test]
fn negative_zero_passes_through_plain_connections_and_sums() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let cases: [(&str, f64); 3] = [
        ("\"z.y2 -> s.u\"", -0.0),
        ("\"z.y2 -> s.u, sum\", \"z.y2 -> s.u, sum\"", -0.0),
        ("\"z.y2 -> s.u, gain = 2.0\"", 0.0),
    ];
    for (connections, expected) in cases {
        // z.y2 = k*u = -1 * 0.0 = -0.0; s.y2 = 1 * s.u shows s.u
        let text = format!(
            "connections = [{connections}]\n[simulation]\nstop_time = 0.05\nstep_size = 0.01\n\
             [[instances]]\nname = \"z\"\nfmu = \"testfmu.fmu\"\nparameters = {{ u = 0.0, k = -1.0 }}\n\
             [[instances]]\nname = \"s\"\nfmu = \"testfmu.fmu\"\n"
        );
        let p = write_system(d.path(), "zero.toml", &text);
        let m = run_memory(&p);
        assert_eq!(
            bits(m.column("z.y2").unwrap()),
            vec![(-0.0f64).to_bits(); 6]
        );
        assert_eq!(
            bits(m.column("s.y2").unwrap()),
            vec![expected.to_bits(); 6],
            "{connections}"
        );
    }
}
