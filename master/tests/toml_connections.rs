//! The string form of connections in the native TOML (issue 18, friction point 9): gain, offset
//! and convert in the string, strings and inline tables in one list, and errors that name TOML's
//! own rules when the list comes after a table or next to [[connections]] tables.

use shipsim::format::toml;
use shipsim::system::{ConnectionSpec, System};
use std::path::Path;

const TAIL: &str = "[simulation]\nstop_time = 1.0\nstep_size = 0.25\n\
[[instances]]\nname = \"a\"\nfmu = \"t.fmu\"\n[[instances]]\nname = \"b\"\nfmu = \"t.fmu\"\n";

fn parse(text: &str) -> shipsim::Result<System> {
    toml::parse(Path::new("/sys/c.toml"), text)
}

fn ends(c: &ConnectionSpec) -> (String, String, f64, f64, bool) {
    (
        c.from.to_string(),
        c.to.to_string(),
        c.gain,
        c.offset,
        c.convert,
    )
}

#[test]
fn string_form_carries_gain_offset_and_convert() {
    let text = format!(
        "connections = [\n\
         \"a.y -> b.u\",\n\
         \"a.y -> b.u, gain = 2.5\",\n\
         \"a.y->b.u,offset=-0.5,gain=1e-3\",\n\
         \"a.y -> b.u, gain = 0.0174532925199433, convert\",\n\
         \"a.y -> b.u, convert = false\",\n\
         {{ from = \"a.t_last\", to = \"b.k\", gain = 3.0, convert = true }},\n\
         ]\n{TAIL}"
    );
    let sys = parse(&text).unwrap();
    let got: Vec<_> = sys.connections.iter().map(ends).collect();
    let s = |x: &str| x.to_string();
    assert_eq!(
        got,
        vec![
            (s("a.y"), s("b.u"), 1.0, 0.0, false),
            (s("a.y"), s("b.u"), 2.5, 0.0, false),
            (s("a.y"), s("b.u"), 1e-3, -0.5, false),
            (s("a.y"), s("b.u"), 0.0174532925199433, 0.0, true),
            (s("a.y"), s("b.u"), 1.0, 0.0, false),
            (s("a.t_last"), s("b.k"), 3.0, 0.0, true),
        ]
    );
    // Each entry keeps its own line.
    let lines: Vec<_> = sys.connections.iter().map(|c| c.line).collect();
    assert_eq!(
        lines,
        [Some(2), Some(3), Some(4), Some(5), Some(6), Some(7)]
    );
}

#[test]
fn malformed_string_connections_are_errors_with_their_lines() {
    let cases = [
        (
            "a.y => b.u",
            "must read \"instance.output -> instance.input\"",
        ),
        ("a.y -> b.u, gain = two", "gain must be a number"),
        ("a.y -> b.u, gain = 2, gain = 3", "gain is given twice"),
        ("a.y -> b.u, scale = 2", "unknown key 'scale'"),
        ("a.y -> b.u, convert = yes", "convert is true or false"),
        ("a.y -> b.u, offset = inf", "offset must be a number"),
    ];
    for (conn, want) in cases {
        let text = format!("connections = [\n\"{conn}\"]\n{TAIL}");
        let err = parse(&text).err().unwrap().to_string();
        assert!(err.contains("/sys/c.toml:2"), "{conn}: {err}");
        assert!(err.contains(want), "{conn}: {err}");
    }
}

#[test]
fn list_after_a_table_names_the_toml_rule() {
    let text = format!("{TAIL}connections = [\"a.y -> b.u\"]\n");
    let err = parse(&text).err().unwrap().to_string();
    assert!(err.contains("/sys/c.toml:10"), "{err}");
    assert!(
        err.contains("is read as a key of the table [[instances]] above it"),
        "{err}"
    );
    assert!(
        err.contains("top-level keys must come before the first table"),
        "{err}"
    );
}

#[test]
fn list_and_tables_in_one_file_name_the_toml_rule() {
    let text = format!(
        "connections = [\"a.y -> b.u\"]\n{TAIL}[[connections]]\nfrom = \"a.y\"\nto = \"b.u\"\n"
    );
    let err = parse(&text).err().unwrap().to_string();
    assert!(err.contains("/sys/c.toml:11"), "{err}");
    assert!(
        err.contains("TOML allows only one of the two for a key"),
        "{err}"
    );
    // The way out the message gives parses.
    let fixed =
        format!("connections = [\"a.y -> b.u\", {{ from = \"a.y\", to = \"b.u\" }}]\n{TAIL}");
    assert_eq!(parse(&fixed).unwrap().connections.len(), 2);
}

#[test]
fn tables_alone_still_parse() {
    let text = format!("{TAIL}[[connections]]\nfrom = \"a.y\"\nto = \"b.u\"\ngain = 2.0\n");
    let sys = parse(&text).unwrap();
    assert_eq!(
        ends(&sys.connections[0]),
        ("a.y".into(), "b.u".into(), 2.0, 0.0, false)
    );
}
