//! Real-time runs end to end through the CLI, on loopback with ports chosen by the OS, every
//! loop bounded and every run under a time limit (`shipsim_in`: 60 s):
//!
//! - a bench autopilot's HTC and then OpenCPN's APB turn the ship of systems/hil_heading.toml
//!   to the commanded heading, and the journal replays the paced session bit for bit;
//! - a hostile stream (bad checksums, garbage, NaN fields, 10^5 datagrams, a sender that goes
//!   quiet) leaves the run to complete with the rejections counted in its summary;
//! - a paced run of N s takes N s plus start-up;
//! - the journal is flushed at most a second apart while a paced run goes, and a replay from a
//!   checkpoint is the full replay's tail byte for byte;
//! - nmea-out through a TCP listener, udp-out (binary) and udp-in (JSON) end to end.
mod common;
use common::*;
use std::net::UdpSocket;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

fn sentence(body: &str) -> Vec<u8> {
    let mut s = String::new();
    shipsim::realtime::nmea::frame(&mut s, body);
    s.into_bytes()
}

/// A UDP port free on loopback now.
fn free_port() -> u16 {
    UdpSocket::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

/// systems/hil_heading.toml with our FMUs, its ports replaced and `extra` appended to the
/// nmea-in inputs' table text replaced by `inputs` when given.
fn hil(dir: &Path, out_port: u16, in_port: u16, inputs: Option<&str>) -> PathBuf {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../systems/hil_heading.toml"),
    )
    .unwrap();
    let fmu_dir = our_fmu("NomotoShip").parent().unwrap().to_path_buf();
    let mut text = text
        .replace("../target/fmu/", &format!("{}/", fmu_dir.display()))
        .replace("127.0.0.1:10110", &format!("127.0.0.1:{out_port}"))
        .replace("127.0.0.1:10111", &format!("127.0.0.1:{in_port}"))
        .replace("../target/demo/hil_heading.csv", "hil.csv");
    if let Some(i) = inputs {
        let at = text.find("inputs = [").unwrap();
        text = format!("{}{i}\n", &text[..at]);
    }
    write_system(dir, "hil.toml", &text)
}

/// The UTC seconds of day of the GGA sentences in a datagram (the simulated time + 12 h).
fn gga_time(d: &str) -> Option<f64> {
    let line = d.lines().find(|l| l.contains("GGA,"))?;
    let t = line.split(',').nth(1)?;
    let (h, m, s): (f64, f64, f64) = (
        t[..2].parse().ok()?,
        t[2..4].parse().ok()?,
        t[4..].parse().ok()?,
    );
    Some(h * 3600.0 + m * 60.0 + s - 12.0 * 3600.0)
}

#[test]
fn htc_then_apb_turn_the_ship_and_the_session_replays() {
    let dir = tempfile::tempdir().unwrap();
    let (out_port, in_port) = (free_port(), free_port());
    let sys = hil(dir.path(), out_port, in_port, None);
    let rx = UdpSocket::bind(("127.0.0.1", out_port)).unwrap();
    rx.set_read_timeout(Some(Duration::from_millis(200)))
        .unwrap();
    let sender = std::thread::spawn(move || {
        let tx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let to = ("127.0.0.1", in_port);
        let (mut htc, mut apb) = (false, false);
        let mut buf = [0u8; 4096];
        let end = Instant::now() + Duration::from_secs(40);
        while Instant::now() < end && !apb {
            let Ok(n) = rx.recv(&mut buf) else { continue };
            let t = gga_time(std::str::from_utf8(&buf[..n]).unwrap()).unwrap_or(0.0);
            if !htc {
                // A bench autopilot: heading control, heading to steer 30 deg, null rudder.
                tx.send_to(&sentence("APHTC,V,,,H,N,,,,,30.0,,,T"), to)
                    .unwrap();
                htc = true;
            } else if t >= 40.0 {
                // OpenCPN following a route: heading to steer 350 deg (10 deg to port of north).
                let s = sentence("ECAPB,A,A,0.010,L,N,V,V,350.0,T,002,350.0,T,350.0,T,A");
                tx.send_to(&s, to).unwrap();
                apb = true;
            }
        }
        (htc, apb)
    });
    let (ok, err) = shipsim_in(
        dir.path(),
        &[
            "run",
            sys.to_str().unwrap(),
            "--real-time-factor",
            "8",
            "--stop-time",
            "120",
        ],
    );
    assert!(ok, "{err}");
    assert_eq!(sender.join().unwrap(), (true, true));
    eprintln!("{err}");
    let (h, rows) = read_csv(&dir.path().join("hil.csv"));
    let (head, used) = (
        col(&h, "ship.heading"),
        col(&h, "ap.heading_reference_used"),
    );
    let at = |t: f64| rows.iter().find(|r| r[0] >= t).unwrap();
    // Before the APB the ship steers 30 deg; at the end -10 deg (350 taken nearest).
    let before_apb = rows
        .iter()
        .filter(|r| (r[used] - 30f64.to_radians()).abs() < 1e-12)
        .count();
    assert!(before_apb > 200, "HTC's 30 deg held for {before_apb} rows");
    assert!(
        (at(40.0)[head].to_degrees() - 30.0).abs() < 3.0,
        "{}",
        at(40.0)[head].to_degrees()
    );
    let last = rows.last().unwrap();
    assert!((last[used].to_degrees() + 10.0).abs() < 1e-9);
    assert!(
        (last[head].to_degrees() + 10.0).abs() < 1.5,
        "{}",
        last[head].to_degrees()
    );
    assert!(err.contains("2 input values applied"), "{err}");
    // The paced session replays bit for bit.
    let (ok, rerr) = shipsim_in(dir.path(), &["replay", "hil.jsonl", "-o", "replayed.csv"]);
    assert!(ok, "{rerr}");
    let a = std::fs::read(dir.path().join("hil.csv")).unwrap();
    let b = std::fs::read(dir.path().join("replayed.csv")).unwrap();
    assert!(a == b, "the replay differs from the paced run's CSV");
}

#[test]
fn a_hostile_stream_is_counted_and_the_run_completes() {
    let dir = tempfile::tempdir().unwrap();
    let (out_port, in_port) = (free_port(), free_port());
    let inputs = r#"inputs = [
  { field = "HTC.heading_to_steer", variable = "ap.heading_reference", near = "ship.heading", on_quiet = "fallback", after = 1.5, fallback = 0.0 },
]"#;
    let sys = hil(dir.path(), out_port, in_port, Some(inputs));
    let sender = std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(700));
        let tx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let to = ("127.0.0.1", in_port);
        let body = "APHTC,V,,,H,N,,,,,20.0,,,T";
        let sum = shipsim::realtime::nmea::checksum(body.as_bytes()) ^ 0x5A;
        let bad = format!("${body}*{sum:02X}\r\n").into_bytes();
        let hostile: Vec<Vec<u8>> = vec![
            bad,
            b"\xff\x00garbage\r\n".to_vec(),
            sentence("APHTC,V,,,H,N,,,,,NaN,,,T"),
            sentence("APHTC,V,,,H,N,,,,,720,,,T"),
            sentence("APHTC,V,,,H,N,,,,,,,,T"),
            sentence("GPGGA,1,2"),
            vec![b'$'; 2000],
            sentence("APHTC,V,,,H,N,,,,,20.0,,,T"),
        ];
        for i in 0..100_000usize {
            let _ = tx.send_to(&hostile[i % hostile.len()], to);
        }
        // Then quiet: the input falls back to 0 after 1.5 s.
    });
    let begin = Instant::now();
    let (ok, err) = shipsim_in(
        dir.path(),
        &[
            "run",
            sys.to_str().unwrap(),
            "--real-time-factor",
            "4",
            "--stop-time",
            "24",
        ],
    );
    sender.join().unwrap();
    assert!(ok, "{err}");
    eprintln!("{err}");
    assert!(begin.elapsed() < Duration::from_secs(20));
    for kind in [
        "bad checksum",
        "malformed",
        "not a number",
        "out of range",
        "missing required field",
        "unknown sentence",
    ] {
        assert!(
            err.contains(&format!("{kind}: ")),
            "no count of '{kind}' in:\n{err}"
        );
    }
    assert!(err.contains("falls back to 0"), "{err}");
    // Each kind logged once while it ran.
    assert_eq!(
        err.matches("rejected input (bad checksum)").count(),
        1,
        "{err}"
    );
    let (h, rows) = read_csv(&dir.path().join("hil.csv"));
    let used = col(&h, "ap.heading_reference_used");
    assert_eq!(rows.last().unwrap()[used], 0.0);
}

#[test]
fn a_quiet_sender_can_end_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = r#"inputs = [ { field = "APB.heading_to_steer", variable = "ap.heading_reference", on_quiet = "end", after = 1.0 } ]"#;
    let sys = hil(dir.path(), free_port(), free_port(), Some(inputs));
    let (ok, err) = shipsim_in(
        dir.path(),
        &[
            "run",
            sys.to_str().unwrap(),
            "--real-time",
            "--stop-time",
            "30",
        ],
    );
    assert!(ok, "{err}");
    assert!(err.contains("was quiet for 1 s"), "{err}");
    let (_, rows) = read_csv(&dir.path().join("hil.csv"));
    let end = rows.last().unwrap()[0];
    assert!((0.9..3.0).contains(&end), "ended at {end}");
}

/// A paced RRS run of 4 s takes 4 s plus start-up (loose band: 4 to 7 s on a loaded machine),
/// and says its lateness.
#[test]
fn a_paced_run_takes_its_simulated_time() {
    let dir = tempfile::tempdir().unwrap();
    let sys = rrs_file(dir.path());
    let begin = Instant::now();
    let (ok, err) = shipsim_in(
        dir.path(),
        &[
            "run",
            sys.to_str().unwrap(),
            "--real-time",
            "--stop-time",
            "4",
            "-o",
            "rrs.csv",
        ],
    );
    let wall = begin.elapsed().as_secs_f64();
    assert!(ok, "{err}");
    eprintln!("{err}");
    assert!((4.0..7.0).contains(&wall), "{wall} s");
    assert!(
        err.contains("paced at 1x real time: lateness median"),
        "{err}"
    );
    // Unpaced, the same rows (the session is the run; pacing only waits).
    let (ok, e2) = shipsim_in(
        dir.path(),
        &[
            "run",
            sys.to_str().unwrap(),
            "--stop-time",
            "4",
            "-o",
            "plain.csv",
        ],
    );
    assert!(ok, "{e2}");
    let a = std::fs::read(dir.path().join("rrs.csv")).unwrap();
    let b = std::fs::read(dir.path().join("plain.csv")).unwrap();
    assert!(a == b, "the paced run's CSV differs from the plain run's");
}

/// A paced run that fails before its instances run (a value outside its declared range) leaves
/// the last run's CSV as it was, as `shipsim run` does (issue 36).
#[test]
fn a_paced_run_that_fails_at_start_keeps_the_last_csv() {
    let dir = tempfile::tempdir().unwrap();
    let sys = rrs_file(dir.path());
    std::fs::write(dir.path().join("rrs.csv"), "the last run\n").unwrap();
    let (ok, err) = shipsim_in(
        dir.path(),
        &[
            "run",
            sys.to_str().unwrap(),
            "--real-time",
            "--stop-time",
            "1",
            "--set",
            "gear.rate_max=-1",
            "-o",
            "rrs.csv",
        ],
    );
    assert!(!ok && err.contains("rate_max"), "{err}");
    let kept = std::fs::read_to_string(dir.path().join("rrs.csv")).unwrap();
    assert_eq!(kept, "the last run\n");
}

/// A paced run flushes its journal at most a wall second apart: an HTC sent early in a 6 s run
/// is in the journal's file 2.5 s later, while the run still goes (a crash loses at most a
/// second of inputs).
#[test]
fn a_paced_run_flushes_its_journal_every_second() {
    let dir = tempfile::tempdir().unwrap();
    let (out_port, in_port) = (free_port(), free_port());
    let sys = hil(dir.path(), out_port, in_port, None);
    let rx = UdpSocket::bind(("127.0.0.1", out_port)).unwrap();
    rx.set_read_timeout(Some(Duration::from_millis(200)))
        .unwrap();
    let journal = dir.path().join("hil.jsonl");
    let watcher = std::thread::spawn(move || {
        let mut buf = [0u8; 4096];
        let end = Instant::now() + Duration::from_secs(30);
        while Instant::now() < end && rx.recv(&mut buf).is_err() {}
        // The run is under way (it sent its first datagram): command a heading.
        let tx = UdpSocket::bind("127.0.0.1:0").unwrap();
        tx.send_to(
            &sentence("APHTC,V,,,H,N,,,,,30.0,,,T"),
            ("127.0.0.1", in_port),
        )
        .unwrap();
        std::thread::sleep(Duration::from_millis(2500));
        std::fs::read_to_string(&journal).unwrap_or_default()
    });
    let (ok, err) = shipsim_in(
        dir.path(),
        &[
            "run",
            sys.to_str().unwrap(),
            "--real-time",
            "--stop-time",
            "6",
        ],
    );
    let mid_run = watcher.join().unwrap();
    assert!(ok, "{err}");
    assert!(err.contains("1 input values applied"), "{err}");
    assert!(
        mid_run.contains(r#""record":"set""#) && !mid_run.contains(r#""record":"end""#),
        "the journal 2.5 s after the HTC, mid-run:\n{mid_run}"
    );
}

/// `shipsim replay JOURNAL --from CHECKPOINT`: a paced run with a checkpoint every 10 s and
/// heading commands before and after the checkpoint at 10 s; the replay from it writes the full
/// replay's rows from t = 10 s on, byte for byte (and a checkpoint after the journal's end is
/// refused).
#[test]
fn a_replay_from_a_checkpoint_is_the_full_replays_tail() {
    let dir = tempfile::tempdir().unwrap();
    let (out_port, in_port) = (free_port(), free_port());
    let sys = hil(dir.path(), out_port, in_port, None);
    let rx = UdpSocket::bind(("127.0.0.1", out_port)).unwrap();
    rx.set_read_timeout(Some(Duration::from_millis(200)))
        .unwrap();
    let sender = std::thread::spawn(move || {
        let tx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let to = ("127.0.0.1", in_port);
        let mut buf = [0u8; 4096];
        let mut sent = 0;
        let end = Instant::now() + Duration::from_secs(30);
        while Instant::now() < end && sent < 3 {
            let Ok(n) = rx.recv(&mut buf) else { continue };
            let t = gga_time(std::str::from_utf8(&buf[..n]).unwrap()).unwrap_or(0.0);
            // Before the checkpoint, at about it, and after it.
            let (at, heading) = [(0.0, "30.0"), (10.0, "20.0"), (15.0, "350.0")][sent];
            if t >= at {
                let body = format!("APHTC,V,,,H,N,,,,,{heading},,,T");
                tx.send_to(&sentence(&body), to).unwrap();
                sent += 1;
            }
        }
        sent
    });
    let (ok, err) = shipsim_in(
        dir.path(),
        &[
            "run",
            sys.to_str().unwrap(),
            "--real-time-factor",
            "10",
            "--stop-time",
            "25",
            "--checkpoint-every",
            "10",
        ],
    );
    assert!(ok, "{err}");
    assert_eq!(sender.join().unwrap(), 3);
    assert!(err.contains("3 input values applied"), "{err}");
    let ckpt = dir.path().join("hil-10.ckpt");
    assert!(ckpt.is_file(), "{err}");
    let (ok, e) = shipsim_in(dir.path(), &["replay", "hil.jsonl", "-o", "full.csv"]);
    assert!(ok, "{e}");
    let (ok, e) = shipsim_in(
        dir.path(),
        &[
            "replay",
            "hil.jsonl",
            "--from",
            "hil-10.ckpt",
            "-o",
            "tail.csv",
        ],
    );
    assert!(ok, "{e}");
    assert!(e.contains("from t = 10 s to t = 25 s"), "{e}");
    let full = std::fs::read_to_string(dir.path().join("full.csv")).unwrap();
    let tail = std::fs::read_to_string(dir.path().join("tail.csv")).unwrap();
    let mut lines = full.split_inclusive('\n');
    let mut expected = lines.next().unwrap().to_string();
    for l in lines {
        let t: f64 = l.split(',').next().unwrap().parse().unwrap();
        if t >= 10.0 - 1e-9 {
            expected.push_str(l);
        }
    }
    assert!(expected.lines().count() > 100);
    assert!(
        tail == expected,
        "the replay from t = 10 s is not the full replay's tail"
    );
    assert_eq!(
        std::fs::read(dir.path().join("full.csv")).unwrap(),
        std::fs::read(dir.path().join("hil.csv")).unwrap()
    );
    // A checkpoint after the journal's end: the run to 5 s has a journal ending at step 100.
    let (ok, e) = shipsim_in(
        dir.path(),
        &[
            "run",
            sys.to_str().unwrap(),
            "--real-time-factor",
            "20",
            "--stop-time",
            "5",
            "-o",
            "short.csv",
        ],
    );
    assert!(ok, "{e}");
    let (ok, e) = shipsim_in(
        dir.path(),
        &["replay", "short.jsonl", "--from", "hil-10.ckpt"],
    );
    assert!(!ok && e.contains("after the journal's last step"), "{e}");
}

/// The hil_heading system with its `[[io]]` tables replaced by `io`.
fn with_io(dir: &Path, io: &str) -> PathBuf {
    let sys = hil(dir, free_port(), free_port(), None);
    let text = std::fs::read_to_string(&sys).unwrap();
    let at = text.find("[[io]]").unwrap();
    write_system(dir, "hil.toml", &format!("{}{io}\n", &text[..at]))
}

/// The other channels end to end, on loopback: nmea-out to the clients of a TCP listener (a
/// client connected while the run goes gets checksummed HDT lines), udp-out's binary datagrams
/// (layout, consecutive sequence numbers, the CSV's values bit for bit) and udp-in's JSON (a
/// heading reference in degrees, applied and journaled).
#[test]
fn tcp_listener_udp_out_and_udp_in_end_to_end() {
    let dir = tempfile::tempdir().unwrap();
    let tcp_port = std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let (out_port, in_port) = (free_port(), free_port());
    let io = format!(
        r#"[[io]]
kind = "nmea-out"
transport = "tcp"
listen = "127.0.0.1:{tcp_port}"
datum = [63.44, 10.30]
sentences = ["HDT"]
rate = 2.0
bind = {{ heading = "ship.heading" }}

[[io]]
kind = "udp-out"
to = "127.0.0.1:{out_port}"
variables = ["ship.heading", "ap.heading_reference_used"]
rate = 20.0

[[io]]
kind = "udp-in"
listen = "127.0.0.1:{in_port}"
format = "json"
inputs = [ {{ field = "ref", variable = "ap.heading_reference", unit = "deg" }} ]
"#
    );
    let sys = with_io(dir.path(), &io);
    let tcp = std::thread::spawn(move || {
        let end = Instant::now() + Duration::from_secs(30);
        let mut stream = loop {
            match std::net::TcpStream::connect(("127.0.0.1", tcp_port)) {
                Ok(s) => break s,
                Err(_) if Instant::now() < end => std::thread::sleep(Duration::from_millis(20)),
                Err(e) => panic!("no TCP listener: {e}"),
            }
        };
        stream
            .set_read_timeout(Some(Duration::from_secs(10)))
            .unwrap();
        let mut text = String::new();
        let _ = std::io::Read::read_to_string(&mut stream, &mut text);
        text
    });
    let udp = std::thread::spawn(move || {
        let rx = UdpSocket::bind(("127.0.0.1", out_port)).unwrap();
        rx.set_read_timeout(Some(Duration::from_secs(3))).unwrap();
        let tx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let mut got: Vec<Vec<u8>> = Vec::new();
        let mut buf = [0u8; 2048];
        let mut sent = false;
        let end = Instant::now() + Duration::from_secs(30);
        while Instant::now() < end {
            let Ok(n) = rx.recv(&mut buf) else { break };
            let d = buf[..n].to_vec();
            let t = f64::from_le_bytes(d[16..24].try_into().unwrap());
            if !sent && t >= 2.0 {
                let json = r#"{"seq":1,"time":0,"values":{"ref":20.0}}"#;
                tx.send_to(json.as_bytes(), ("127.0.0.1", in_port)).unwrap();
                sent = true;
            }
            got.push(d);
        }
        got
    });
    let (ok, err) = shipsim_in(
        dir.path(),
        &[
            "run",
            sys.to_str().unwrap(),
            "--real-time-factor",
            "4",
            "--stop-time",
            "12",
        ],
    );
    assert!(ok, "{err}");
    assert!(err.contains("1 input values applied"), "{err}");
    // TCP: checksummed HDT lines, a heading in [0, 360).
    let text = tcp.join().unwrap();
    let lines: Vec<&str> = text.split("\r\n").filter(|l| !l.is_empty()).collect();
    assert!(lines.len() >= 10, "{text}");
    for l in &lines {
        let (body, sum) = l[1..].split_once('*').unwrap();
        assert!(l.starts_with('$') && body.starts_with("IIHDT,"), "{l}");
        let want = shipsim::realtime::nmea::checksum(body.as_bytes());
        assert_eq!(u8::from_str_radix(sum, 16).unwrap(), want, "{l}");
        let h: f64 = body.split(',').nth(1).unwrap().parse().unwrap();
        assert!((0.0..360.0).contains(&h), "{l}");
    }
    // UDP out: SHIP v1, 2 values, consecutive sequence numbers, the CSV's values.
    let got = udp.join().unwrap();
    assert!(got.len() >= 200, "{} datagrams", got.len());
    let (h, rows) = read_csv(&dir.path().join("hil.csv"));
    let (head, used) = (
        col(&h, "ship.heading"),
        col(&h, "ap.heading_reference_used"),
    );
    let f = |d: &[u8], at: usize| f64::from_le_bytes(d[at..at + 8].try_into().unwrap());
    for (i, d) in got.iter().enumerate() {
        assert_eq!(d.len(), 24 + 16);
        assert_eq!(&d[..4], b"SHIP");
        assert_eq!(u16::from_le_bytes([d[4], d[5]]), 1);
        assert_eq!(u16::from_le_bytes([d[6], d[7]]), 2);
        let seq = u64::from_le_bytes(d[8..16].try_into().unwrap());
        if i > 0 {
            let prev = u64::from_le_bytes(got[i - 1][8..16].try_into().unwrap());
            assert_eq!(seq, prev + 1);
        }
        let t = f(d, 16);
        let row = rows.iter().find(|r| (r[0] - t).abs() < 1e-9).unwrap();
        assert_eq!(f(d, 24).to_bits(), row[head].to_bits(), "t = {t}");
        assert_eq!(f(d, 32).to_bits(), row[used].to_bits(), "t = {t}");
    }
    // UDP in: the reference of 20 deg was applied (in rad) and is in the journal.
    let last = got.last().unwrap();
    assert!((f(last, 32) - 20f64.to_radians()).abs() < 1e-12);
    let journal = std::fs::read_to_string(dir.path().join("hil.jsonl")).unwrap();
    assert!(journal.contains(r#""variable":"ap.heading_reference""#));
}
