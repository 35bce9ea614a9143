//! The master's end of an isolated instance: the `shipsim fmu-host` child process and the two
//! pipes to it ([`super::protocol`]). [`Client`] is the out-of-process [`Slave`]: each call is
//! one request, answered by the host's in-process slave; each returns the fmi2Status the FMU
//! returned, or [`GONE`] when the child died, hung past the call time limit or was interrupted
//! ([`Client::error`] then says which).
//!
//! The request and reply buffers are allocated once: a call whose arguments and results fit
//! the buffers (every call of the step loop after its first) allocates nothing. Log messages
//! from the child are the exception: they are delivered to the instance's log sink as they come.

use super::protocol::{self, Put, Reader, HEADER, LOG, MAX_FRAME, REPLY};
use super::Isolation;
use crate::error::{Error, Result};
use crate::fmu::VR;
use crate::log::LogCtx;
use crate::slave::{Op, Slave, StateHandle, GONE};
use fmi2::fmi2Status;
use std::ffi::CString;
use std::io::{Read, Write};
use std::os::fd::AsRawFd;
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, ChildStdout, Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// How long the master waits between checks of the interrupt flag while a call runs.
const SLICE_MS: i32 = 100;
/// How long a child may take to exit after fmi2FreeInstance or an end of input.
const EXIT_GRACE: Duration = Duration::from_secs(2);

/// Why the child no longer answers.
#[derive(Debug, Clone)]
enum Failure {
    /// It died or was killed during `function` (the description says how).
    Died { function: &'static str, how: String },
    /// The call did not return within the time limit; the child was killed.
    TimedOut {
        function: &'static str,
        limit: Duration,
    },
    /// The interrupt flag was set while the call ran; the child was killed.
    Interrupted,
    /// The instance was freed (or abandoned) and the child has exited.
    Closed,
}

/// An FMU host process serving one instance.
pub struct Client {
    child: Child,
    to: ChildStdin,
    from: ChildStdout,
    /// The request being written.
    out: Vec<u8>,
    /// Bytes read from the child: frames from `start` to `end`.
    inb: Vec<u8>,
    start: usize,
    end: usize,
    /// The last reply's results (after its status) in `inb`.
    reply: (usize, usize),
    timeout: Option<Duration>,
    interrupt: Option<Arc<AtomicBool>>,
    instance: String,
    log: Arc<LogCtx>,
    /// The simulation time for messages: the start time, the start of a step in progress, the
    /// end of the last step.
    time: f64,
    failure: Option<Failure>,
    /// The child's extraction directory, removed here if the child cannot remove it.
    child_dir: Option<PathBuf>,
    /// fmi2FreeInstance was answered: the child exits by itself.
    freed: bool,
}

impl Client {
    /// Starts `shipsim fmu-host FMU` for instance `instance` and instantiates it there
    /// (`fmi2Instantiate` with the host's logger, FMI 2.0, sec. 2.1.5). An FMU that cannot be
    /// loaded or instantiated there is an error with the host's message.
    pub(crate) fn spawn(
        fmu: &Path,
        instance: &str,
        logging_on: bool,
        log: Arc<LogCtx>,
        iso: &Isolation,
        interrupt: Option<Arc<AtomicBool>>,
    ) -> Result<Client> {
        let (host, host_args) = iso.host_command()?;
        let mut child = Command::new(&host)
            .args(&host_args)
            .arg("fmu-host")
            .arg(fmu)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            // Its own process group: a Ctrl-C at the terminal reaches the master only, which
            // stops the child itself.
            .process_group(0)
            .spawn()
            .map_err(|e| {
                Error::io(
                    format!(
                        "instance '{instance}': cannot start the FMU host {} fmu-host",
                        host.display()
                    ),
                    e,
                )
            })?;
        let to = child.stdin.take().expect("piped");
        let from = child.stdout.take().expect("piped");
        let mut c = Client {
            child,
            to,
            from,
            out: Vec::with_capacity(1 << 12),
            inb: vec![0; 1 << 16],
            start: 0,
            end: 0,
            reply: (0, 0),
            timeout: iso.call_timeout,
            interrupt,
            instance: instance.to_string(),
            log,
            time: f64::NAN,
            failure: None,
            child_dir: None,
            freed: false,
        };
        let s = c.request(Op::Instantiate, |o| {
            instance.put(o);
            (logging_on as i32).put(o);
        });
        if s == GONE {
            return Err(c.error());
        }
        let text = c.results().string();
        if s != fmi2::fmi2OK {
            c.freed = true;
            return Err(Error::Other(text));
        }
        c.child_dir = Some(PathBuf::from(text));
        Ok(c)
    }

    /// The child's process id.
    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// Sends one call and waits for its reply; the status, or [`GONE`].
    fn request(&mut self, op: Op, args: impl FnOnce(&mut Vec<u8>)) -> fmi2Status {
        if self.failure.is_some() {
            return GONE;
        }
        protocol::begin(&mut self.out, op as u32);
        args(&mut self.out);
        protocol::finish(&mut self.out);
        if self.to.write_all(&self.out).is_err() {
            self.died(op);
            return GONE;
        }
        self.await_reply(op)
    }

    /// Reads frames until the reply: log messages go to the sink.
    fn await_reply(&mut self, op: Op) -> fmi2Status {
        loop {
            match self.next_frame() {
                Some((REPLY, a, b)) if b - a >= 4 => {
                    self.reply = (a + 4, b);
                    return i32::from_ne_bytes(self.inb[a..a + 4].try_into().unwrap());
                }
                Some((LOG, a, b)) => self.deliver_log(a, b),
                Some(_) => {
                    let _ = self.child.kill();
                    self.died(op);
                    return GONE;
                }
                None => {
                    if !self.fill(op) {
                        return GONE;
                    }
                }
            }
        }
    }

    /// The next whole frame in the buffer: (tag, payload start, payload end).
    #[inline]
    fn next_frame(&mut self) -> Option<(u32, usize, usize)> {
        if self.end - self.start < HEADER {
            return None;
        }
        let h = &self.inb[self.start..self.start + HEADER];
        let tag = u32::from_ne_bytes(h[0..4].try_into().unwrap());
        let len = u32::from_ne_bytes(h[4..8].try_into().unwrap()) as usize;
        if self.end - self.start < HEADER + len {
            return None;
        }
        let a = self.start + HEADER;
        self.start = a + len;
        Some((tag, a, a + len))
    }

    /// Reads more bytes from the child (waiting for them with the time limit and the interrupt
    /// flag); false when the child is gone.
    fn fill(&mut self, op: Op) -> bool {
        if self.start == self.end {
            self.start = 0;
            self.end = 0;
        }
        let need = self.pending_frame_len();
        if need > MAX_FRAME {
            let _ = self.child.kill();
            self.died(op);
            return false;
        }
        if self.inb.len() - self.start < need.max(HEADER) || self.end == self.inb.len() {
            self.inb.copy_within(self.start..self.end, 0);
            self.end -= self.start;
            self.start = 0;
            if self.inb.len() < need {
                self.inb.resize(need, 0);
            }
        }
        if !self.wait_readable(op) {
            return false;
        }
        match self.from.read(&mut self.inb[self.end..]) {
            Ok(0) | Err(_) => {
                self.died(op);
                false
            }
            Ok(n) => {
                self.end += n;
                true
            }
        }
    }

    /// The length of the frame being received, once its header is in.
    fn pending_frame_len(&self) -> usize {
        if self.end - self.start < HEADER {
            return HEADER;
        }
        let h = &self.inb[self.start + 4..self.start + 8];
        HEADER + u32::from_ne_bytes(h.try_into().unwrap()) as usize
    }

    /// Waits until the child's pipe is readable; false (the child killed, the failure noted)
    /// on the time limit or an interrupt.
    fn wait_readable(&mut self, op: Op) -> bool {
        let fd = self.from.as_raw_fd();
        let mut since: Option<Instant> = None;
        loop {
            let mut pfd = libc::pollfd {
                fd,
                events: libc::POLLIN,
                revents: 0,
            };
            // SAFETY: one valid pollfd.
            let r = unsafe { libc::poll(&mut pfd, 1, SLICE_MS) };
            if r != 0 {
                // Readable, closed, or an error (EINTR included): the read says which.
                if r > 0
                    || std::io::Error::last_os_error().kind() != std::io::ErrorKind::Interrupted
                {
                    return true;
                }
            }
            let began = *since
                .get_or_insert_with(|| Instant::now() - Duration::from_millis(SLICE_MS as u64));
            if self
                .interrupt
                .as_ref()
                .is_some_and(|f| f.load(Ordering::Relaxed))
            {
                self.kill(Failure::Interrupted);
                return false;
            }
            if let Some(limit) = self.timeout.filter(|l| began.elapsed() >= *l) {
                let function = op.name();
                self.kill(Failure::TimedOut { function, limit });
                return false;
            }
        }
    }

    fn kill(&mut self, why: Failure) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        self.failure = Some(why);
        self.remove_child_dir();
    }

    /// The child closed its pipe or could not be written to during `op`: how it ended.
    #[cold]
    fn died(&mut self, op: Op) {
        let status = self.reap();
        self.failure = Some(Failure::Died {
            function: op.name(),
            how: describe(status),
        });
        self.remove_child_dir();
    }

    /// Waits for the child to exit (killing it after [`EXIT_GRACE`]).
    fn reap(&mut self) -> Option<ExitStatus> {
        let until = Instant::now() + EXIT_GRACE;
        loop {
            match self.child.try_wait() {
                Ok(Some(s)) => return Some(s),
                Ok(None) if Instant::now() < until => std::thread::sleep(Duration::from_millis(2)),
                _ => {
                    let _ = self.child.kill();
                    return self.child.wait().ok();
                }
            }
        }
    }

    /// A killed or crashed child cannot remove its extraction directory: do it here.
    fn remove_child_dir(&mut self) {
        if let Some(d) = self.child_dir.take() {
            let ours = d
                .file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("shipsim-fmu-"));
            if ours && d.is_dir() {
                let _ = std::fs::remove_dir_all(&d);
            }
        }
    }

    fn deliver_log(&mut self, a: usize, b: usize) {
        let mut r = Reader::new(&self.inb[a..b]);
        let status = r.i32();
        let category = r.string();
        let message = r.string();
        self.log.deliver(String::new(), status, category, message);
    }

    /// The results of the last reply, after its status.
    fn results(&self) -> Reader<'_> {
        Reader::new(&self.inb[self.reply.0..self.reply.1])
    }

    /// The error for a call that returned [`GONE`]: the instance, the call, the simulation
    /// time, how the child ended, and the FMU's last log messages.
    pub fn error(&self) -> Error {
        let t = self.time;
        let at = match t.is_nan() {
            true => String::new(),
            false => format!(" at t = {t} s"),
        };
        let (function, msg) = match &self.failure {
            Some(Failure::Interrupted) => return Error::Interrupted { time: t },
            Some(Failure::Died { function, how }) => (*function, format!(
                "instance '{}': the FMU's process {how} during {function}{at} (isolated: the master and the other instances are unaffected)",
                self.instance
            )),
            Some(Failure::TimedOut { function, limit }) => (*function, format!(
                "instance '{}': {function}{at} did not return within {} s (the call time limit); its process was killed",
                self.instance,
                limit.as_secs_f64()
            )),
            Some(Failure::Closed) => ("", format!(
                "instance '{}': called after fmi2FreeInstance",
                self.instance
            )),
            None => ("", format!("instance '{}': the FMU host answered wrongly", self.instance)),
        };
        let log = self.log.recent_lines();
        let message = match log.is_empty() {
            true => msg,
            false => format!("{msg}; last FMU log messages:\n    {}", log.join("\n    ")),
        };
        Error::Isolated {
            instance: self.instance.clone(),
            function,
            time: (!t.is_nan()).then_some(t),
            message,
        }
    }

    /// Ends the child without more FMI calls (after fmi2Fatal, or when it is gone): its input
    /// is closed, so it exits and removes its directory; killed after a grace time.
    pub fn abandon(mut self) {
        self.close();
    }

    fn close(&mut self) {
        if self.failure.is_some() {
            return;
        }
        // Closing our end of its input ends the host's loop (a duplicate handle replaces it).
        let devnull = std::fs::File::open("/dev/null").ok();
        if let Some(f) = devnull {
            // SAFETY: dup2 onto our own pipe fd: the pipe's write end is closed atomically.
            unsafe { libc::dup2(f.as_raw_fd(), self.to.as_raw_fd()) };
        }
        let status = self.reap();
        if !status.is_some_and(|s| s.success()) {
            self.remove_child_dir();
        }
        self.failure = Some(Failure::Closed);
    }
}

impl Drop for Client {
    fn drop(&mut self) {
        self.close();
    }
}

/// How a child ended, in words.
fn describe(status: Option<ExitStatus>) -> String {
    let Some(s) = status else {
        return "ended (its status is unknown)".into();
    };
    if let Some(sig) = s.signal() {
        let name = match sig {
            libc::SIGSEGV => " (SIGSEGV, a segmentation fault)",
            libc::SIGABRT => " (SIGABRT: abort() or a failed assertion)",
            libc::SIGBUS => " (SIGBUS)",
            libc::SIGFPE => " (SIGFPE)",
            libc::SIGILL => " (SIGILL)",
            libc::SIGKILL => " (SIGKILL)",
            libc::SIGTERM => " (SIGTERM)",
            _ => "",
        };
        return format!("was killed by signal {sig}{name}");
    }
    match s.code() {
        Some(c) => format!("exited with status {c} (the FMU called exit())"),
        None => "ended".into(),
    }
}

/// The FMI calls, one request each (FMI 2.0, sec. 2.1 and 4.2). The arguments and results are
/// those of the C functions; FMU states are handles into the child. The calls of the step loop
/// are out of line, so that the in-process path of an instance's calls stays small.
impl Slave for Client {
    fn setup_experiment(&mut self, tol: Option<f64>, start: f64, stop: Option<f64>) -> fmi2Status {
        self.time = start;
        self.request(Op::SetupExperiment, |o| {
            (tol.is_some() as i32).put(o);
            tol.unwrap_or(0.0).put(o);
            start.put(o);
            (stop.is_some() as i32).put(o);
            stop.unwrap_or(0.0).put(o);
        })
    }

    fn enter_initialization_mode(&mut self) -> fmi2Status {
        self.request(Op::EnterInitializationMode, |_| {})
    }

    fn exit_initialization_mode(&mut self) -> fmi2Status {
        self.request(Op::ExitInitializationMode, |_| {})
    }

    #[inline(never)]
    fn do_step(&mut self, t: f64, h: f64) -> fmi2Status {
        self.time = t;
        let s = self.request(Op::DoStep, |o| {
            t.put(o);
            h.put(o);
        });
        if s == fmi2::fmi2OK || s == fmi2::fmi2Warning {
            self.time = t + h;
        }
        s
    }

    fn terminate(&mut self) -> fmi2Status {
        self.request(Op::Terminate, |_| {})
    }

    /// fmi2FreeInstance: the child frees the instance and exits.
    fn free_instance(&mut self) -> fmi2Status {
        if self.freed || self.failure.is_some() {
            return fmi2::fmi2OK;
        }
        let s = self.request(Op::FreeInstance, |_| {});
        if s != GONE {
            self.freed = true;
            let status = self.reap();
            if !status.is_some_and(|s| s.success()) {
                self.died(Op::FreeInstance);
                return GONE;
            }
            self.failure = Some(Failure::Closed);
        }
        s
    }

    #[inline(never)]
    fn set_real(&mut self, vrs: &[VR], values: &[f64]) -> fmi2Status {
        self.set(Op::SetReal, vrs, values)
    }

    #[inline(never)]
    fn set_integer(&mut self, vrs: &[VR], values: &[i32]) -> fmi2Status {
        self.set(Op::SetInteger, vrs, values)
    }

    #[inline(never)]
    fn set_boolean(&mut self, vrs: &[VR], values: &[i32]) -> fmi2Status {
        self.set(Op::SetBoolean, vrs, values)
    }

    fn set_string(&mut self, vrs: &[VR], values: &[CString]) -> fmi2Status {
        self.request(Op::SetString, |o| {
            (vrs.len() as u32).put(o);
            vrs.put(o);
            for v in values {
                v.as_bytes().put(o);
            }
        })
    }

    #[inline(never)]
    fn get_real(&mut self, vrs: &[VR], out: &mut [f64]) -> fmi2Status {
        let s = self.get(Op::GetReal, vrs);
        self.results().fill(out, Reader::f64);
        s
    }

    #[inline(never)]
    fn get_integer(&mut self, vrs: &[VR], out: &mut [i32]) -> fmi2Status {
        let s = self.get(Op::GetInteger, vrs);
        self.results().fill(out, Reader::i32);
        s
    }

    #[inline(never)]
    fn get_boolean(&mut self, vrs: &[VR], out: &mut [i32]) -> fmi2Status {
        let s = self.get(Op::GetBoolean, vrs);
        self.results().fill(out, Reader::i32);
        s
    }

    fn get_string(&mut self, vrs: &[VR], out: &mut [String]) -> fmi2Status {
        let s = self.get(Op::GetString, vrs);
        let mut r = self.results();
        for o in out.iter_mut() {
            *o = r.string();
        }
        s
    }

    fn terminated(&mut self) -> (fmi2Status, bool) {
        let s = self.request(Op::GetBooleanStatus, |_| {});
        (s, self.results().i32() != 0)
    }

    fn last_successful_time(&mut self) -> (fmi2Status, f64) {
        let s = self.request(Op::GetRealStatus, |_| {});
        (s, self.results().f64())
    }

    fn get_state(&mut self) -> (fmi2Status, StateHandle) {
        self.state_call(Op::GetFmuState, 0)
    }

    fn set_state(&mut self, state: StateHandle) -> fmi2Status {
        self.state_call(Op::SetFmuState, state).0
    }

    fn free_state(&mut self, state: StateHandle) -> (fmi2Status, StateHandle) {
        self.state_call(Op::FreeFmuState, state)
    }

    fn serialized_size(&mut self, state: StateHandle) -> (fmi2Status, usize) {
        let (s, n) = self.state_call(Op::SerializedSize, state);
        (s, n as usize)
    }

    fn serialize(&mut self, state: StateHandle, size: usize) -> (fmi2Status, Vec<u8>) {
        let s = self.request(Op::Serialize, |o| {
            state.put(o);
            (size as u64).put(o);
        });
        (s, self.results().bytes().to_vec())
    }

    fn deserialize(&mut self, bytes: &[u8]) -> (fmi2Status, StateHandle) {
        let s = self.request(Op::Deserialize, |o| bytes.put(o));
        (s, self.results().u64())
    }

    fn lost(&self) -> Option<Error> {
        self.failure.as_ref().map(|_| self.error())
    }
}

impl Client {
    fn set<T: Copy>(&mut self, op: Op, vrs: &[u32], values: &[T]) -> fmi2Status
    where
        for<'a> &'a [T]: Put,
    {
        self.request(op, |o| {
            (vrs.len() as u32).put(o);
            vrs.put(o);
            values.put(o);
        })
    }

    fn get(&mut self, op: Op, vrs: &[u32]) -> fmi2Status {
        self.request(op, |o| {
            (vrs.len() as u32).put(o);
            vrs.put(o);
        })
    }

    /// A call on an FMU state handle (or none) that returns a handle or a size as u64 (the
    /// request's second u64, the size of [`Op::Serialize`], is 0).
    fn state_call(&mut self, op: Op, handle: StateHandle) -> (fmi2Status, u64) {
        let s = self.request(op, |o| {
            handle.put(o);
            0u64.put(o);
        });
        (s, self.results().u64())
    }
}
