//! Every system, campaign and model-description file is read with a bound (issue 19, defect
//! 7): `/dev/zero` as a system file grew to 6.5 GB before; a file larger than the limit is
//! refused, naming the file and the limit, and a device, FIFO or socket is refused before it is
//! opened (issue 38, item 11: a FIFO blocked `open` forever). The binary runs with a 4 GB address-space limit, so the old
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
                "/dev/zero: cannot read the system file: it is a device, not a regular file"
            ),
            "{cmd}: {err}"
        );
    }
    // The OSP reader is chosen by the extension; a link named .xml to /dev/zero.
    std::os::unix::fs::symlink("/dev/zero", s.path().join("OspSystemStructure.xml")).unwrap();
    let (code, err) = s.run(&["run", "OspSystemStructure.xml"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("it is a device, not a regular file"), "{err}");
    // A regular file over the limit (sparse: 65 MiB of zeros) is refused after 64 MiB + 1 bytes.
    let big = std::fs::File::create(s.path().join("big.toml")).unwrap();
    big.set_len(65 << 20).unwrap();
    let (code, err) = s.run(&["check", "big.toml"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains(
            "big.toml: cannot read the system file: it is larger than 64 MiB, the most shipsim reads"
        ),
        "{err}"
    );
}

/// A FIFO as a system, campaign or FMU file is refused before it is opened (opening one blocks
/// until a writer comes: `timeout 3 shipsim check fifo` took 13 s and a SIGKILL).
#[test]
fn fifos_are_refused_before_they_block() {
    let s = Sandbox::new();
    let fifo = s.path().join("fifo.toml");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    for (args, what) in [
        (&["check", "fifo.toml"][..], "cannot read the system file"),
        (
            &["campaign", "run", "fifo.toml"][..],
            "cannot read the campaign file",
        ),
        (
            &["inspect", "fifo.toml"][..],
            "is a FIFO (named pipe); an FMU is a zip archive",
        ),
    ] {
        let (code, err) = s.run(args);
        assert_eq!(code, Some(1), "{args:?}: {err}");
        assert!(
            err.contains(what) && err.contains("FIFO (named pipe)"),
            "{args:?}: {err}"
        );
    }
}

#[test]
fn endless_campaign_file_is_refused() {
    let s = Sandbox::new();
    std::os::unix::fs::symlink("/dev/zero", s.path().join("c.toml")).unwrap();
    let (code, err) = s.run(&["campaign", "run", "c.toml"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("c.toml: cannot read the campaign file: it is a device, not a regular file"),
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

/// A checkpoint to resume from is read with a bound (1 GiB): `/dev/zero` as one is refused at
/// once, naming the file. Before, it was read whole (`std::fs::read`) until the allocation
/// failed under the 4 GB limit and the process aborted.
#[test]
fn endless_checkpoint_is_refused() {
    let s = Sandbox::new();
    testfmu_with(s.path(), "t.fmu", vec![]);
    std::fs::write(
        s.path().join("s.toml"),
        system("t.fmu", "a", "1.0", "0.1", ""),
    )
    .unwrap();
    std::os::unix::fs::symlink("/dev/zero", s.path().join("cp.bin")).unwrap();
    let (code, err) = s.run(&["run", "s.toml", "--resume", "cp.bin", "-o", "out.csv"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("checkpoint file cp.bin: cannot read it: it is a device, not a regular file"),
        "{err}"
    );
    assert!(s.leftovers().is_empty(), "{:?}", s.leftovers());
}

/// An OSP model description (variable groups) is read with the system-file bound, and the
/// FMU's modelDescription.xml for its model name with the model-description bound.
#[test]
fn endless_osp_model_description_is_refused() {
    let s = Sandbox::new();
    testfmu_with(s.path(), "testfmu.fmu", vec![]);
    // A sparse 5 GiB regular file (a link to /dev/zero is not a file, and is not looked for):
    // read whole before, which failed under the 4 GB limit.
    std::fs::File::create(s.path().join("testfmu_OspModelDescription.xml"))
        .unwrap()
        .set_len(5 << 30)
        .unwrap();
    let osp = r#"<?xml version="1.0" encoding="utf-8"?>
<OspSystemStructure xmlns="http://opensimulationplatform.com/MSMI/OSPSystemStructure" version="0.1">
    <StartTime>0.0</StartTime>
    <EndTime>0.1</EndTime>
    <BaseStepSize>0.01</BaseStepSize>
    <Simulators>
        <Simulator name="a" source="testfmu.fmu"/>
        <Simulator name="b" source="testfmu.fmu"/>
    </Simulators>
    <Connections>
        <VariableGroupConnection>
            <VariableGroup simulator="a" name="g"/>
            <VariableGroup simulator="b" name="g"/>
        </VariableGroupConnection>
    </Connections>
</OspSystemStructure>
"#;
    std::fs::write(s.path().join("OspSystemStructure.xml"), osp).unwrap();
    let (code, err) = s.run(&["check", "OspSystemStructure.xml"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains(
            "testfmu_OspModelDescription.xml: cannot read the OSP model description: it is larger than 64 MiB"
        ),
        "{err}"
    );
}
