//! The library's top-level modules depend on each other without a loop (issue 15): every
//! `crate::X` path in a module's files (code only: comments, strings and character literals are
//! skipped) is an arrow from that module to `X`, and the arrows form a directed acyclic graph.
//! A loop is reported with the file and line of each arrow, so whoever adds one sees where.
//!
//! It reads the source tree as text (no build of anything else), so it is cheap.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// An arrow's origin: file (relative to `src/`) and line.
type Site = (String, usize);

/// Module → module it names → where it names it first.
type Graph = BTreeMap<String, BTreeMap<String, Site>>;

/// `text` with comments, string literals (raw and byte strings included) and character
/// literals replaced by spaces, line breaks kept (so lines still count).
fn code_only(text: &str) -> String {
    let c: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let blank = |out: &mut String, ch: char| out.push(if ch == '\n' { '\n' } else { ' ' });
    let mut i = 0;
    while i < c.len() {
        let at = |k: usize| c.get(k).copied().unwrap_or('\0');
        if c[i] == '/' && at(i + 1) == '/' {
            while i < c.len() && c[i] != '\n' {
                i += 1;
                out.push(' ');
            }
        } else if c[i] == '/' && at(i + 1) == '*' {
            let mut depth = 0;
            loop {
                if i >= c.len() {
                    break;
                }
                if c[i] == '/' && at(i + 1) == '*' {
                    depth += 1;
                    out.push_str("  ");
                    i += 2;
                } else if c[i] == '*' && at(i + 1) == '/' {
                    depth -= 1;
                    out.push_str("  ");
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    blank(&mut out, c[i]);
                    i += 1;
                }
            }
        } else if (c[i] == 'r' || (c[i] == 'b' && at(i + 1) == 'r'))
            && !is_ident(at(i.wrapping_sub(1)))
            && {
                let mut k = i + if c[i] == 'b' { 2 } else { 1 };
                while at(k) == '#' {
                    k += 1;
                }
                at(k) == '"'
            }
        {
            // Raw string r#"…"#: ends at a quote followed by as many hashes.
            let mut k = i + if c[i] == 'b' { 2 } else { 1 };
            let mut hashes = 0;
            while c[k] == '#' {
                hashes += 1;
                k += 1;
            }
            k += 1;
            while k < c.len() && !(c[k] == '"' && (1..=hashes).all(|h| at(k + h) == '#')) {
                k += 1;
            }
            let end = (k + 1 + hashes).min(c.len());
            for &ch in &c[i..end] {
                blank(&mut out, ch);
            }
            i = end;
        } else if c[i] == '"' {
            blank(&mut out, c[i]);
            i += 1;
            while i < c.len() && c[i] != '"' {
                if c[i] == '\\' {
                    blank(&mut out, c[i]);
                    i += 1;
                }
                if i < c.len() {
                    blank(&mut out, c[i]);
                    i += 1;
                }
            }
            if i < c.len() {
                out.push(' ');
                i += 1;
            }
        } else if c[i] == '\'' {
            // A character literal ('x', '\n', '\u{1b}') or a lifetime ('a): a literal closes
            // within a few characters.
            let close = if at(i + 1) == '\\' {
                (i + 3..(i + 12).min(c.len())).find(|&k| c[k] == '\'')
            } else if at(i + 2) == '\'' {
                Some(i + 2)
            } else {
                None
            };
            match close {
                Some(k) => {
                    for _ in i..=k {
                        out.push(' ');
                    }
                    i = k + 1;
                }
                None => {
                    out.push(c[i]);
                    i += 1;
                }
            }
        } else {
            out.push(c[i]);
            i += 1;
        }
    }
    out
}

fn is_ident(ch: char) -> bool {
    ch.is_alphanumeric() || ch == '_'
}

/// The leading identifier of `s` (after white space).
fn ident(s: &str) -> &str {
    let s = s.trim_start();
    let end = s.find(|ch: char| !is_ident(ch)).unwrap_or(s.len());
    &s[..end]
}

/// The first-level items of a brace group's contents `a::B, c::{D, E}, f` → `a`, `c`, `f`.
fn group_heads(body: &str) -> Vec<&str> {
    let (mut depth, mut start, mut heads) = (0, 0, Vec::new());
    for (k, ch) in body.char_indices() {
        match ch {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                heads.push(ident(&body[start..k]));
                start = k + 1;
            }
            _ => {}
        }
    }
    heads.push(ident(&body[start..]));
    heads.into_iter().filter(|h| !h.is_empty()).collect()
}

/// Every top-level module a file's code names through `crate::`, with the line.
fn names(code: &str) -> Vec<(String, usize)> {
    let mut found = Vec::new();
    let line_of = |at: usize| code[..at].matches('\n').count() + 1;
    for (at, _) in code.match_indices("crate::") {
        let before = code[..at].chars().next_back().unwrap_or(' ');
        if is_ident(before) || before == '$' {
            continue; // `$crate::` or part of a longer name
        }
        let rest = code[at + "crate::".len()..].trim_start();
        if let Some(body) = rest.strip_prefix('{') {
            let mut depth = 1;
            let end = body
                .char_indices()
                .find(|&(_, ch)| {
                    depth += match ch {
                        '{' => 1,
                        '}' => -1,
                        _ => 0,
                    };
                    depth == 0
                })
                .map_or(body.len(), |(k, _)| k);
            for head in group_heads(&body[..end]) {
                found.push((head.to_string(), line_of(at)));
            }
        } else {
            found.push((ident(rest).to_string(), line_of(at)));
        }
    }
    found
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = fs::read_dir(dir)
        .expect("src is readable")
        .flatten()
        .collect();
    entries.sort_by_key(|e| e.path());
    for e in entries {
        let p = e.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The arrows between the top-level modules of `src` (`lib.rs` and `main.rs` are the roots,
/// not modules).
fn graph(src: &Path) -> Graph {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let module_of = |p: &Path| {
        let rel = p.strip_prefix(src).expect("under src");
        let first = rel.components().next().expect("a file").as_os_str();
        let first = first.to_string_lossy();
        first.strip_suffix(".rs").unwrap_or(&first).to_string()
    };
    let modules: BTreeSet<String> = files
        .iter()
        .map(|p| module_of(p))
        .filter(|m| m != "lib" && m != "main")
        .collect();
    let mut g = Graph::new();
    for m in &modules {
        g.entry(m.clone()).or_default();
    }
    for p in &files {
        let from = module_of(p);
        if !modules.contains(&from) {
            continue;
        }
        let code = code_only(&fs::read_to_string(p).expect("a UTF-8 source file"));
        assert!(
            !code.contains("super::super::super"),
            "{}: a path three levels up is not followed by this test",
            p.display()
        );
        let rel = p
            .strip_prefix(src)
            .expect("under src")
            .display()
            .to_string();
        for (to, line) in names(&code) {
            if to != from && modules.contains(&to) {
                g.get_mut(&from)
                    .expect("every module")
                    .entry(to)
                    .or_insert((rel.clone(), line));
            }
        }
    }
    g
}

/// A loop of the graph, if any: the modules in order, the first repeated at the end.
fn find_loop(g: &Graph) -> Option<Vec<String>> {
    // 0: not seen, 1: on the current path, 2: done.
    fn visit(
        g: &Graph,
        m: &str,
        state: &mut BTreeMap<String, u8>,
        path: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(m.to_string(), 1);
        path.push(m.to_string());
        for to in g[m].keys() {
            match state.get(to.as_str()).copied().unwrap_or(0) {
                1 => {
                    let start = path.iter().position(|p| p == to).expect("on the path");
                    let mut cycle = path[start..].to_vec();
                    cycle.push(to.clone());
                    return Some(cycle);
                }
                0 => {
                    if let Some(c) = visit(g, to, state, path) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        path.pop();
        state.insert(m.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for m in g.keys() {
        if state.get(m.as_str()).copied().unwrap_or(0) == 0 {
            if let Some(c) = visit(g, m, &mut state, &mut Vec::new()) {
                return Some(c);
            }
        }
    }
    None
}

#[test]
fn the_top_level_modules_form_no_loop() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let g = graph(&src);
    assert!(
        g.len() > 10,
        "the modules of src/ were found: {:?}",
        g.keys()
    );
    if let Some(cycle) = find_loop(&g) {
        let arrows: Vec<String> = cycle
            .windows(2)
            .map(|w| {
                let (file, line) = &g[&w[0]][&w[1]];
                format!("  {} → {} ({file}:{line})", w[0], w[1])
            })
            .collect();
        panic!(
            "the modules depend on each other in a loop: {}\n{}",
            cycle.join(" → "),
            arrows.join("\n")
        );
    }
}

/// The reader of the test above sees what it sees: comments, strings, character literals and
/// lifetimes do not count; groups and paths do.
#[test]
fn the_scanner_reads_paths_not_prose() {
    let code = code_only(
        "use crate::{a::X, b::{Y, Z}, c};\n\
         // crate::d in a comment\n\
         /* crate::e /* nested */ crate::e2 */\n\
         let s = \"crate::f\"; let r = r#\"crate::g \"quoted\" \"#;\n\
         let q = '\"'; fn l<'a>(x: &'a str) -> crate::h::T { crate::i::f() }\n\
         let t = $crate::j;\n",
    );
    let got: Vec<(String, usize)> = names(&code);
    let got: Vec<(&str, usize)> = got.iter().map(|(m, l)| (m.as_str(), *l)).collect();
    assert_eq!(got, [("a", 1), ("b", 1), ("c", 1), ("h", 5), ("i", 5)]);
}

/// The graph as text, for a reader who wants the layout: `cargo test --test module_graph --
/// --ignored --nocapture print`.
#[test]
#[ignore = "prints the module graph; run by hand"]
fn print_the_module_graph() {
    let g = graph(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"));
    for (m, to) in &g {
        println!("{m} → {}", to.keys().cloned().collect::<Vec<_>>().join(" "));
    }
}
