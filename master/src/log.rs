//! FMU log messages: one formatted record per `fmi2CallbackLogger` call (FMI 2.0, sec. 2.1.5),
//! where they go (a [`LogSink`]), and each instance's last messages for error reports
//! ([`LogCtx`]). The C side of the logger is the in-process slave's
//! ([`crate::slave`]); an isolated instance's messages arrive over its pipe and are delivered
//! here the same way.

use fmi2::{fmi2Warning, status_name};
use std::collections::VecDeque;
use std::sync::{Arc, Mutex};

/// One formatted FMU log message.
#[derive(Debug, Clone)]
pub struct LogRecord {
    pub instance: String,
    pub status: i32,
    pub category: String,
    pub message: String,
}

/// Where FMU log messages go. The default prints warnings and worse to stderr (all with verbose).
pub type LogSink = Arc<dyn Fn(&LogRecord) + Send + Sync>;

pub fn stderr_sink(verbose: bool) -> LogSink {
    Arc::new(move |r: &LogRecord| {
        if verbose || r.status >= fmi2Warning {
            eprintln!(
                "[{}] {} {}: {}",
                r.instance,
                status_name(r.status),
                r.category,
                r.message
            );
        }
    })
}

/// What an error report says when an FMU with debug logging off logged nothing.
const NO_REASON_HINT: &str = "(none: the FMU logged no reason with debug logging off; rerun \
     with -v (loggingOn = true): some FMUs, PythonFMU's among them, report their errors only then)";

/// How many messages an instance keeps for its error reports.
const RECENT: usize = 8;

/// An instance's log: the sink and the last messages (for error reports).
pub(crate) struct LogCtx {
    name: String,
    sink: LogSink,
    recent: Mutex<VecDeque<String>>,
    /// The instance was instantiated with loggingOn = fmi2True (debug logging).
    pub(crate) debug_logging: bool,
}

impl LogCtx {
    /// The log of instance `name`, instantiated with loggingOn = `debug_logging`.
    pub(crate) fn new(name: &str, sink: LogSink, debug_logging: bool) -> LogCtx {
        LogCtx {
            name: name.to_string(),
            sink,
            recent: Mutex::new(VecDeque::new()),
            debug_logging,
        }
    }

    /// The last messages, or, when the FMU logged none, one line that says so and, if debug
    /// logging was off, how to switch it on: some FMUs (PythonFMU's) report even their errors
    /// only with debug logging on.
    pub(crate) fn recent_or_hint(&self, debug_logging: bool) -> Vec<String> {
        let recent = self.recent_lines();
        if !recent.is_empty() {
            recent
        } else if debug_logging {
            vec!["(none: the FMU logged no reason)".to_string()]
        } else {
            vec![NO_REASON_HINT.to_string()]
        }
    }

    pub(crate) fn is_empty(&self) -> bool {
        self.recent.lock().map(|r| r.is_empty()).unwrap_or(true)
    }

    /// The last messages.
    pub(crate) fn recent_lines(&self) -> Vec<String> {
        self.recent
            .lock()
            .map(|r| r.iter().cloned().collect())
            .unwrap_or_default()
    }

    /// One message of the FMU (`instance` as it named itself, empty for this instance): kept
    /// among the last ones and passed to the sink.
    pub(crate) fn deliver(&self, instance: String, status: i32, category: String, message: String) {
        let rec = LogRecord {
            instance: if instance.is_empty() {
                self.name.clone()
            } else {
                instance
            },
            status,
            category,
            message,
        };
        if let Ok(mut r) = self.recent.lock() {
            if r.len() == RECENT {
                r.pop_front();
            }
            r.push_back(format!(
                "{} {}: {}",
                status_name(rec.status),
                rec.category,
                rec.message
            ));
        }
        (self.sink)(&rec);
    }
}
