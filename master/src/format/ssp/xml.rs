//! A small element tree over quick-xml for the SSP files (SSD, SSV, SSM): local names (the
//! `ssd:`, `ssc:`, `ssv:`, `ssm:` prefixes dropped, as the SSP 1.0 schemas qualify every element),
//! attributes by local name, and the line of each element for error messages. Text content is
//! not kept: SSP 1.0 carries everything the reader needs in attributes.
//!
//! Bounded: at most [`MAX_DEPTH`] levels and [`MAX_ELEMENTS`] elements, so a hostile file
//! cannot exhaust the stack or the memory.

use crate::error::{Error, Result};
use crate::format::LineIndex;
use quick_xml::events::{BytesStart, Event};
use std::path::Path;

/// Deepest element nesting accepted (SSP files nest systems; 64 levels is far beyond any real one).
pub const MAX_DEPTH: usize = 64;
/// Most elements accepted in one file.
pub const MAX_ELEMENTS: usize = 1_000_000;

/// One XML element: local name, attributes (local names, unescaped values), children, line.
#[derive(Debug, Clone)]
pub struct Element {
    pub name: String,
    pub attrs: Vec<(String, String)>,
    pub children: Vec<Element>,
    pub line: usize,
}

impl Element {
    /// The attribute's value, by local name.
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }

    /// The first child with this local name.
    pub fn child(&self, name: &str) -> Option<&Element> {
        self.children.iter().find(|c| c.name == name)
    }

    /// The children with this local name.
    pub fn children_named<'s>(&'s self, name: &'s str) -> impl Iterator<Item = &'s Element> {
        self.children.iter().filter(move |c| c.name == name)
    }
}

/// 1-based line of a byte offset.
fn line_at(lines: &LineIndex, pos: u64) -> usize {
    lines.line(usize::try_from(pos).unwrap_or(usize::MAX))
}

fn start(e: &BytesStart, line: usize, path: &Path) -> Result<Element> {
    let name = String::from_utf8_lossy(e.local_name().as_ref()).into_owned();
    let mut attrs = Vec::new();
    for a in e.attributes() {
        let a = a.map_err(|err| {
            Error::system(path, Some(line), format!("<{name}>: bad attribute: {err}"))
        })?;
        let key = String::from_utf8_lossy(a.key.local_name().as_ref()).into_owned();
        if a.key.as_ref().starts_with(b"xmlns") {
            continue;
        }
        let value = a.unescape_value().map_err(|err| {
            Error::system(
                path,
                Some(line),
                format!("<{name}>: bad value of attribute '{key}': {err}"),
            )
        })?;
        attrs.push((key, value.into_owned()));
    }
    Ok(Element {
        name,
        attrs,
        children: Vec::new(),
        line,
    })
}

/// Parses `text` (the contents of `path`) into its root element; an error names the file and the
/// line where the XML goes wrong.
pub fn parse(path: &Path, text: &str) -> Result<Element> {
    let mut reader = quick_xml::Reader::from_str(text);
    reader.config_mut().trim_text(true);
    let mut stack: Vec<Element> = Vec::new();
    let mut root: Option<Element> = None;
    let mut count = 0usize;
    let lines = LineIndex::new(text);
    let bad = |pos: u64, msg: String| Error::system(path, Some(line_at(&lines, pos)), msg);
    loop {
        let pos = reader.buffer_position();
        let event = reader
            .read_event()
            .map_err(|e| bad(reader.error_position(), format!("not well-formed XML: {e}")))?;
        match event {
            Event::Start(e) | Event::Empty(e) if root.is_some() => {
                return Err(bad(
                    pos,
                    format!(
                        "<{}> after the root element",
                        String::from_utf8_lossy(e.local_name().as_ref())
                    ),
                ));
            }
            Event::Start(e) => {
                count += 1;
                if stack.len() >= MAX_DEPTH || count > MAX_ELEMENTS {
                    return Err(bad(
                        pos,
                        format!(
                            "the XML is nested deeper than {MAX_DEPTH} levels or has more than {MAX_ELEMENTS} elements"
                        ),
                    ));
                }
                stack.push(start(&e, line_at(&lines, pos), path)?);
            }
            Event::Empty(e) => {
                count += 1;
                if count > MAX_ELEMENTS {
                    return Err(bad(
                        pos,
                        format!("the XML has more than {MAX_ELEMENTS} elements"),
                    ));
                }
                let el = start(&e, line_at(&lines, pos), path)?;
                match stack.last_mut() {
                    Some(parent) => parent.children.push(el),
                    None => root = Some(el),
                }
            }
            Event::End(_) => {
                // quick-xml checks that end tags match their start tags
                let el = stack
                    .pop()
                    .ok_or_else(|| bad(pos, "unmatched end tag".into()))?;
                match stack.last_mut() {
                    Some(parent) => parent.children.push(el),
                    None => root = Some(el),
                }
            }
            Event::Eof => break,
            _ => {}
        }
    }
    if let Some(open) = stack.last() {
        return Err(Error::system(
            path,
            Some(open.line),
            format!("not well-formed XML: <{}> is never closed", open.name),
        ));
    }
    root.ok_or_else(|| Error::system(path, None, "no XML root element"))
}
