//! Resource limits on what shipsim reads: text files (system files, campaign files, model
//! descriptions) are read through [`read_text`], which refuses a file larger than a limit
//! instead of reading it whole (`shipsim run /dev/zero` would otherwise grow until killed);
//! FMU archives are unpacked under [`Limits`] (total size, number of entries, compression
//! ratio), see [`crate::fmu::Unpack`].

use crate::error::{Error, Result};
use std::io::Read;
use std::path::Path;

/// The largest system, scenario or campaign file read: 64 MiB (the largest file of the
/// repository is a few kB; an OSP file of 10,000 simulators is about 2 MB).
pub const MAX_SYSTEM_FILE: u64 = 64 << 20;

/// The largest `modelDescription.xml` read: 256 MiB (a model description with 100,000
/// variables is about 30 MB).
pub const MAX_MODEL_DESCRIPTION: u64 = 256 << 20;

/// The largest checkpoint file read: 1 GiB (the most one instance's serialized state may
/// take, `MAX_STATE_BYTES` in `instance.rs`; the checkpoints of the repository's systems are a
/// few kB).
pub const MAX_CHECKPOINT: u64 = 1 << 30;

/// Limits on unpacking one FMU archive. An archive beyond one is refused before more is
/// written than the limit, with an error naming the entry, the limit and how to raise it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Total uncompressed bytes of all entries (default 1 GiB; CLI `--max-fmu-size`).
    pub max_size: u64,
    /// Number of entries (default 10,000; CLI `--max-fmu-files`).
    pub max_files: u64,
    /// Uncompressed / compressed size of one entry that unpacks to more than
    /// [`Limits::RATIO_EXEMPT`] bytes (default 200; CLI `--max-fmu-ratio`). Deflate reaches
    /// about 1,030 on runs of one byte (a zip bomb); binaries and XML of real FMUs stay
    /// below 30.
    pub max_ratio: u64,
}

impl Limits {
    /// Entries up to this many uncompressed bytes are not checked for their ratio (a small
    /// but very repetitive XML file may compress better than [`Limits::max_ratio`]).
    pub const RATIO_EXEMPT: u64 = 1 << 20;
}

impl Default for Limits {
    fn default() -> Limits {
        Limits {
            max_size: 1 << 30,
            max_files: 10_000,
            max_ratio: 200,
        }
    }
}

/// Why [`read_limited`] could not read a file.
#[derive(Debug)]
pub enum ReadError {
    Io(std::io::Error),
    /// A directory where a file was expected.
    Directory,
    /// A device, FIFO or socket where a file was expected (what it is).
    NotRegular(&'static str),
    /// Larger than the limit (the limit in bytes).
    TooLarge(u64),
    /// Not UTF-8 (the offset of the first invalid byte).
    NotUtf8(usize),
}

impl std::fmt::Display for ReadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ReadError::Io(e) => write!(f, "{e}"),
            ReadError::Directory => write!(f, "it is a directory"),
            ReadError::NotRegular(what) => write!(f, "it is {what}, not a regular file"),
            ReadError::TooLarge(max) => write!(
                f,
                "it is larger than {}, the most shipsim reads",
                human_bytes(*max)
            ),
            ReadError::NotUtf8(at) => write!(f, "not UTF-8 text (invalid byte at offset {at})"),
        }
    }
}

/// Reads a UTF-8 text file of at most `max` bytes. A larger file (or an endless one such as
/// `/dev/zero`) is refused after reading `max + 1` bytes: memory stays bounded by the limit.
pub fn read_limited(path: &Path, max: u64) -> std::result::Result<String, ReadError> {
    regular(path)?;
    let file = std::fs::File::open(path).map_err(ReadError::Io)?;
    read_limited_from(file, max)
}

/// Refuses, before opening it, a path (after its links) that is a directory, a device, a FIFO
/// or a socket: opening a FIFO blocks until a writer comes, reading a device may never end.
pub fn regular(path: &Path) -> std::result::Result<(), ReadError> {
    use std::os::unix::fs::FileTypeExt;
    let t = match std::fs::metadata(path) {
        Ok(m) => m.file_type(),
        Err(e) => return Err(ReadError::Io(e)),
    };
    if t.is_file() {
        Ok(())
    } else if t.is_dir() {
        Err(ReadError::Directory)
    } else if t.is_fifo() {
        Err(ReadError::NotRegular("a FIFO (named pipe)"))
    } else if t.is_socket() {
        Err(ReadError::NotRegular("a socket"))
    } else {
        Err(ReadError::NotRegular("a device"))
    }
}

/// [`read_limited`] on an open file.
pub fn read_limited_from(file: std::fs::File, max: u64) -> std::result::Result<String, ReadError> {
    if file.metadata().is_ok_and(|m| m.is_dir()) {
        return Err(ReadError::Directory);
    }
    let bytes = read_bytes_from(file, max)?;
    String::from_utf8(bytes).map_err(|e| ReadError::NotUtf8(e.utf8_error().valid_up_to()))
}

/// The bytes of a file of at most `max` bytes (a binary file: a checkpoint), refused like
/// [`read_limited`] when larger.
pub fn read_bytes_limited(path: &Path, max: u64) -> std::result::Result<Vec<u8>, ReadError> {
    regular(path)?;
    let file = std::fs::File::open(path).map_err(ReadError::Io)?;
    if file.metadata().is_ok_and(|m| m.is_dir()) {
        return Err(ReadError::Directory);
    }
    read_bytes_from(file, max)
}

/// At most `max` bytes of `r`; more is [`ReadError::TooLarge`] after reading `max + 1`.
pub fn read_bytes_from(r: impl Read, max: u64) -> std::result::Result<Vec<u8>, ReadError> {
    let mut bytes = Vec::new();
    r.take(max.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(ReadError::Io)?;
    if bytes.len() as u64 > max {
        return Err(ReadError::TooLarge(max));
    }
    Ok(bytes)
}

/// [`read_limited`] for the files of a system (system, scenario and campaign files): an error
/// names the file and says what it is (`what`: "system file", "campaign file").
pub fn read_text(path: &Path, max: u64, what: &str) -> Result<String> {
    read_limited(path, max)
        .map_err(|e| Error::system(path, None, format!("cannot read the {what}: {e}")))
}

/// `1 GiB`, `64 MiB`, `1500 bytes`: whole binary units when exact, else bytes.
pub fn human_bytes(n: u64) -> String {
    for (shift, unit) in [(40, "TiB"), (30, "GiB"), (20, "MiB"), (10, "KiB")] {
        if n >= 1 << shift && n % (1 << shift) == 0 {
            return format!("{} {unit}", n >> shift);
        }
    }
    format!("{n} bytes")
}

/// Parses a size for `--max-fmu-size`: a whole number of bytes with an optional binary unit
/// `K`, `M`, `G` or `T` (`KiB`, `MiB`, ... and `KB`, `MB`, ... mean the same: powers of 1024).
pub fn parse_size(s: &str) -> std::result::Result<u64, String> {
    let t = s.trim();
    let split = t.find(|c: char| !c.is_ascii_digit()).unwrap_or(t.len());
    let (digits, unit) = t.split_at(split);
    let shift = match unit.trim().to_ascii_uppercase().as_str() {
        "" | "B" => 0,
        "K" | "KB" | "KIB" => 10,
        "M" | "MB" | "MIB" => 20,
        "G" | "GB" | "GIB" => 30,
        "T" | "TB" | "TIB" => 40,
        _ => return Err(format!("'{s}': use a number of bytes with K, M, G or T")),
    };
    let n: u64 = digits
        .parse()
        .map_err(|_| format!("'{s}': use a number of bytes with K, M, G or T"))?;
    n.checked_mul(1 << shift)
        .filter(|&n| n > 0)
        .ok_or_else(|| format!("'{s}': must be between 1 byte and 16 EiB"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes() {
        assert_eq!(parse_size("4G"), Ok(4 << 30));
        assert_eq!(parse_size("512 MiB"), Ok(512 << 20));
        assert_eq!(parse_size("1500"), Ok(1500));
        assert!(parse_size("0").is_err());
        assert!(parse_size("1.5G").is_err());
        assert!(parse_size("99999999999T").is_err());
        assert_eq!(human_bytes(1 << 30), "1 GiB");
        assert_eq!(human_bytes(64 << 20), "64 MiB");
        assert_eq!(human_bytes(1500), "1500 bytes");
    }
}
