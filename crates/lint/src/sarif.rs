//! Findings as SARIF 2.1.0 (OASIS Static Analysis Results Interchange
//! Format), the log GitHub code scanning reads to show findings inline on a
//! pull request: one run of the tool `btfsm`, every rule in
//! `tool.driver.rules` (id, short description, default level, where its
//! page is),
//! one result per finding with its rule, level, message and physical
//! location (the file as a relative URI, the line and column when known);
//! one invocation saying whether every file was linted
//! (`executionSuccessful`) and, as `toolExecutionNotifications`, each file
//! that was not (with why) and what could not be checked (SARIF 2.1.0
//! §3.20 `invocation`, §3.58 `notification`). The output validates against the official schema
//! (`tests/differential/sarif_check.py`, run by `make differential`).

use super::{Finding, Level, RULES};
use serde_json::{Value, json};

fn level(l: Level) -> &'static str {
    match l {
        Level::Error => "error",
        Level::Warning => "warning",
        Level::Note => "note",
        Level::Allow => "none",
    }
}

/// What the run could not do, for its invocation.
#[derive(Debug, Default)]
pub struct Invocation {
    /// Files not linted (they do not load): the path and why.
    pub not_linted: Vec<(String, String)>,
    /// Notes on what was not checked (node types no model declares).
    pub notes: Vec<String>,
}

/// A path as a relative URI reference: `/` separators, every byte outside
/// the unreserved set and `/` percent-encoded. A backslash is part of a
/// file's name on the systems btfsm runs on, so it is encoded too (`%5C`):
/// read as a separator, `a\b.toml` from a pull request pointed code
/// scanning at another file, `a/b.toml` (issue 33).
pub fn uri(path: &str) -> String {
    let p = path.strip_prefix("./").unwrap_or(path);
    let mut out = String::with_capacity(p.len());
    for b in p.bytes() {
        if b.is_ascii_alphanumeric() || matches!(b, b'-' | b'.' | b'_' | b'~' | b'/') {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}

/// The SARIF log of `findings`, with the invocation `inv` describes.
pub fn render(findings: &[Finding], inv: &Invocation) -> String {
    let rules: Vec<Value> = RULES
        .iter()
        .map(|r| {
            json!({
                "id": r.code,
                "name": r.code,
                "shortDescription": { "text": r.summary },
                "help": { "text": format!("docs/lint.md#{}", r.code) },
                "defaultConfiguration": {
                    "level": level(r.level),
                    "enabled": r.level != Level::Allow,
                },
            })
        })
        .collect();
    let results: Vec<Value> = findings
        .iter()
        .map(|f| {
            let index = RULES.iter().position(|r| r.code == f.code).unwrap_or(0);
            let mut physical = json!({ "artifactLocation": { "uri": uri(&f.file) } });
            if let (Some(l), Some(c)) = (f.line, f.column) {
                physical["region"] = json!({ "startLine": l.max(1), "startColumn": c.max(1) });
            }
            let text = if f.help.is_empty() {
                f.message.clone()
            } else {
                format!("{} (help: {})", f.message, f.help)
            };
            json!({
                "ruleId": f.code,
                "ruleIndex": index,
                "level": level(f.level),
                "message": { "text": text },
                "locations": [ { "physicalLocation": physical } ],
            })
        })
        .collect();
    let log = json!({
        "$schema": "https://json.schemastore.org/sarif-2.1.0.json",
        "version": "2.1.0",
        "runs": [ {
            "tool": { "driver": {
                "name": "btfsm",
                "version": env!("CARGO_PKG_VERSION"),
                "rules": rules,
            } },
            "invocations": [ invocation(inv) ],
            "columnKind": "unicodeCodePoints",
            "results": results,
        } ],
    });
    let mut s =
        btfsm_core::sanitize::json(serde_json::to_string_pretty(&log).expect("serializable"));
    s.push('\n');
    s
}

/// The run's one invocation: successful when every file was linted; a
/// notification per file that was not (an error, tied to the `load-error`
/// rule) and per note.
fn invocation(inv: &Invocation) -> Value {
    let load_error = RULES
        .iter()
        .position(|r| r.code == super::load::LOAD_ERROR.code)
        .unwrap_or(0);
    let mut notes: Vec<Value> = inv
        .not_linted
        .iter()
        .map(|(file, why)| {
            json!({
                "level": "error",
                "message": { "text": format!("{file} was not linted: {why}") },
                "locations": [ { "physicalLocation": { "artifactLocation": { "uri": uri(file) } } } ],
                "associatedRule": { "id": super::load::LOAD_ERROR.code, "index": load_error },
            })
        })
        .collect();
    notes.extend(
        inv.notes
            .iter()
            .map(|n| json!({ "level": "note", "message": { "text": n } })),
    );
    let mut v = json!({ "executionSuccessful": inv.not_linted.is_empty() });
    if !notes.is_empty() {
        v["toolExecutionNotifications"] = Value::Array(notes);
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_become_relative_uri_references() {
        assert_eq!(
            uri("./policies/paper/fig 03.toml"),
            "policies/paper/fig%2003.toml"
        );
        assert_eq!(uri("a\\b#c"), "a%5Cb%23c");
    }
}
