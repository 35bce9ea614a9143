//! The master's seams, checked by `cargo xtask test` (issue 29): no import cycle in
//! `master/src` and no source file there over [`MAX_LINES`] lines.
//!
//! An edge is a path in code (comments are skipped) from one module to another:
//!
//! * between **top-level modules** of the library (`crate::a` used in a file of module `b`,
//!   `a != b`);
//! * between **files of one folder** (`crate::f::x` or `super::x` used in `f/y.rs`, where `x`
//!   is a sibling file `f/x.rs` or `f/x/`); the folder's own root file (`f.rs` or `f/mod.rs`)
//!   is its facade and not a node.
//!
//! Use groups (`use crate::{a::X, b}`) count each path. The binary's files (`main.rs`, `cli/`)
//! use the library by name and are not counted. A cycle among either kind of node fails with
//! the cycle and, for each of its edges, a file that makes it.

use anyhow::{bail, Result};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The longest source file allowed in master/src.
pub const MAX_LINES: usize = 1000;

/// The module path of a file under `src`: `a/b.rs` -> [a, b]; `a/mod.rs` -> [a].
fn module_of(rel: &Path) -> Vec<String> {
    let mut parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().trim_end_matches(".rs").to_string())
        .collect();
    if parts.last().is_some_and(|p| p == "mod") {
        parts.pop();
    }
    parts
}

/// Every path after `prefix` (`crate::` or `super::`) in `code`, as its segments, with use
/// groups expanded: `crate::run::{time_grid::LastStep, Options}` gives [run, time_grid,
/// LastStep] and [run, Options].
fn paths_after(code: &str, prefix: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let mut rest = code;
    while let Some(i) = rest.find(prefix) {
        let before = rest[..i].chars().last();
        rest = &rest[i + prefix.len()..];
        if !before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            expand(rest, &mut Vec::new(), &mut out);
        }
    }
    out
}

/// The paths of the tree at the start of `s` (`a::b`, `a::{b, c::d}`), each after `head`.
fn expand(s: &str, head: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
    let depth = head.len();
    let mut rest = s;
    loop {
        if let Some(group) = rest.strip_prefix('{') {
            for item in split_group(group) {
                expand(item.trim(), head, out);
            }
            break;
        }
        let n = rest
            .find(|c: char| !(c.is_alphanumeric() || c == '_'))
            .unwrap_or(rest.len());
        if n == 0 {
            out.push(head.clone());
            break;
        }
        head.push(rest[..n].to_string());
        match rest[n..].strip_prefix("::") {
            Some(r) => rest = r,
            None => {
                out.push(head.clone());
                break;
            }
        }
    }
    head.truncate(depth);
}

/// The items of a use group whose text starts after its `{`, split at top-level commas.
fn split_group(group: &str) -> Vec<&str> {
    let (mut items, mut depth, mut start) = (Vec::new(), 0usize, 0);
    for (i, c) in group.char_indices() {
        match c {
            '{' => depth += 1,
            '}' if depth == 0 => {
                items.push(&group[start..i]);
                return items;
            }
            '}' => depth -= 1,
            ',' if depth == 0 => {
                items.push(&group[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    items.push(&group[start..]);
    items
}

/// The code of a file without its comment lines and trailing `//` comments.
fn code_of(text: &str) -> String {
    text.lines()
        .map(|l| {
            let t = l.trim_start();
            if t.starts_with("//") {
                ""
            } else {
                l.split(" //").next().unwrap_or(l)
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

type Graph = BTreeMap<String, BTreeMap<String, PathBuf>>;

fn add(g: &mut Graph, from: &str, to: &str, file: &Path) {
    if from != to {
        g.entry(from.to_string())
            .or_default()
            .entry(to.to_string())
            .or_insert_with(|| file.to_path_buf());
    }
}

/// Checks `master/src` under `root`; an error lists every cycle and every long file.
pub fn check(root: &Path) -> Result<()> {
    let src = root.join("master/src");
    let mut files = Vec::new();
    collect(&src, &mut files)?;
    let nodes: BTreeSet<Vec<String>> = files
        .iter()
        .map(|f| module_of(f.strip_prefix(&src).unwrap()))
        .collect();
    let mut top = Graph::new();
    let mut sibling = Graph::new();
    let mut problems = Vec::new();
    for f in &files {
        let rel = f.strip_prefix(&src).unwrap();
        let first = rel.iter().next().unwrap().to_string_lossy();
        if first == "main.rs" || first == "cli" {
            continue;
        }
        let text = std::fs::read_to_string(f)?;
        if text.lines().count() > MAX_LINES {
            problems.push(format!(
                "{} has {} lines (at most {MAX_LINES})",
                rel.display(),
                text.lines().count()
            ));
        }
        let me = module_of(rel);
        let code = code_of(&text);
        for p in paths_after(&code, "crate::") {
            let Some(head) = p.first() else { continue };
            if nodes.iter().any(|n| n.first() == Some(head)) {
                add(&mut top, &me[0], head, rel);
            }
            if me.len() >= 2 && p.len() >= 2 && p[..me.len() - 1] == me[..me.len() - 1] {
                let target = &p[me.len() - 1];
                add(
                    &mut sibling,
                    &me.join("::"),
                    &sibling_of(&me, target, &nodes),
                    rel,
                );
            }
        }
        if me.len() >= 2 {
            for p in paths_after(&code, "super::") {
                if let Some(target) = p.first() {
                    add(
                        &mut sibling,
                        &me.join("::"),
                        &sibling_of(&me, target, &nodes),
                        rel,
                    );
                }
            }
        }
    }
    // Only edges between sibling files are nodes of the folder graphs.
    let files_only: Graph = sibling
        .into_iter()
        .map(|(from, to)| {
            let to = to.into_iter().filter(|(t, _)| !t.is_empty()).collect();
            (from, to)
        })
        .collect();
    for (kind, g) in [("modules", &top), ("files of one folder", &files_only)] {
        for cycle in cycles(g) {
            let via: Vec<String> = cycle
                .windows(2)
                .map(|w| format!("{} -> {} ({})", w[0], w[1], g[&w[0]][&w[1]].display()))
                .collect();
            problems.push(format!("import cycle between {kind}: {}", via.join(", ")));
        }
    }
    if !problems.is_empty() {
        bail!("master/src:\n  {}", problems.join("\n  "));
    }
    Ok(())
}

/// The module path of `target` when it names a sibling file of `me`, else "" (an item of the
/// folder's root).
fn sibling_of(me: &[String], target: &str, nodes: &BTreeSet<Vec<String>>) -> String {
    let mut path = me[..me.len() - 1].to_vec();
    path.push(target.to_string());
    match nodes.contains(&path) {
        true => path.join("::"),
        false => String::new(),
    }
}

/// One cycle through each strongly connected group of `g` (as a closed walk a -> ... -> a).
fn cycles(g: &Graph) -> Vec<Vec<String>> {
    let mut found = Vec::new();
    let mut seen = BTreeSet::new();
    for start in g.keys() {
        if seen.contains(start) {
            continue;
        }
        if let Some(path) = walk_back(
            g,
            start,
            start,
            &mut vec![start.clone()],
            &mut BTreeSet::new(),
        ) {
            seen.extend(path.iter().cloned());
            found.push(path);
        }
    }
    found
}

/// A path from `at` back to `start`, depth first.
fn walk_back(
    g: &Graph,
    start: &str,
    at: &str,
    path: &mut Vec<String>,
    visited: &mut BTreeSet<String>,
) -> Option<Vec<String>> {
    for next in g.get(at).map(|m| m.keys()).into_iter().flatten() {
        if next == start {
            let mut p = path.clone();
            p.push(next.clone());
            return Some(p);
        }
        if visited.insert(next.clone()) {
            path.push(next.clone());
            if let Some(p) = walk_back(g, start, next, path, visited) {
                return Some(p);
            }
            path.pop();
        }
    }
    None
}

fn collect(dir: &Path, out: &mut Vec<PathBuf>) -> Result<()> {
    let mut entries: Vec<_> = std::fs::read_dir(dir)?.collect::<std::io::Result<_>>()?;
    entries.sort_by_key(|e| e.path());
    for e in entries {
        let p = e.path();
        if p.is_dir() {
            collect(&p, out)?;
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_and_groups() {
        let code = "use crate::run::{time_grid::LastStep, Options};\nlet x = crate::system::Plan::new(); supercrate::no;\nuse crate::{a::{b, c::D}, e};";
        let p = paths_after(code, "crate::");
        assert_eq!(
            p,
            vec![
                vec!["run".to_string(), "time_grid".into(), "LastStep".into()],
                vec!["run".to_string(), "Options".into()],
                vec!["system".to_string(), "Plan".into(), "new".into()],
                vec!["a".to_string(), "b".into()],
                vec!["a".to_string(), "c".into(), "D".into()],
                vec!["e".to_string()],
            ]
        );
    }

    #[test]
    fn finds_a_cycle() {
        let mut g = Graph::new();
        let f = Path::new("x.rs");
        add(&mut g, "a", "b", f);
        add(&mut g, "b", "c", f);
        add(&mut g, "c", "a", f);
        add(&mut g, "c", "d", f);
        let c = cycles(&g);
        assert_eq!(c.len(), 1);
        assert_eq!(c[0], ["a", "b", "c", "a"]);
        let mut acyclic = Graph::new();
        add(&mut acyclic, "a", "b", f);
        add(&mut acyclic, "a", "c", f);
        add(&mut acyclic, "b", "c", f);
        assert!(cycles(&acyclic).is_empty());
    }
}
