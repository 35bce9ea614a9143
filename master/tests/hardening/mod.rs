//! Helpers of the hardening tests (issue 19): hostile FMU archives built with the `zip` crate,
//! and the real `shipsim` binary run with a private `TMPDIR` (to count the temporary
//! directories it leaves) and a 4 GB address-space limit (so that a reader without a bound
//! fails instead of taking the machine's memory).
#![allow(dead_code)]

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};

/// One entry of a hand-made archive.
pub struct Entry {
    pub name: String,
    pub data: Vec<u8>,
    /// Unix mode bits stored in the archive (default: the zip crate's 0644).
    pub mode: Option<u32>,
    /// A symbolic link to `data` (as text).
    pub symlink: bool,
}

pub fn file(name: &str, data: impl Into<Vec<u8>>) -> Entry {
    Entry {
        name: name.into(),
        data: data.into(),
        mode: None,
        symlink: false,
    }
}

pub fn link(name: &str, target: &str) -> Entry {
    Entry {
        name: name.into(),
        data: target.as_bytes().to_vec(),
        mode: None,
        symlink: true,
    }
}

/// Writes the entries, deflated, into `path`.
pub fn archive(path: &Path, entries: &[Entry]) {
    let f = std::fs::File::create(path).unwrap();
    let mut z = zip::ZipWriter::new(f);
    for e in entries {
        let mut opts = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated)
            .large_file(e.data.len() > u32::MAX as usize / 2);
        if let Some(m) = e.mode {
            opts = opts.unix_permissions(m);
        }
        if e.symlink {
            z.add_symlink(e.name.as_str(), String::from_utf8_lossy(&e.data), opts)
                .unwrap();
        } else if e.name.ends_with('/') {
            z.add_directory(e.name.as_str(), opts).unwrap();
        } else {
            z.start_file(e.name.as_str(), opts).unwrap();
            z.write_all(&e.data).unwrap();
        }
    }
    z.finish().unwrap();
}

/// The test FMU's model description and binary (compiled once per call into `dir`).
pub fn testfmu(dir: &Path) -> (Vec<u8>, Vec<u8>) {
    let so = crate::common::compile(
        dir,
        "testfmu_bin",
        &crate::common::c_source("testfmu.c"),
        &[],
    );
    (
        crate::common::model_description(crate::common::GUID, "2.0").into_bytes(),
        std::fs::read(so).unwrap(),
    )
}

/// The test FMU as archive entries, with `extra` added.
pub fn testfmu_with(dir: &Path, name: &str, extra: Vec<Entry>) -> PathBuf {
    let (md, so) = testfmu(dir);
    let mut entries = vec![
        file("modelDescription.xml", md),
        file("binaries/linux64/testfmu.so", so),
    ];
    entries.extend(extra);
    let p = dir.join(name);
    archive(&p, &entries);
    p
}

/// A working directory and a private TMPDIR for runs of the real binary.
pub struct Sandbox {
    pub work: tempfile::TempDir,
    pub tmp: PathBuf,
}

impl Sandbox {
    pub fn new() -> Sandbox {
        let work = tempfile::tempdir().unwrap();
        let tmp = work.path().join("tmp");
        std::fs::create_dir(&tmp).unwrap();
        Sandbox { work, tmp }
    }

    pub fn path(&self) -> &Path {
        self.work.path()
    }

    /// `shipsim ARGS` in the working directory, TMPDIR private, at most 4 GB of address
    /// space.
    pub fn command(&self, args: &[&str]) -> Command {
        let mut c = Command::new("sh");
        c.arg("-c")
            .arg("ulimit -v 4000000 && exec \"$0\" \"$@\"")
            .arg(env!("CARGO_BIN_EXE_shipsim"))
            .args(args)
            .current_dir(self.work.path())
            .env("TMPDIR", &self.tmp)
            .stdin(Stdio::null());
        c
    }

    /// Runs to the end: (exit code, None when killed by a signal; stderr).
    pub fn run(&self, args: &[&str]) -> (Option<i32>, String) {
        let Output { status, stderr, .. } = self.command(args).output().unwrap();
        (status.code(), String::from_utf8_lossy(&stderr).into_owned())
    }

    pub fn spawn(&self, args: &[&str], stderr: Stdio) -> Child {
        self.command(args)
            .stdout(Stdio::null())
            .stderr(stderr)
            .spawn()
            .unwrap()
    }

    /// Everything left in the private TMPDIR (relative paths, sorted).
    pub fn leftovers(&self) -> Vec<String> {
        let mut out = Vec::new();
        let mut stack = vec![self.tmp.clone()];
        while let Some(d) = stack.pop() {
            for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
                let p = e.path();
                out.push(p.strip_prefix(&self.tmp).unwrap().display().to_string());
                if e.file_type().is_ok_and(|t| t.is_dir()) {
                    stack.push(p);
                }
            }
        }
        out.sort();
        out
    }

    /// Waits (up to 120 s, polling every 20 ms) until `cond` holds; panics with `what`.
    pub fn wait_for(&self, what: &str, mut cond: impl FnMut() -> bool) {
        for _ in 0..6000 {
            if cond() {
                return;
            }
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        panic!("waited 120 s for {what}");
    }
}

/// Sends `sig` to the child.
pub fn signal(child: &Child, sig: i32) {
    let r = unsafe { libc::kill(child.id() as i32, sig) };
    assert_eq!(r, 0, "kill failed");
}

/// A native system file of one test-FMU instance `name`, recording `name.y`.
pub fn system(fmu: &str, name: &str, stop: &str, step: &str, extra: &str) -> String {
    format!(
        "[simulation]\nstart_time = 0.0\nstop_time = {stop}\nstep_size = {step}\n\n[[instances]]\nname = {name:?}\nfmu = {fmu:?}\n{extra}\n[output]\nvariables = [\"{name}.*\"]\n"
    )
}
