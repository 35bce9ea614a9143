//! OSP `OspSystemStructure.xml` (libcosim's format) read and write.
use crate::error::{Error, Result};
use crate::system::System;
use std::path::Path;

pub fn parse(path: &Path, _text: &str) -> Result<System> {
    Err(Error::system(path, None, "OSP not yet supported"))
}

pub fn write(_s: &System, _out: &Path) -> Result<Vec<String>> {
    Err(Error::Other("not yet".into()))
}
