//! Where the exports write without `-o` (issue 36, item 6): into the current folder, named
//! after the system, never beside the system file (which may lie in the source tree: the
//! README's `export-osp systems/rrs.toml` wrote into systems/).
mod common;
use common::*;

#[test]
fn exports_without_o_write_into_the_current_folder() {
    let src = tempfile::tempdir().unwrap();
    let cwd = tempfile::tempdir().unwrap();
    let sys = rrs_file(src.path());
    let sys = sys.to_str().unwrap();
    let (ok, err) = shipsim_in(cwd.path(), &["export-osp", sys]);
    assert!(ok, "{err}");
    assert!(err.contains("wrote rrs/OspSystemStructure.xml"), "{err}");
    let (ok, err) = shipsim_in(cwd.path(), &["export-ssp", sys]);
    assert!(ok, "{err}");
    assert!(err.contains("wrote rrs.ssp"), "{err}");
    let beside: Vec<_> = std::fs::read_dir(src.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert_eq!(
        beside,
        ["rrs.toml"],
        "an export wrote beside the system file"
    );
    // Both run from where they were written, as the README's next lines do.
    for file in ["rrs/OspSystemStructure.xml", "rrs.ssp"] {
        let (ok, err) = shipsim_in(
            cwd.path(),
            &["run", file, "--stop-time", "1", "-q", "--no-output"],
        );
        assert!(ok, "{file}: {err}");
    }
}
