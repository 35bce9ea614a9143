//! Watching a child process: its records and stray output as lines from one pipe (stdout and
//! stderr joined), its CPU time from /proc, and the per-call limit.

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{channel, Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

/// How long one call may take: `cpu` of the child's CPU time (so that a loaded machine does
/// not make a slow call a hang), and `wall` for a call that blocks without computing (long
/// enough that a computing call on a machine loaded many times over reaches the CPU limit
/// first).
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    pub cpu: Duration,
    pub wall: Duration,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            cpu: Duration::from_secs(1),
            wall: Duration::from_secs(60),
        }
    }
}

/// A running child with its output as a stream of lines.
pub struct Watched {
    pub child: Child,
    lines: Receiver<String>,
}

/// What the next poll of a child gave.
pub enum Poll {
    Line(String),
    Quiet,
    Eof,
}

impl Watched {
    /// Starts `cmd` with stdout and stderr on one pipe.
    pub fn spawn(mut cmd: Command) -> std::io::Result<Watched> {
        let (reader, writer) = std::io::pipe()?;
        cmd.stdin(Stdio::null())
            .stdout(writer.try_clone()?)
            .stderr(writer);
        let child = cmd.spawn()?;
        // The parent's copies of the write end are gone with `cmd`.
        drop(cmd);
        let (tx, rx) = channel();
        std::thread::spawn(move || {
            let mut r = BufReader::new(reader);
            let mut buf = Vec::new();
            loop {
                buf.clear();
                match r.read_until(b'\n', &mut buf) {
                    Ok(0) | Err(_) => break,
                    Ok(_) => {
                        let line = String::from_utf8_lossy(&buf)
                            .trim_end_matches(['\n', '\r'])
                            .to_string();
                        if tx.send(line).is_err() {
                            break;
                        }
                    }
                }
            }
        });
        Ok(Watched { child, lines: rx })
    }

    pub fn poll(&self, wait: Duration) -> Poll {
        match self.lines.recv_timeout(wait) {
            Ok(l) => Poll::Line(l),
            Err(RecvTimeoutError::Timeout) => Poll::Quiet,
            Err(RecvTimeoutError::Disconnected) => Poll::Eof,
        }
    }

    /// CPU time (user + system) the child has used so far.
    pub fn cpu(&self) -> Duration {
        cpu_of(self.child.id())
    }

    pub fn kill(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// CPU time of process `pid` from /proc/<pid>/stat (fields 14 and 15, utime and stime, in
/// clock ticks: proc(5)); zero when it cannot be read.
pub fn cpu_of(pid: u32) -> Duration {
    let Ok(stat) = std::fs::read_to_string(format!("/proc/{pid}/stat")) else {
        return Duration::ZERO;
    };
    // The command name may hold spaces and parentheses: fields follow the last ')'.
    let Some(rest) = stat.rfind(')').map(|i| &stat[i + 1..]) else {
        return Duration::ZERO;
    };
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: u64 = f.get(11).and_then(|x| x.parse().ok()).unwrap_or(0)
        + f.get(12).and_then(|x| x.parse().ok()).unwrap_or(0);
    // SAFETY: sysconf has no preconditions.
    let hz = unsafe { libc::sysconf(libc::_SC_CLK_TCK) }.max(1) as u64;
    Duration::from_nanos(ticks.saturating_mul(1_000_000_000) / hz)
}

/// A call in progress: when it started, in wall and CPU time.
#[derive(Clone, Copy)]
pub struct InCall {
    pub wall: Instant,
    pub cpu: Duration,
}

impl InCall {
    pub fn now(w: &Watched) -> InCall {
        InCall {
            wall: Instant::now(),
            cpu: w.cpu(),
        }
    }

    /// Whether the call has gone over a limit; the description of the overrun.
    pub fn over(&self, w: &Watched, limits: &Limits) -> Option<String> {
        let cpu = w.cpu().saturating_sub(self.cpu);
        let wall = self.wall.elapsed();
        if cpu > limits.cpu {
            Some(format!(
                "still running after {:.1} s of CPU time (limit {:.1} s)",
                cpu.as_secs_f64(),
                limits.cpu.as_secs_f64()
            ))
        } else if wall > limits.wall {
            Some(format!(
                "blocked for {:.1} s of wall time (limit {:.1} s)",
                wall.as_secs_f64(),
                limits.wall.as_secs_f64()
            ))
        } else {
            None
        }
    }
}

/// How a process ended, in words (exit code or signal).
pub fn describe_exit(status: std::process::ExitStatus) -> String {
    use std::os::unix::process::ExitStatusExt;
    if let Some(sig) = status.signal() {
        let name = match sig {
            libc::SIGSEGV => "SIGSEGV",
            libc::SIGABRT => "SIGABRT",
            libc::SIGBUS => "SIGBUS",
            libc::SIGFPE => "SIGFPE",
            libc::SIGILL => "SIGILL",
            libc::SIGKILL => "SIGKILL",
            libc::SIGTRAP => "SIGTRAP",
            _ => "signal",
        };
        format!("killed by {name} ({sig})")
    } else {
        format!("exited with status {}", status.code().unwrap_or(-1))
    }
}
