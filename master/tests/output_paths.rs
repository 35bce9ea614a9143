//! Output paths cannot be turned against their user (issue 38, items 1 and 2): a campaign's
//! name is one folder name under `results/`, and every output follows one rule
//! (master/src/output_path.rs): a regular file is replaced, a symbolic link to one is followed,
//! anything else is refused before anything is written.
mod common;

use common::*;
use shipsim::campaign::CampaignSpec;
use std::os::unix::fs::FileTypeExt;
use std::path::{Path, PathBuf};
use std::process::Command;

fn mkfifo(path: &Path) {
    let c = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
}

fn is_fifo(path: &Path) -> bool {
    std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_fifo())
}

/// systems/rrs.toml pointing at $SHIPSIM_FMU_DIR, in `dir`.
fn rrs_file(dir: &Path) -> PathBuf {
    let text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../systems/rrs.toml"))
            .unwrap();
    let fmu_dir = our_fmu("RrsShip").parent().unwrap().to_path_buf();
    let text = text.replace("../target/fmu/", &format!("{}/", fmu_dir.display()));
    write_system(dir, "rrs.toml", &text)
}

/// `shipsim ARGS` in `dir`, killed after 60 s (a write into a FIFO would block forever):
/// (success, stderr).
fn shipsim(dir: &Path, args: &[&str]) -> (bool, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_shipsim"))
        .current_dir(dir)
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let out = child.wait_with_output().unwrap();
            return (
                status.success(),
                String::from_utf8_lossy(&out.stderr).into_owned(),
            );
        }
        if start.elapsed() > std::time::Duration::from_secs(60) {
            let _ = child.kill();
            panic!("shipsim {args:?} did not end in 60 s");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
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
    let (ok, err) = shipsim(&work, &["campaign", "run", "c.toml", "-q"]);
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
    let (ok, err) = shipsim(
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
        let (ok, err) = shipsim(d.path(), args);
        assert!(!ok, "{args:?} succeeded");
        assert!(
            err.contains("is a FIFO (named pipe); an output must be a regular file"),
            "{args:?}: {err}"
        );
        assert!(is_fifo(&fifo), "{args:?} replaced the FIFO");
    }
    let (ok, err) = shipsim(d.path(), &["run", sys, "--stop-time", "1", "-q", "-o", "."]);
    assert!(!ok && err.contains("is a directory"), "{err}");
}
