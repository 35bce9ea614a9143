//! The child's end: `shipsim fmu-host FMU` loads one FMU with the importer ([`crate::fmu`]),
//! instantiates it on the first request and makes each requested FMI call, replying with the
//! status and results ([`super::protocol`]). The FMU's log messages are sent back as they come.
//! When the master closes the pipe without fmi2FreeInstance (after fmi2Fatal, or when it ends),
//! the host exits without another FMI call, removing its extraction directory.
//!
//! The requests arrive on stdin and the replies leave on stdout; both are moved to other file
//! descriptors first, and stdout is pointed at stderr, so whatever the FMU prints cannot
//! corrupt the replies. On Linux the host dies with its master (PR_SET_PDEATHSIG).

use super::protocol::{self, Op, Put, Reader, HEADER, LOG, MAX_FRAME, REPLY};
use crate::fmu::{Api, Fmu};
use crate::instance::{Instance, Instantiated, LogRecord, LogSink};
use fmi2::*;
use std::ffi::CString;
use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Write};
use std::os::fd::FromRawFd;
use std::path::Path;
use std::sync::{Arc, Mutex};

/// The largest serialized state a host hands out (as [`crate::instance`] accepts).
const MAX_STATE_BYTES: u64 = 1 << 30;

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
        let inst = f.instantiate(&name, logging_on, log_sink(output.clone()))?;
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
        inst: Some(inst),
        vrs: Vec::new(),
        reals: Vec::new(),
        ints: Vec::new(),
    };
    while let Some(op) = read_frame(&mut input, &mut payload) {
        if !host.call(op, &payload) {
            break;
        }
    }
    if let Some(inst) = host.inst.take() {
        // The master left without fmi2FreeInstance: no more FMI calls (after fmi2Fatal none
        // is allowed).
        inst.abandon();
    }
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
    inst: Option<Instance<Instantiated>>,
    vrs: Vec<fmi2ValueReference>,
    reals: Vec<f64>,
    ints: Vec<i32>,
}

impl Host {
    /// Makes one call and replies; false after fmi2FreeInstance or on a malformed request.
    fn call(&mut self, op: u32, payload: &[u8]) -> bool {
        let Some(op) = Op::from_u32(op) else {
            return false;
        };
        if op == Op::FreeInstance {
            drop(self.inst.take());
            reply(&self.out, fmi2OK, |_| {});
            return false;
        }
        let Some(inst) = self.inst.as_ref() else {
            return false;
        };
        let (api, c) = inst.raw();
        // The table lives in the loaded library, which outlives this call.
        let api: *const Api = api;
        let mut r = Reader::new(payload);
        // SAFETY: the calls of FMI 2.0 with the arguments the master sent, on the instance
        // this host made; buffers are sized to the counts passed.
        unsafe {
            let api = &*api;
            match op {
                Op::SetupExperiment => {
                    let (td, tol, t0, sd, stop) = (r.i32(), r.f64(), r.f64(), r.i32(), r.f64());
                    let s = (api.fmi2SetupExperiment)(c, td, tol, t0, sd, stop);
                    reply(&self.out, s, |_| {});
                    true
                }
                Op::EnterInitializationMode => self.simple((api.fmi2EnterInitializationMode)(c)),
                Op::ExitInitializationMode => self.simple((api.fmi2ExitInitializationMode)(c)),
                Op::Terminate => self.simple((api.fmi2Terminate)(c)),
                Op::DoStep => {
                    let (t, h) = (r.f64(), r.f64());
                    self.simple((api.fmi2DoStep)(c, t, h, fmi2True))
                }
                _ => self.values(api, c, op, r),
            }
        }
    }

    fn simple(&self, s: fmi2Status) -> bool {
        reply(&self.out, s, |_| {});
        true
    }

    /// The calls that move values or states.
    unsafe fn values(&mut self, api: &Api, c: fmi2Component, op: Op, mut r: Reader) -> bool {
        match op {
            Op::SetReal
            | Op::SetInteger
            | Op::SetBoolean
            | Op::GetReal
            | Op::GetInteger
            | Op::GetBoolean => self.batch(api, c, op, r),
            Op::SetString => {
                self.read_vrs(&mut r);
                let cs: Vec<CString> = self
                    .vrs
                    .iter()
                    .map(|_| CString::new(r.bytes()).unwrap_or_default())
                    .collect();
                let ptrs: Vec<fmi2String> = cs.iter().map(|s| s.as_ptr()).collect();
                let n = self.vrs.len().min(ptrs.len());
                self.simple((api.fmi2SetString)(c, self.vrs.as_ptr(), n, ptrs.as_ptr()))
            }
            Op::GetString => {
                self.read_vrs(&mut r);
                let mut ptrs: Vec<fmi2String> = vec![std::ptr::null(); self.vrs.len()];
                let s = (api.fmi2GetString)(c, self.vrs.as_ptr(), ptrs.len(), ptrs.as_mut_ptr());
                reply(&self.out, s, |o| {
                    for p in &ptrs {
                        lossy_str(*p).as_str().put(o);
                    }
                });
                true
            }
            Op::GetBooleanStatus => {
                let mut v: fmi2Boolean = fmi2False;
                let s = (api.fmi2GetBooleanStatus)(c, r.i32(), &mut v);
                reply(&self.out, s, |o| (v as f64).put(o));
                true
            }
            Op::GetRealStatus => {
                let mut v = 0.0;
                let s = (api.fmi2GetRealStatus)(c, r.i32(), &mut v);
                reply(&self.out, s, |o| v.put(o));
                true
            }
            Op::Deserialize => {
                let bytes = r.bytes();
                let mut st: fmi2FMUstate = std::ptr::null_mut();
                let s = (api.fmi2DeSerializeFMUstate)(
                    c,
                    bytes.as_ptr() as *const fmi2Byte,
                    bytes.len(),
                    &mut st,
                );
                reply(&self.out, s, |o| (st as usize as u64).put(o));
                true
            }
            _ => self.state(api, c, op, r),
        }
    }

    /// Batched fmi2Set/GetReal, Integer, Boolean into the host's reused buffers.
    unsafe fn batch(&mut self, api: &Api, c: fmi2Component, op: Op, mut r: Reader) -> bool {
        self.read_vrs(&mut r);
        let (vr, n) = (self.vrs.as_ptr(), self.vrs.len());
        let s = match op {
            Op::SetReal => {
                self.reals.resize(n, 0.0);
                r.fill(&mut self.reals, Reader::f64);
                (api.fmi2SetReal)(c, vr, n, self.reals.as_ptr())
            }
            Op::SetInteger | Op::SetBoolean => {
                self.ints.resize(n, 0);
                r.fill(&mut self.ints, Reader::i32);
                match op {
                    Op::SetInteger => (api.fmi2SetInteger)(c, vr, n, self.ints.as_ptr()),
                    _ => (api.fmi2SetBoolean)(c, vr, n, self.ints.as_ptr()),
                }
            }
            Op::GetReal => {
                self.reals.resize(n, 0.0);
                let s = (api.fmi2GetReal)(c, vr, n, self.reals.as_mut_ptr());
                reply(&self.out, s, |o| self.reals.as_slice().put(o));
                return true;
            }
            _ => {
                self.ints.resize(n, 0);
                let s = match op {
                    Op::GetInteger => (api.fmi2GetInteger)(c, vr, n, self.ints.as_mut_ptr()),
                    _ => (api.fmi2GetBoolean)(c, vr, n, self.ints.as_mut_ptr()),
                };
                reply(&self.out, s, |o| self.ints.as_slice().put(o));
                return true;
            }
        };
        self.simple(s)
    }

    /// FMU-state calls (FMI 2.0, sec. 2.1.8); a state is a handle: the FMU's pointer.
    unsafe fn state(&mut self, api: &Api, c: fmi2Component, op: Op, mut r: Reader) -> bool {
        let mut handle = r.u64() as usize as fmi2FMUstate;
        let arg = r.u64();
        let (s, result) = match op {
            Op::GetFmuState => {
                let s = (api.fmi2GetFMUstate)(c, &mut handle);
                (s, handle as usize as u64)
            }
            Op::SerializedSize => {
                let mut size = 0usize;
                let s = (api.fmi2SerializedFMUstateSize)(c, handle, &mut size);
                (s, size as u64)
            }
            Op::Serialize => {
                if arg > MAX_STATE_BYTES {
                    return false;
                }
                let mut bytes = vec![0u8; arg as usize];
                let s = (api.fmi2SerializeFMUstate)(
                    c,
                    handle,
                    bytes.as_mut_ptr() as *mut fmi2Byte,
                    bytes.len(),
                );
                reply(&self.out, s, |o| bytes.as_slice().put(o));
                return true;
            }
            Op::SetFmuState => ((api.fmi2SetFMUstate)(c, handle), 0),
            Op::FreeFmuState => {
                let s = (api.fmi2FreeFMUstate)(c, &mut handle);
                (s, handle as usize as u64)
            }
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
