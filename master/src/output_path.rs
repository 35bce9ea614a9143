//! The one rule for every file the master writes: run CSVs, campaign tables and series,
//! checkpoints, OSP and SSP exports, plots.
//!
//! * a path that does not exist is created;
//! * a regular file is replaced;
//! * a symbolic link to a regular file is followed: its target is written (through a temporary
//!   file beside the target where the write is atomic), and the link stays a link;
//! * anything else that exists is refused, naming what it is: a directory, a device, a FIFO, a
//!   socket, a link to one of those or to nothing. (Writing through `/dev/full` or a FIFO, or
//!   renaming a temporary file over a device node or a link, is never what the user meant.)
//!
//! The check runs before anything is written, so a refused path is left as it was.

use crate::error::{Error, Result};
use std::os::unix::fs::FileTypeExt;
use std::path::{Path, PathBuf};

/// The file to write for the output path `path` (see the module documentation): `path` itself,
/// or for a symbolic link to a regular file, that file.
pub fn writable(path: &Path) -> Result<PathBuf> {
    let Ok(meta) = std::fs::symlink_metadata(path) else {
        // nothing there (or a folder on the way that is not one): creating it says why not
        return Ok(path.to_path_buf());
    };
    if meta.file_type().is_file() {
        return Ok(path.to_path_buf());
    }
    if meta.file_type().is_symlink() {
        return match std::fs::metadata(path) {
            Ok(target) if target.is_file() => path
                .canonicalize()
                .map_err(|e| Error::io(format!("output {}", path.display()), e)),
            Ok(target) => Err(refused(
                path,
                &format!("a symbolic link to {}", kind(&target.file_type())),
            )),
            Err(_) => Err(refused(path, "a symbolic link to nothing")),
        };
    }
    Err(refused(path, kind(&meta.file_type())))
}

fn kind(t: &std::fs::FileType) -> &'static str {
    if t.is_dir() {
        "a directory"
    } else if t.is_char_device() || t.is_block_device() {
        "a device"
    } else if t.is_fifo() {
        "a FIFO (named pipe)"
    } else if t.is_socket() {
        "a socket"
    } else {
        "not a regular file"
    }
}

fn refused(path: &Path, what: &str) -> Error {
    Error::Other(format!(
        "output {} is {what}; an output must be a regular file (or a symbolic link to one), \
         which is replaced: give another path",
        path.display()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn message(p: &Path) -> String {
        writable(p).unwrap_err().to_string()
    }

    #[test]
    fn new_and_regular_files_are_written_in_place() {
        let d = tempfile::tempdir().unwrap();
        let new = d.path().join("sub/new.csv");
        assert_eq!(writable(&new).unwrap(), new);
        let file = d.path().join("old.csv");
        std::fs::write(&file, "x").unwrap();
        assert_eq!(writable(&file).unwrap(), file);
    }

    #[test]
    fn a_link_to_a_regular_file_is_followed() {
        let d = tempfile::tempdir().unwrap();
        let target = d.path().join("target.csv");
        std::fs::write(&target, "x").unwrap();
        let link = d.path().join("link.csv");
        std::os::unix::fs::symlink(&target, &link).unwrap();
        assert_eq!(writable(&link).unwrap(), target.canonicalize().unwrap());
    }

    #[test]
    fn anything_else_is_refused_naming_what_it_is() {
        let d = tempfile::tempdir().unwrap();
        assert!(message(d.path()).contains("is a directory; an output must be a regular file"));
        assert!(message(Path::new("/dev/null")).contains("/dev/null is a device"));
        let fifo = d.path().join("fifo");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        // SAFETY: a valid NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        assert!(message(&fifo).contains("is a FIFO (named pipe)"));
        let dangling = d.path().join("dangling");
        std::os::unix::fs::symlink(d.path().join("nothing"), &dangling).unwrap();
        assert!(message(&dangling).contains("is a symbolic link to nothing"));
        let to_dir = d.path().join("to_dir");
        std::os::unix::fs::symlink(d.path(), &to_dir).unwrap();
        assert!(message(&to_dir).contains("is a symbolic link to a directory"));
    }
}
