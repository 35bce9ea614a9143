//! Hostile FMU archives (issue 19, defects 1, 7 and 9; the cases of the reliability probe's
//! summary_zips.txt): modes from the archive, symbolic links, binaries outside the archive,
//! zip bombs, too many entries, duplicate entries, a directory given as an FMU. Every archive
//! is built here with the `zip` crate; the CLI runs with a private TMPDIR, which must be empty
//! afterwards.
mod common;
mod hardening;

use hardening::*;
use shipsim::fmu::UnpackedFmu;
use std::os::unix::fs::PermissionsExt;

/// The unpacked directory is private (0700), its files 0600 and the binary 0700, whatever
/// modes the archive stores (here 0777 and setuid 04777, directories 0777).
#[test]
fn modes_from_the_archive_are_ignored() {
    let d = tempfile::tempdir().unwrap();
    let (md, so) = testfmu(d.path());
    let p = d.path().join("modes.fmu");
    let mut dir = file("binaries/", Vec::new());
    dir.mode = Some(0o777);
    let mut bin = file("binaries/linux64/testfmu.so", so);
    bin.mode = Some(0o4777);
    let mut mdf = file("modelDescription.xml", md);
    mdf.mode = Some(0o777);
    let mut res = file("resources/data.txt", "x");
    res.mode = Some(0o6777);
    archive(&p, &[mdf, dir, bin, res]);
    let u = UnpackedFmu::open(&p).unwrap();
    let mode = |rel: &str| {
        std::fs::symlink_metadata(u.dir.path().join(rel))
            .unwrap()
            .permissions()
            .mode()
            & 0o7777
    };
    assert_eq!(mode(""), 0o700, "the unpacked directory");
    assert_eq!(mode("binaries"), 0o700);
    assert_eq!(mode("resources"), 0o700);
    assert_eq!(mode("modelDescription.xml"), 0o600);
    assert_eq!(mode("resources/data.txt"), 0o600);
    assert_eq!(mode("binaries/linux64/testfmu.so"), 0o700);
}

/// A symbolic link in the archive is refused with a message naming it: a binary linked to a
/// library of the host, and a model description linked to /etc/hostname (whose content the
/// old code echoed in its error) or to /dev/zero (read until memory ran out).
#[test]
fn symbolic_links_are_refused() {
    let s = Sandbox::new();
    let (md, _) = testfmu(s.path());
    let cases = [
        (
            "so_link.fmu",
            vec![
                file("modelDescription.xml", md.clone()),
                link(
                    "binaries/linux64/testfmu.so",
                    "/lib/x86_64-linux-gnu/libc.so.6",
                ),
            ],
            "binaries/linux64/testfmu.so",
        ),
        (
            "md_hostname.fmu",
            vec![link("modelDescription.xml", "/etc/hostname")],
            "modelDescription.xml",
        ),
        (
            "md_zero.fmu",
            vec![link("modelDescription.xml", "/dev/zero")],
            "modelDescription.xml",
        ),
    ];
    let hostname = std::fs::read_to_string("/etc/hostname").unwrap_or_default();
    for (name, entries, entry) in cases {
        archive(&s.path().join(name), &entries);
        for cmd in ["inspect", "check-as-run"] {
            let (code, err) = match cmd {
                "inspect" => s.run(&["inspect", name]),
                _ => {
                    std::fs::write(s.path().join("sys.toml"), system(name, "g", "1", "0.1", ""))
                        .unwrap();
                    s.run(&["run", "sys.toml", "-q"])
                }
            };
            assert_eq!(code, Some(1), "{name} {cmd}: {err}");
            assert!(
                err.contains(&format!("entry '{entry}' is a symbolic link")),
                "{name} {cmd}: {err}"
            );
            if !hostname.trim().is_empty() {
                assert!(!err.contains(hostname.trim()), "{name}: {err}");
            }
        }
    }
    assert_eq!(s.leftovers(), Vec::<String>::new());
}

/// A modelIdentifier that is a path (absolute, or with `..`) is refused before anything is
/// loaded: the old code loaded /lib/.../libc.so.6 from the absolute one.
#[test]
fn model_identifier_must_be_a_file_name() {
    let s = Sandbox::new();
    let (md, so) = testfmu(s.path());
    let md = String::from_utf8(md).unwrap();
    for (name, id) in [
        ("abs.fmu", "/lib/x86_64-linux-gnu/libc"),
        ("up.fmu", "../../../../../../lib/x86_64-linux-gnu/libc"),
        ("sub.fmu", "sub/testfmu"),
    ] {
        let md = md.replace(
            "modelIdentifier=\"testfmu\"",
            &format!("modelIdentifier=\"{id}\""),
        );
        archive(
            &s.path().join(name),
            &[
                file("modelDescription.xml", md),
                file("binaries/linux64/testfmu.so", so.clone()),
                file("binaries/linux64/sub/testfmu.so", so.clone()),
            ],
        );
        std::fs::write(s.path().join("sys.toml"), system(name, "g", "1", "0.1", "")).unwrap();
        let (code, err) = s.run(&["run", "sys.toml", "-q"]);
        assert_eq!(code, Some(1), "{name}: {err}");
        assert!(
            err.contains(&format!("modelIdentifier \"{id}\" is not a file name")),
            "{name}: {err}"
        );
    }
    assert_eq!(s.leftovers(), Vec::<String>::new());
}

/// A zip bomb (one entry of 64 MiB of zeros, about 64 kB deflated: a ratio near 1,000) is
/// refused by `inspect` and `run` without unpacking it; `--max-fmu-ratio` raises the limit.
#[test]
fn zip_bomb_is_refused_and_the_limit_can_be_raised() {
    let s = Sandbox::new();
    testfmu_with(
        s.path(),
        "bomb.fmu",
        vec![file("resources/zeros.bin", vec![0u8; 64 << 20])],
    );
    std::fs::write(
        s.path().join("sys.toml"),
        system("bomb.fmu", "g", "1", "0.1", ""),
    )
    .unwrap();
    for args in [&["inspect", "bomb.fmu"][..], &["run", "sys.toml", "-q"]] {
        let (code, err) = s.run(args);
        assert_eq!(code, Some(1), "{args:?}: {err}");
        assert!(
            err.contains(
                "entry 'resources/zeros.bin' unpacks to more than 200 times its compressed size"
            ) && err.contains("--max-fmu-ratio"),
            "{args:?}: {err}"
        );
        assert_eq!(s.leftovers(), Vec::<String>::new());
    }
    let (code, err) = s.run(&["inspect", "bomb.fmu", "--max-fmu-ratio", "2000"]);
    assert_eq!(code, Some(0), "{err}");
}

/// The unpacked size is bounded (here by `--max-fmu-size 2M` against 3 MiB of incompressible
/// data, which passes the ratio check), and the error names the entry and the option.
#[test]
fn unpacked_size_is_limited() {
    let s = Sandbox::new();
    let mut x = 0x2545_F491_4F6C_DD1D_u64;
    let noise: Vec<u8> = (0..3 << 20)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x as u8
        })
        .collect();
    testfmu_with(
        s.path(),
        "big.fmu",
        vec![file("resources/noise.bin", noise)],
    );
    let (code, err) = s.run(&["inspect", "big.fmu", "--max-fmu-size", "2M"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("unpacking entry 'resources/noise.bin' takes the archive past 2 MiB")
            && err.contains("--max-fmu-size"),
        "{err}"
    );
    assert_eq!(s.leftovers(), Vec::<String>::new());
    let (code, err) = s.run(&["inspect", "big.fmu"]);
    assert_eq!(code, Some(0), "{err}");
}

/// More entries than the limit (10,000 by default) are refused before anything is unpacked.
#[test]
fn entry_count_is_limited() {
    let s = Sandbox::new();
    let extra = (0..10_001)
        .map(|i| file(&format!("resources/f{i}.txt"), "x"))
        .collect();
    testfmu_with(s.path(), "many.fmu", extra);
    let (code, err) = s.run(&["inspect", "many.fmu"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("the archive has 10003 entries, more than the limit of 10000")
            && err.contains("--max-fmu-files"),
        "{err}"
    );
    assert_eq!(s.leftovers(), Vec::<String>::new());
    let (code, err) = s.run(&["inspect", "many.fmu", "--max-fmu-files", "20000"]);
    assert_eq!(code, Some(0), "{err}");
}

/// An entry that appears twice is refused (which copy is the real one?); the old code kept
/// the last.
#[test]
fn duplicate_entries_are_refused() {
    let s = Sandbox::new();
    // The zip crate refuses to write a name twice: write another of the same length and
    // rename it in the bytes (local header and central directory).
    let p = testfmu_with(
        s.path(),
        "dup.fmu",
        vec![file("modelDescriptioX.xml", "<fmiModelDescription/>")],
    );
    let bytes = std::fs::read(&p).unwrap();
    let (from, to) = (b"modelDescriptioX.xml", b"modelDescription.xml");
    let mut patched = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i..].starts_with(from) {
            patched.extend_from_slice(to);
            i += from.len();
        } else {
            patched.push(bytes[i]);
            i += 1;
        }
    }
    std::fs::write(&p, patched).unwrap();
    let (code, err) = s.run(&["inspect", "dup.fmu"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("it holds 3 entries under 2 names (a name appears twice"),
        "{err}"
    );
}

/// A directory given as an FMU says so (the old message was "i/o error").
#[test]
fn directory_as_fmu() {
    let s = Sandbox::new();
    std::fs::create_dir(s.path().join("unpacked.fmu")).unwrap();
    let (code, err) = s.run(&["inspect", "unpacked.fmu"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("FMU 'unpacked.fmu': is a directory; an FMU is a zip archive"),
        "{err}"
    );
}

/// fmiVersion must be "2.0" ("2.garbage" was accepted), and variable names unique (FMI 2.0,
/// sec. 2.2.7; a duplicate was accepted and the second silently shadowed).
#[test]
fn bad_fmi_version_and_duplicate_names_are_refused() {
    let s = Sandbox::new();
    let (md, so) = testfmu(s.path());
    let md = String::from_utf8(md).unwrap();
    let garbage = md.replace("fmiVersion=\"2.0\"", "fmiVersion=\"2.garbage\"");
    let dup = md.replace("name=\"t_last\"", "name=\"y\"");
    for (name, md, expect) in [
        (
            "garbage.fmu",
            garbage,
            "fmiVersion is \"2.garbage\"; this master imports FMI 2.0 only",
        ),
        ("dup.fmu", dup, "declares the variable 'y' twice"),
    ] {
        archive(
            &s.path().join(name),
            &[
                file("modelDescription.xml", md),
                file("binaries/linux64/testfmu.so", so.clone()),
            ],
        );
        let e = shipsim::Fmu::load(s.path().join(name))
            .unwrap_err()
            .to_string();
        assert!(e.contains(expect), "{name}: {e}");
    }
    // "2.0" as some 2.0.x tools write it stays accepted.
    let ok = md.replace("fmiVersion=\"2.0\"", "fmiVersion=\"2.0.4\"");
    archive(
        &s.path().join("ok.fmu"),
        &[
            file("modelDescription.xml", ok),
            file("binaries/linux64/testfmu.so", so),
        ],
    );
    shipsim::Fmu::load(s.path().join("ok.fmu")).unwrap();
}

/// A panic unwinding through a holder of an unpacked FMU removes its directory.
#[test]
fn panic_unwinding_removes_the_directory() {
    let d = tempfile::tempdir().unwrap();
    let p = testfmu_with(d.path(), "t.fmu", vec![]);
    let mut dir = None;
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let u = UnpackedFmu::open(&p).unwrap();
        dir = Some(u.dir.path().to_path_buf());
        assert!(dir.as_ref().unwrap().join("modelDescription.xml").is_file());
        panic!("on purpose");
    }));
    assert!(r.is_err());
    let dir = dir.unwrap();
    assert!(!dir.exists(), "{} left behind", dir.display());
}
