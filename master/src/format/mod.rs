//! System file formats. Each reader turns a file into the format-neutral
//! [`System`]; the writer turns one back into a file another tool runs.
//!
//! - [`toml`]: shipsim's native system file (read).
//! - [`osp`]: OSP `OspSystemStructure.xml`, libcosim's format (read and write).
//! - [`ssp`]: SSP 1.0, an `.ssp` archive or a `SystemStructure.ssd` (read).
//!
//! The readers depend on [`crate::system`]; `system` depends on no reader.

use crate::error::{Error, Result};
use crate::system::System;
use std::path::Path;

pub mod osp;
pub mod ssp;
pub mod toml;

impl System {
    /// Reads a system file: `.ssp` is an SSP 1.0 archive and `.ssd` an SSP system structure
    /// description, `.xml` is OSP `OspSystemStructure.xml`, anything else TOML.
    pub fn load(path: &Path) -> Result<System> {
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

/// 1-based line of a byte offset.
pub fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].matches('\n').count() + 1
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
