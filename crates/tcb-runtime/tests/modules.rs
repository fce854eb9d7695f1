//! Module imports run one way: in no crate of the workspace do two files
//! (modules) import each other, directly or round a longer circle. A file
//! imports a module when its code (not its comments) names it through
//! `crate::`, `super::` or, from a `mod.rs`, a child module's name. The
//! crate root counts as a module: reaching another module through its
//! re-exports (`use crate::Clip`) is an import of the root.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Module path (`["compile", "rotation"]`, `[]` for the root) of each file.
fn modules(src: &Path) -> BTreeMap<Vec<String>, PathBuf> {
    let mut out = BTreeMap::new();
    let mut stack = vec![src.to_path_buf()];
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
            let rel = path.strip_prefix(src).unwrap().with_extension("");
            let mut parts: Vec<String> = rel
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect();
            if parts
                .last()
                .is_some_and(|p| p == "mod" || p == "lib" || p == "main")
            {
                parts.pop();
            }
            // A binary's root and the library's are apart; skip `bin/` roots.
            if rel.starts_with("bin") {
                continue;
            }
            out.insert(parts, path);
        }
    }
    out
}

/// The code of a file without comments, string literals and its test module.
fn code(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    let text = match text.find("#[cfg(test)]\nmod tests") {
        Some(at) => &text[..at],
        None => &text[..],
    };
    let mut out = String::new();
    for line in text.lines() {
        let line = match line.find("//") {
            Some(at) => &line[..at],
            None => line,
        };
        // Drop string literals (error messages name modules in prose).
        let mut in_str = false;
        let mut prev = ' ';
        for ch in line.chars() {
            if ch == '"' && prev != '\\' {
                in_str = !in_str;
            } else if !in_str {
                out.push(ch);
            }
            prev = ch;
        }
        out.push('\n');
    }
    out
}

/// Paths the code names after `prefix` (`crate::` or `super::`), as
/// segments, braces expanded one level (`use crate::{a::B, c}`).
fn paths_after(code: &str, prefix: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let mut rest = code;
    while let Some(at) = rest.find(prefix) {
        let before = rest[..at].chars().next_back();
        rest = &rest[at + prefix.len()..];
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            continue; // `mycrate::`, not `crate::`
        }
        let mut chained = vec![];
        let mut s = rest;
        loop {
            let ident: String = s
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if ident.is_empty() {
                break;
            }
            s = &s[ident.len()..];
            chained.push(ident);
            if let Some(t) = s.strip_prefix("::") {
                s = t;
            } else {
                break;
            }
        }
        if s.starts_with('{') {
            let inner = &s[1..s.find('}').unwrap_or(s.len())];
            for item in inner.split(',') {
                let mut p = chained.clone();
                p.extend(
                    item.trim()
                        .split("::")
                        .map(|x| x.trim().to_string())
                        .filter(|x| !x.is_empty() && x != "{"),
                );
                out.push(p);
            }
        } else {
            out.push(chained);
        }
    }
    out
}

/// The longest module that `path` (absolute segments) lies in.
fn module_of(path: &[String], mods: &BTreeMap<Vec<String>, PathBuf>) -> Vec<String> {
    (0..=path.len())
        .rev()
        .map(|n| path[..n].to_vec())
        .find(|p| mods.contains_key(p))
        .unwrap_or_default()
}

/// Module import edges of one crate's `src`.
fn edges(src: &Path) -> BTreeMap<Vec<String>, BTreeSet<Vec<String>>> {
    let mods = modules(src);
    let mut out: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
    for (module, path) in &mods {
        let code = code(path);
        let is_dir_root = path
            .file_name()
            .is_some_and(|f| f == "mod.rs" || f == "lib.rs");
        let mut named: Vec<Vec<String>> = paths_after(&code, "crate::");
        // `super::` from a file is its parent module.
        let parent: Vec<String> = module[..module.len().saturating_sub(1)].to_vec();
        for p in paths_after(&code, "super::") {
            named.push(parent.iter().cloned().chain(p).collect());
        }
        // A `mod.rs` (or the root) names its children bare: `use child::X`.
        if is_dir_root {
            for line in code.lines() {
                let line = line.trim();
                if let Some(rest) = line
                    .strip_prefix("pub use ")
                    .or_else(|| line.strip_prefix("use "))
                    .or_else(|| line.strip_prefix("pub(crate) use "))
                {
                    let child: String = rest
                        .chars()
                        .take_while(|c| c.is_alphanumeric() || *c == '_')
                        .collect();
                    let mut p = module.clone();
                    p.push(child);
                    if mods.contains_key(&p) {
                        named.push(p);
                    }
                }
            }
        }
        for p in named {
            let target = module_of(&p, &mods);
            if &target != module {
                out.entry(module.clone()).or_default().insert(target);
            }
        }
    }
    out
}

/// A circle of imports, if any.
fn circle(edges: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>) -> Option<Vec<Vec<String>>> {
    fn visit(
        node: &Vec<String>,
        edges: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
        state: &mut BTreeMap<Vec<String>, u8>,
        stack: &mut Vec<Vec<String>>,
    ) -> Option<Vec<Vec<String>>> {
        state.insert(node.clone(), 1);
        stack.push(node.clone());
        for next in edges.get(node).into_iter().flatten() {
            match state.get(next).copied().unwrap_or(0) {
                1 => {
                    let from = stack.iter().position(|n| n == next).unwrap();
                    let mut c = stack[from..].to_vec();
                    c.push(next.clone());
                    return Some(c);
                }
                0 => {
                    if let Some(c) = visit(next, edges, state, stack) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        stack.pop();
        state.insert(node.clone(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for node in edges.keys() {
        if state.get(node).copied().unwrap_or(0) == 0 {
            let mut stack = Vec::new();
            if let Some(c) = visit(node, edges, &mut state, &mut stack) {
                return Some(c);
            }
        }
    }
    None
}

fn name(m: &[String]) -> String {
    if m.is_empty() {
        "crate".into()
    } else {
        m.join("::")
    }
}

#[test]
fn no_crate_has_a_circle_of_module_imports() {
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut found = Vec::new();
    let mut checked = 0;
    for entry in std::fs::read_dir(&crates).unwrap() {
        let src = entry.unwrap().path().join("src");
        if !src.is_dir() {
            continue;
        }
        checked += 1;
        if let Some(c) = circle(&edges(&src)) {
            let c: Vec<String> = c.iter().map(|m| name(m)).collect();
            found.push(format!("{}: {}", src.display(), c.join(" -> ")));
        }
    }
    assert!(checked >= 7, "{checked} crates found");
    assert!(
        found.is_empty(),
        "circles of imports:\n{}",
        found.join("\n")
    );
}

#[test]
fn the_check_finds_a_circle() {
    // Two files naming each other, one through `super::`, one bare.
    let dir = std::env::temp_dir().join(format!("tcb-modules-{}", std::process::id()));
    let src = dir.join("src");
    std::fs::create_dir_all(src.join("a")).unwrap();
    std::fs::write(src.join("lib.rs"), "mod a;\nmod b;\n").unwrap();
    std::fs::write(src.join("a/mod.rs"), "mod c;\nuse c::X;\n").unwrap();
    std::fs::write(
        src.join("a/c.rs"),
        "pub struct X;\nuse super::Y; // a comment: crate::b\n",
    )
    .unwrap();
    std::fs::write(src.join("b.rs"), "use crate::a::Y;\n").unwrap();
    let e = edges(&src);
    let c = circle(&e).expect("a -> a::c -> a");
    assert_eq!(c.first(), c.last());
    assert!(
        !e.get(&vec!["a".to_string(), "c".to_string()])
            .unwrap()
            .contains(&vec!["b".to_string()])
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The `pub mod`s of the crate at `src` whose file declares no public item
/// that the root does not re-export (`pub use name::{..}`): a public path
/// to nothing new. A `pub use` or an item-making macro (`named_enum!`) in
/// the module counts as an item of its own.
fn empty_pub_mods(src: &Path) -> Vec<String> {
    let root = code(&src.join("lib.rs"));
    let mut empty = Vec::new();
    for line in root.lines() {
        let Some(name) = line
            .strip_prefix("pub mod ")
            .and_then(|l| l.trim().strip_suffix(';'))
        else {
            continue;
        };
        let file = [
            src.join(format!("{name}.rs")),
            src.join(name).join("mod.rs"),
        ]
        .into_iter()
        .find(|p| p.is_file())
        .unwrap_or_else(|| panic!("{}: no file for `pub mod {name}`", src.display()));
        // What the root re-exports from it, `pub use name::{A, b::C};` up to the `;`.
        let mut reexported = BTreeSet::new();
        let prefix = format!("pub use {name}::");
        let mut rest = &root[..];
        while let Some(at) = rest.find(&prefix) {
            rest = &rest[at + prefix.len()..];
            let end = rest.find(';').unwrap_or(rest.len());
            for part in rest[..end].split(|c: char| "{},".contains(c)) {
                let last = part.trim().rsplit("::").next().unwrap_or("");
                let last = last.split(" as ").next().unwrap_or("").trim();
                if !last.is_empty() {
                    reexported.insert(last.to_string());
                }
            }
        }
        let own = code(&file).lines().any(|l| {
            if l.ends_with("! {") && !l.starts_with(' ') && !l.starts_with("macro_rules") {
                return true;
            }
            let Some(item) = l.strip_prefix("pub ") else {
                return false;
            };
            let words: Vec<&str> = item
                .split(|c: char| !(c.is_alphanumeric() || c == '_'))
                .filter(|w| !w.is_empty())
                .collect();
            let kinds = [
                "fn", "struct", "enum", "trait", "const", "static", "type", "mod",
            ];
            match words.iter().position(|w| kinds.contains(w) || *w == "use") {
                Some(i) if words[i] == "use" => true,
                // `const fn f`: the name follows the last keyword.
                Some(i) => {
                    let mut j = i;
                    while words.get(j).is_some_and(|w| kinds.contains(w)) {
                        j += 1;
                    }
                    words.get(j).is_some_and(|w| !reexported.contains(*w))
                }
                None => false,
            }
        });
        if !own {
            empty.push(name.to_string());
        }
    }
    empty
}

/// Issue 31: a `pub mod` whose items all stand at the crate's root too is
/// a second path to the same things; such modules are private. Kept public
/// on purpose, for their module page: tcb-runtime's `clip` (the compiled
/// layout) and `rig` (rig order against a clip's), tcb-core's `vector` (the
/// vector interface the tangent rules are written against) and
/// tcb-bench's `baseline` (what the scalar baseline does); and, until the
/// work on those files lands, tcb-fit's `compress` and tcb-io's `error`.
#[test]
fn every_pub_mod_exports_something_of_its_own() {
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let kept = [
        "tcb-runtime::clip",
        "tcb-runtime::rig",
        "tcb-core::vector",
        "tcb-bench::baseline",
        "tcb-fit::compress",
        "tcb-io::error",
    ];
    let mut found = Vec::new();
    let mut checked = 0;
    for entry in std::fs::read_dir(&crates).unwrap() {
        let dir = entry.unwrap().path();
        if !dir.join("src/lib.rs").is_file() {
            continue;
        }
        checked += 1;
        let krate = dir.file_name().unwrap().to_string_lossy().into_owned();
        for m in empty_pub_mods(&dir.join("src")) {
            let m = format!("{krate}::{m}");
            if !kept.contains(&m.as_str()) {
                found.push(m);
            }
        }
    }
    assert!(checked >= 7, "{checked} library crates found");
    assert!(
        found.is_empty(),
        "`pub mod`s that export nothing the root does not (make them private):\n{}",
        found.join("\n")
    );
}

#[test]
fn the_check_finds_a_pub_mod_that_exports_nothing() {
    let dir = std::env::temp_dir().join(format!("tcb-pub-mods-{}", std::process::id()));
    let src = dir.join("src");
    std::fs::create_dir_all(src.join("b")).unwrap();
    std::fs::write(
        src.join("lib.rs"),
        "pub mod a;\npub mod b;\npub mod c;\npub use a::{X, f as g};\npub use b::Y;\n",
    )
    .unwrap();
    std::fs::write(src.join("a.rs"), "pub struct X;\npub const fn f() {}\n").unwrap();
    std::fs::write(src.join("b/mod.rs"), "pub struct Y;\npub enum Z {}\n").unwrap();
    std::fs::write(src.join("c.rs"), "pub(crate) struct W;\n// pub struct V;\n").unwrap();
    assert_eq!(empty_pub_mods(&src), ["a", "c"]);
    std::fs::remove_dir_all(&dir).unwrap();
}
