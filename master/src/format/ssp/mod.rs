//! SSP 1.0 (Modelica Association, System Structure and Parameterization) import: an `.ssp`
//! archive or a `SystemStructure.ssd` file read into a [`System`].
//!
//! - [`load`]: `.ssp` is unpacked (with the FMU importer's archive code, [`crate::fmu`]) and its
//!   `SystemStructure.ssd` read; `.ssd` is read in place, its FMUs found next to it by their
//!   relative `source` URIs (SSP 1.0, sec. 5.3.2, `Component@source`).
//! - [`xml`]: the element tree over quick-xml; [`read`]: the SSD (systems, components,
//!   connectors, connections, units, the default experiment and the fixed-step annotations);
//!   [`params`]: parameter bindings, `.ssv` parameter sets and `.ssm` parameter mappings.
//! - [`write`]: the export, a [`System`] as a self-contained `.ssp` archive.
//!
//! What is not supported is refused with an error naming the file, the line and the element
//! (`docs/ssp.md` lists both).

use crate::error::{Error, Result};
use crate::system::System;
use std::path::Path;

mod connect;
mod params;
pub mod read;
mod reader;
pub mod write;
mod xml;

/// Largest SSD, SSV or SSM file read (bytes): real ones are kilobytes.
pub const MAX_FILE_BYTES: u64 = 32 << 20;

/// The default SSD of an archive (SSP 1.0, sec. 4: `SystemStructure.ssd` at the root).
pub const DEFAULT_SSD: &str = "SystemStructure.ssd";

/// Is this path an SSP archive or an SSD file (by extension)?
pub fn is_ssp_path(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("ssp") || e.eq_ignore_ascii_case("ssd"))
}

/// Reads an `.ssp` archive or an `.ssd` file.
pub fn load(path: &Path) -> Result<System> {
    let is_archive = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("ssp"));
    if !is_archive {
        return read::read_ssd(path, path, false);
    }
    if !path.is_file() {
        return Err(Error::system(path, None, "cannot read: no such file"));
    }
    let dir =
        crate::fmu::unpack_archive(path, &crate::fmu::Unpack::default()).map_err(|e| match e {
            Error::Fmu { message, .. } => {
                Error::system(path, None, message.replace("FMU (zip)", "SSP (zip)"))
            }
            e => e,
        })?;
    let ssd = dir.path().join(DEFAULT_SSD);
    if !ssd.is_file() {
        return Err(Error::system(
            path,
            None,
            format!("the archive has no {DEFAULT_SSD} at its root"),
        ));
    }
    let mut sys = read::read_ssd(&ssd, path, true)?;
    sys.archive = Some(std::sync::Arc::new(dir));
    Ok(sys)
}

/// The contents of an SSP file, refused when larger than [`MAX_FILE_BYTES`] or not UTF-8.
pub(crate) fn read_bounded(path: &Path, shown: &Path) -> Result<String> {
    use std::io::Read;
    let f = std::fs::File::open(path)
        .map_err(|e| Error::system(shown, None, format!("cannot read: {e}")))?;
    let mut bytes = Vec::new();
    f.take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| Error::system(shown, None, format!("cannot read: {e}")))?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(Error::system(
            shown,
            None,
            format!(
                "the file is larger than {} MiB; refused",
                MAX_FILE_BYTES >> 20
            ),
        ));
    }
    String::from_utf8(bytes).map_err(|e| Error::system(shown, None, format!("not UTF-8 text: {e}")))
}
