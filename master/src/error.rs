//! One error type for the master. Every variant names what a user needs to find the problem:
//! the file, the instance, the variable, the value, the simulation time and the FMI status.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A problem with an FMU archive or its modelDescription/binary.
    #[error("FMU '{}': {message}", path.display())]
    Fmu { path: PathBuf, message: String },

    /// An FMI function returned a status worse than fmi2Warning (or NULL from fmi2Instantiate).
    #[error("{}", fmt_fmi(.instance, .function, *.status, .time, .log))]
    Fmi {
        instance: String,
        function: &'static str,
        status: i32,
        time: Option<f64>,
        log: Vec<String>,
    },

    /// A problem in a system description (TOML or OSP XML).
    #[error("{}{}: {message}", file.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
    System {
        file: PathBuf,
        line: Option<usize>,
        message: String,
    },

    /// Several validation errors at once.
    #[error("{} error(s):\n{}", .0.len(), .0.iter().map(|e| format!("  - {e}")).collect::<Vec<_>>().join("\n"))]
    Many(Vec<Error>),

    /// A checkpoint file that cannot be used: not one, another version, truncated, corrupt,
    /// or from a different system.
    #[error("checkpoint file {}: {message}", file.display())]
    Checkpoint { file: PathBuf, message: String },

    /// An isolated instance's process died, was killed after the call time limit, or answered
    /// wrongly during `function` ([`crate::isolate`]); `message` says how, with the FMU's last
    /// log messages.
    #[error("{message}")]
    Isolated {
        instance: String,
        function: &'static str,
        time: Option<f64>,
        message: String,
    },

    /// The run was interrupted (Ctrl-C) at the given time.
    #[error("interrupted at t = {time} s")]
    Interrupted { time: f64 },

    /// A campaign ran to its end and wrote its tables, but runs in them failed (the command
    /// line exits with status 2).
    #[error("{0}")]
    RunsFailed(String),

    #[error("{0}")]
    Other(String),

    #[error("{context}: {source}")]
    Io {
        context: String,
        #[source]
        source: std::io::Error,
    },
}

fn fmt_fmi(
    instance: &str,
    function: &str,
    status: i32,
    time: &Option<f64>,
    log: &[String],
) -> String {
    let mut s = format!(
        "instance '{instance}': {function} returned {}",
        fmi2::status_name(status)
    );
    if let Some(t) = time {
        s.push_str(&format!(" at t = {t} s"));
    }
    if !log.is_empty() {
        s.push_str("; last FMU log messages:");
        for l in log {
            s.push_str("\n    ");
            s.push_str(l);
        }
    }
    s
}

impl Error {
    pub fn fmu(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Error::Fmu {
            path: path.into(),
            message: message.into(),
        }
    }
    pub fn system(
        file: impl Into<PathBuf>,
        line: Option<usize>,
        message: impl Into<String>,
    ) -> Self {
        Error::System {
            file: file.into(),
            line,
            message: message.into(),
        }
    }
    pub fn io(context: impl Into<String>, source: std::io::Error) -> Self {
        Error::Io {
            context: context.into(),
            source,
        }
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Names within `candidates` close to `name` (edit distance), best first, for "did you mean".
pub fn suggest<'a, I>(name: &str, candidates: I) -> Vec<String>
where
    I: IntoIterator<Item = &'a str>,
{
    let lname = name.to_lowercase();
    let mut scored: Vec<(usize, &str)> = candidates
        .into_iter()
        .map(|c| (levenshtein(&lname, &c.to_lowercase()), c))
        .filter(|(d, c)| {
            let limit = (name.len().max(c.len()) / 3).max(2);
            *d <= limit || c.to_lowercase().contains(&lname) || lname.contains(&c.to_lowercase())
        })
        .collect();
    scored.sort();
    scored
        .into_iter()
        .take(3)
        .map(|(_, c)| c.to_string())
        .collect()
}

/// " (did you mean 'a', 'b'?)" or "" when nothing is close.
pub fn did_you_mean<'a, I>(name: &str, candidates: I) -> String
where
    I: IntoIterator<Item = &'a str>,
{
    let s = suggest(name, candidates);
    if s.is_empty() {
        String::new()
    } else {
        format!(
            " (did you mean {}?)",
            s.iter()
                .map(|x| format!("'{x}'"))
                .collect::<Vec<_>>()
                .join(", ")
        )
    }
}

fn levenshtein(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    let mut cur = vec![0; b.len() + 1];
    for i in 1..=a.len() {
        cur[0] = i;
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            cur[j] = (prev[j] + 1).min(cur[j - 1] + 1).min(prev[j - 1] + cost);
        }
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn suggestions() {
        let c = ["rudder_angle", "rudder_rate", "heading"];
        assert_eq!(suggest("rudder_angel", c)[0], "rudder_angle");
        assert!(suggest("zzzzzzzz", c).is_empty());
        assert_eq!(did_you_mean("Heading", c), " (did you mean 'heading'?)");
    }
}
