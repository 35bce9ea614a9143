//! Every system, campaign and model-description file is read with a bound (issue 19, defect
//! 7): `/dev/zero` as a system file grew to 6.5 GB before; now it is refused at once, naming
//! the file and the limit. The binary runs with a 4 GB address-space limit, so the old
//! unbounded read fails instead of filling the machine.
mod common;
mod hardening;

use hardening::*;

#[test]
fn endless_system_file_is_refused() {
    let s = Sandbox::new();
    for cmd in ["run", "check", "export-osp"] {
        let (code, err) = s.run(&[cmd, "/dev/zero"]);
        assert_eq!(code, Some(1), "{cmd}: {err}");
        assert!(
            err.contains(
                "/dev/zero: cannot read the system file: it is larger than 64 MiB, the most shipsim reads"
            ),
            "{cmd}: {err}"
        );
    }
    // The OSP reader is chosen by the extension; a link named .xml to /dev/zero.
    std::os::unix::fs::symlink("/dev/zero", s.path().join("OspSystemStructure.xml")).unwrap();
    let (code, err) = s.run(&["run", "OspSystemStructure.xml"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("it is larger than 64 MiB"), "{err}");
}

#[test]
fn endless_campaign_file_is_refused() {
    let s = Sandbox::new();
    std::os::unix::fs::symlink("/dev/zero", s.path().join("c.toml")).unwrap();
    let (code, err) = s.run(&["campaign", "run", "c.toml"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("c.toml: cannot read the campaign file: it is larger than 64 MiB"),
        "{err}"
    );
}

/// A system file that is a directory says so.
#[test]
fn directory_as_system_file() {
    let s = Sandbox::new();
    let (code, err) = s.run(&["run", "."]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains(".: cannot read the system file"), "{err}");
}
