//! System file formats. Each reader turns a file into the format-neutral
//! [`System`]; the writer turns one back into a file another tool runs.
//!
//! - [`toml`]: shipsim's native system file (read).
//! - [`osp`]: OSP `OspSystemStructure.xml`, libcosim's format (read and write).
//! - [`ssp`]: SSP 1.0, an `.ssp` archive or a `SystemStructure.ssd` (read).
//! - [`fmu`]: one `.fmu` run alone over its default experiment (read).
//!
//! The readers depend on [`crate::system`]; `system` depends on no reader.

use crate::error::{Error, Result};
use crate::system::System;
use std::path::Path;

pub mod fmu;
pub mod osp;
pub mod ssp;
pub mod toml;

impl System {
    /// Reads a system file: `.ssp` is an SSP 1.0 archive and `.ssd` an SSP system structure
    /// description, `.xml` is OSP `OspSystemStructure.xml`, `.fmu` one FMU run alone,
    /// anything else TOML.
    pub fn load(path: &Path) -> Result<System> {
        if fmu::is_fmu_path(path) {
            return fmu::load(path);
        }
        if ssp::is_ssp_path(path) {
            return ssp::load(path);
        }
        let is_xml = path
            .extension()
            .map(|e| e.eq_ignore_ascii_case("xml"))
            .unwrap_or(false);
        let text = crate::limits::read_text(path, crate::limits::MAX_SYSTEM_FILE, "system file")?;
        if is_xml {
            osp::parse(path, &text)
        } else {
            toml::parse(path, &text)
        }
    }
}

/// The line numbers of one text: the offsets of its newlines, found once, so that each lookup
/// is a binary search. A reader that numbers every entry of a file builds one and reads in
/// linear time (counting the newlines before each entry took 30 s for 32,000 `[[events]]`,
/// issue 36).
pub struct LineIndex {
    newlines: Vec<usize>,
}

impl LineIndex {
    pub fn new(text: &str) -> LineIndex {
        let newlines = text
            .bytes()
            .enumerate()
            .filter(|&(_, b)| b == b'\n')
            .map(|(i, _)| i)
            .collect();
        LineIndex { newlines }
    }

    /// 1-based line of a byte offset: one more than the newlines before it (an offset past
    /// the end is on the last line).
    pub fn line(&self, offset: usize) -> usize {
        self.newlines.partition_point(|&n| n < offset) + 1
    }
}

/// The errors a reader collected, as one error (or `Ok` when there are none).
pub(crate) fn collected(mut errors: Vec<Error>) -> Result<()> {
    match errors.len() {
        0 => Ok(()),
        1 => Err(errors.pop().unwrap()),
        _ => Err(Error::Many(errors)),
    }
}

/// The warning of an export to `format` (a file OSP or SSP tools read) for the instances with
/// `isolate = true`, which neither format can carry; None when there are none.
pub(crate) fn isolation_left_out(sys: &crate::system::System, format: &str) -> Option<String> {
    let isolated: Vec<&str> = sys
        .instances
        .iter()
        .filter(|i| i.isolate)
        .map(|i| i.name.as_str())
        .collect();
    (!isolated.is_empty()).then(|| {
        format!(
            "`isolate = true` ({}) is not part of {format} and is left out: run it with \
             --isolate={}",
            isolated.join(", "),
            isolated.join(",")
        )
    })
}

#[cfg(test)]
mod tests {
    use super::LineIndex;

    /// The index gives every offset the line a count of the newlines before it gives.
    #[test]
    fn line_index_counts_the_newlines_before_an_offset() {
        for text in [
            "",
            "a",
            "\n",
            "a\nb",
            "a\r\nb\n\nc\n",
            "é\nü\n\nx",
            "\n\n\n",
        ] {
            let lines = LineIndex::new(text);
            for offset in 0..text.len() + 3 {
                let before = &text.as_bytes()[..offset.min(text.len())];
                let count = before.iter().filter(|&&b| b == b'\n').count();
                assert_eq!(lines.line(offset), count + 1, "{text:?} at {offset}");
            }
        }
    }
}
