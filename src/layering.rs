//! The rooms of the library depend downwards only (ARCHITECTURE.md): a simulator never sees a dataset, a model
//! never sees an evaluation protocol, and no learning method reaches into another's folder. This test reads
//! every `crate::` path in `src/` and holds the tree to that order, so a shortcut fails here, not in review.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Each room's floor: a room may use rooms on a strictly lower floor, and itself. Rooms on one floor are
/// siblings and may not use each other.
const FLOORS: &[(&str, u8)] = &[
    ("error", 0),
    ("util", 1),
    ("run", 2),
    ("envs", 3),
    ("data", 4),
    ("nn", 5),
    ("train", 6),
    ("control", 7),
    ("filtering", 8),
    ("planning", 8),
    ("rl", 8),
    ("models", 9),
    ("eval", 10),
    ("tui", 10),
    ("sweep", 11),
    ("jobs", 12),
];

/// Folders of `models/` that are one learning method each; shared pieces (`gp`, `context_net`) are not.
const METHODS: &[&str] = &["pets", "context", "tradyn", "dlgpd", "seads", "ball"];

/// Method-to-method uses allowed, with the reason; none today (TRADYN and Explore the Context share their
/// network through `context_net`).
const KNOWN_CROSSINGS: &[(&str, &str, &str)] = &[];

fn floor(room: &str) -> Option<u8> {
    FLOORS.iter().find(|(name, _)| *name == room).map(|(_, f)| *f)
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("src/ is readable").flatten() {
        let path = entry.path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The text without `//` comments, so doc examples and prose do not count as imports.
fn code_of(text: &str) -> String {
    text.lines().map(|line| line.split("//").next().unwrap_or("")).collect::<Vec<_>>().join("\n")
}

/// Every path a file names below `crate::`, as its first two segments (`["models", "pets"]`), following use
/// trees (`crate::{envs::Env, models::{pets, gp}}`).
fn crate_paths(code: &str) -> BTreeSet<Vec<String>> {
    let chars: Vec<char> = code.chars().collect();
    let mut out = BTreeSet::new();
    let mut i = 0;
    while let Some(at) = find(&chars, i, "crate::") {
        let before = at.checked_sub(1).map(|k| chars[k]);
        i = at + "crate::".len();
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == '$') {
            continue;
        }
        use_tree(&chars, &mut i, Vec::new(), &mut out);
    }
    out
}

fn find(chars: &[char], from: usize, needle: &str) -> Option<usize> {
    let needle: Vec<char> = needle.chars().collect();
    (from..chars.len().saturating_sub(needle.len() - 1)).find(|&k| chars[k..k + needle.len()] == needle[..])
}

fn skip_space(chars: &[char], i: &mut usize) {
    while *i < chars.len() && chars[*i].is_whitespace() {
        *i += 1;
    }
}

fn use_tree(chars: &[char], i: &mut usize, prefix: Vec<String>, out: &mut BTreeSet<Vec<String>>) {
    skip_space(chars, i);
    if chars.get(*i) == Some(&'{') {
        *i += 1;
        loop {
            skip_space(chars, i);
            match chars.get(*i) {
                None => return,
                Some('}') => {
                    *i += 1;
                    return;
                }
                Some(',') => *i += 1,
                _ => {
                    let before = *i;
                    use_tree(chars, i, prefix.clone(), out);
                    if *i == before {
                        *i += 1;
                    }
                }
            }
        }
    }
    let start = *i;
    while *i < chars.len() && (chars[*i].is_alphanumeric() || chars[*i] == '_') {
        *i += 1;
    }
    if *i == start {
        if !prefix.is_empty() {
            out.insert(prefix);
        }
        return;
    }
    let mut path = prefix;
    path.push(chars[start..*i].iter().collect());
    if path.len() == 2 {
        out.insert(path.clone());
    }
    if chars.get(*i) == Some(&':') && chars.get(*i + 1) == Some(&':') {
        *i += 2;
        if path.len() < 2 {
            use_tree(chars, i, path, out);
        } else {
            skip_tree(chars, i);
            out.insert(path);
        }
    } else {
        out.insert(path);
    }
}

/// Steps over the rest of a path or use tree (`a::b`, `{c, d::e}`) whose first two segments are known.
fn skip_tree(chars: &[char], i: &mut usize) {
    let mut depth = 0usize;
    while let Some(&c) = chars.get(*i) {
        match c {
            '{' => depth += 1,
            '}' if depth == 0 => return,
            '}' => depth -= 1,
            ',' | ';' | ')' if depth == 0 => return,
            c if depth == 0 && !(c.is_alphanumeric() || c == '_' || c == ':') => return,
            _ => {}
        }
        *i += 1;
    }
}

/// The room and, inside `models/`, the method folder a source file belongs to.
fn place(src: &Path, file: &Path) -> (String, Option<String>) {
    let parts: Vec<String> =
        file.strip_prefix(src).unwrap().components().map(|c| c.as_os_str().to_string_lossy().into_owned()).collect();
    let room = parts[0].trim_end_matches(".rs").to_string();
    let folder = (parts.len() > 2).then(|| parts[1].clone());
    (room, folder)
}

fn violations() -> Vec<String> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let mut found = Vec::new();
    for file in files {
        let (room, folder) = place(&src, &file);
        if matches!(room.as_str(), "lib" | "layering") {
            continue;
        }
        let Some(own) = floor(&room) else {
            found.push(format!("{}: room '{room}' has no floor in FLOORS", file.display()));
            continue;
        };
        let code = code_of(&std::fs::read_to_string(&file).unwrap());
        for path in crate_paths(&code) {
            let target = path[0].as_str();
            let shown = path.join("::");
            match floor(target) {
                _ if target == room => {
                    let method = folder.as_deref().filter(|f| METHODS.contains(f));
                    let other = path.get(1).map(String::as_str).filter(|p| METHODS.contains(p));
                    if let (Some(method), Some(other)) = (method, other) {
                        let known = KNOWN_CROSSINGS.iter().any(|(a, b, _)| *a == method && *b == other);
                        if method != other && !known {
                            found
                                .push(format!("{}: method '{method}' uses method '{other}' ({shown})", file.display()));
                        }
                    }
                }
                Some(theirs) if theirs < own => {}
                Some(_) => {
                    found.push(format!("{}: room '{room}' uses '{shown}', which is not below it", file.display()))
                }
                // Items at the crate root (`crate::VERSION`, `crate::Result`, exported macros) belong to no room.
                None => {}
            }
        }
    }
    found
}

#[test]
fn rooms_depend_downwards_only() {
    let found = violations();
    assert!(found.is_empty(), "imports against the layering:\n{}", found.join("\n"));
}

#[test]
fn the_parser_sees_nested_use_trees_and_paths_in_code() {
    let code = code_of(
        "use crate::{envs::Env, models::{pets::x, gp}};\nfn f() { crate::eval::swingup::run(); } // crate::tui::x\nuse crate::VERSION;",
    );
    let paths: Vec<String> = crate_paths(&code).into_iter().map(|p| p.join("::")).collect();
    assert_eq!(paths, ["VERSION", "envs::Env", "eval::swingup", "models::gp", "models::pets"]);
}

/// Flags are parsed in one room: the engine below `jobs/` takes typed settings and never names clap.
#[test]
fn only_jobs_know_clap() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let offenders: Vec<String> = files
        .iter()
        .filter(|file| place(&src, file).0 != "jobs" && !file.ends_with("layering.rs"))
        .filter(|file| code_of(&std::fs::read_to_string(file).unwrap()).contains("clap::"))
        .map(|file| file.display().to_string())
        .collect();
    assert!(offenders.is_empty(), "clap used outside src/jobs/: {}", offenders.join(", "));
}
