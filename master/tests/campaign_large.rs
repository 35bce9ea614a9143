//! Campaigns of many runs (issue 38, item 8): runs are made from their index when needed, so
//! showing or counting a campaign of the largest size allowed takes little memory, and a larger
//! one is refused, naming the file and the count, before anything is allocated for its runs.

mod common;

use shipsim::campaign::Campaign;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The address space `shipsim campaign show` gets in these tests: 1 GiB (the code before lazy
/// runs needed 1 GB of memory for 10^6 runs and asked for 12.8 GB at once for 10^8).
const LIMIT: &str = "--as=1073741824";

/// `dir/NAME.toml`: a campaign of the C test FMU (in `dir`) with factors `a` and `b` (TOML
/// values), `reps` replications and two arms.
fn campaign(dir: &Path, name: &str, a: &str, b: &str, reps: u32) -> PathBuf {
    if !dir.join("testfmu.fmu").exists() {
        common::tiny_system(dir);
    }
    common::write_system(
        dir,
        &format!("{name}.toml"),
        &format!(
            "system = \"sys.toml\"\n\
             [[factors]]\nname = \"a\"\nvariable = \"m.k\"\n{a}\n\
             [[factors]]\nname = \"b\"\nvariable = \"m.u\"\n{b}\n\
             [replications]\ncount = {reps}\nseeds = [\"m.s1\"]\n\
             [[arms]]\nname = \"off\"\nset = {{ \"m.s2\" = 0 }}\n\
             [[arms]]\nname = \"on\"\nset = {{ \"m.s2\" = 1 }}\n\
             [[kpis]]\nname = \"y_mean\"\nvariable = \"m.y\"\nstat = \"mean\"\n"
        ),
    )
}

/// `shipsim campaign show FILE` in `dir` within [`LIMIT`] and 60 s: (success, stdout, stderr).
fn show_limited(dir: &Path, file: &Path) -> (bool, String, String) {
    let out = Command::new("timeout")
        .args(["60", "prlimit", LIMIT])
        .arg(env!("CARGO_BIN_EXE_shipsim"))
        .args(["campaign", "show"])
        .arg(file)
        .current_dir(dir)
        .output()
        .expect("timeout and prlimit (util-linux) run shipsim");
    let text = |b: Vec<u8>| String::from_utf8_lossy(&b).into_owned();
    (out.status.success(), text(out.stdout), text(out.stderr))
}

#[test]
fn a_campaign_of_the_largest_size_allowed_is_shown_in_little_memory() {
    let dir = tempfile::tempdir().unwrap();
    // 1000 x 100 points x 50 replications x 2 arms = 10^7 runs
    let file = campaign(
        dir.path(),
        "c7",
        "range = [1, 1000, 1]",
        "range = [1, 100, 1]",
        50,
    );
    let (ok, stdout, stderr) = show_limited(dir.path(), &file);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("10000000 runs"), "{stdout}");
    // the last run, made from its index: point 99,999 (a = 1000, b = 100), replication 49, on
    let c = Campaign::load(&file).unwrap();
    assert_eq!(c.runs.len(), 10_000_000);
    let last = c.runs.run(9_999_999);
    assert_eq!((last.point, last.replication, last.arm), (99_999, 49, 1));
    assert_eq!(last.factors, vec![1000.0, 100.0]);
    assert_eq!(c.runs.get(10_000_000), None);
}

#[test]
fn a_larger_campaign_is_refused_naming_the_file_and_the_count_before_it_allocates() {
    let dir = tempfile::tempdir().unwrap();
    let range = "range = [1, 1000, 1]";
    let cases = [
        (
            campaign(dir.path(), "c8", range, range, 50),
            "c8.toml: 100000000 runs (1000000 points × 50 replications × 2 arms), more than \
             the 10000000 a campaign may have",
        ),
        (
            campaign(dir.path(), "p8", range, "range = [1, 100000, 1]", 1),
            "p8.toml: 100000000 design points (1000 × 100000 levels crossed), more than the \
             10000000",
        ),
        (
            campaign(dir.path(), "p12", "linspace = [0, 1, 1000000]", range, 1),
            "p12.toml: 1000000000 design points (1000000 × 1000 levels crossed)",
        ),
    ];
    for (file, message) in cases {
        let (ok, _, stderr) = show_limited(dir.path(), &file);
        assert!(!ok);
        assert!(stderr.contains(message), "{stderr}");
        assert!(!stderr.contains("memory allocation"), "{stderr}");
    }
}

#[test]
fn runs_that_set_the_same_values_are_found_without_making_every_run() {
    let dir = tempfile::tempdir().unwrap();
    // 10^5 x 3 points x 10 replications x 2 arms = 6 x 10^6 runs; b's levels 0 and 2 are
    // equal, so points 0 and 2 (runs 0 and 2 x 10 x 2 = 40) set the same values
    let file = campaign(
        dir.path(),
        "same",
        "range = [1, 100000, 1]",
        "values = [1, 2, 1]",
        10,
    );
    let (ok, _, stderr) = show_limited(dir.path(), &file);
    assert!(!ok);
    assert!(
        stderr.contains("same.toml: runs 0 and 40 set the same values"),
        "{stderr}"
    );
}
