//! SHA-256 digests of files: what identifies an FMU or a system file in a checkpoint's
//! fingerprint and a campaign's provenance.

use crate::error::{Error, Result};
use sha2::{Digest, Sha256};
use std::path::Path;

/// SHA-256 of a file's bytes, lower-case hex. Streamed: a file of any size hashes in constant
/// memory.
pub fn file_sha256(path: &Path) -> Result<String> {
    let io = |e| Error::io(format!("cannot read {}", path.display()), e);
    let mut file = std::fs::File::open(path).map_err(io)?;
    let mut hasher = Sha256::new();
    std::io::copy(&mut file, &mut hasher).map_err(io)?;
    Ok(format!("{:x}", hasher.finalize()))
}
