//! The child's end: `shipsim fmu-host FMU` loads one FMU with the importer ([`crate::fmu`]),
//! instantiates it on the first request and makes each requested FMI call, replying with the
//! status and results ([`super::protocol`]). The FMU's log messages are sent back as they come.
//! When the master closes the pipe without fmi2FreeInstance (after fmi2Fatal, or when it ends),
//! the host exits without another FMI call, removing its extraction directory.
//!
//! The requests arrive on stdin and the replies leave on stdout; both are moved to other file
//! descriptors first, and stdout is pointed at stderr, so whatever the FMU prints cannot
//! corrupt the replies. On Linux the host dies with its master (PR_SET_PDEATHSIG).

use super::protocol::{self, Put, Reader, HEADER, LOG, MAX_FRAME, REPLY};
use crate::fmu::Fmu;
use crate::log::{LogCtx, LogRecord, LogSink};
use crate::slave::{InProcess, Op, Slave, MAX_STATE_BYTES};
use fmi2::*;
use std::ffi::CString;
use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Write};
use std::os::fd::FromRawFd;
use std::path::Path;
use std::sync::{Arc, Mutex};

type Out = Arc<Mutex<BufWriter<File>>>;

/// Runs the host for `fmu` until fmi2FreeInstance or the end of the requests; the process's
/// exit status (0 when the master ended it in order).
pub fn serve(fmu: &Path) -> i32 {
    let Some((input, output)) = take_pipes() else {
        eprintln!("shipsim fmu-host: cannot set up its pipes");
        return 2;
    };
    let mut input = BufReader::new(input);
    let output: Out = Arc::new(Mutex::new(BufWriter::new(output)));
    let mut payload = Vec::new();
    // The first request instantiates.
    match read_frame(&mut input, &mut payload) {
        Some(op) if op == Op::Instantiate as u32 => {}
        _ => return 2,
    }
    let mut r = Reader::new(&payload);
    let name = r.string();
    let logging_on = r.i32() != 0;
    let loaded = Fmu::load(fmu).and_then(|f| {
        let log = Arc::new(LogCtx::new(&name, log_sink(output.clone()), logging_on));
        let inst = InProcess::instantiate(&f, &name, log, None)?;
        Ok((f, inst))
    });
    let (fmu, inst) = match loaded {
        Ok(x) => x,
        Err(e) => {
            reply(&output, fmi2Error, |o| e.to_string().as_str().put(o));
            return 0;
        }
    };
    let dir = fmu.unpacked.to_string_lossy().into_owned();
    reply(&output, fmi2OK, |o| dir.as_str().put(o));
    let mut host = Host {
        out: output,
        inst,
        vrs: Vec::new(),
        reals: Vec::new(),
        ints: Vec::new(),
        strings: Vec::new(),
    };
    while let Some(op) = read_frame(&mut input, &mut payload) {
        if !host.call(op, &payload) {
            break;
        }
    }
    // The instance is dropped without another FMI call: freed on request, or the master left
    // without fmi2FreeInstance (after fmi2Fatal none is allowed).
    drop(host);
    drop(fmu);
    0
}

/// The request and reply pipes, moved off stdin and stdout (which become /dev/null and
/// stderr); on Linux, the host is killed when its master dies.
fn take_pipes() -> Option<(File, File)> {
    // SAFETY: plain descriptor operations on this process's own standard descriptors.
    unsafe {
        let req = libc::dup(0);
        let rep = libc::dup(1);
        if req < 0 || rep < 0 {
            return None;
        }
        let null = libc::open(c"/dev/null".as_ptr(), libc::O_RDONLY);
        if null >= 0 {
            libc::dup2(null, 0);
            libc::close(null);
        }
        libc::dup2(2, 1);
        libc::fcntl(req, libc::F_SETFD, libc::FD_CLOEXEC);
        libc::fcntl(rep, libc::F_SETFD, libc::FD_CLOEXEC);
        #[cfg(target_os = "linux")]
        {
            let parent = libc::getppid();
            libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL);
            if libc::getppid() != parent {
                libc::_exit(3);
            }
        }
        Some((File::from_raw_fd(req), File::from_raw_fd(rep)))
    }
}

/// The next request: its op, with the payload in `payload`; None at the end of input or on a
/// malformed frame.
fn read_frame(input: &mut impl Read, payload: &mut Vec<u8>) -> Option<u32> {
    let mut h = [0u8; HEADER];
    input.read_exact(&mut h).ok()?;
    let op = u32::from_ne_bytes(h[0..4].try_into().unwrap());
    let len = u32::from_ne_bytes(h[4..8].try_into().unwrap()) as usize;
    if len > MAX_FRAME {
        return None;
    }
    payload.resize(len, 0);
    input.read_exact(payload).ok()?;
    Some(op)
}

fn reply(out: &Out, status: fmi2Status, results: impl FnOnce(&mut Vec<u8>)) {
    let mut frame = Vec::new();
    protocol::begin(&mut frame, REPLY);
    status.put(&mut frame);
    results(&mut frame);
    protocol::finish(&mut frame);
    let mut w = out.lock().unwrap_or_else(|e| e.into_inner());
    if w.write_all(&frame).and_then(|_| w.flush()).is_err() {
        // The master is gone.
        unsafe { libc::_exit(0) };
    }
}

/// The instance's log messages, each sent to the master at once (a crash right after a
/// message loses nothing).
fn log_sink(out: Out) -> LogSink {
    Arc::new(move |r: &LogRecord| {
        let mut frame = Vec::new();
        protocol::begin(&mut frame, LOG);
        r.status.put(&mut frame);
        r.category.as_str().put(&mut frame);
        r.message.as_str().put(&mut frame);
        protocol::finish(&mut frame);
        let mut w = out.lock().unwrap_or_else(|e| e.into_inner());
        let _ = w.write_all(&frame).and_then(|_| w.flush());
    })
}

struct Host {
    out: Out,
    /// The instance, served through the same in-process slave the master uses.
    inst: InProcess,
    vrs: Vec<fmi2ValueReference>,
    reals: Vec<f64>,
    ints: Vec<i32>,
    strings: Vec<String>,
}

impl Host {
    /// Makes one call and replies; false after fmi2FreeInstance or on a malformed request.
    fn call(&mut self, op: u32, payload: &[u8]) -> bool {
        let Some(op) = Op::from_u32(op) else {
            return false;
        };
        let mut r = Reader::new(payload);
        let inst = &mut self.inst;
        let s = match op {
            Op::FreeInstance => {
                let s = inst.free_instance();
                reply(&self.out, s, |_| {});
                return false;
            }
            Op::SetupExperiment => {
                let (td, tol, t0, sd, stop) = (r.i32(), r.f64(), r.f64(), r.i32(), r.f64());
                inst.setup_experiment((td != 0).then_some(tol), t0, (sd != 0).then_some(stop))
            }
            Op::EnterInitializationMode => inst.enter_initialization_mode(),
            Op::ExitInitializationMode => inst.exit_initialization_mode(),
            Op::Terminate => inst.terminate(),
            Op::DoStep => {
                let (t, h) = (r.f64(), r.f64());
                inst.do_step(t, h)
            }
            Op::GetBooleanStatus => {
                let (s, terminated) = inst.terminated();
                reply(&self.out, s, |o| (terminated as i32).put(o));
                return true;
            }
            Op::GetRealStatus => {
                let (s, t) = inst.last_successful_time();
                reply(&self.out, s, |o| t.put(o));
                return true;
            }
            Op::SetString => return self.set_string(r),
            Op::GetString => return self.get_string(r),
            Op::SetReal | Op::SetInteger | Op::SetBoolean => return self.set(op, r),
            Op::GetReal | Op::GetInteger | Op::GetBoolean => return self.get(op, r),
            _ => return self.state(op, r),
        };
        reply(&self.out, s, |_| {});
        true
    }

    /// Batched fmi2SetReal, Integer, Boolean from the host's reused buffers.
    fn set(&mut self, op: Op, mut r: Reader) -> bool {
        self.read_vrs(&mut r);
        let n = self.vrs.len();
        let s = match op {
            Op::SetReal => {
                self.reals.resize(n, 0.0);
                r.fill(&mut self.reals, Reader::f64);
                self.inst.set_real(&self.vrs, &self.reals)
            }
            _ => {
                self.ints.resize(n, 0);
                r.fill(&mut self.ints, Reader::i32);
                match op {
                    Op::SetInteger => self.inst.set_integer(&self.vrs, &self.ints),
                    _ => self.inst.set_boolean(&self.vrs, &self.ints),
                }
            }
        };
        reply(&self.out, s, |_| {});
        true
    }

    /// Batched fmi2GetReal, Integer, Boolean into the host's reused buffers.
    fn get(&mut self, op: Op, mut r: Reader) -> bool {
        self.read_vrs(&mut r);
        let n = self.vrs.len();
        if op == Op::GetReal {
            self.reals.resize(n, 0.0);
            let s = self.inst.get_real(&self.vrs, &mut self.reals);
            reply(&self.out, s, |o| self.reals.as_slice().put(o));
            return true;
        }
        self.ints.resize(n, 0);
        let s = match op {
            Op::GetInteger => self.inst.get_integer(&self.vrs, &mut self.ints),
            _ => self.inst.get_boolean(&self.vrs, &mut self.ints),
        };
        reply(&self.out, s, |o| self.ints.as_slice().put(o));
        true
    }

    fn set_string(&mut self, mut r: Reader) -> bool {
        self.read_vrs(&mut r);
        let cs: Vec<CString> = self
            .vrs
            .iter()
            .map(|_| CString::new(r.bytes()).unwrap_or_default())
            .collect();
        let s = self.inst.set_string(&self.vrs, &cs);
        reply(&self.out, s, |_| {});
        true
    }

    fn get_string(&mut self, mut r: Reader) -> bool {
        self.read_vrs(&mut r);
        self.strings.resize(self.vrs.len(), String::new());
        let s = self.inst.get_string(&self.vrs, &mut self.strings);
        reply(&self.out, s, |o| {
            for v in &self.strings {
                v.as_str().put(o);
            }
        });
        true
    }

    /// FMU-state calls (FMI 2.0, sec. 2.1.8); a state is a handle: the FMU's pointer.
    fn state(&mut self, op: Op, mut r: Reader) -> bool {
        if op == Op::Deserialize {
            let (s, state) = self.inst.deserialize(r.bytes());
            reply(&self.out, s, |o| state.put(o));
            return true;
        }
        let handle = r.u64();
        let arg = r.u64();
        let (s, result) = match op {
            Op::GetFmuState => self.inst.get_state(),
            Op::SerializedSize => {
                let (s, size) = self.inst.serialized_size(handle);
                (s, size as u64)
            }
            Op::Serialize => {
                if arg > MAX_STATE_BYTES as u64 {
                    return false;
                }
                let (s, bytes) = self.inst.serialize(handle, arg as usize);
                reply(&self.out, s, |o| bytes.as_slice().put(o));
                return true;
            }
            Op::SetFmuState => (self.inst.set_state(handle), 0),
            Op::FreeFmuState => self.inst.free_state(handle),
            _ => return false,
        };
        reply(&self.out, s, |o| result.put(o));
        true
    }

    fn read_vrs(&mut self, r: &mut Reader) {
        let n = r.u32() as usize;
        self.vrs.resize(n.min(r.buf.len() / 4), 0);
        r.fill(&mut self.vrs, Reader::u32);
    }
}
