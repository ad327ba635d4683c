//! The CLI's modules import each other without a circle: each `crate::X`
//! a module names (outside comments and its tests), braced imports
//! `crate::{X, Y}` included, is an edge, and the
//! graph of `cli/src`'s top-level modules has no cycle. A circle (the
//! error type importing the file reader that returns it, say) fails here
//! with the modules that form it.

use std::collections::{BTreeMap, BTreeSet};

mod common;

/// Top-level module -> the top-level modules it names.
fn graph() -> BTreeMap<String, BTreeSet<String>> {
    let src = common::root().join("cli/src");
    let mut out: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut stack = vec![src.clone()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
                continue;
            }
            if path.extension().is_none_or(|e| e != "rs") {
                continue;
            }
            let rel = path.strip_prefix(&src).unwrap();
            let top = rel
                .components()
                .next()
                .unwrap()
                .as_os_str()
                .to_string_lossy()
                .trim_end_matches(".rs")
                .to_string();
            if top == "lib" || top == "main" {
                continue;
            }
            let text = std::fs::read_to_string(&path).unwrap();
            let code = text.split("#[cfg(test)]").next().unwrap();
            let edges = out.entry(top.clone()).or_default();
            edges.extend(named(code).into_iter().filter(|name| *name != top));
        }
    }
    out
}

/// The top-level modules `code` names outside comments: `crate::X` and
/// each `X` of a braced `crate::{X, Y::Z, ...}` (over several lines too).
fn named(code: &str) -> BTreeSet<String> {
    let code: String = code
        .lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n");
    let ident = |s: &str| -> String { s.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect() };
    let mut out = BTreeSet::new();
    for (i, _) in code.match_indices("crate::") {
        let rest = &code[i + 7..];
        let Some(group) = rest.strip_prefix('{') else {
            out.insert(ident(rest));
            continue;
        };
        // The names at the group's top level, before its closing brace.
        let mut depth = 0;
        let mut start = true;
        for (j, c) in group.char_indices() {
            match c {
                '{' => depth += 1,
                '}' if depth == 0 => break,
                '}' => depth -= 1,
                ',' if depth == 0 => start = true,
                c if start && !c.is_whitespace() => {
                    out.insert(ident(&group[j..]));
                    start = false;
                }
                _ => {}
            }
        }
    }
    out.remove("");
    out
}

#[test]
fn the_scan_reads_plain_and_braced_imports() {
    let code = "use crate::error::CliError;\n// crate::commented\nuse crate::{\n    plot,\n    sweep::{self, stream},\n    units::Units,\n};\nlet x = crate::display::sig(1.0, 2);";
    let want: BTreeSet<String> = ["display", "error", "plot", "sweep", "units"].map(String::from).into();
    assert_eq!(named(code), want);
}

#[test]
fn the_modules_import_each_other_without_a_circle() {
    let g = graph();
    assert!(g.len() >= 20, "{} modules: the scan lost them", g.len());
    // Depth-first search for a back edge.
    fn visit(
        n: &str,
        g: &BTreeMap<String, BTreeSet<String>>,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(i) = path.iter().position(|p| p == n) {
            let mut cycle = path[i..].to_vec();
            cycle.push(n.to_string());
            return Some(cycle);
        }
        if done.contains(n) {
            return None;
        }
        path.push(n.to_string());
        for d in g.get(n).into_iter().flatten() {
            if let Some(c) = visit(d, g, path, done) {
                return Some(c);
            }
        }
        path.pop();
        done.insert(n.to_string());
        None
    }
    let mut done = BTreeSet::new();
    for n in g.keys() {
        if let Some(cycle) = visit(n, &g, &mut Vec::new(), &mut done) {
            panic!("import circle: {}", cycle.join(" -> "));
        }
    }
}
