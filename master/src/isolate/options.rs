//! A run's isolation options as its caller gives them: one parser for `shipsim run --isolate`
//! and `--call-timeout` and for Python's `System.run(isolate=..., call_timeout=...)`, with the
//! same accepted values and the same messages (docs/isolation.md).
//!
//! - [`IsolateMode::parse`]: `all` (every instance), `foreign` (the instances of FMUs not built
//!   by this project) or instance names separated by commas (`gear,autopilot`; spaces around a
//!   name are ignored). The words are lower case, as written here. An empty value names
//!   nothing and is an error.
//! - [`call_timeout`]: a positive number of seconds, at most 10^9.
//! - [`Isolation::from_options`]: both together, and every instance named is one of the
//!   system's (with close names suggested).
//!
//! Python's `isolate=True` is `all`, and its list of names is [`IsolateMode::Instances`] as
//! given; both are checked here too.

use super::{IsolateMode, Isolation};
use crate::error::did_you_mean;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The longest call time limit in seconds: longer is no limit at all (about 31 years).
pub const MAX_CALL_TIMEOUT: f64 = 1e9;

/// An isolation option that cannot be used.
#[derive(Debug, Clone, PartialEq)]
pub enum IsolationError {
    /// An `isolate` value that names nothing (empty, or only commas and spaces).
    Value(String),
    /// A call time limit that is not a positive number of seconds up to [`MAX_CALL_TIMEOUT`].
    CallTimeout(f64),
    /// An instance name that is not one of the system's.
    UnknownInstance {
        name: String,
        /// The system file.
        source: PathBuf,
        /// `" (did you mean 'x'?)"` or empty.
        suggestion: String,
    },
}

impl std::fmt::Display for IsolationError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            IsolationError::Value(v) => write!(
                f,
                "isolate \"{v}\": give all, foreign or instance names separated by commas"
            ),
            IsolationError::CallTimeout(s) => write!(
                f,
                "call timeout {s}: give a positive number of seconds (at most 1e9)"
            ),
            IsolationError::UnknownInstance {
                name,
                source,
                suggestion,
            } => write!(
                f,
                "isolate: no instance '{name}' in {}{suggestion}",
                source.display()
            ),
        }
    }
}

impl std::error::Error for IsolationError {}

impl From<IsolationError> for crate::error::Error {
    fn from(e: IsolationError) -> Self {
        crate::error::Error::Other(e.to_string())
    }
}

impl IsolateMode {
    /// `--isolate=VALUE` or Python's `isolate="VALUE"`: `all`, `foreign`, or instance names
    /// separated by commas (see the module documentation). The names are checked against a
    /// system by [`Isolation::from_options`].
    pub fn parse(value: &str) -> Result<IsolateMode, IsolationError> {
        match value.trim() {
            "all" => Ok(IsolateMode::All),
            "foreign" => Ok(IsolateMode::Foreign),
            names => {
                let names: Vec<String> = names
                    .split(',')
                    .map(|n| n.trim().to_string())
                    .filter(|n| !n.is_empty())
                    .collect();
                match names.is_empty() {
                    true => Err(IsolationError::Value(value.to_string())),
                    false => Ok(IsolateMode::Instances(names)),
                }
            }
        }
    }
}

/// `--call-timeout SECONDS` or Python's `call_timeout=SECONDS`: a positive number of seconds,
/// at most [`MAX_CALL_TIMEOUT`].
pub fn call_timeout(seconds: f64) -> Result<Duration, IsolationError> {
    match seconds.is_finite() && seconds > 0.0 && seconds <= MAX_CALL_TIMEOUT {
        true => Ok(Duration::from_secs_f64(seconds)),
        false => Err(IsolationError::CallTimeout(seconds)),
    }
}

impl Isolation {
    /// The isolation of a run of the system read from `source` with the instances named
    /// `instances`: `mode` (from [`IsolateMode::parse`], or a list of names), every name of
    /// which must be an instance, and a call time limit in seconds ([`call_timeout`]). The
    /// host is the default one.
    pub fn from_options(
        mode: IsolateMode,
        call_timeout_s: Option<f64>,
        source: &Path,
        instances: &[&str],
    ) -> Result<Isolation, IsolationError> {
        if let IsolateMode::Instances(names) = &mode {
            if let Some(name) = names.iter().find(|n| !instances.contains(&n.as_str())) {
                return Err(IsolationError::UnknownInstance {
                    name: name.clone(),
                    source: source.to_path_buf(),
                    suggestion: did_you_mean(name, instances.iter().copied()),
                });
            }
        }
        Ok(Isolation {
            mode,
            call_timeout: call_timeout_s.map(call_timeout).transpose()?,
            host: None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_names_and_messages() {
        assert_eq!(IsolateMode::parse("all"), Ok(IsolateMode::All));
        assert_eq!(IsolateMode::parse("foreign"), Ok(IsolateMode::Foreign));
        assert_eq!(
            IsolateMode::parse(" gear , autopilot,"),
            Ok(IsolateMode::Instances(vec![
                "gear".into(),
                "autopilot".into()
            ]))
        );
        for v in ["", " ", ",", " , "] {
            assert_eq!(
                IsolateMode::parse(v).unwrap_err().to_string(),
                format!("isolate \"{v}\": give all, foreign or instance names separated by commas")
            );
        }
        for s in [0.0, -1.0, f64::NAN, f64::INFINITY, 2e9] {
            assert_eq!(
                call_timeout(s).unwrap_err().to_string(),
                format!("call timeout {s}: give a positive number of seconds (at most 1e9)")
            );
        }
        assert_eq!(call_timeout(0.5), Ok(Duration::from_millis(500)));
        let names = ["ship", "gear"];
        let e = Isolation::from_options(
            IsolateMode::Instances(vec!["gear".into(), "shipp".into()]),
            None,
            Path::new("s.toml"),
            &names,
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "isolate: no instance 'shipp' in s.toml (did you mean 'ship'?)"
        );
        let ok = Isolation::from_options(IsolateMode::All, Some(2.0), Path::new("s"), &names);
        let ok = ok.unwrap();
        assert_eq!(
            (ok.mode, ok.call_timeout),
            (IsolateMode::All, Some(Duration::from_secs(2)))
        );
    }
}
