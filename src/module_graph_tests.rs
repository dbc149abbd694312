//! The layering of the crate, checked from its source: which top-level
//! modules of `src/` name which others (`use crate::X…`, `crate::X::…`
//! anywhere in code, `crate::{X…, Y…}` groups, `super::…` paths that climb
//! to the crate root), and that these imports form no cycle.
//!
//! What counts: the library's code as the compiler builds it without
//! `cfg(test)`. The files are found by following `mod` declarations from
//! `src/lib.rs` (`#[path]` included); a file or item under `#[cfg(test)]`
//! (a `tests` folder, `mod tests { … }`, `#[cfg(test)] pub mod raycast;`,
//! `test_support`) is left out: the white-box tests of a technique render
//! whole scenes through the renderer and compare techniques with each other,
//! so they sit above the renderer by design and are no part of the layering.
//! Comments (doc links included) and string literals are left out as well.
//! `src/main.rs` and `src/cli/` are the binary, a crate of its own that uses
//! only the front door.
//!
//! The rules: no cycle between top-level modules; no technique (nor
//! `surface`, `view`, `graph`, `vulkan` below them) names the `renderer` or
//! the `cli`; `surface`, the types the techniques share, names no technique.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The technique folders: graph nodes that may take each other's outputs
/// but never form a cycle.
const TECHNIQUES: [&str; 6] = ["lighting", "points", "post", "synthesis", "terrain", "texturing"];
/// The layers below the techniques.
const BELOW_TECHNIQUES: [&str; 4] = ["surface", "view", "graph", "vulkan"];
/// What nothing below the renderer may name.
const ABOVE_TECHNIQUES: [&str; 2] = ["renderer", "cli"];

#[derive(Clone, Debug, PartialEq)]
enum Token {
    Ident(String),
    Str(String),
    Punct(char),
    /// Numbers, char literals, lifetimes.
    Other,
}

/// The tokens of Rust source `text`, without comments.
fn tokenize(text: &str) -> Vec<Token> {
    let c: Vec<char> = text.chars().collect();
    let (mut i, mut out) = (0, Vec::new());
    let ident_char = |ch: char| ch.is_alphanumeric() || ch == '_';
    while i < c.len() {
        let ch = c[i];
        let next = c.get(i + 1).copied();
        if ch.is_whitespace() {
            i += 1;
        } else if ch == '/' && next == Some('/') {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if ch == '/' && next == Some('*') {
            let mut depth = 0;
            while i < c.len() {
                if c[i] == '/' && c.get(i + 1) == Some(&'*') {
                    depth += 1;
                    i += 2;
                } else if c[i] == '*' && c.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if let Some((len, value)) = string_literal(&c[i..]) {
            out.push(Token::Str(value));
            i += len;
        } else if ch == '\'' {
            // A char literal ('a', '\n', '{') or a lifetime ('a).
            if next == Some('\\') {
                i += 2;
                while i < c.len() && c[i] != '\'' {
                    i += 1;
                }
                i += 1;
            } else if c.get(i + 2) == Some(&'\'') {
                i += 3;
            } else {
                i += 1;
                while i < c.len() && ident_char(c[i]) {
                    i += 1;
                }
            }
            out.push(Token::Other);
        } else if ch.is_ascii_digit() {
            while i < c.len() && ident_char(c[i]) {
                i += 1;
            }
            out.push(Token::Other);
        } else if ident_char(ch) {
            let start = i;
            while i < c.len() && ident_char(c[i]) {
                i += 1;
            }
            let word: String = c[start..i].iter().collect();
            out.push(Token::Ident(word.strip_prefix("r#").unwrap_or(&word).to_string()));
        } else {
            out.push(Token::Punct(ch));
            i += 1;
        }
    }
    out
}

/// A string literal at the start of `c` ("…", b"…", r#"…"#, br"…"): its
/// length in chars and its (unescaped only as far as `\"`) contents.
fn string_literal(c: &[char]) -> Option<(usize, String)> {
    let mut i = 0;
    if c.first() == Some(&'b') {
        i += 1;
    }
    if c.get(i) == Some(&'r') && matches!(c.get(i + 1), Some('"' | '#')) {
        i += 1;
        let mut hashes = 0;
        while c.get(i) == Some(&'#') {
            hashes += 1;
            i += 1;
        }
        if c.get(i) != Some(&'"') {
            return None;
        }
        let start = i + 1;
        let mut j = start;
        while j < c.len() {
            if c[j] == '"' && (0..hashes).all(|h| c.get(j + 1 + h) == Some(&'#')) {
                return Some((j + 1 + hashes, c[start..j].iter().collect()));
            }
            j += 1;
        }
        return Some((c.len(), String::new()));
    }
    if c.get(i) != Some(&'"') {
        return None;
    }
    let mut j = i + 1;
    let mut value = String::new();
    while j < c.len() && c[j] != '"' {
        if c[j] == '\\' {
            j += 1;
        }
        if let Some(&ch) = c.get(j) {
            value.push(ch);
        }
        j += 1;
    }
    Some((j + 1, value))
}

fn is_punct(t: Option<&Token>, p: char) -> bool {
    t == Some(&Token::Punct(p))
}

fn ident(t: Option<&Token>) -> Option<&str> {
    match t {
        Some(Token::Ident(s)) => Some(s),
        _ => None,
    }
}

/// One source file of the library as the walk found it.
struct SourceFile {
    path: PathBuf,
    /// Its module path from the crate root (`["terrain", "shading"]`).
    module: Vec<String>,
    /// Compiled only with `cfg(test)`.
    test: bool,
}

/// A `mod name;` declaration: the child's name, its `#[path]`, and
/// whether it is under `#[cfg(test)]`.
struct ModDecl {
    name: String,
    path: Option<String>,
    test: bool,
}

/// The tokens of `tokens` outside `#[cfg(test)]` items, and the file
/// modules declared (under `cfg(test)` or not).
fn split_test_items(tokens: &[Token]) -> (Vec<Token>, Vec<ModDecl>) {
    let mut kept = Vec::new();
    let mut mods = Vec::new();
    let mut i = 0;
    let (mut cfg_test, mut path_attr) = (false, None);
    while i < tokens.len() {
        // An attribute: #[…] or #![…].
        if is_punct(tokens.get(i), '#') {
            let open = if is_punct(tokens.get(i + 1), '!') { i + 2 } else { i + 1 };
            if is_punct(tokens.get(open), '[') {
                let close = matching(tokens, open);
                let body = &tokens[open + 1..close];
                let inner = open == i + 2;
                if is_cfg_test(body) {
                    if inner {
                        // #![cfg(test)]: the whole file (or block) is test code.
                        return (Vec::new(), Vec::new());
                    }
                    cfg_test = true;
                }
                if ident(body.first()) == Some("path") && is_punct(body.get(1), '=') {
                    if let Some(Token::Str(p)) = body.get(2) {
                        path_attr = Some(p.clone());
                    }
                }
                i = close + 1;
                continue;
            }
        }
        // The item the attributes belong to (or any token without them).
        let item_end = match cfg_test {
            true => item_end(tokens, i),
            false => i + 1,
        };
        let mut next = item_end;
        if let Some((name, len)) = mod_declaration(&tokens[i..]) {
            mods.push(ModDecl {
                name,
                path: path_attr.take(),
                test: cfg_test,
            });
            next = next.max(i + len);
        }
        if !cfg_test {
            kept.extend_from_slice(&tokens[i..next]);
        }
        i = next;
        cfg_test = false;
        path_attr = None;
    }
    (kept, mods)
}

/// Whether an attribute body is `cfg(test)` or `cfg(all(test, …))`.
fn is_cfg_test(body: &[Token]) -> bool {
    let words: Vec<&str> = body.iter().filter_map(|t| ident(Some(t))).collect();
    words.first() == Some(&"cfg")
        && (words.get(1) == Some(&"test") || (words.get(1) == Some(&"all") && words.contains(&"test")))
        && !words.contains(&"not")
        && !words.contains(&"any")
}

/// The index of the bracket closing the one at `open`.
fn matching(tokens: &[Token], open: usize) -> usize {
    let mut depth = 0i32;
    for (k, t) in tokens.iter().enumerate().skip(open) {
        match t {
            Token::Punct('(' | '[' | '{') => depth += 1,
            Token::Punct(')' | ']' | '}') => {
                depth -= 1;
                if depth == 0 {
                    return k;
                }
            }
            _ => {}
        }
    }
    tokens.len() - 1
}

/// One past the end of the item (or field, arm, statement) starting at
/// `start`: a `;` or `,` at its own depth, a `}` closing its first block,
/// or the bracket closing the enclosing one.
fn item_end(tokens: &[Token], start: usize) -> usize {
    let mut depth = 0i32;
    for (k, t) in tokens.iter().enumerate().skip(start) {
        match t {
            Token::Punct('(' | '[' | '{') => depth += 1,
            Token::Punct(')' | ']' | '}') => {
                depth -= 1;
                if depth < 0 {
                    return k;
                }
                if depth == 0 && *t == Token::Punct('}') {
                    let semicolon = is_punct(tokens.get(k + 1), ';');
                    return k + 1 + usize::from(semicolon);
                }
            }
            Token::Punct(';' | ',') if depth == 0 => return k + 1,
            _ => {}
        }
    }
    tokens.len()
}

/// `name` and the declaration's length in tokens if `tokens` starts with
/// `[pub[(…)]] mod name;`.
fn mod_declaration(tokens: &[Token]) -> Option<(String, usize)> {
    let mut i = 0;
    if ident(tokens.first()) == Some("pub") {
        i = 1;
        if is_punct(tokens.get(1), '(') {
            i = matching(tokens, 1) + 1;
        }
    }
    if ident(tokens.get(i)) != Some("mod") || !is_punct(tokens.get(i + 2), ';') {
        return None;
    }
    ident(tokens.get(i + 1)).map(|name| (name.to_string(), i + 3))
}

/// The top-level modules that the non-test `tokens` of a file at module
/// path `module` name, besides its own.
fn imports(tokens: &[Token], module: &[String]) -> BTreeSet<String> {
    let mut names = BTreeSet::new();
    let path_sep = |k: usize| is_punct(tokens.get(k), ':') && is_punct(tokens.get(k + 1), ':');
    for k in 0..tokens.len() {
        // `crate::` not preceded by `::` ($crate and the like aside).
        let start_of_path = k == 0 || !is_punct(tokens.get(k - 1), ':');
        if ident(tokens.get(k)) == Some("crate") && start_of_path && path_sep(k + 1) {
            if let Some(name) = ident(tokens.get(k + 3)) {
                names.insert(name.to_string());
            } else if is_punct(tokens.get(k + 3), '{') {
                // crate::{a::…, b, c::{…}}: the first segment of each entry.
                let close = matching(tokens, k + 3);
                let mut depth = 0;
                for (j, token) in tokens.iter().enumerate().take(close).skip(k + 3) {
                    match token {
                        Token::Punct('{' | '(' | '[') => depth += 1,
                        Token::Punct('}' | ')' | ']') => depth -= 1,
                        _ => {}
                    }
                    let entry_start = depth == 1 && matches!(token, Token::Punct('{' | ','));
                    if entry_start {
                        if let Some(name) = ident(tokens.get(j + 1)) {
                            names.insert(name.to_string());
                        }
                    }
                }
            }
        }
        // super::super::X climbing to the root.
        if ident(tokens.get(k)) == Some("super") && start_of_path {
            let mut supers = 0;
            let mut j = k;
            while ident(tokens.get(j)) == Some("super") && path_sep(j + 1) {
                supers += 1;
                j += 3;
            }
            if supers >= module.len() {
                if let Some(name) = ident(tokens.get(j)) {
                    names.insert(name.to_string());
                }
            }
        }
    }
    names.remove(&module[0]);
    names
}

/// The library's files from `src/lib.rs` down its `mod` declarations.
fn library_files(src: &Path) -> (Vec<SourceFile>, Vec<String>) {
    let lib = std::fs::read_to_string(src.join("lib.rs")).unwrap();
    let (_, top) = split_test_items(&tokenize(&lib));
    let top_names = top.iter().map(|m| m.name.clone()).collect();
    let mut files = Vec::new();
    let mut queue: Vec<(PathBuf, Vec<String>, bool)> = Vec::new();
    for m in top {
        queue.push((child_file(src, &src.join("lib.rs"), &m), vec![m.name.clone()], m.test));
    }
    while let Some((path, module, test)) = queue.pop() {
        let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let (_, mods) = split_test_items(&tokenize(&text));
        for m in mods {
            let mut child = module.clone();
            child.push(m.name.clone());
            queue.push((child_file(src, &path, &m), child, test || m.test));
        }
        files.push(SourceFile { path, module, test });
    }
    (files, top_names)
}

/// The file of module `decl` declared in `parent`.
fn child_file(src: &Path, parent: &Path, decl: &ModDecl) -> PathBuf {
    let dir = parent.parent().unwrap_or(src);
    if let Some(p) = &decl.path {
        return dir.join(p);
    }
    let stem = parent.file_stem().unwrap().to_str().unwrap();
    let base = match stem {
        "lib" | "mod" | "main" => dir.to_path_buf(),
        _ => dir.join(stem),
    };
    let flat = base.join(format!("{}.rs", decl.name));
    match flat.exists() {
        true => flat,
        false => base.join(&decl.name).join("mod.rs"),
    }
}

/// Edges between top-level modules: importer → (imported → files).
type Graph = BTreeMap<String, BTreeMap<String, BTreeSet<String>>>;

/// The import graph of the library's non-test code under `src`.
fn module_graph(src: &Path) -> Graph {
    let (files, top) = library_files(src);
    let mut graph = Graph::new();
    for file in files.iter().filter(|f| !f.test) {
        let text = std::fs::read_to_string(&file.path).unwrap();
        let (code, _) = split_test_items(&tokenize(&text));
        let from = graph.entry(file.module[0].clone()).or_default();
        for to in imports(&code, &file.module) {
            if top.contains(&to) {
                let shown = file.path.strip_prefix(src).unwrap_or(&file.path).display().to_string();
                from.entry(to).or_default().insert(shown);
            }
        }
    }
    graph
}

/// A cycle of `graph` (its first module repeated at the end), if any.
fn find_cycle(graph: &Graph) -> Option<Vec<String>> {
    /// 0 unvisited, 1 on the stack, 2 done.
    fn visit(
        node: &str,
        graph: &Graph,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(node.to_string(), 1);
        stack.push(node.to_string());
        for next in graph.get(node).into_iter().flat_map(|e| e.keys()) {
            match state.get(next.as_str()).copied().unwrap_or(0) {
                1 => {
                    let at = stack.iter().position(|n| n == next).unwrap();
                    let mut cycle = stack[at..].to_vec();
                    cycle.push(next.clone());
                    return Some(cycle);
                }
                0 => {
                    if let Some(cycle) = visit(next, graph, state, stack) {
                        return Some(cycle);
                    }
                }
                _ => {}
            }
        }
        stack.pop();
        state.insert(node.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for node in graph.keys() {
        if state.get(node).copied().unwrap_or(0) == 0 {
            if let Some(cycle) = visit(node, graph, &mut state, &mut Vec::new()) {
                return Some(cycle);
            }
        }
    }
    None
}

/// One line per edge of `cycle`, with the files that make it.
fn describe(graph: &Graph, cycle: &[String]) -> String {
    let edges: Vec<String> = cycle
        .windows(2)
        .map(|w| {
            let files: Vec<&String> = graph[&w[0]][&w[1]].iter().collect();
            format!("  {} → {} ({files:?})", w[0], w[1])
        })
        .collect();
    format!("{}\n{}", cycle.join(" → "), edges.join("\n"))
}

/// The rules of the module docs, broken: one line each.
fn violations(graph: &Graph) -> Vec<String> {
    let mut broken = Vec::new();
    if let Some(cycle) = find_cycle(graph) {
        broken.push(format!(
            "import cycle between top-level modules: {}",
            describe(graph, &cycle)
        ));
    }
    for (from, edges) in graph {
        let below_renderer = TECHNIQUES.contains(&from.as_str()) || BELOW_TECHNIQUES.contains(&from.as_str());
        for (to, files) in edges {
            if below_renderer && ABOVE_TECHNIQUES.contains(&to.as_str()) {
                broken.push(format!("{from} names {to}, above it: {files:?}"));
            }
            if from == "surface" && TECHNIQUES.contains(&to.as_str()) {
                broken.push(format!(
                    "surface (below the techniques) names the technique {to}: {files:?}"
                ));
            }
        }
    }
    broken
}

fn src_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

#[test]
fn no_cycle_between_top_level_modules_and_techniques_stay_below_the_renderer() {
    let graph = module_graph(&src_dir());
    for (from, edges) in &graph {
        let names: Vec<&String> = edges.keys().collect();
        println!("{from} → {names:?}");
    }
    let broken = violations(&graph);
    assert!(broken.is_empty(), "{}", broken.join("\n"));
}

/// Every library file is reached by the walk (so none escapes the check),
/// and the walk finds the test-only files as such.
#[test]
fn the_walk_reaches_every_library_file() {
    let src = src_dir();
    let (files, top) = library_files(&src);
    assert!(top.iter().any(|t| t == "terrain") && top.iter().any(|t| t == "surface"));
    let reached: BTreeSet<&PathBuf> = files.iter().map(|f| &f.path).collect();
    let mut all = Vec::new();
    crate::test_support::rust_files(&src, &mut all);
    let binary = [src.join("main.rs"), src.join("lib.rs")];
    let missed: Vec<&PathBuf> = all
        .iter()
        .filter(|p| !reached.contains(p) && !binary.contains(p) && !p.starts_with(src.join("cli")))
        .collect();
    assert!(missed.is_empty(), "files no mod declaration reaches: {missed:?}");
    let test_only = |path: &str| files.iter().any(|f| f.path == src.join(path) && f.test);
    assert!(test_only("lighting/reference/cpu.rs"), "a #[cfg(test)] mod declaration");
    assert!(
        test_only("texturing/quadtree_tests.rs"),
        "a #[cfg(test)] #[path] module"
    );
    assert!(test_only("test_support/mod.rs"));
    assert!(!test_only("surface/layers.rs"));
}

/// The check fails on a cycle (naming it and its files), on a technique
/// that names the renderer and on surface naming a technique, and it sees
/// through grouped imports, `super::` paths and `#[cfg(test)]` items.
#[test]
fn the_check_catches_cycles_and_upward_imports() {
    let file = |text: &str, module: &[&str]| {
        let (code, _) = split_test_items(&tokenize(text));
        let module: Vec<String> = module.iter().map(|m| m.to_string()).collect();
        imports(&code, &module)
    };
    let set = |names: &[&str]| names.iter().map(|n| n.to_string()).collect::<BTreeSet<String>>();
    assert_eq!(
        file(
            "use crate::{error::Result, texturing::x, view::{A, B}};",
            &["terrain", "a"]
        ),
        set(&["error", "texturing", "view"])
    );
    assert_eq!(
        file("use super::super::points::P;", &["terrain", "a"]),
        set(&["points"])
    );
    assert_eq!(file("use super::super::x::P;", &["terrain", "a", "b"]), set(&[]));
    let test_only = "#[cfg(test)]\nmod tests { use crate::renderer::R; }\n#[cfg(test)]\nuse crate::lighting::L;\nfn f() -> char { '{' }";
    assert_eq!(file(test_only, &["terrain"]), set(&[]));
    let commented = "// crate::renderer\n/// [`crate::lighting::x`]\nconst S: &str = \"crate::post\"; fn g() { crate::io::read(); }";
    assert_eq!(file(commented, &["terrain"]), set(&["io"]));

    let graph = |edges: &[(&str, &str)]| {
        let mut g = Graph::new();
        for (a, b) in edges {
            g.entry(a.to_string())
                .or_default()
                .entry(b.to_string())
                .or_default()
                .insert(format!("{a}/x.rs"));
        }
        g
    };
    let cycle = graph(&[
        ("terrain", "texturing"),
        ("texturing", "points"),
        ("points", "terrain"),
        ("points", "view"),
    ]);
    let broken = violations(&cycle);
    assert_eq!(broken.len(), 1, "{broken:?}");
    assert!(
        broken[0].contains("terrain → texturing → points → terrain")
            || broken[0].contains("points → terrain → texturing → points"),
        "{}",
        broken[0]
    );
    assert!(broken[0].contains("texturing/x.rs"), "{}", broken[0]);
    assert_eq!(
        violations(&graph(&[("terrain", "texturing"), ("texturing", "surface")])),
        Vec::<String>::new()
    );
    assert_eq!(violations(&graph(&[("lighting", "renderer")])).len(), 1);
    assert_eq!(violations(&graph(&[("surface", "terrain")])).len(), 1);
}
