//! Malformed files through the CLI: system TOML files, OSP `OspSystemStructure.xml` files and
//! FMU model descriptions, each a valid file of the project mutated one to three times, given to
//! `shipsim check`, `shipsim run` (and `inspect` for FMUs). The oracle: an exit status of 0 (the
//! mutation kept the file valid) or an error exit with a message; never status 101 (a panic), a
//! signal, a panic message or a run that does not end.

use super::report::{FailKind, Failure, Report};
use super::rng::{unit_rng, Rng};
use super::watch::{describe_exit, InCall, Limits, Poll, Watched};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    Toml,
    Osp,
    Md,
}

impl Family {
    pub fn name(self) -> &'static str {
        match self {
            Family::Toml => "toml",
            Family::Osp => "osp",
            Family::Md => "md",
        }
    }
    pub fn parse(s: &str) -> Option<Family> {
        [Family::Toml, Family::Osp, Family::Md]
            .into_iter()
            .find(|f| f.name() == s)
    }
}

/// A valid model description with the binary it goes with.
pub struct MdBase {
    pub name: String,
    pub xml: String,
    pub binary: PathBuf,
    pub model_identifier: String,
}

/// The valid files the mutations start from, and where cases run.
pub struct Bases {
    pub shipsim: PathBuf,
    pub work: PathBuf,
    pub toml: Vec<(String, String)>,
    pub osp: Vec<(String, String)>,
    pub md: Vec<MdBase>,
}

/// Limits of one shipsim command: a run of a malformed file is cut to 1 s of simulated time, so
/// a few seconds of CPU time is far more than any valid case needs.
pub const CLI_LIMITS: Limits = Limits {
    cpu: Duration::from_secs(5),
    wall: Duration::from_secs(60),
};

/// Rewrites every `fmu = "…/X.fmu"` and `source="…/X.fmu"` to `<fmu_dir>/X.fmu`, so a mutated
/// copy runs from any folder.
pub fn absolute_fmu_paths(text: &str, fmu_dir: &Path) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(i) = rest.find(".fmu\"") {
        let head = &rest[..i];
        let start = head.rfind('"').map_or(0, |q| q + 1);
        let name = head[start..].rsplit('/').next().unwrap_or("");
        out.push_str(&rest[..start]);
        out.push_str(&fmu_dir.join(format!("{name}.fmu")).to_string_lossy());
        out.push('"');
        rest = &rest[i + 5..];
    }
    out.push_str(rest);
    out
}

impl Bases {
    /// Reads the systems of `root/systems`, exports OSP files of a few of them with `shipsim
    /// export-osp`, and takes the model descriptions of `mds` (unpacked FMUs).
    pub fn prepare(
        root: &Path,
        fmu_dir: &Path,
        shipsim: &Path,
        work: &Path,
        mds: Vec<MdBase>,
    ) -> Result<Bases, String> {
        std::fs::create_dir_all(work).map_err(|e| format!("{}: {e}", work.display()))?;
        let mut systems: Vec<PathBuf> = std::fs::read_dir(root.join("systems"))
            .map_err(|e| format!("systems/: {e}"))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "toml"))
            .collect();
        systems.sort();
        let mut toml = Vec::new();
        let mut osp = Vec::new();
        for s in &systems {
            let name = s.file_stem().unwrap().to_string_lossy().into_owned();
            let text = std::fs::read_to_string(s).map_err(|e| format!("{}: {e}", s.display()))?;
            toml.push((name.clone(), absolute_fmu_paths(&text, fmu_dir)));
            if [
                "rrs",
                "steering_gear_classification",
                "dp_observer",
                "autopilot_current",
            ]
            .contains(&name.as_str())
            {
                let out = work
                    .join("osp-base")
                    .join(&name)
                    .join("OspSystemStructure.xml");
                let st = Command::new(shipsim)
                    .arg("export-osp")
                    .arg(s)
                    .arg("-o")
                    .arg(&out)
                    .output()
                    .map_err(|e| format!("{}: {e}", shipsim.display()))?;
                if !st.status.success() {
                    return Err(format!(
                        "shipsim export-osp {} failed: {}",
                        s.display(),
                        String::from_utf8_lossy(&st.stderr)
                    ));
                }
                let xml = std::fs::read_to_string(&out).map_err(|e| e.to_string())?;
                osp.push((name, absolute_fmu_paths(&xml, fmu_dir)));
            }
        }
        Ok(Bases {
            shipsim: shipsim.to_path_buf(),
            work: work.to_path_buf(),
            toml,
            osp,
            md: mds,
        })
    }
}

const NUMBERS: [&str; 18] = [
    "NaN",
    "nan",
    "inf",
    "-inf",
    "1e300",
    "-1e300",
    "1e-300",
    "0",
    "-0",
    "-1",
    "1e999",
    "99999999999999999999",
    "0x10",
    "1.5",
    "",
    ".",
    "1e",
    "4294967296",
];
const STRINGS: [&str; 14] = [
    "",
    "a.b",
    "..",
    "/dev/zero",
    "/etc/hostname",
    "a,b",
    "\\",
    "&lol;",
    "%s%n",
    "\u{202e}x",
    "2.garbage",
    "x y",
    "\u{0}",
    "]]>",
];

fn is_num_start(b: u8) -> bool {
    b.is_ascii_digit() || b == b'-' || b == b'+'
}

/// Spans (start, end) of number-like tokens (inside quotes too: XML attributes are quoted) and of
/// the contents of double-quoted strings.
type Spans = Vec<(usize, usize)>;

fn tokens(text: &[u8]) -> (Spans, Spans) {
    let (mut nums, mut strs) = (Vec::new(), Vec::new());
    let mut i = 0;
    while i < text.len() {
        if text[i] == b'"' {
            match text[i + 1..].iter().position(|&c| c == b'"' || c == b'\n') {
                Some(e) => {
                    strs.push((i + 1, i + 1 + e));
                    i += e + 2;
                }
                None => i += 1,
            }
        } else {
            i += 1;
        }
    }
    let mut i = 0;
    while i < text.len() {
        if is_num_start(text[i]) && (i == 0 || !text[i - 1].is_ascii_alphanumeric()) {
            let mut j = i + 1;
            while j < text.len()
                && (text[j].is_ascii_digit() || matches!(text[j], b'.' | b'e' | b'E' | b'-' | b'+'))
            {
                j += 1;
            }
            if text[i..j].iter().any(u8::is_ascii_digit) {
                nums.push((i, j));
                i = j;
                continue;
            }
        }
        i += 1;
    }
    (nums, strs)
}

fn line_spans(text: &[u8]) -> Spans {
    let mut spans = Vec::new();
    let mut start = 0;
    for (i, b) in text.iter().enumerate() {
        if *b == b'\n' {
            spans.push((start, i + 1));
            start = i + 1;
        }
    }
    if start < text.len() {
        spans.push((start, text.len()));
    }
    spans
}

/// One to three mutations of a text file; the list of what was done.
pub fn mutate(rng: &mut Rng, text: &[u8], xml: bool) -> (Vec<u8>, Vec<String>) {
    let mut t = text.to_vec();
    let mut done = Vec::new();
    for _ in 0..1 + rng.below(3) {
        let (nums, strs) = tokens(&t);
        let lines = line_spans(&t);
        let op = rng.weighted(&[35, 30, 8, 6, 4, 4, 5, 4, 4]);
        let (at, end, new): (usize, usize, Vec<u8>) = match op {
            0 if !nums.is_empty() => {
                let (a, b) = *rng.pick(&nums);
                let v = *rng.pick(&NUMBERS);
                done.push(format!("number@{a}={v}"));
                (a, b, v.as_bytes().to_vec())
            }
            1 if !strs.is_empty() => {
                let (a, b) = *rng.pick(&strs);
                let v = if rng.chance(0.1) {
                    "x".repeat(100_000)
                } else {
                    rng.pick(&STRINGS).to_string()
                };
                done.push(format!(
                    "string@{a}={:?}",
                    v.chars().take(20).collect::<String>()
                ));
                (a, b, v.into_bytes())
            }
            2 if !lines.is_empty() => {
                let (a, b) = *rng.pick(&lines);
                done.push(format!("delete-line@{a}"));
                (a, b, Vec::new())
            }
            3 if !lines.is_empty() => {
                let (a, b) = *rng.pick(&lines);
                done.push(format!("duplicate-line@{a}"));
                (a, a, t[a..b].to_vec())
            }
            4 => {
                let n = rng.below(t.len().max(1));
                done.push(format!("truncate@{n}"));
                (n, t.len(), Vec::new())
            }
            5 => {
                let n = rng.below(t.len().max(1));
                let junk = [0u8, 0xff, b'<', b'&', b'"', b'\\', b'[', b'='][rng.below(8)];
                done.push(format!("insert@{n}={junk}"));
                (n, n, vec![junk])
            }
            6 if xml => {
                let n = rng.below(t.len().max(1));
                done.push(format!("entity@{n}"));
                (n, n, b"&lol9;".to_vec())
            }
            7 if !lines.is_empty() => {
                let (a, _) = *rng.pick(&lines);
                let depth = *rng.pick(&[2, 100, 10_000]);
                done.push(format!("nest@{a}x{depth}"));
                let mut s = if xml {
                    "<a>".repeat(depth)
                } else {
                    "[".repeat(depth)
                };
                s.push_str(&if xml {
                    "</a>".repeat(depth)
                } else {
                    "]".repeat(depth)
                });
                s.push('\n');
                (a, a, s.into_bytes())
            }
            _ => {
                let n = rng.below(t.len().max(1));
                done.push(format!("bitflip@{n}"));
                let mut b = t.get(n).copied().unwrap_or(0);
                b ^= 1 << rng.below(8);
                (n, (n + 1).min(t.len()), vec![b])
            }
        };
        let end = end.min(t.len());
        let at = at.min(end);
        t.splice(at..end, new);
    }
    (t, done)
}

/// Runs one shipsim command; the oracle's verdict, if any.
fn run_cli(shipsim: &Path, args: &[&std::ffi::OsStr], cwd: &Path) -> Option<(FailKind, String)> {
    let mut cmd = Command::new(shipsim);
    cmd.args(args).current_dir(cwd).env_remove("RUST_BACKTRACE");
    super::child_limits(&mut cmd);
    let mut w = match Watched::spawn(cmd) {
        Ok(w) => w,
        Err(e) => return Some((FailKind::Setup, format!("cannot start shipsim: {e}"))),
    };
    let started = InCall::now(&w);
    let mut output = String::new();
    loop {
        match w.poll(Duration::from_millis(20)) {
            Poll::Line(l) => {
                if output.len() < 4000 {
                    output.push_str(&l);
                    output.push('|');
                }
            }
            Poll::Quiet => {}
            Poll::Eof => break,
        }
        if let Some(why) = started.over(&w, &CLI_LIMITS) {
            w.kill();
            return Some((FailKind::Hang, format!("shipsim {why}; output: {output}")));
        }
    }
    let status = match w.child.wait() {
        Ok(s) => s,
        Err(e) => return Some((FailKind::Setup, e.to_string())),
    };
    let short: String = output.chars().take(300).collect();
    if output.to_ascii_lowercase().contains("panicked") {
        return Some((
            FailKind::Panic,
            format!("{}: {short}", describe_exit(status)),
        ));
    }
    if status.code() == Some(101) {
        return Some((FailKind::Exit101, short));
    }
    if status.code().is_none() {
        return Some((
            FailKind::Crash,
            format!("shipsim {}: {short}", describe_exit(status)),
        ));
    }
    if !status.success() && output.trim_matches('|').trim().is_empty() {
        return Some((FailKind::NoMessage, describe_exit(status)));
    }
    None
}

/// The file of one unit written into `dir`; the commands to run on it.
fn write_case(
    b: &Bases,
    family: Family,
    rng: &mut Rng,
    unit: u64,
    dir: &Path,
) -> std::io::Result<(String, Vec<String>, Vec<Vec<std::ffi::OsString>>)> {
    let os = |s: &str| std::ffi::OsString::from(s);
    let out = dir.join("out.csv");
    let run = |sys: &Path| {
        vec![
            vec![os("check"), sys.as_os_str().to_owned()],
            vec![
                os("run"),
                sys.as_os_str().to_owned(),
                os("--stop-time"),
                os("1"),
                os("-o"),
                out.as_os_str().to_owned(),
            ],
        ]
    };
    Ok(match family {
        Family::Toml | Family::Osp => {
            let bases = if family == Family::Toml {
                &b.toml
            } else {
                &b.osp
            };
            let (name, text) = &bases[unit as usize % bases.len()];
            let (data, done) = mutate(rng, text.as_bytes(), family == Family::Osp);
            let file = dir.join(if family == Family::Toml {
                "system.toml"
            } else {
                "OspSystemStructure.xml"
            });
            std::fs::write(&file, data)?;
            (name.clone(), done, run(&file))
        }
        Family::Md => {
            let base = &b.md[unit as usize % b.md.len()];
            let (data, done) = mutate(rng, base.xml.as_bytes(), true);
            let fmu = dir.join(format!("{}.fmu", base.model_identifier));
            write_fmu(&fmu, &data, base)?;
            let sys = dir.join("system.toml");
            std::fs::write(
                &sys,
                format!(
                    "[simulation]\nstop_time = 1.0\nstep_size = 0.1\n\n[[instances]]\nname = \"a\"\nfmu = \"{}\"\n",
                    fmu.display()
                ),
            )?;
            let mut cmds = vec![vec![os("inspect"), fmu.as_os_str().to_owned()]];
            cmds.extend(run(&sys));
            (base.name.clone(), done, cmds)
        }
    })
}

fn write_fmu(path: &Path, xml: &[u8], base: &MdBase) -> std::io::Result<()> {
    let f = std::fs::File::create(path)?;
    let mut z = zip::ZipWriter::new(f);
    let opts =
        zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    let err = |e: zip::result::ZipError| std::io::Error::other(e.to_string());
    z.start_file("modelDescription.xml", opts).map_err(err)?;
    z.write_all(xml)?;
    z.start_file(
        format!(
            "binaries/{}/{}.so",
            shipsim::fmu::PLATFORM,
            base.model_identifier
        ),
        opts,
    )
    .map_err(err)?;
    z.write_all(&std::fs::read(&base.binary)?)?;
    z.finish().map_err(err)?;
    Ok(())
}

/// One malformed-file case: mutate, write, run each command, judge.
pub fn run_unit(b: &Bases, _limits: &Limits, family: Family, seed: u64, unit: u64) -> Report {
    let mut report = Report::default();
    let mut rng = unit_rng(seed, family.name(), "files", unit);
    let dir = b.work.join(format!("{}-{seed}-{unit}", family.name()));
    let _ = std::fs::remove_dir_all(&dir);
    let result =
        std::fs::create_dir_all(&dir).and_then(|_| write_case(b, family, &mut rng, unit, &dir));
    let (target, done, cmds) = match result {
        Ok(x) => x,
        Err(e) => {
            report.failures.push(Failure {
                fail: FailKind::Setup,
                case: family.name(),
                target: String::new(),
                seed,
                unit,
                detail: format!("cannot write the case: {e}"),
                calls: Vec::new(),
            });
            return report;
        }
    };
    *report.units.entry(family.name()).or_default() += 1;
    for args in &cmds {
        let a: Vec<&std::ffi::OsStr> = args.iter().map(|s| s.as_os_str()).collect();
        if let Some((fail, detail)) = run_cli(&b.shipsim, &a, &dir) {
            let line: Vec<String> = args
                .iter()
                .map(|s| s.to_string_lossy().into_owned())
                .collect();
            report.failures.push(Failure {
                fail,
                case: family.name(),
                target: target.clone(),
                seed,
                unit,
                detail,
                calls: vec![
                    format!("mutations {}", done.join(",")),
                    format!("shipsim {}", line.join(" ")),
                ],
            });
            // Keep the file for whoever fixes it.
            return report;
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    report
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fmu_paths_become_absolute() {
        let t = "fmu = \"../target/fmu/RrsShip.fmu\"\nx = 1\n<Simulator source=\"../../a/b/Waves.fmu\"/>";
        let out = absolute_fmu_paths(t, Path::new("/f"));
        assert_eq!(
            out,
            "fmu = \"/f/RrsShip.fmu\"\nx = 1\n<Simulator source=\"/f/Waves.fmu\"/>"
        );
    }

    #[test]
    fn tokens_find_numbers_and_strings() {
        let t = b"step_size = 0.05\nname = \"ship\"\nx1 = -3e-2 <a stepSize=\"0.1\"/>";
        let (nums, strs) = tokens(t);
        let n: Vec<&[u8]> = nums.iter().map(|(a, b)| &t[*a..*b]).collect();
        let s: Vec<&[u8]> = strs.iter().map(|(a, b)| &t[*a..*b]).collect();
        assert_eq!(n, vec![&b"0.05"[..], &b"-3e-2"[..], &b"0.1"[..]]);
        assert_eq!(s, vec![&b"ship"[..], &b"0.1"[..]]);
    }

    #[test]
    fn mutation_is_a_function_of_the_seed() {
        let base = b"[simulation]\nstop_time = 10.0\nname = \"a\"\n";
        let a = mutate(&mut Rng::new(3), base, false);
        let b = mutate(&mut Rng::new(3), base, false);
        assert_eq!(a, b);
        assert_ne!(a.0, base.to_vec());
    }
}
