//! The variable groups of an OSP model (`<modelName>_OspModelDescription.xml`, OSP Interface
//! Specification): named groups such as `LinearMechanicalPort`, `Force`, `LinearVelocity` or any
//! other element name, each holding `<Variable ref="..."/>` elements and nested groups.
//!
//! Found as libcosim finds it (`src/cosim/osp_config_parser.cpp`, `load_osp_config`): the file
//! named after the FMU's `modelName` beside the FMU, else beside the `OspSystemStructure.xml`.
//! The group type (the element name) is not checked: libcosim connects groups by name and
//! position only.

use crate::error::{Error, Result};
use crate::limits;
use crate::model_description::ModelDescription;
use quick_xml::events::{BytesStart, Event};
use std::path::{Path, PathBuf};

/// One variable group: its variables (`<Variable ref>`) and nested groups, in file order.
#[derive(Debug, Clone, Default)]
pub(crate) struct Group {
    pub name: String,
    pub variables: Vec<String>,
    pub groups: Vec<Group>,
}

/// The variable groups of one simulator's model, and the file they came from.
#[derive(Debug)]
pub(crate) struct Groups {
    pub file: PathBuf,
    pub top: Vec<Group>,
}

impl Groups {
    /// The group named `name`: a top-level one, else one nested (depth first), as libcosim's
    /// `get_variable_group_variables` looks it up.
    pub fn find(&self, name: &str) -> Option<&Group> {
        fn within<'g>(groups: &'g [Group], name: &str) -> Option<&'g Group> {
            groups
                .iter()
                .find(|g| g.name == name)
                .or_else(|| groups.iter().find_map(|g| within(&g.groups, name)))
        }
        within(&self.top, name)
    }

    /// The top-level group named `name` (libcosim's `VectorSum` looks only there).
    pub fn top_level(&self, name: &str) -> Option<&Group> {
        self.top.iter().find(|g| g.name == name)
    }
}

/// The `modelName` in the FMU's `modelDescription.xml` (read from the archive, nothing
/// unpacked).
fn model_name(fmu: &Path) -> Result<String> {
    let file =
        std::fs::File::open(fmu).map_err(|e| Error::fmu(fmu, format!("cannot open: {e}")))?;
    let mut zip = zip::ZipArchive::new(file)
        .map_err(|e| Error::fmu(fmu, format!("not a valid FMU (zip) archive: {e}")))?;
    let entry = zip
        .by_name("modelDescription.xml")
        .map_err(|e| Error::fmu(fmu, format!("no modelDescription.xml: {e}")))?;
    let bytes = limits::read_bytes_from(entry, limits::MAX_MODEL_DESCRIPTION)
        .map_err(|e| Error::fmu(fmu, format!("cannot read modelDescription.xml: {e}")))?;
    let xml = String::from_utf8(bytes)
        .map_err(|e| Error::fmu(fmu, format!("modelDescription.xml is not UTF-8: {e}")))?;
    let md = ModelDescription::parse(&xml)
        .map_err(|e| Error::fmu(fmu, format!("modelDescription.xml does not parse: {e}")))?;
    Ok(md.model_name)
}

/// The variable groups of the model in `fmu`, from `<modelName>_OspModelDescription.xml` beside
/// the FMU or else in `config_dir`; `None` when there is no such file.
pub(crate) fn load(fmu: &Path, config_dir: &Path) -> Result<Option<Groups>> {
    let name = format!("{}_OspModelDescription.xml", model_name(fmu)?);
    let beside = fmu.parent().unwrap_or(Path::new(".")).join(&name);
    let file = [beside, config_dir.join(&name)]
        .into_iter()
        .find(|p| p.is_file());
    let Some(file) = file else {
        return Ok(None);
    };
    let text = limits::read_text(&file, limits::MAX_SYSTEM_FILE, "OSP model description")?;
    let top = parse(&text).map_err(|m| Error::system(&file, None, m))?;
    Ok(Some(Groups { file, top }))
}

fn attribute(e: &BytesStart, key: &str) -> std::result::Result<Option<String>, String> {
    match e.try_get_attribute(key) {
        Ok(Some(a)) => a
            .unescape_value()
            .map(|v| Some(v.into_owned()))
            .map_err(|e| format!("bad attribute '{key}': {e}")),
        Ok(None) => Ok(None),
        Err(e) => Err(format!("bad attribute '{key}': {e}")),
    }
}

/// The groups under `<VariableGroups>` of an `OspModelDescription.xml`.
fn parse(text: &str) -> std::result::Result<Vec<Group>, String> {
    let mut reader = quick_xml::Reader::from_str(text);
    // The groups being read, innermost last; the root collects the top-level ones.
    let mut stack: Vec<Group> = Vec::new();
    let mut inside = false;
    loop {
        let event = reader
            .read_event()
            .map_err(|e| format!("not a valid OspModelDescription.xml: {e}"))?;
        match event {
            Event::Empty(e) if !inside && e.local_name().as_ref() == b"VariableGroups" => {
                return Ok(Vec::new());
            }
            Event::Start(e) if !inside && e.local_name().as_ref() == b"VariableGroups" => {
                inside = true;
                stack.push(Group::default());
            }
            Event::Start(_) | Event::Empty(_) if !inside => {}
            Event::Start(e) => stack.push(element(&e)?),
            Event::Empty(e) => {
                let child = element(&e)?;
                add(&mut stack, child);
            }
            Event::End(_) if inside => {
                let done = stack.pop().unwrap_or_default();
                if stack.is_empty() {
                    return Ok(done.groups);
                }
                add(&mut stack, done);
            }
            Event::Eof => break,
            _ => {}
        }
    }
    match stack.pop() {
        Some(root) if stack.is_empty() => Ok(root.groups),
        _ if !inside => Ok(Vec::new()),
        _ => Err("not a valid OspModelDescription.xml: <VariableGroups> is not closed".into()),
    }
}

/// A `<Variable ref>` (a group with no name and one variable, folded in by [`add`]) or a group.
fn element(e: &BytesStart) -> std::result::Result<Group, String> {
    let tag = String::from_utf8_lossy(e.local_name().as_ref()).into_owned();
    if tag == "Variable" {
        let r = attribute(e, "ref")?.ok_or("a <Variable> without ref")?;
        return Ok(Group {
            name: String::new(),
            variables: vec![r],
            groups: Vec::new(),
        });
    }
    // An element without a name (say, unit details inside a <Variable>) is no group: ignored.
    let name = attribute(e, "name")?.unwrap_or_default();
    Ok(Group {
        name,
        ..Group::default()
    })
}

/// Adds a finished element to the group above it: a variable to its variables, a group to its
/// groups.
fn add(stack: &mut [Group], child: Group) {
    let Some(parent) = stack.last_mut() else {
        return;
    };
    if child.name.is_empty() && child.groups.is_empty() {
        parent.variables.extend(child.variables);
    } else {
        parent.groups.push(child);
    }
}
