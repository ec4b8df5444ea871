//! What the VS Code extension declares in `vscode-extension/package.json`
//! holds against the real server and the real `semo` binary: every semantic
//! token type the server sends is coloured by the default themes, the
//! extension wakes only for SeMo files, its problem matcher reads exactly the
//! diagnostics `semo check` prints, and its icon is there.

mod support;

use semo::ide::mission::semantic_tokens::{MODIFIERS, TokenKind};
use serde_json::Value;
use std::collections::BTreeSet;
use std::process::Command;
use support::{check_json_in, repo_root};

fn package_json() -> Value {
    let path = repo_root().join("vscode-extension/package.json");
    serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap()
}

/// The token types and modifiers every LSP client knows (LSP 3.17,
/// `SemanticTokenTypes` and `SemanticTokenModifiers`); themes colour these.
const STANDARD_TYPES: &[&str] = &[
    "namespace",
    "type",
    "class",
    "enum",
    "interface",
    "struct",
    "typeParameter",
    "parameter",
    "variable",
    "property",
    "enumMember",
    "event",
    "function",
    "method",
    "macro",
    "keyword",
    "modifier",
    "comment",
    "string",
    "number",
    "regexp",
    "operator",
    "decorator",
];
const STANDARD_MODIFIERS: &[&str] = &[
    "declaration",
    "definition",
    "readonly",
    "static",
    "deprecated",
    "abstract",
    "async",
    "modification",
    "documentation",
    "defaultLibrary",
];

#[test]
fn every_token_type_the_server_sends_is_declared_and_given_a_theme_scope() {
    let package = package_json();
    let contributes = &package["contributes"];
    let declared: BTreeSet<&str> = contributes["semanticTokenTypes"]
        .as_array()
        .expect("semanticTokenTypes")
        .iter()
        .map(|t| {
            let super_type = t["superType"].as_str().expect("a superType");
            assert!(
                STANDARD_TYPES.contains(&super_type),
                "{t}: themes colour a type through a standard superType"
            );
            t["id"].as_str().expect("id")
        })
        .collect();
    let scopes = contributes["semanticTokenScopes"]
        .as_array()
        .expect("semanticTokenScopes")
        .iter()
        .find(|s| s["language"] == "semo")
        .expect("scopes for the semo language")["scopes"]
        .as_object()
        .expect("a scope map");

    let sent: BTreeSet<&str> = TokenKind::ALL.iter().map(|k| k.name()).collect();
    for name in &sent {
        assert!(
            STANDARD_TYPES.contains(name) || declared.contains(name),
            "`{name}` is sent by the server but neither standard nor declared"
        );
        // VS Code maps the standard types to TextMate scopes itself.
        let scope = scopes.get(*name).and_then(Value::as_array);
        assert!(
            STANDARD_TYPES.contains(name)
                || scope.is_some_and(|s| !s.is_empty() && s.iter().all(|s| s.is_string())),
            "`{name}` has no TextMate scope, so themes without semantic colours leave it plain"
        );
    }
    let unused: Vec<_> = declared.difference(&sent).collect();
    assert!(unused.is_empty(), "declared but never sent: {unused:?}");
    let unused: Vec<_> = scopes
        .keys()
        .filter(|k| !sent.contains(k.as_str()))
        .collect();
    assert!(unused.is_empty(), "scoped but never sent: {unused:?}");
    for modifier in MODIFIERS {
        assert!(
            STANDARD_MODIFIERS.contains(&modifier),
            "modifier `{modifier}` must be standard or declared in semanticTokenModifiers"
        );
    }
}

#[test]
fn the_extension_wakes_only_for_semo_files() {
    let package = package_json();
    let events: Vec<&str> = package["activationEvents"]
        .as_array()
        .expect("activationEvents")
        .iter()
        .map(|e| e.as_str().unwrap())
        .collect();
    assert!(events.contains(&"onLanguage:semo"), "{events:?}");
    const SEMO_FILES: &[&str] = &[
        "**/semo.toml",
        "**/*.mission",
        "**/*.robot.xml",
        "**/*.strategy.xml",
        "**/*.taskgraph.xml",
    ];
    for event in &events {
        let ok = *event == "onLanguage:semo"
            || event
                .strip_prefix("workspaceContains:")
                .is_some_and(|glob| SEMO_FILES.contains(&glob));
        assert!(
            ok,
            "`{event}` wakes the extension for files that are not SeMo's"
        );
    }
}

#[test]
fn the_extension_has_a_128_pixel_png_icon() {
    let package = package_json();
    let icon = package["icon"].as_str().expect("an icon");
    let bytes = std::fs::read(repo_root().join("vscode-extension").join(icon)).unwrap();
    assert_eq!(
        &bytes[..8],
        b"\x89PNG\r\n\x1a\n",
        "the marketplace needs a PNG"
    );
    let width = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    let height = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
    assert_eq!((width, height), (128, 128));
}

/// One problem as VS Code's problem matcher reads it.
#[derive(Debug, PartialEq, Eq, PartialOrd, Ord)]
struct Problem {
    file: String,
    line: u64,
    column: u64,
    severity: &'static str,
    code: String,
    message: String,
}

/// VS Code's severity names: anything else takes the matcher's default.
fn severity(word: &str, default: &'static str) -> &'static str {
    match word.to_lowercase().as_str() {
        "error" => "error",
        "warning" | "warn" => "warning",
        "info" | "information" => "info",
        _ => default,
    }
}

/// Runs the `semo` problem matcher of package.json over terminal output as
/// VS Code does: colours removed, a match of the first pattern followed by
/// one of the second on the next line makes a problem.
fn match_problems(output: &str) -> Vec<Problem> {
    let package = package_json();
    let matcher = package["contributes"]["problemMatchers"]
        .as_array()
        .expect("problemMatchers")
        .iter()
        .find(|m| m["name"] == "semo")
        .expect("a `semo` problem matcher");
    let default = severity(matcher["severity"].as_str().unwrap_or("error"), "error");
    let patterns = matcher["pattern"].as_array().expect("a multi-line pattern");
    assert_eq!(patterns.len(), 2);
    let regex = |p: &Value| regex::Regex::new(p["regexp"].as_str().unwrap()).unwrap();
    let group = |p: &Value, key: &str| p[key].as_u64().map(|g| g as usize);
    let (head, location) = (regex(&patterns[0]), regex(&patterns[1]));
    let ansi = regex::Regex::new("\x1b\\[[0-9;]*m").unwrap();
    let lines: Vec<String> = output
        .lines()
        .map(|l| ansi.replace_all(l, "").into_owned())
        .collect();
    let mut problems = Vec::new();
    for pair in lines.windows(2) {
        let (Some(h), Some(l)) = (head.captures(&pair[0]), location.captures(&pair[1])) else {
            continue;
        };
        let text = |c: &regex::Captures, p: &Value, key: &str| {
            let g = group(p, key).unwrap_or_else(|| panic!("pattern has no `{key}`"));
            c.get(g).unwrap().as_str().to_string()
        };
        problems.push(Problem {
            code: text(&h, &patterns[0], "code"),
            severity: severity(&text(&h, &patterns[0], "severity"), default),
            message: text(&h, &patterns[0], "message"),
            file: text(&l, &patterns[1], "file"),
            line: text(&l, &patterns[1], "line").parse().unwrap(),
            column: text(&l, &patterns[1], "column").parse().unwrap(),
        });
    }
    problems.sort();
    problems
}

#[test]
fn the_problem_matcher_reads_every_diagnostic_semo_check_prints() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::create_dir(dir.join("sub")).unwrap();
    std::fs::write(
        dir.join("sub/bad.mission"),
        "{\n  T: iRobotCreat r\n}\nT.Listen.X {\n  foo()\n}\nT.M { set(Listen, X) }\n",
    )
    .unwrap();
    let args = ["check", "sub/bad.mission"];

    // As in a VS Code task: a terminal, so colours are on.
    let out = Command::new(env!("CARGO_BIN_EXE_semo"))
        .args(args)
        .arg("--color=always")
        .current_dir(dir)
        .output()
        .unwrap();
    let printed = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let matched = match_problems(&printed);

    let (_, diags) = check_json_in(dir, &args[1..]);
    let mut expected: Vec<Problem> = diags
        .into_iter()
        .map(|d| Problem {
            severity: severity(&d.severity, "info"),
            file: d.file,
            line: d.start.0,
            column: d.start.1,
            code: d.code,
            message: d.message,
        })
        .collect();
    expected.sort();
    assert!(
        expected.iter().any(|p| p.severity == "error") && expected.len() >= 3,
        "the fixture must give errors and warnings: {expected:#?}"
    );
    assert_eq!(matched, expected, "printed:\n{printed}");
}

#[test]
fn neovim_links_the_same_token_types_that_vs_code_declares() {
    let package = package_json();
    let declared: BTreeSet<String> = package["contributes"]["semanticTokenTypes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["id"].as_str().unwrap().to_string())
        .collect();
    let lua = std::fs::read_to_string(repo_root().join("editors/nvim/lua/semo/init.lua")).unwrap();
    let table = lua
        .split_once("M.token_links = {")
        .and_then(|(_, rest)| rest.split_once('}'))
        .expect("M.token_links in init.lua")
        .0;
    let entry = regex::Regex::new(r"(?m)^\s*(\w+) = '@lsp\.type\.(\w+)',$").unwrap();
    let mut linked = BTreeSet::new();
    for c in entry.captures_iter(table) {
        assert!(
            STANDARD_TYPES.contains(&&c[2]),
            "{} links to a group Neovim does not define",
            &c[1]
        );
        linked.insert(c[1].to_string());
    }
    assert_eq!(linked, declared);
}

/// The entries of `DOCUMENT_SELECTOR` in the extension's `server.ts`: the
/// files VS Code sends to the server.
fn document_selector() -> Vec<String> {
    let source = std::fs::read_to_string(repo_root().join("vscode-extension/src/server.ts"))
        .expect("server.ts");
    let start = source
        .find("export const DOCUMENT_SELECTOR = [")
        .expect("server.ts declares DOCUMENT_SELECTOR");
    let body = &source[start..];
    let body = &body[..body.find("];").expect("the selector ends")];
    body.lines()
        .map(str::trim)
        .filter(|l| l.starts_with('{'))
        .map(str::to_string)
        .collect()
}

#[test]
fn the_project_file_wakes_the_extension_and_is_sent_to_the_server() {
    let package = package_json();
    let events = package["activationEvents"]
        .as_array()
        .expect("activationEvents");
    assert!(
        events.iter().any(|e| e == "workspaceContains:**/semo.toml"),
        "{events:?}"
    );
    let selector = document_selector();
    assert!(
        selector
            .iter()
            .any(|entry| entry == "{ scheme: 'file', pattern: '**/semo.toml' },"),
        "{selector:#?}"
    );
    // Only the project file among TOML files (no `language: 'toml'` entry).
    assert!(
        !selector
            .iter()
            .any(|e| e.contains("toml'") && e.contains("language"))
    );
}
