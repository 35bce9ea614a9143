//! Output paths cannot be turned against their user (issue 38, items 1 and 2): a campaign's
//! name is one folder name under `results/`, and every output follows one rule
//! (master/src/output_path.rs): a regular file is replaced, a symbolic link to one is followed,
//! anything else is refused before anything is written.
mod common;

use common::*;
use shipsim::campaign::CampaignSpec;
use std::os::unix::fs::FileTypeExt;
use std::path::Path;

fn mkfifo(path: &Path) {
    let c = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
}

fn is_fifo(path: &Path) -> bool {
    std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_fifo())
}

const CAMPAIGN: &str = r#"system = "sys.toml"
[[factors]]
variable = "m.k"
values = [1, 2]
"#;

#[test]
fn a_campaign_name_is_one_folder_name() {
    let d = tempfile::tempdir().unwrap();
    for (name, why) in [
        ("../../escape", "contains a path separator"),
        ("/tmp/absolute", "contains a path separator"),
        ("a\\\\b", "contains a path separator"),
        ("..", "is a relative folder, not a name"),
        ("", "is empty"),
        ("tab\\there", "contains a control character"),
    ] {
        let p = d.path().join("c.toml");
        std::fs::write(&p, format!("name = \"{name}\"\n{CAMPAIGN}")).unwrap();
        let e = CampaignSpec::load(&p).unwrap_err().to_string();
        assert!(e.contains("c.toml:1:") && e.contains(why), "{name}: {e}");
        assert!(e.contains("must be one folder name"), "{e}");
    }
    let p = d.path().join("c.toml");
    std::fs::write(&p, format!("name = \"rrs polar, v2\"\n{CAMPAIGN}")).unwrap();
    assert_eq!(CampaignSpec::load(&p).unwrap().name, "rrs polar, v2");
}

#[test]
fn campaign_run_writes_nothing_outside_results_for_a_hostile_name() {
    let d = tempfile::tempdir().unwrap();
    let work = d.path().join("a/b");
    std::fs::create_dir_all(&work).unwrap();
    std::fs::write(
        work.join("c.toml"),
        format!("name = \"../../..\"\n{CAMPAIGN}"),
    )
    .unwrap();
    let (ok, err) = shipsim_in(&work, &["campaign", "run", "c.toml", "-q"]);
    assert!(!ok && err.contains("must be one folder name"), "{err}");
    for stale in ["runs.csv", "runs.jsonl", "campaign.json"] {
        assert!(!d.path().join(stale).exists(), "{stale} written");
    }
    assert!(!work.join("results").exists());
}

#[test]
fn a_checkpoint_through_a_symbolic_link_writes_its_target_and_keeps_the_link() {
    let d = tempfile::tempdir().unwrap();
    let sys = rrs_file(d.path());
    let target = d.path().join("kept/cp.bin");
    std::fs::create_dir_all(target.parent().unwrap()).unwrap();
    std::fs::write(&target, "old").unwrap();
    let link = d.path().join("cp-link.bin");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let (ok, err) = shipsim_in(
        d.path(),
        &[
            "run",
            sys.to_str().unwrap(),
            "--stop-time",
            "20",
            "-q",
            "--no-output",
            "--checkpoint-at",
            "10",
            link.to_str().unwrap(),
        ],
    );
    assert!(ok, "{err}");
    let meta = std::fs::symlink_metadata(&link).unwrap();
    assert!(meta.file_type().is_symlink(), "the link was replaced");
    assert!(shipsim::run::Checkpoint::read(&target).is_ok());
}

#[test]
fn outputs_that_are_not_regular_files_are_refused_and_left_alone() {
    let d = tempfile::tempdir().unwrap();
    let sys = rrs_file(d.path());
    let fifo = d.path().join("fifo");
    mkfifo(&fifo);
    let sys = sys.to_str().unwrap();
    let f = fifo.to_str().unwrap();
    let cases: [&[&str]; 4] = [
        &["run", sys, "--stop-time", "1", "-q", "-o", f],
        &[
            "run",
            sys,
            "--stop-time",
            "20",
            "-q",
            "--no-output",
            "--checkpoint-at",
            "10",
            f,
        ],
        &["export-ssp", sys, "-o", f],
        &["export-osp", sys, "-o", f],
    ];
    for args in cases {
        let (ok, err) = shipsim_in(d.path(), args);
        assert!(!ok, "{args:?} succeeded");
        assert!(
            err.contains("is a FIFO (named pipe); an output must be a regular file"),
            "{args:?}: {err}"
        );
        assert!(is_fifo(&fifo), "{args:?} replaced the FIFO");
    }
    let (ok, err) = shipsim_in(d.path(), &["run", sys, "--stop-time", "1", "-q", "-o", "."]);
    assert!(!ok && err.contains("is a directory"), "{err}");
}
