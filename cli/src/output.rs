//! Where and in what shape every command reports: diagnostics for people on
//! standard error, data (and `--format json|sarif` documents) on standard
//! output. The one JSON document shape (`{"version", "command",
//! "diagnostics", …}`, docs/diagnostics-json.md) and SARIF 2.1.0 are built
//! here from [`Record`]s, so every command's machine output agrees.

use semo::diag::{Code, Diagnostic, Severity};
use semo::text::ColumnUnit;
use semo::workspace::Files;
use serde::Serialize;
use std::io::{self, Write};
use std::path::Path;

/// The version of the JSON document shape; raised when a field changes
/// meaning or goes away (new fields may be added within a version).
pub const JSON_VERSION: u32 = 1;

/// How a command reports its diagnostics.
#[derive(Clone, Copy, Debug, clap::ValueEnum, PartialEq, Eq)]
pub enum Format {
    /// Source snippets on standard error; the command's data on standard output.
    Human,
    /// One JSON document on standard output (docs/diagnostics-json.md).
    Json,
    /// A SARIF 2.1.0 log on standard output (code-scanning tools).
    Sarif,
    /// One line per problem on standard error (`FILE:LINE:COL: error[E017]:
    /// message`), for grep, editors' error lists and CI logs.
    Concise,
}

impl Format {
    /// Whether the diagnostics are for people, on standard error (the
    /// command's data then goes to standard output as text).
    pub fn for_people(self) -> bool {
        matches!(self, Format::Human | Format::Concise)
    }
}

/// A 1-based line and column (columns in characters).
#[derive(Clone, Copy, Debug, Serialize, PartialEq, Eq)]
pub struct Position {
    pub line: u32,
    pub column: u32,
}

#[derive(Clone, Debug, Serialize)]
pub struct RelatedRecord {
    pub file: String,
    pub line: u32,
    pub column: u32,
    pub message: String,
}

/// One diagnostic as every machine-readable output shows it.
#[derive(Clone, Debug, Serialize)]
pub struct Record {
    /// The code (`E015`), or null for a problem outside the code table (a
    /// scenario file's error).
    #[serde(serialize_with = "code_name")]
    pub code: Option<Code>,
    pub severity: &'static str,
    pub file: String,
    pub start: Position,
    pub end: Position,
    pub message: String,
    pub suggestion: Option<String>,
    pub related: Vec<RelatedRecord>,
}

impl Record {
    pub fn of(files: &Files, d: &Diagnostic) -> Record {
        let file = files.get(d.file);
        let position = |offset: usize| {
            let lc = file.lines.line_col(&file.text, offset, ColumnUnit::Char);
            Position {
                line: lc.line + 1,
                column: lc.col + 1,
            }
        };
        Record {
            code: Some(d.code),
            severity: d.severity.as_str(),
            file: file.path.display().to_string(),
            start: position(d.span.start),
            end: position(d.span.end),
            message: d.message.clone(),
            suggestion: d.suggestion.clone(),
            related: d
                .related
                .iter()
                .map(|r| {
                    let rf = files.get(r.file);
                    let lc = rf.lines.line_col(&rf.text, r.span.start, ColumnUnit::Char);
                    RelatedRecord {
                        file: rf.path.display().to_string(),
                        line: lc.line + 1,
                        column: lc.col + 1,
                        message: r.message.clone(),
                    }
                })
                .collect(),
        }
    }

    /// A mistake (`Severity::Error`) or a warning of the scenario `text`
    /// read from `file`, with its did-you-mean.
    pub fn scenario(
        file: &Path,
        text: &str,
        mistake: semo::sim::ScenarioError,
        severity: Severity,
    ) -> Record {
        let (line, column) = mistake.line_col(text);
        Record {
            severity: severity.as_str(),
            suggestion: mistake.suggestion,
            ..Record::uncoded_error(file, line, column, mistake.message)
        }
    }

    /// The record for people: `scenario FILE:LINE:COL: [warning: ]MESSAGE`.
    pub fn scenario_line(&self) -> String {
        let severity = match self.severity {
            "error" => String::new(),
            other => format!("{other}: "),
        };
        format!(
            "scenario {}:{}:{}: {severity}{}",
            self.file, self.start.line, self.start.column, self.message
        )
    }

    /// An error at one point of a file that has no code (a scenario's).
    pub fn uncoded_error(file: &Path, line: u32, column: u32, message: String) -> Record {
        let at = Position { line, column };
        Record {
            code: None,
            severity: Severity::Error.as_str(),
            file: file.display().to_string(),
            start: at,
            end: at,
            message,
            suggestion: None,
            related: Vec::new(),
        }
    }
}

/// A code as its stable name (`E015`).
fn code_name<S: serde::Serializer>(code: &Option<Code>, to: S) -> Result<S::Ok, S::Error> {
    code.map(Code::as_str).serialize(to)
}

pub fn records(files: &Files, diagnostics: &[Diagnostic]) -> Vec<Record> {
    diagnostics.iter().map(|d| Record::of(files, d)).collect()
}

/// The JSON document of `command`: its version, its diagnostics and the
/// command's own `data` fields (an object, merged in).
pub fn json_document(
    command: &str,
    records: &[Record],
    data: serde_json::Value,
) -> serde_json::Value {
    let mut document = serde_json::json!({
        "version": JSON_VERSION,
        "command": command,
        "diagnostics": records,
    });
    if let (Some(fields), serde_json::Value::Object(data)) = (document.as_object_mut(), data) {
        fields.extend(data);
    }
    document
}

/// Writes one JSON document and a line break on `out`.
pub fn write_json(out: &mut impl Write, document: &serde_json::Value) -> io::Result<()> {
    writeln!(out, "{document}")
}

/// A URI reference for a path, as SARIF's `artifactLocation.uri` wants it:
/// relative paths stay relative (to the folder the command ran in), absolute
/// ones become `file://` URIs; anything else than unreserved characters and
/// `/` is percent-encoded (so `<stdin>` is `%3Cstdin%3E`).
fn uri_of(path: &str) -> String {
    use percent_encoding::{AsciiSet, NON_ALPHANUMERIC, utf8_percent_encode};
    const KEEP: &AsciiSet = &NON_ALPHANUMERIC
        .remove(b'-')
        .remove(b'.')
        .remove(b'_')
        .remove(b'~')
        .remove(b'/');
    let path = path.replace('\\', "/");
    let encoded = utf8_percent_encode(&path, KEEP).to_string();
    if path.starts_with('/') {
        format!("file://{encoded}")
    } else {
        encoded
    }
}

fn sarif_level(severity: &str) -> &'static str {
    match severity {
        "error" => "error",
        "warning" => "warning",
        _ => "note",
    }
}

fn sarif_location(file: &str, start: Position, end: Position) -> serde_json::Value {
    serde_json::json!({
        "physicalLocation": {
            "artifactLocation": { "uri": uri_of(file) },
            "region": {
                "startLine": start.line,
                "startColumn": start.column,
                "endLine": end.line,
                "endColumn": end.column,
            },
        },
    })
}

/// A SARIF 2.1.0 log of one run of `semo`: each code reported is a rule (its
/// summary and default level), each record a result.
pub fn sarif(records: &[Record]) -> serde_json::Value {
    let mut rule_codes: Vec<Code> = records.iter().filter_map(|r| r.code).collect();
    rule_codes.sort_unstable();
    rule_codes.dedup();
    let rules: Vec<serde_json::Value> = rule_codes
        .iter()
        .map(|code| {
            serde_json::json!({
                "id": code.as_str(),
                "shortDescription": { "text": code.summary() },
                "help": { "text": format!("semo explain {code}") },
                "defaultConfiguration": { "level": sarif_level(code.default_severity().as_str()) },
            })
        })
        .collect();
    let results: Vec<serde_json::Value> = records
        .iter()
        .map(|r| {
            let mut result = serde_json::json!({
                "level": sarif_level(r.severity),
                "message": { "text": r.message },
                "locations": [sarif_location(&r.file, r.start, r.end)],
            });
            if let Some(code) = r.code {
                result["ruleId"] = code.as_str().into();
                result["ruleIndex"] = rule_codes.binary_search(&code).ok().into();
            }
            if !r.related.is_empty() {
                let related: Vec<serde_json::Value> = r
                    .related
                    .iter()
                    .enumerate()
                    .map(|(i, rel)| {
                        let at = Position {
                            line: rel.line,
                            column: rel.column,
                        };
                        let mut location = sarif_location(&rel.file, at, at);
                        location["id"] = i.into();
                        location["message"] = serde_json::json!({ "text": rel.message });
                        location
                    })
                    .collect();
                result["relatedLocations"] = related.into();
            }
            result
        })
        .collect();
    serde_json::json!({
        "$schema": "https://docs.oasis-open.org/sarif/sarif/v2.1.0/errata01/os/schemas/sarif-schema-2.1.0.json",
        "version": "2.1.0",
        "runs": [{
            "tool": { "driver": {
                "name": "semo",
                "version": env!("CARGO_PKG_VERSION"),
                "rules": rules,
            }},
            "columnKind": "unicodeCodePoints",
            "results": results,
        }],
    })
}

/// Reports `diagnostics` of `command` in `format`: people's snippets on
/// standard error, a JSON document (with `data`) or a SARIF log on `out`.
pub fn report(
    format: Format,
    command: &str,
    files: &Files,
    diagnostics: &[Diagnostic],
    color: bool,
    data: serde_json::Value,
    out: &mut impl Write,
) -> io::Result<()> {
    match format {
        Format::Human | Format::Concise => {
            super::render::people(format, files, diagnostics, color, &mut io::stderr().lock())
        }
        Format::Json => write_json(
            out,
            &json_document(command, &records(files, diagnostics), data),
        ),
        Format::Sarif => write_json(out, &sarif(&records(files, diagnostics))),
    }
}

/// A command that stops before it has diagnostics (a file it cannot read,
/// or of the wrong kind): the one line for people on standard error, and in
/// JSON or SARIF the document all the same, its one diagnostic the refusal
/// (no code, at the start of `file`), so that a reader of the document
/// always gets one. Gives the exit status, 2.
pub fn refused(
    format: Format,
    command: &str,
    file: &Path,
    message: &str,
    out: &mut impl Write,
) -> i32 {
    eprintln!("error: {message}");
    let records = [Record::uncoded_error(file, 1, 1, message.to_string())];
    let written = match format {
        Format::Human | Format::Concise => Ok(()),
        Format::Json => write_json(
            out,
            &json_document(command, &records, serde_json::json!({})),
        ),
        Format::Sarif => write_json(out, &sarif(&records)),
    };
    let _ = self::written(written);
    2
}

/// What a failed write of a report means: a reader that went away (`semo
/// check | head`) is no problem; anything else is exit status 2.
pub fn written(result: io::Result<()>) -> Result<(), i32> {
    match result {
        Err(e) if e.kind() == io::ErrorKind::BrokenPipe => Ok(()),
        Err(e) => {
            eprintln!("error: cannot write the report: {e}");
            Err(2)
        }
        Ok(()) => Ok(()),
    }
}
