//! The child's reports to the parent: one line per event on stdout, marked by a leading
//! U+001E (record separator). The child's stderr is the same pipe, so anything the FMU prints
//! (a panic message, say) arrives in order between the records of the call that printed it.

use std::io::Write;

pub const MARK: char = '\u{1e}';

/// One record of the child.
#[derive(Clone, Debug, PartialEq)]
pub enum Record {
    /// A unit starts.
    Unit(u64),
    /// A call starts (its text).
    Begin(String),
    /// The call returned this status.
    End(i32),
    /// An fmi2OK call left a Real output non-finite (the detail names call, variable and value).
    NonFinite(String),
    /// The unit could not run (the FMU failed to load, say): a failure of the setup.
    Setup(String),
    /// The unit ended normally.
    Done(u64),
}

impl Record {
    pub fn parse(line: &str) -> Option<Record> {
        let body = line.strip_prefix(MARK)?;
        let (tag, rest) = body.split_once(' ').unwrap_or((body, ""));
        Some(match tag {
            "U" => Record::Unit(rest.parse().ok()?),
            "B" => Record::Begin(rest.to_string()),
            "E" => Record::End(rest.parse().ok()?),
            "N" => Record::NonFinite(rest.to_string()),
            "S" => Record::Setup(rest.to_string()),
            "D" => Record::Done(rest.parse().ok()?),
            _ => return None,
        })
    }

    fn line(&self) -> String {
        match self {
            Record::Unit(i) => format!("{MARK}U {i}\n"),
            Record::Begin(t) => format!("{MARK}B {}\n", one_line(t)),
            Record::End(s) => format!("{MARK}E {s}\n"),
            Record::NonFinite(t) => format!("{MARK}N {}\n", one_line(t)),
            Record::Setup(t) => format!("{MARK}S {}\n", one_line(t)),
            Record::Done(i) => format!("{MARK}D {i}\n"),
        }
    }

    /// Writes the record and flushes it (the parent must see a call begin before it hangs).
    pub fn send(&self) {
        let mut out = std::io::stdout().lock();
        let _ = out.write_all(self.line().as_bytes());
        let _ = out.flush();
    }
}

fn one_line(t: &str) -> String {
    t.replace(['\n', '\r'], " ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_round_trip() {
        for r in [
            Record::Unit(3),
            Record::Begin("doStep(t=0,h=1e9)".into()),
            Record::End(-7),
            Record::NonFinite("after doStep: y = NaN".into()),
            Record::Setup("no binary".into()),
            Record::Done(3),
        ] {
            let line = r.line();
            assert_eq!(Record::parse(line.trim_end_matches('\n')), Some(r));
        }
        assert_eq!(Record::parse("thread 'main' panicked at x"), None);
    }
}
