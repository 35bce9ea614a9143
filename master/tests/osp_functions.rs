//! OSP functions and variable groups in `OspSystemStructure.xml` (issue 17): `Sum`,
//! `LinearTransformation` and `VectorSum` with their `SignalConnection`s and
//! `SignalGroupConnection`s, and `VariableGroupConnection`s of groups declared in the model's
//! `OspModelDescription.xml` (OSP Interface Specification), read as libcosim reads them, with
//! errors that name the file, the function and the signal or group.
//!
//! The test FMU (tests/c/testfmu.c) has the feed-through y2 = k*u (k = 1 here), so an instance
//! shows in y2 exactly the value its input u was set to. Every comparison is exact (bits).
mod common;
use common::*;
use shipsim::system::System;
use std::path::Path;

/// Sources a, b, c (y2 = u = 0.1, 0.2, 0.3) and sinks s, e; `functions` and `connections` as
/// given.
fn osp(functions: &str, connections: &str) -> String {
    let sim = |name: &str, u: Option<f64>| {
        match u {
        Some(u) => format!(
            "<Simulator name=\"{name}\" source=\"testfmu.fmu\"><InitialValues><InitialValue variable=\"u\"><Real value=\"{u}\"/></InitialValue></InitialValues></Simulator>"
        ),
        None => format!("<Simulator name=\"{name}\" source=\"testfmu.fmu\"/>"),
    }
    };
    format!(
        r#"<?xml version="1.0" encoding="utf-8"?>
<OspSystemStructure xmlns="http://opensimulationplatform.com/MSMI/OSPSystemStructure" version="0.1">
    <StartTime>0.0</StartTime>
    <EndTime>0.1</EndTime>
    <BaseStepSize>0.01</BaseStepSize>
    <Simulators>
        {}
        {}
        {}
        {}
        {}
    </Simulators>
    <Functions>
{functions}
    </Functions>
    <Connections>
{connections}
    </Connections>
</OspSystemStructure>
"#,
        sim("a", Some(0.1)),
        sim("b", Some(0.2)),
        sim("c", Some(0.3)),
        sim("s", None),
        sim("e", None),
    )
}

fn signal(sim: &str, var: &str, function: &str, name: &str) -> String {
    format!(
        "<SignalConnection><Variable simulator=\"{sim}\" name=\"{var}\"/><Signal function=\"{function}\" name=\"{name}\"/></SignalConnection>"
    )
}

fn signal_group(sim: &str, group: &str, function: &str, name: &str) -> String {
    format!(
        "<SignalGroupConnection><SignalGroup function=\"{function}\" name=\"{name}\"/><VariableGroup simulator=\"{sim}\" name=\"{group}\"/></SignalGroupConnection>"
    )
}

/// The test FMU's variable groups, as an OSP tool writes them beside the FMU.
const GROUPS: &str = r#"<?xml version="1.0" encoding="utf-8"?>
<OspModelDescription xmlns="https://opensimulationplatform.com/xsd/OspModelDescription-1.0.0" version="1.0">
  <UnitDefinitions><Unit name="m"><BaseUnit m="1"/></Unit></UnitDefinitions>
  <VariableGroups>
    <Generic name="vin"><Variable ref="u" unit="m"/></Generic>
    <Generic name="vout"><Variable ref="y2"/></Generic>
    <LinearMechanicalPort name="port_out">
      <Force name="force_out"><Variable ref="y"/></Force>
      <LinearVelocity name="velocity_in"><Variable ref="u"/></LinearVelocity>
    </LinearMechanicalPort>
    <LinearMechanicalPort name="port_in">
      <Force name="force_in"><Variable ref="u"/></Force>
      <LinearVelocity name="velocity_out"><Variable ref="y"/></LinearVelocity>
    </LinearMechanicalPort>
    <Generic name="two"><Variable ref="y"/><Variable ref="y2"/></Generic>
  </VariableGroups>
</OspModelDescription>
"#;

/// A folder with the test FMU, its variable groups and `OspSystemStructure.xml` = `text`.
fn setup(text: &str) -> (tempfile::TempDir, std::path::PathBuf) {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    std::fs::write(d.path().join("testfmu_OspModelDescription.xml"), GROUPS).unwrap();
    let p = write_system(d.path(), "OspSystemStructure.xml", text);
    (d, p)
}

fn error_of(path: &Path) -> String {
    match load_plan(path) {
        Ok(_) => panic!("{} loads", path.display()),
        Err(e) => e.to_string(),
    }
}

/// A Sum of a, b, c in the index order `order` (as sources of in[0], in[1], in[2]), its signal
/// connections written in reverse document order (the index decides, not the document).
fn sum_of(order: [&str; 3]) -> String {
    let mut conns: Vec<String> = order
        .iter()
        .enumerate()
        .map(|(i, s)| signal(s, "y2", "total", &format!("in[{i}]")))
        .collect();
    conns.reverse();
    conns.push(
        "<SignalConnection><Signal function=\"total\" name=\"out\"/><Variable simulator=\"s\" name=\"u\"/></SignalConnection>".into(),
    );
    osp("<Sum name=\"total\" inputCount=\"3\"/>", &conns.join("\n"))
}

#[test]
fn sum_adds_its_inputs_in_index_order() {
    let forward: f64 = (0.1 + 0.2) + 0.3;
    let backward: f64 = (0.3 + 0.2) + 0.1;
    assert_ne!(forward.to_bits(), backward.to_bits());
    for (order, expected) in [(["a", "b", "c"], forward), (["c", "b", "a"], backward)] {
        let (_d, p) = setup(&sum_of(order));
        let m = run_memory(&p);
        assert_eq!(
            bits(m.column("s.y2").unwrap()),
            vec![expected.to_bits(); 11],
            "{order:?}"
        );
    }
}

#[test]
fn linear_transformation_beside_a_sum() {
    let functions = "<LinearTransformation name=\"lt\" factor=\"2.0\" offset=\"0.5\"/>\n<Sum name=\"total\" inputCount=\"3\"/>";
    let mut conns = vec![
        signal("a", "y2", "lt", "in"),
        "<SignalConnection><Signal function=\"lt\" name=\"out\"/><Variable simulator=\"e\" name=\"u\"/></SignalConnection>".to_string(),
    ];
    for (i, s) in ["a", "b", "c"].iter().enumerate() {
        conns.push(signal(s, "y2", "total", &format!("in[{i}]")));
    }
    conns.push(signal("s", "u", "total", "out"));
    let (_d, p) = setup(&osp(functions, &conns.join("\n")));
    let m = run_memory(&p);
    let lt: f64 = 2.0 * 0.1 + 0.5;
    assert_eq!(bits(m.column("e.y2").unwrap()), vec![lt.to_bits(); 11]);
    let sum: f64 = (0.1 + 0.2) + 0.3;
    assert_eq!(bits(m.column("s.y2").unwrap()), vec![sum.to_bits(); 11]);
}

#[test]
fn vector_sum_adds_variable_groups_component_by_component() {
    let mut conns: Vec<String> = ["c", "a", "b"]
        .iter()
        .enumerate()
        .map(|(i, s)| signal_group(s, "vout", "vs", &format!("in[{i}]")))
        .collect();
    conns.push(signal_group("s", "vin", "vs", "out"));
    let text = osp(
        "<VectorSum name=\"vs\" inputCount=\"3\" dimension=\"1\"/>",
        &conns.join("\n"),
    );
    let (_d, p) = setup(&text);
    let m = run_memory(&p);
    let expected: f64 = (0.3 + 0.1) + 0.2;
    assert_eq!(
        bits(m.column("s.y2").unwrap()),
        vec![expected.to_bits(); 11]
    );
}

#[test]
fn variable_group_connection_connects_nested_groups_by_causality() {
    let conns = "<VariableGroupConnection><VariableGroup simulator=\"a\" name=\"port_out\"/><VariableGroup simulator=\"b\" name=\"port_in\"/></VariableGroupConnection>";
    let (_d, p) = setup(&osp("", conns));
    let (plan, _) = load_plan(&p).unwrap();
    let names: Vec<&str> = plan.connections.iter().map(|c| c.name.as_str()).collect();
    // Force: a.y -> b.u; LinearVelocity: b.y -> a.u (turned around: a.u is the input)
    assert_eq!(names, ["a.y -> b.u", "b.y -> a.u"]);
    // a nested group by its own name: Force to Force
    let conns = "<VariableGroupConnection><VariableGroup simulator=\"a\" name=\"force_out\"/><VariableGroup simulator=\"b\" name=\"force_in\"/></VariableGroupConnection>";
    let (_d, p) = setup(&osp("", conns));
    let (plan, _) = load_plan(&p).unwrap();
    assert_eq!(plan.connections.len(), 1);
    assert_eq!(plan.connections[0].name, "a.y -> b.u");
    // and the value flows: b.u (shown in b.y2) is a.y of the previous communication point
    let m = run_memory(&p);
    let (a_y, b_y2) = (m.column("a.y").unwrap(), m.column("b.y2").unwrap());
    assert!(a_y[10] > 0.0, "{a_y:?}");
    assert_eq!(bits(&b_y2[1..]), bits(&a_y[..10]));
}

#[test]
fn export_writes_the_sum_and_reads_back_to_the_same_run() {
    let (d, p) = setup(&sum_of(["c", "a", "b"]));
    let sys = System::load(&p).unwrap();
    let out = d.path().join("back/OspSystemStructure.xml");
    shipsim::format::osp::write(&sys, &out).unwrap();
    let xml = std::fs::read_to_string(&out).unwrap();
    assert!(
        xml.contains("<Sum name=\"sum0\" inputCount=\"3\"/>"),
        "{xml}"
    );
    let expected: f64 = (0.3 + 0.1) + 0.2;
    for m in [run_memory(&p), run_memory(&out)] {
        assert_eq!(
            bits(m.column("s.y2").unwrap()),
            vec![expected.to_bits(); 11]
        );
    }
}

#[test]
fn malformed_functions_and_groups_are_errors_naming_them() {
    let out = "<SignalConnection><Signal function=\"total\" name=\"out\"/><Variable simulator=\"s\" name=\"u\"/></SignalConnection>";
    let cases: Vec<(String, &str)> = vec![
        (
            osp(
                "<Sum name=\"total\" inputCount=\"3\"/>",
                &[signal("a", "y2", "total", "in[0]"), signal("b", "y2", "total", "in[1]"), out.into()].join("\n"),
            ),
            "function 'total': nothing is connected to its signal 'in[2]'",
        ),
        (
            osp(
                "<Sum name=\"total\" inputCount=\"2\"/>",
                &[signal("a", "y2", "total", "in[0]"), signal("b", "y2", "total", "in[1]"), signal("c", "y2", "total", "in[2]"), out.into()].join("\n"),
            ),
            "function 'total': unknown signal 'in[2]' (Sum has 'in[0]' to 'in[1]' and 'out')",
        ),
        (
            osp("<Sum name=\"total\" inputCount=\"1\"/>", &signal("a", "y2", "totl", "in[0]")),
            "SignalConnection refers to unknown function 'totl'",
        ),
        (
            osp("<VectorSum name=\"vs\" inputCount=\"1\" dimension=\"1\"/>", &signal("a", "y2", "vs", "in[0]")),
            "SignalConnection to VectorSum 'vs': a VectorSum is connected through SignalGroupConnection",
        ),
        (
            osp(
                "<VectorSum name=\"vs\" inputCount=\"1\" dimension=\"1\"/>",
                &[signal_group("a", "vot", "vs", "in[0]"), signal_group("s", "vin", "vs", "out")].join("\n"),
            ),
            "simulator 'a' has no top-level variable group 'vot'",
        ),
        (
            osp(
                "<VectorSum name=\"vs\" inputCount=\"1\" dimension=\"3\"/>",
                &[signal_group("a", "two", "vs", "in[0]"), signal_group("s", "vin", "vs", "out")].join("\n"),
            ),
            "VectorSum 'vs' has dimension 3, but variable group 'two' of simulator 'a' (signal 'in[0]') has 2 variable(s)",
        ),
        (
            osp("", "<VariableGroupConnection><VariableGroup simulator=\"a\" name=\"two\"/><VariableGroup simulator=\"b\" name=\"vin\"/></VariableGroupConnection>"),
            "VariableGroupConnection: group 'two' of simulator 'a' has 2 variables but group 'vin' of simulator 'b' has 1",
        ),
        (
            osp("", "<VariableConnection><Variable simulator=\"a\" name=\"y\"/><Variable simulator=\"s\" name=\"u\"/></VariableConnection>\n<VariableConnection><Variable simulator=\"b\" name=\"y\"/><Variable simulator=\"s\" name=\"u\"/></VariableConnection>"),
            "input 's.u' is driven twice: by b.y -> s.u and by a.y -> s.u (line 17); to add them, connect them through a Sum function",
        ),
    ];
    for (text, want) in cases {
        let (_d, p) = setup(&text);
        let e = error_of(&p);
        assert!(
            e.contains("OspSystemStructure.xml") && e.contains(want),
            "want {want:?} in:\n{e}"
        );
    }
}

#[test]
fn variable_groups_need_the_osp_model_description() {
    let conns = "<VariableGroupConnection><VariableGroup simulator=\"a\" name=\"port_out\"/><VariableGroup simulator=\"b\" name=\"port_in\"/></VariableGroupConnection>";
    let (d, p) = setup(&osp("", conns));
    std::fs::remove_file(d.path().join("testfmu_OspModelDescription.xml")).unwrap();
    let e = error_of(&p);
    assert!(
        e.contains("simulator 'a': variable groups need the model's <modelName>_OspModelDescription.xml beside its FMU"),
        "{e}"
    );
    // beside the system file instead of the FMU: found there (libcosim's second place)
    let sub = d.path().join("sys");
    std::fs::create_dir(&sub).unwrap();
    std::fs::write(sub.join("testfmu_OspModelDescription.xml"), GROUPS).unwrap();
    let text = osp("", conns).replace("source=\"testfmu.fmu\"", "source=\"../testfmu.fmu\"");
    let p = write_system(&sub, "OspSystemStructure.xml", &text);
    assert_eq!(load_plan(&p).unwrap().0.connections.len(), 2);
}

/// Export names each connected variable by value reference *and type*: the test FMU's Boolean
/// `enabled_out` (1) and input `enabled` (0) share their value references with the Real `y`
/// and `u`, and its Integer `n_out` (3) with the Real `t_last`. Before, the lookup ignored the
/// type and wrote `a.y -> b.u` for `a.enabled_out -> b.enabled`.
#[test]
fn export_names_connected_variables_by_value_reference_and_type() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    let p = write_system(
        d.path(),
        "sys.toml",
        r#"
connections = ["a.enabled_out -> b.enabled", "a.n_out -> b.n_in", "a.y -> b.u"]
[simulation]
stop_time = 0.1
step_size = 0.01
[[instances]]
name = "a"
fmu = "testfmu.fmu"
[[instances]]
name = "b"
fmu = "testfmu.fmu"
"#,
    );
    let sys = System::load(&p).unwrap();
    let out = d.path().join("OspSystemStructure.xml");
    shipsim::format::osp::write(&sys, &out).unwrap();
    let xml = std::fs::read_to_string(&out).unwrap();
    for (from, to) in [("enabled_out", "enabled"), ("n_out", "n_in"), ("y", "u")] {
        let connection = format!(
            "<Variable simulator=\"a\" name=\"{from}\" causality=\"output\"/>\n            \
             <Variable simulator=\"b\" name=\"{to}\" causality=\"input\"/>"
        );
        assert!(xml.contains(&connection), "{connection} not in\n{xml}");
    }
    // The file reads back into the same three connections.
    let back = System::load(&out).unwrap();
    let mut names: Vec<String> = back
        .connections
        .iter()
        .map(|c| format!("{} -> {}", c.from, c.to))
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "a.enabled_out -> b.enabled",
            "a.n_out -> b.n_in",
            "a.y -> b.u"
        ]
    );
}
