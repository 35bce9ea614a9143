//! The CSV of `shipsim run` (issue 19, defects 4 and 9): names with a comma, a quote or a
//! line break are quoted as RFC 4180 says (a comma in an instance name gave a header of more
//! fields than the rows), rows reach the file at least once a second (a killed process lost
//! every buffered row), and `-o` never overwrites the system file or an FMU.
mod common;
mod hardening;

use hardening::*;

/// Header fields are quoted where needed and nowhere else; every row has as many fields as
/// the header (read back with the `csv` crate).
#[test]
fn names_with_commas_and_quotes_are_quoted() {
    let s = Sandbox::new();
    common::test_fmu(s.path());
    let text = "[simulation]\nstop_time = 0.3\nstep_size = 0.1\n\n[[instances]]\nname = \"a,b\"\nfmu = \"testfmu.fmu\"\n\n[[instances]]\nname = 'q\"x'\nfmu = \"testfmu.fmu\"\n\n[[instances]]\nname = \"plain\"\nfmu = \"testfmu.fmu\"\n\n[output]\nvariables = [\"a,b.y\", 'q\"x.steps', \"plain.y\"]\n";
    std::fs::write(s.path().join("q.toml"), text).unwrap();
    let (code, err) = s.run(&["run", "q.toml", "-q", "-o", "q.csv"]);
    assert_eq!(code, Some(0), "{err}");
    let csv = std::fs::read_to_string(s.path().join("q.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert_eq!(header, "time,\"a,b.y\",\"q\"\"x.steps\",plain.y");
    let mut r = csv::Reader::from_reader(csv.as_bytes());
    let names: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    assert_eq!(names, ["time", "a,b.y", "q\"x.steps", "plain.y"]);
    let rows: Vec<csv::StringRecord> = r.records().map(Result::unwrap).collect();
    assert_eq!(rows.len(), 4);
    assert_eq!(
        rows.iter().map(|r| r[0].to_string()).collect::<Vec<_>>(),
        ["0", "0.1", "0.2", "0.3"]
    );
    assert!(rows.iter().all(|r| r.len() == 4));
    assert_eq!(&rows[3][2], "3", "steps of q\"x after three steps");
}

/// A process killed with SIGKILL keeps the rows of all but about the last second: with rows
/// coming slowly (one per 10^7 macro steps, a few a second, so that the 64 kB buffer would
/// take minutes to fill), the CSV has the header and rows while the run is still going. The
/// old recorder wrote nothing until its buffer filled (the wait below gives up after 120 s).
#[test]
fn rows_reach_the_file_while_the_run_goes_on() {
    let s = Sandbox::new();
    common::test_fmu(s.path());
    let text = system("testfmu.fmu", "a", "1e9", "0.001", "")
        .replace("[output]\n", "[output]\ndecimation = 10000000\n");
    std::fs::write(s.path().join("slow.toml"), text).unwrap();
    let mut child = s.spawn(
        &["run", "slow.toml", "-q", "-o", "slow.csv"],
        std::process::Stdio::null(),
    );
    let out = s.path().join("slow.csv");
    let lines = || {
        std::fs::read_to_string(&out)
            .map(|t| t.matches('\n').count())
            .unwrap_or(0)
    };
    s.wait_for("the header and three rows in slow.csv", || lines() >= 4);
    signal(&child, libc::SIGKILL);
    child.wait().unwrap();
    let text = std::fs::read_to_string(&out).unwrap();
    let mut it = text.lines();
    assert_eq!(
        it.next(),
        Some("time,a.y,a.t_last,a.grid_error,a.y2,a.steps,a.n_out,a.enabled_out")
    );
    assert_eq!(it.next().unwrap().split(',').next(), Some("0"));
    assert_eq!(it.next().unwrap().split(',').next(), Some("10000"));
}

/// `-o` naming the system file or an input FMU (also through another path or a hard link)
/// is refused with both named, and the file is left as it was.
#[test]
fn output_never_overwrites_an_input() {
    let s = Sandbox::new();
    let fmu = common::test_fmu(s.path());
    std::fs::write(
        s.path().join("sys.toml"),
        system("testfmu.fmu", "a", "1", "0.1", ""),
    )
    .unwrap();
    std::fs::hard_link(&fmu, s.path().join("link.fmu")).unwrap();
    let before = (
        std::fs::read(s.path().join("sys.toml")).unwrap(),
        std::fs::read(&fmu).unwrap(),
    );
    for (out, expect) in [
        (
            "sys.toml",
            "the output file sys.toml is the system file sys.toml; refusing to overwrite it",
        ),
        (
            "./sys.toml",
            "the output file ./sys.toml is the system file sys.toml",
        ),
        (
            "testfmu.fmu",
            "the output file testfmu.fmu is the FMU testfmu.fmu of instance 'a'",
        ),
        (
            "link.fmu",
            "the output file link.fmu is the FMU testfmu.fmu of instance 'a'",
        ),
    ] {
        let (code, err) = s.run(&["run", "sys.toml", "-q", "-o", out]);
        assert_eq!(code, Some(1), "{out}: {err}");
        assert!(err.contains(expect), "{out}: {err}");
    }
    assert_eq!(std::fs::read(s.path().join("sys.toml")).unwrap(), before.0);
    assert_eq!(std::fs::read(&fmu).unwrap(), before.1);
    let (code, err) = s.run(&["run", "sys.toml", "-q", "-o", "fine.csv"]);
    assert_eq!(code, Some(0), "{err}");
}
