//! The review as one GitHub pull-request comment: the hidden marker line
//! a bot finds its comment by, a headline, the gates, a summary table (one
//! row per file), then one collapsible `<details>` section per file with
//! its gate failures, new findings, change list (a `diff` block) and
//! Mermaid diff drawing. At most [`MAX_COMMENT_CHARS`] characters, GitHub's
//! limit on a comment's body: sections (then rows) that do not fit are
//! left out, and a line says how many.
//!
//! Every string from the repository is inert (issue 33): table cells and
//! list items through `sanitize::markdown_cell`/`markdown_code`, file names
//! in a `<summary>` as HTML-escaped `<code>` (no mention, link or tag),
//! code blocks fenced longer than any run of backticks in them and with
//! `<` written `\u{3c}`, Mermaid labels escaped by `render::mermaid` and
//! every `%` in a drawing as Mermaid's `#37;` (no `%%{init}%%` directive).

use super::{FileReview, Metrics, Review, Status};
use btfsm_core::sanitize::{code_fence, markdown_cell, markdown_code, markup};

/// The first line of every review comment (a bot updates the comment that
/// starts with it).
pub const MARKER: &str = "<!-- btfsm-review -->";

/// GitHub's limit on a comment body, in characters.
pub const MAX_COMMENT_CHARS: usize = 65_536;

/// Room kept for the line saying what was left out.
const RESERVE: usize = 400;

/// The comment.
pub fn render_markdown(r: &Review) -> String {
    render_within(r, MAX_COMMENT_CHARS)
}

/// The comment within `max` characters.
pub(crate) fn render_within(r: &Review, max: usize) -> String {
    let mut out = head(r);
    let budget = max.saturating_sub(RESERVE);
    let mut rows = 0;
    if !r.files.is_empty() {
        out.push_str(
            "| file | change | kind | vertices | edges | cc | essential cc | GED | TED | new findings |\n|---|---|---|---:|---:|---:|---:|---:|---:|---:|\n",
        );
    }
    for f in &r.files {
        let row = row(f);
        if len(&out) + len(&row) > budget / 2 {
            break;
        }
        out.push_str(&row);
        rows += 1;
    }
    out.push('\n');
    let mut sections = 0;
    for f in r.files.iter().take(rows) {
        let s = section(f);
        if len(&out) + len(&s) > budget {
            continue;
        }
        out.push_str(&s);
        sections += 1;
    }
    let (n, left_rows, left_sections) = (
        r.files.len(),
        n_minus(r.files.len(), rows),
        n_minus(r.files.len(), sections),
    );
    if left_rows + left_sections > 0 {
        out.push_str(&format!(
            "\n_Left out to stay within GitHub's {MAX_COMMENT_CHARS} characters: {left_rows} of {n} table rows and {left_sections} of {n} file sections. `btfsm review --format json` has every file._\n"
        ));
    }
    out
}

fn n_minus(a: usize, b: usize) -> usize {
    a.saturating_sub(b)
}

fn len(s: &str) -> usize {
    s.chars().count()
}

/// Marker, headline and gates.
fn head(r: &Review) -> String {
    let n = r.files.len();
    let mut out = format!(
        "{MARKER}\n### btfsm review: {n} polic{} changed\n\nbase {} → head {}",
        if n == 1 { "y" } else { "ies" },
        markdown_code(&r.base.label),
        markdown_code(&r.head.label),
    );
    if r.other_changes > 0 {
        out.push_str(&format!(
            "; {} other changed file{} (no policy and read by none)",
            r.other_changes,
            if r.other_changes == 1 { "" } else { "s" }
        ));
    }
    out.push_str("\n\n");
    let failures: Vec<_> = r.failures().collect();
    let from = r
        .gates
        .config
        .as_deref()
        .map_or_else(|| "no btfsm.toml in base".to_string(), markdown_code);
    if r.gates.is_empty() {
        out.push_str(if r.gates.config.is_some() {
            "No gates set: the base revision's `btfsm.toml` has no `[review]` gate.\n\n"
        } else {
            "No gates set: the base revision has no `btfsm.toml`.\n\n"
        });
    } else if failures.is_empty() {
        out.push_str(&format!("**Gates passed** ({from}).\n\n"));
    } else {
        out.push_str(&format!(
            "**{} gate failure{}** ({from}):\n\n",
            failures.len(),
            if failures.len() == 1 { "" } else { "s" }
        ));
        for f in failures.iter().take(50) {
            out.push_str(&format!(
                "- {} `{}`: {}\n",
                markdown_code(&f.file),
                f.gate,
                markdown_cell(&f.message)
            ));
        }
        if failures.len() > 50 {
            out.push_str(&format!("- … and {} more\n", failures.len() - 50));
        }
        out.push('\n');
    }
    let not_loaded = r.not_loaded();
    if !not_loaded.is_empty() {
        out.push_str(&format!(
            "**{} file{} do{} not load in head.**\n\n",
            not_loaded.len(),
            if not_loaded.len() == 1 { "" } else { "s" },
            if not_loaded.len() == 1 { "es" } else { "" }
        ));
    }
    out
}

/// `before → after (+d)`, or the one side there is.
fn metric(f: &FileReview, get: fn(&Metrics) -> i64) -> String {
    match (&f.before, &f.after) {
        (Some(a), Some(b)) => {
            let (x, y) = (get(a), get(b));
            if x == y {
                y.to_string()
            } else {
                format!("{x} → {y} ({:+})", y.saturating_sub(x))
            }
        }
        (None, Some(b)) => format!("{} (new)", get(b)),
        (Some(a), None) => format!("{} (gone)", get(a)),
        (None, None) => "–".into(),
    }
}

pub(crate) fn status(f: &FileReview) -> &'static str {
    match f.status {
        Status::Added => "added",
        Status::Removed => "removed",
        Status::Modified => "modified",
        Status::Renamed => "renamed",
        Status::Dependency => "reads a changed file",
    }
}

fn row(f: &FileReview) -> String {
    let opt = |x: Option<u64>| x.map_or_else(|| "–".to_string(), |v| v.to_string());
    let kind = f.kind.clone().unwrap_or_else(|| match f.holds {
        super::Holds::Scenario => "scenario".into(),
        super::Holds::Domain => "domain".into(),
        _ if f.load_error.is_some() => "does not load".into(),
        _ => "–".into(),
    });
    format!(
        "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
        markdown_code(&f.path),
        status(f),
        kind,
        metric(f, |m| m.vertices),
        metric(f, |m| m.edges),
        metric(f, |m| m.cc),
        metric(f, |m| m.essential_cc),
        opt(f.ged),
        opt(f.ted.as_ref().map(|t| t.distance)),
        f.new_findings.len(),
    )
}

/// One file's collapsible section.
fn section(f: &FileReview) -> String {
    let mut out = format!(
        "<details><summary><code>{}</code>: {}</summary>\n\n",
        markup(&f.path, 300),
        status(f)
    );
    if let Some(from) = &f.from {
        out.push_str(&format!("Renamed from {}.\n\n", markdown_code(from)));
    }
    if !f.via.is_empty() {
        let via: Vec<String> = f.via.iter().map(|v| markdown_code(v)).collect();
        out.push_str(&format!("It reads changed {}.\n\n", via.join(", ")));
    }
    if let Some(e) = &f.load_error {
        out.push_str(&format!(
            "**Does not load in head:** {}\n\n",
            markdown_cell(e)
        ));
    }
    for g in &f.gate_failures {
        out.push_str(&format!(
            "- gate `{}`: {}\n",
            g.gate,
            markdown_cell(&g.message)
        ));
    }
    if !f.gate_failures.is_empty() {
        out.push('\n');
    }
    findings(&mut out, f);
    changes(&mut out, f);
    diagram(&mut out, f);
    out.push_str("</details>\n\n");
    out
}

fn findings(out: &mut String, f: &FileReview) {
    if f.new_findings.is_empty() && f.fixed_findings == 0 {
        return;
    }
    out.push_str(&format!(
        "New lint findings: {}; fixed: {}.\n\n",
        f.new_findings.len(),
        f.fixed_findings
    ));
    for n in f.new_findings.iter().take(50) {
        let line = n.line.map_or_else(String::new, |l| format!(" (line {l})"));
        out.push_str(&format!(
            "- {} `{}` at {}{line}: {}\n",
            n.level,
            n.code,
            markdown_code(&n.at),
            markdown_cell(&n.message)
        ));
    }
    if f.new_findings.len() > 50 {
        out.push_str(&format!("- … and {} more\n", f.new_findings.len() - 50));
    }
    out.push('\n');
}

fn changes(out: &mut String, f: &FileReview) {
    if f.changes.is_empty() {
        return;
    }
    let mut body: String = f
        .changes
        .iter()
        .map(|l| format!("{}\n", btfsm_core::sanitize::shown(l)))
        .collect::<String>()
        .replace('<', "\\u{3c}");
    if f.changes_total > f.changes.len() {
        body.push_str(&format!(
            "# … and {} more\n",
            f.changes_total - f.changes.len()
        ));
    }
    let fence = code_fence(&body);
    out.push_str(&format!(
        "Changes ({}, {}):\n\n{fence}diff\n{body}{fence}\n\n",
        f.changes_total,
        if f.ted.is_some() {
            "ordered tree mapping"
        } else {
            "named mapping"
        }
    ));
}

fn diagram(out: &mut String, f: &FileReview) {
    match &f.diagram {
        Some(Ok(text)) => {
            // Mermaid reads a `%%{init}%%` directive anywhere in the text,
            // a label included: `%` as its entity code (`#37;`); the
            // drawings write no `%%` comment of their own.
            let text = &text.replace('%', "#37;");
            let fence = code_fence(text);
            let what = if f.status == Status::Added {
                "the new policy"
            } else {
                "diff: added magenta, removed dashed grey, changed orange"
            };
            out.push_str(&format!("{what}:\n\n{fence}mermaid\n{text}{fence}\n\n"));
        }
        Some(Err((nodes, links))) => out.push_str(&format!(
            "The diff drawing is left out: {nodes} nodes and {links} links are too many to read; `--svg-dir DIR` draws it.\n\n"
        )),
        None => {}
    }
}
