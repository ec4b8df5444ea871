//! The library's layering, checked against the table written once in
//! ARCHITECTURE.md ("## Layers"). A row names the modules a module reads
//! directly; it may also read what those read, and so on down. Every
//! `crate::…` path in a module's source must be allowed that way, every
//! module a row names must really be read (so the table cannot drift from the
//! code), every module of `src/` has a row, and the table has no cycle (it is
//! a layering). Comments and strings are ignored; test code counts like any
//! other.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

const HEADING: &str = "## Layers";

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).to_path_buf()
}

/// The rows of the table under [`HEADING`]: module → the modules it may use.
/// A row is `| `module` | `a`, `b` | why |`; `—` for none.
fn allowed(architecture: &str) -> BTreeMap<String, BTreeSet<String>> {
    table(architecture, HEADING)
        .into_iter()
        .map(|(module, cells)| {
            (
                module,
                cells.first().map_or_else(BTreeSet::new, |c| names(c)),
            )
        })
        .collect()
}

/// The names in backquotes in a cell.
fn names(cell: &str) -> BTreeSet<String> {
    cell.split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

/// The rows of the first table under `heading`: the module its first cell
/// names → its other cells.
fn table(architecture: &str, heading: &str) -> BTreeMap<String, Vec<String>> {
    let start = architecture
        .find(heading)
        .unwrap_or_else(|| panic!("ARCHITECTURE.md has no `{heading}` section"));
    let mut rows = BTreeMap::new();
    let mut in_table = false;
    for line in architecture[start..].lines().skip(1) {
        let line = line.trim();
        if !line.starts_with('|') {
            if in_table {
                break;
            }
            continue;
        }
        in_table = true;
        let cells: Vec<&str> = line.trim_matches('|').split('|').map(str::trim).collect();
        let module: Vec<String> = names(cells[0]).into_iter().collect();
        let [module] = module.as_slice() else {
            continue; // the header and the separator
        };
        let rest: Vec<String> = cells[1..].iter().map(|c| c.to_string()).collect();
        let previous = rows.insert(module.clone(), rest);
        assert!(previous.is_none(), "`{module}` has two rows in {heading}");
    }
    assert!(!rows.is_empty(), "the {heading} table is empty");
    rows
}

/// The library's modules: `src/*.rs` (but `lib.rs`) and `src/*/`, each with
/// its files.
fn modules(src: &Path) -> BTreeMap<String, Vec<PathBuf>> {
    let mut modules = BTreeMap::new();
    for entry in std::fs::read_dir(src).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        // A module is `name.rs`, `name/`, or both (`host.rs` with `host/`).
        let mut files = Vec::new();
        if path.is_dir() {
            rust_files(&path, &mut files);
        } else if path.extension().is_some_and(|e| e == "rs") && name != "lib" {
            files.push(path);
        }
        if !files.is_empty() {
            modules.entry(name).or_insert_with(Vec::new).extend(files);
        }
    }
    modules
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The source without comments (`//…` to the end of the line, `/*…*/`) and
/// with string and char literals blanked: a path in a comment or a string is
/// no dependency.
fn code_only(source: &str) -> String {
    let bytes = source.as_bytes();
    let mut out = String::with_capacity(source.len());
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'/' if bytes.get(i + 1) == Some(&b'/') => {
                while i < bytes.len() && bytes[i] != b'\n' {
                    i += 1;
                }
            }
            b'/' if bytes.get(i + 1) == Some(&b'*') => {
                let end = source[i + 2..]
                    .find("*/")
                    .map_or(bytes.len(), |e| i + 2 + e + 2);
                i = end;
            }
            b'r' if source[i..].starts_with("r#\"") || source[i..].starts_with("r\"") => {
                let hashes = source[i + 1..].bytes().take_while(|&b| b == b'#').count();
                let close = format!("\"{}", "#".repeat(hashes));
                let body = i + 1 + hashes + 1;
                i = source[body..]
                    .find(&close)
                    .map_or(bytes.len(), |e| body + e + close.len());
                out.push_str("\"\"");
            }
            // A char literal (`'"'`, `'\''`), not a lifetime (`'a`).
            b'\'' if bytes.get(i + 1) == Some(&b'\\') => {
                let end = source[i + 3..]
                    .find('\'')
                    .map_or(bytes.len(), |e| i + 3 + e + 1);
                i = end;
                out.push_str("' '");
            }
            b'\'' if source[i + 1..].chars().nth(1) == Some('\'') => {
                i += 1 + source[i + 1..].chars().next().unwrap().len_utf8() + 1;
                out.push_str("' '");
            }
            b'"' => {
                i += 1;
                while i < bytes.len() && bytes[i] != b'"' {
                    i += if bytes[i] == b'\\' { 2 } else { 1 };
                }
                i += 1;
                out.push_str("\"\"");
            }
            _ => {
                // Copy one whole character (the source is UTF-8).
                let len = source[i..].chars().next().unwrap().len_utf8();
                out.push_str(&source[i..i + len]);
                i += len;
            }
        }
    }
    out
}

/// The first segments of every `crate::` path: `crate::a::b` gives `a`,
/// `crate::{a::b, c}` gives `a` and `c`.
fn crate_paths(code: &str) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    for (at, _) in code.match_indices("crate::") {
        let preceded = code[..at]
            .chars()
            .next_back()
            .is_some_and(|c| c.is_alphanumeric() || c == '_' || c == '$');
        if preceded {
            continue; // `$crate::`, or a name ending in `crate`
        }
        let rest = code[at + "crate::".len()..].trim_start();
        if let Some(group) = rest.strip_prefix('{') {
            let mut depth = 0;
            let mut start = true;
            for (i, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => start = true,
                    c if start && !c.is_whitespace() => {
                        start = false;
                        found.insert(ident(&group[i..]));
                    }
                    _ => {}
                }
            }
        } else {
            found.insert(ident(rest));
        }
    }
    found.remove("");
    found
}

/// Names `lib.rs` re-exports at the root (`pub use sema::{Analysis, …};`),
/// with the module they come from.
fn root_reexports(lib: &str) -> BTreeMap<String, String> {
    let mut names = BTreeMap::new();
    for line in code_only(lib).lines() {
        let Some(rest) = line.trim().strip_prefix("pub use ") else {
            continue;
        };
        let module = rest.split("::").next().unwrap_or("").to_string();
        let items = rest.trim_end_matches(';');
        let items = items.split_once('{').map_or(items, |(_, i)| i);
        for item in items.trim_end_matches('}').split(',') {
            let name = item.trim().rsplit("::").next().unwrap_or("").trim();
            if !name.is_empty() {
                names.insert(name.to_string(), module.clone());
            }
        }
    }
    names
}

/// The modules `module` may read: those its row names, and theirs, down.
fn below(module: &str, rows: &BTreeMap<String, BTreeSet<String>>) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    let mut stack: Vec<&str> = vec![module];
    while let Some(next) = stack.pop() {
        for used in rows.get(next).into_iter().flatten() {
            if seen.insert(used.clone()) {
                stack.push(used);
            }
        }
    }
    seen
}

fn find_cycle(rows: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        node: &str,
        rows: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        match state.get(node) {
            Some(2) => return None,
            Some(1) => {
                let from = stack.iter().position(|n| n == node).unwrap();
                let mut cycle = stack[from..].to_vec();
                cycle.push(node.to_string());
                return Some(cycle);
            }
            _ => {}
        }
        state.insert(node.to_string(), 1);
        stack.push(node.to_string());
        for next in rows.get(node).into_iter().flatten() {
            if let Some(cycle) = visit(next, rows, state, stack) {
                return Some(cycle);
            }
        }
        stack.pop();
        state.insert(node.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    rows.keys()
        .find_map(|m| visit(m, rows, &mut state, &mut Vec::new()))
}

#[test]
fn modules_use_only_what_the_architecture_table_allows() {
    let architecture = std::fs::read_to_string(root().join("../ARCHITECTURE.md")).unwrap();
    let src = root().join("src");
    let reexports = root_reexports(&std::fs::read_to_string(src.join("lib.rs")).unwrap());
    // The library's root only re-exports: any other root name is a mistake.
    let problems = check_layers(&src, &allowed(&architecture), HEADING, |first| {
        Some(
            reexports
                .get(first)
                .cloned()
                .unwrap_or_else(|| first.to_string()),
        )
    });
    assert!(
        problems.is_empty(),
        "ARCHITECTURE.md's layering and the code disagree:\n  {}",
        problems.join("\n  ")
    );
}

/// The two back ends over `refine`, the C generator and the simulator, are
/// siblings: neither may read the other, directly or through a module it
/// reads (the host's build plan, say). So the simulator's meaning of a
/// mission cannot come from the generator's code, nor the C from the
/// simulator's, and whatever both need lives below both (`refine`).
#[test]
fn codegen_and_sim_are_sibling_back_ends() {
    let architecture = std::fs::read_to_string(root().join("../ARCHITECTURE.md")).unwrap();
    let rows = allowed(&architecture);
    for (back_end, other) in [("sim", "codegen"), ("codegen", "sim")] {
        let reaches = below(back_end, &rows);
        assert!(
            reaches.contains("refine"),
            "`{back_end}` should read the refined programs"
        );
        assert!(
            !reaches.contains(other),
            "`{back_end}` reaches `{other}` in ARCHITECTURE.md's layers: the back ends are siblings over `refine`"
        );
    }
}

/// The problems of the modules of `src` against `rows` (the table under
/// `heading`); `root_item` names the module a `crate::NAME` that is no
/// module comes from (a re-export at the root), or `None` for an item of
/// the root itself, which is outside the table.
fn check_layers(
    src: &Path,
    rows: &BTreeMap<String, BTreeSet<String>>,
    heading: &str,
    root_item: impl Fn(&str) -> Option<String>,
) -> Vec<String> {
    let modules = modules(src);
    let mut problems = Vec::new();
    for name in modules.keys().filter(|m| !rows.contains_key(*m)) {
        problems.push(format!(
            "`{name}` ({}) has no row in {heading}",
            src.display()
        ));
    }
    for (name, uses) in rows {
        if !modules.contains_key(name) {
            problems.push(format!(
                "{heading} has a row for `{name}`, which is no module"
            ));
        }
        for used in uses.iter().filter(|u| !rows.contains_key(*u)) {
            problems.push(format!("`{name}`'s row allows `{used}`, which has no row"));
        }
    }
    if let Some(cycle) = find_cycle(rows) {
        problems.push(format!("{heading} has a cycle: {}", cycle.join(" → ")));
    }
    if !problems.is_empty() {
        return problems;
    }
    for (name, files) in &modules {
        let named = &rows[name];
        let may_use = below(name, rows);
        let mut used = BTreeSet::new();
        for file in files {
            let code = code_only(&std::fs::read_to_string(file).unwrap());
            for first in crate_paths(&code) {
                let module = if modules.contains_key(&first) {
                    first
                } else {
                    match root_item(&first) {
                        Some(module) => module,
                        None => continue,
                    }
                };
                if !modules.contains_key(&module) {
                    problems.push(format!(
                        "{}: `crate::{module}` is no module",
                        file.display()
                    ));
                    continue;
                }
                if module == *name {
                    continue;
                }
                if !may_use.contains(&module) {
                    problems.push(format!(
                        "{}: `{name}` uses `{module}`, which its row in {heading} does not allow",
                        file.strip_prefix(src).unwrap_or(file).display()
                    ));
                }
                used.insert(module);
            }
        }
        for unused in named.difference(&used) {
            problems.push(format!(
                "`{name}`'s row in {heading} names `{unused}`, which it does not read: remove it"
            ));
        }
    }
    problems
}

#[test]
fn the_path_reader_finds_plain_grouped_and_reexported_paths() {
    let code = code_only(
        "use crate::diag::{self, Code};\n\
         use crate::{sema::Mission, span::Span as S,\n  text};\n\
         // use crate::ide::lookup;\n\
         /* crate::refine */ let s = \"crate::codegen\";\n\
         let a = crate::check_source(x);\n\
         macro_rules! m { () => { $crate::workspace::x } }\n",
    );
    let found: Vec<String> = crate_paths(&code).into_iter().collect();
    assert_eq!(found, ["check_source", "diag", "sema", "span", "text"]);
    let reexports = root_reexports("pub use sema::{Analysis, check_source};\n");
    assert_eq!(reexports["check_source"], "sema");
    assert_eq!(reexports["Analysis"], "sema");
}

#[test]
fn the_table_reader_reads_rows_and_rejects_nothing_silently() {
    let rows = allowed(
        "# A\n\n## Layers\n\ntext\n\n| module | may use | why |\n| --- | --- | --- |\n\
         | `span` | — | base |\n| `diag` | `span` | |\n\n| `other` | `x` | |\n",
    );
    assert_eq!(rows.len(), 2);
    assert!(rows["span"].is_empty());
    assert_eq!(rows["diag"].iter().collect::<Vec<_>>(), ["span"]);
    let cyclic: BTreeMap<String, BTreeSet<String>> = [
        ("a".to_string(), ["b".to_string()].into()),
        ("b".to_string(), ["a".to_string()].into()),
    ]
    .into();
    assert!(find_cycle(&cyclic).is_some());
    let layered: BTreeMap<String, BTreeSet<String>> = [
        ("a".to_string(), ["b".to_string()].into()),
        ("b".to_string(), ["c".to_string()].into()),
        ("c".to_string(), BTreeSet::new()),
    ]
    .into();
    assert!(find_cycle(&layered).is_none());
    assert_eq!(
        below("a", &layered).into_iter().collect::<Vec<_>>(),
        ["b", "c"]
    );
}

/// Every path a file names from `crate::` or `super::`, as the segments of
/// the module it reaches (`file_module`: the file's own module path, e.g.
/// `["codegen", "output", "write"]` for `codegen/output/write.rs`), each
/// group (`{a, b::c}`) expanded.
fn module_paths(code: &str, file_module: &[String]) -> Vec<Vec<String>> {
    fn ident(s: &str) -> &str {
        let end = s
            .find(|c: char| !(c.is_alphanumeric() || c == '_'))
            .unwrap_or(s.len());
        &s[..end]
    }
    /// The paths under `rest` (after a `::`), each prefixed with `base`.
    fn expand(rest: &str, base: Vec<String>, out: &mut Vec<Vec<String>>) {
        let rest = rest.trim_start();
        if let Some(group) = rest.strip_prefix('{') {
            let mut depth = 0;
            let mut start = 0;
            for (i, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => {
                        expand(&group[start..i], base.clone(), out);
                        return;
                    }
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        expand(&group[start..i], base.clone(), out);
                        start = i + 1;
                    }
                    _ => {}
                }
            }
            return;
        }
        let name = ident(rest);
        let mut path = base;
        if name.is_empty() || name == "self" {
            out.push(path);
            return;
        }
        path.push(name.to_string());
        match rest[name.len()..].trim_start().strip_prefix("::") {
            Some(more) => expand(more, path, out),
            None => out.push(path),
        }
    }
    let mut out = Vec::new();
    for prefix in ["crate::", "super::"] {
        for (at, _) in code.match_indices(prefix) {
            let preceded = code[..at]
                .chars()
                .next_back()
                .is_some_and(|c| c.is_alphanumeric() || c == '_' || c == '$' || c == ':');
            if preceded {
                continue; // `$crate::`, `super::super::` (taken at its first), a longer name
            }
            let mut rest = &code[at + prefix.len()..];
            let base = if prefix == "crate::" {
                Vec::new()
            } else {
                let mut base = file_module[..file_module.len().saturating_sub(1)].to_vec();
                while let Some(more) = rest.trim_start().strip_prefix("super::") {
                    base.pop();
                    rest = more;
                }
                base
            };
            expand(rest, base, &mut out);
        }
    }
    out
}

/// The parts of a folder module (`src/M/`): its files and folders but
/// `mod.rs` and its own tests and their helpers (`tests`, `testing`), each
/// with its files.
fn parts(folder: &Path) -> BTreeMap<String, Vec<PathBuf>> {
    let mut parts: BTreeMap<String, Vec<PathBuf>> = BTreeMap::new();
    for entry in std::fs::read_dir(folder).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        if name == "mod" || name == "tests" || name == "testing" {
            continue;
        }
        let mut files = Vec::new();
        if path.is_dir() {
            rust_files(&path, &mut files);
        } else if path.extension().is_some_and(|e| e == "rs") {
            files.push(path);
        }
        if !files.is_empty() {
            parts.entry(name).or_default().extend(files);
        }
    }
    parts
}

/// A file's module path below `src`: `a/b.rs` → `[a, b]`, `a/b/mod.rs` → `[a, b]`.
fn file_module(src: &Path, file: &Path) -> Vec<String> {
    let relative = file.strip_prefix(src).unwrap().with_extension("");
    let mut path: Vec<String> = relative
        .iter()
        .map(|s| s.to_string_lossy().into_owned())
        .collect();
    if path.last().is_some_and(|l| l == "mod") {
        path.pop();
    }
    path
}

/// Inside each module folder, at every depth, the parts are layered too:
/// no part reads a part that reads it back, directly or through others (the
/// folder's own `mod.rs`, which wires them, and its tests stand above them
/// all).
#[test]
fn the_parts_of_each_module_folder_form_no_cycle() {
    let src = root().join("src");
    let mut folders = Vec::new();
    let mut stack = vec![src.clone()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                folders.push(path.clone());
                stack.push(path);
            }
        }
    }
    let mut problems = Vec::new();
    let mut checked = 0;
    for folder in folders {
        let module = file_module(&src, &folder.join("mod.rs"));
        let parts = parts(&folder);
        let mut reads: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for (part, files) in &parts {
            let edges = reads.entry(part.clone()).or_default();
            for file in files {
                let code = code_only(&std::fs::read_to_string(file).unwrap());
                for path in module_paths(&code, &file_module(&src, file)) {
                    if path.len() > module.len()
                        && path[..module.len()] == module[..]
                        && path[module.len()] != *part
                        && parts.contains_key(&path[module.len()])
                    {
                        edges.insert(path[module.len()].clone());
                    }
                }
            }
        }
        checked += 1;
        if let Some(cycle) = find_cycle(&reads) {
            problems.push(format!("{}/: {}", module.join("/"), cycle.join(" → ")));
        }
    }
    assert!(checked > 10, "only {checked} folders found under src/");
    assert!(
        problems.is_empty(),
        "parts of a module folder read each other in a cycle:\n  {}",
        problems.join("\n  ")
    );
}

#[test]
fn the_module_path_reader_resolves_crate_and_super_paths() {
    let at = |p: &[&str]| p.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let code = code_only(
        "use super::{model::Task, xml::{self, read}};\n\
         use super::super::diag::Code;\n\
         use crate::taskgraph::analysis::analyze;\n\
         let x = crate::{span::Span, text};\n",
    );
    let found = module_paths(&code, &at(&["taskgraph", "subgraph"]));
    let found: Vec<String> = found.iter().map(|p| p.join("::")).collect();
    assert_eq!(
        found,
        [
            "taskgraph::analysis::analyze",
            "span::Span",
            "text",
            "taskgraph::model::Task",
            "taskgraph::xml",
            "taskgraph::xml::read",
            "diag::Code",
        ]
    );
}

const SERVER_HEADING: &str = "## Server layers";

/// The protocol's names a file uses: every name under `tower_lsp_server::`
/// (a `use` tree expanded), `*` for a glob, and the names used through an
/// alias of a protocol module (`use tower_lsp_server::ls_types::{self as lsp}`
/// then `lsp::Diagnostic`).
fn protocol_names(code: &str) -> BTreeSet<String> {
    const MODULES: &[&str] = &[
        "ls_types",
        "jsonrpc",
        "notification",
        "request",
        "self",
        "as",
    ];
    let mut found = BTreeSet::new();
    let mut aliases = Vec::new();
    for (at, _) in code.match_indices("tower_lsp_server::") {
        let rest = &code[at + "tower_lsp_server::".len()..];
        // A path ends at the first character that cannot continue it, unless
        // that is a group's `{`: then at the group's `}`.
        let path_end = rest
            .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':' || c == '*'))
            .unwrap_or(rest.len());
        let mut end = path_end;
        if rest[path_end..].starts_with('{') {
            let mut depth = 0;
            for (i, c) in rest[path_end..].char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' => {
                        depth -= 1;
                        if depth == 0 {
                            end = path_end + i + 1;
                            break;
                        }
                    }
                    _ => {}
                }
            }
        }
        let tree = &rest[..end];
        let words: Vec<&str> = tree
            .split(|c: char| !(c.is_alphanumeric() || c == '_' || c == '*'))
            .filter(|w| !w.is_empty())
            .collect();
        for (i, word) in words.iter().enumerate() {
            if i > 0 && words[i - 1] == "as" {
                aliases.push(word.to_string());
            } else if !MODULES.contains(word) {
                found.insert(word.to_string());
            }
        }
    }
    for alias in aliases {
        for (at, _) in code.match_indices(&format!("{alias}::")) {
            let preceded = code[..at]
                .chars()
                .next_back()
                .is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':');
            if preceded {
                continue;
            }
            let name: String = code[at + alias.len() + 2..]
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            found.insert(name);
        }
    }
    found
}

/// The language server's modules read down their table, and speak the
/// protocol only as far as their row's third cell says: `all`, the names it
/// may use, or `—` (the live view and the monitor, which `semo operator`
/// shares, speak none). So the conversion of the library's answers into
/// protocol types stays in `to_proto`, the handlers and the server's door.
#[test]
fn the_server_reads_down_its_table_and_speaks_the_protocol_where_it_says() {
    let architecture = std::fs::read_to_string(root().join("../ARCHITECTURE.md")).unwrap();
    let src = root().join("../server/src");
    let rows = table(&architecture, SERVER_HEADING);
    let reads: BTreeMap<String, BTreeSet<String>> = rows
        .iter()
        .map(|(m, cells)| {
            (
                m.clone(),
                cells.first().map_or_else(BTreeSet::new, |c| names(c)),
            )
        })
        .collect();
    // `crate::State` and the other items of lib.rs: the state every task
    // shares, above the table.
    let mut problems = check_layers(&src, &reads, SERVER_HEADING, |_| None);
    for (module, files) in modules(&src) {
        let Some(cells) = rows.get(&module) else {
            continue; // reported above
        };
        let cell = cells.get(1).map_or("", |c| c.trim());
        let allowed = names(cell);
        let mut used = BTreeSet::new();
        for file in &files {
            let code = code_only(&std::fs::read_to_string(file).unwrap());
            for name in protocol_names(&code) {
                if cell != "all" && !allowed.contains(&name) {
                    problems.push(format!(
                        "{}: `{module}` uses the protocol's `{name}`, which its row in {SERVER_HEADING} does not allow",
                        file.strip_prefix(&src).unwrap_or(file).display()
                    ));
                }
                used.insert(name);
            }
        }
        for unused in allowed.difference(&used) {
            problems.push(format!(
                "`{module}`'s row in {SERVER_HEADING} names the protocol's `{unused}`, which it does not use: remove it"
            ));
        }
    }
    assert!(
        problems.is_empty(),
        "ARCHITECTURE.md's server layers and the code disagree:\n  {}",
        problems.join("\n  ")
    );
}

#[test]
fn the_protocol_reader_finds_use_trees_globs_and_aliases() {
    let code = code_only(
        "use tower_lsp_server::ls_types::{self as lsp, Uri};\n\
         use tower_lsp_server::{Client, jsonrpc::Result};\n\
         use tower_lsp_server::ls_types::*;\n\
         fn f() -> lsp::Diagnostic { tower_lsp_server::jsonrpc::ErrorCode::InternalError }\n",
    );
    let found: Vec<String> = protocol_names(&code).into_iter().collect();
    assert_eq!(
        found,
        [
            "*",
            "Client",
            "Diagnostic",
            "ErrorCode",
            "InternalError",
            "Result",
            "Uri"
        ]
    );
}
