//! `compare`'s output formats: JSON (SPEC §7), the table with the edit
//! script, and GitHub markdown for a pull-request comment.

use super::changes_text::{Style, change_lines, summary_markdown};
use super::{ArcRef, CompareReport, ModeReport, VertexRef};
use btfsm_metrics::ged::GedMode;

/// SPEC §7: `{"a", "b", "structural": {...}, "labeled": {...}, "named": {...}}`
/// (only the modes computed), in that field order.
pub fn render_json(r: &CompareReport) -> String {
    #[derive(serde::Serialize)]
    struct Out<'a> {
        a: &'a str,
        b: &'a str,
        #[serde(skip_serializing_if = "Option::is_none")]
        structural: Option<&'a ModeReport>,
        #[serde(skip_serializing_if = "Option::is_none")]
        labeled: Option<&'a ModeReport>,
        #[serde(skip_serializing_if = "Option::is_none")]
        named: Option<&'a ModeReport>,
        #[serde(skip_serializing_if = "Option::is_none")]
        tree: Option<&'a super::tree::TreeReport>,
    }
    let out = Out {
        a: &r.a.file,
        b: &r.b.file,
        structural: r.mode(GedMode::Structural),
        labeled: r.mode(GedMode::Labeled),
        named: r.mode(GedMode::Named),
        tree: r.tree.as_ref(),
    };
    let mut s =
        btfsm_core::sanitize::json(serde_json::to_string_pretty(&out).expect("serializable"));
    s.push('\n');
    s
}

/// The human-readable report: both policies, one row per mode, and the edit
/// script of the primary mode.
pub fn render_table(r: &CompareReport) -> String {
    let mut out = String::new();
    for (tag, s) in [("a", &r.a), ("b", &r.b)] {
        out.push_str(&format!(
            "{tag}: {} ({} `{}`, {} vertices, {} arcs)\n",
            s.file, s.kind, s.name, s.vertices, s.arcs
        ));
    }
    if r.a.kind != r.b.kind {
        out.push_str(&format!(
            "note: comparing a {} with a {}: labeled and named GED count every vertex of a differing type or name as replaced\n",
            r.a.kind, r.b.kind
        ));
    }
    out.push('\n');
    if !r.modes.is_empty() {
        let mut t = btfsm_core::table::Table::new(&["mode", "GED", "exact", "interval", "ms"]);
        for m in &r.modes {
            t.row(vec![
                m.mode.as_str().to_string(),
                m.ged.to_string(),
                if m.exact { "yes" } else { "no" }.to_string(),
                format!("[{}, {}]", m.lower_bound, m.upper_bound),
                m.millis.to_string(),
            ]);
        }
        out.push_str(&t.render());
    }
    for line in stop_notes(r) {
        out.push_str(&format!("note: {line}\n"));
    }
    if let Some(p) = r.primary()
        && p.relabels + p.reorders > 0
    {
        out.push_str(&format!(
            "note: the GED counts neither reorders nor relabels; the {} mapping has {} and {}\n",
            p.mode.as_str(),
            plural(p.reorders, "reorder", "reorders"),
            plural(p.relabels, "relabel", "relabels"),
        ));
    }
    if let Some(p) = r.primary() {
        out.push('\n');
        out.push_str(&render_script(p));
    }
    if let Some(t) = &r.tree {
        if !r.modes.is_empty() {
            out.push('\n');
        }
        out.push_str(&super::tree::render_text(t));
    }
    out
}

/// One line per inexact mode: which budget ended its search.
fn stop_notes(r: &CompareReport) -> Vec<String> {
    use btfsm_metrics::ged::StopReason;
    r.modes
        .iter()
        .filter(|m| !m.exact)
        .map(|m| {
            let why = match m.stopped_by {
                Some(StopReason::Time) => {
                    "the CPU-time safety cap (--timeout-ms) ended the search before the work budget; the interval may differ on another machine (raise --timeout-ms)"
                }
                Some(StopReason::Size) => {
                    "the graphs are too large for the exact search (above 2048 vertices): count bound and local search"
                }
                _ => "the work budget (--work) ended the search; the same interval on any machine (raise --work to narrow it)",
            };
            format!(
                "{}: the distance lies in the certified interval [{}, {}]: {why}",
                m.mode.as_str(),
                m.lower_bound,
                m.upper_bound
            )
        })
        .collect()
}

/// The report as GitHub-flavoured markdown, for a pull-request comment:
/// what changed (reorders and relabels first), the two policies and the
/// modes as tables, the primary edit script as a `diff` block (added lines
/// green, removed red) in a collapsible section, and the diff as a Mermaid
/// diagram when it is small enough to read.
pub fn render_markdown(r: &CompareReport) -> String {
    let cell = btfsm_core::sanitize::markdown_cell;
    let code = btfsm_core::sanitize::markdown_code;
    let mut out = format!(
        "### btfsm compare: {} → {}\n\n{}\n| | file | kind | name | vertices | arcs |\n|---|---|---|---|---:|---:|\n",
        code(&r.a.file),
        code(&r.b.file),
        summary_markdown(r)
    );
    for (tag, s) in [("a", &r.a), ("b", &r.b)] {
        out.push_str(&format!(
            "| {tag} | {} | {} | {} | {} | {} |\n",
            code(&s.file),
            s.kind,
            cell(&s.name),
            s.vertices,
            s.arcs
        ));
    }
    if !r.modes.is_empty() {
        out.push_str("\n| mode | GED | exact | interval | ms |\n|---|---:|---|---|---:|\n");
    }
    for m in &r.modes {
        out.push_str(&format!(
            "| {} | {} | {} | [{}, {}] | {} |\n",
            m.mode.as_str(),
            m.ged,
            if m.exact { "yes" } else { "no" },
            m.lower_bound,
            m.upper_bound,
            m.millis
        ));
    }
    let notes = stop_notes(r);
    if !notes.is_empty() {
        out.push('\n');
        for line in notes {
            out.push_str(&format!("- {line}\n"));
        }
    }
    if let Some(p) = r.primary() {
        let script = render_script(p);
        let mut lines = script.lines();
        let title = lines.next().unwrap_or_default().trim_end_matches(':');
        // `<` as the sanitizer's escape: no tag, even inside the block.
        let body: String = lines
            .map(|l| format!("{}\n", l.strip_prefix("  ").unwrap_or(l)))
            .collect::<String>()
            .replace('<', "\\u{3c}");
        // Names are escaped onto one line each and every line starts with
        // its sign; the fence is longer than any run of backticks anyway.
        let fence = btfsm_core::sanitize::code_fence(&body);
        out.push_str(&format!(
            "\n<details><summary>{}</summary>\n\n{fence}diff\n{body}{fence}\n\n</details>\n",
            cell(title)
        ));
    }
    out.push_str(&super::diff_mermaid::markdown_section(r));
    if let Some(t) = &r.tree {
        out.push_str(&tree_markdown(t));
    }
    out
}

/// `--mode tree` in markdown: the distance, then its script as a `diff`
/// block (deletions red, insertions green) in a collapsible section.
fn tree_markdown(t: &super::tree::TreeReport) -> String {
    let cell = btfsm_core::sanitize::markdown_cell;
    let body: String = super::tree::script_lines(t)
        .into_iter()
        .map(|l| format!("{l}\n"))
        .collect();
    let mut out = format!("\n{}\n", cell(&super::tree::summary(t)));
    if !body.is_empty() {
        let fence = btfsm_core::sanitize::code_fence(&body);
        let cost = t.edit_script.cost();
        out.push_str(&format!(
            "\n<details><summary>tree edit script ({cost} edit{})</summary>\n\n{fence}diff\n{body}{fence}\n\n</details>\n",
            if cost == 1 { "" } else { "s" }
        ));
    }
    out
}

/// One line per edit: `+` added, `-` removed, `~` rematched or relabelled.
fn render_script(m: &ModeReport) -> String {
    use btfsm_core::sanitize::shown;
    let s = &m.edit_script;
    let cost = s.cost();
    let mut out = format!(
        "{} edit script ({} edit{}):\n",
        m.mode.as_str(),
        cost,
        if cost == 1 { "" } else { "s" }
    );
    let vertex = |sign: char, v: &VertexRef| {
        let name = if v.name == v.key {
            String::new()
        } else {
            format!(" \"{}\"", shown(&v.name))
        };
        format!("  {sign} {} `{}`{name}\n", v.vtype.as_str(), shown(&v.key))
    };
    let arc = |sign: char, a: &ArcRef| {
        let label = if a.label.is_empty() {
            String::new()
        } else {
            format!(" [{}]", shown(&a.label))
        };
        let times = if a.count > 1 {
            format!(" ×{}", a.count)
        } else {
            String::new()
        };
        format!(
            "  {sign} arc `{}` -> `{}`{label}{times}\n",
            shown(&a.from),
            shown(&a.to)
        )
    };
    for v in &s.vertices_removed {
        out.push_str(&vertex('-', v));
    }
    for v in &s.vertices_added {
        out.push_str(&vertex('+', v));
    }
    for a in &s.arcs_removed {
        out.push_str(&arc('-', a));
    }
    for a in &s.arcs_added {
        out.push_str(&arc('+', a));
    }
    for k in s.rematched() {
        out.push_str(&format!(
            "  ~ `{}` matched to `{}`\n",
            shown(&k.a),
            shown(&k.b)
        ));
    }
    for l in change_lines(s, &Style::plain(), false) {
        out.push_str(&format!("  ~ {l}\n"));
    }
    for a in s.arcs_kept.iter().filter(|a| a.label_in_a.is_some()) {
        out.push_str(&format!(
            "  ~ arc `{}` -> `{}` relabelled [{}] -> [{}]\n",
            shown(&a.from),
            shown(&a.to),
            shown(a.label_in_a.as_deref().unwrap_or_default()),
            shown(&a.label)
        ));
    }
    if s.is_unchanged() {
        out.push_str("  (none: the graphs are identical under this mapping)\n");
    }
    out
}

/// `1 reorder`, `2 relabels`.
fn plural(n: u64, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}
