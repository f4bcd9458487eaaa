//! The review for a terminal (`--format text`) and as JSON (`--format
//! json`, the contract of docs/guide/review.md): the same facts as the
//! markdown comment, without the drawings. Strings from the repository go
//! through `sanitize::shown` (text) and `sanitize::json` (JSON).

use super::markdown::status;
use super::{FileReview, Metrics, Review};
use btfsm_core::sanitize::shown;

/// The review as JSON: `{"version": 1, "base", "head", "gates", "files",
/// "other_changes", "gate_failures"}`.
pub fn render_json(r: &Review) -> String {
    #[derive(serde::Serialize)]
    struct Out<'a> {
        version: u32,
        #[serde(flatten)]
        review: &'a Review,
        gate_failures: usize,
    }
    let out = Out {
        version: 1,
        review: r,
        gate_failures: r.failures().count(),
    };
    let mut s =
        btfsm_core::sanitize::json(serde_json::to_string_pretty(&out).expect("serializable"));
    s.push('\n');
    s
}

/// The review as text.
pub fn render_text(r: &Review) -> String {
    let mut out = format!(
        "btfsm review: {} polic{} changed, base {} → head {}\n",
        r.files.len(),
        if r.files.len() == 1 { "y" } else { "ies" },
        r.base.label,
        r.head.label
    );
    if r.other_changes > 0 {
        out.push_str(&format!(
            "{} other changed file(s): no policy, read by none\n",
            r.other_changes
        ));
    }
    for f in &r.files {
        out.push('\n');
        file(&mut out, f);
    }
    let failures: Vec<_> = r.failures().collect();
    out.push('\n');
    if r.gates.is_empty() {
        out.push_str("gates: none set (base btfsm.toml [review])\n");
    } else if failures.is_empty() {
        out.push_str("gates: passed\n");
    } else {
        for g in &failures {
            out.push_str(&format!(
                "gate failed: {}: {}: {}\n",
                shown(&g.file),
                g.gate,
                shown(&g.message)
            ));
        }
    }
    out
}

fn file(out: &mut String, f: &FileReview) {
    let from = f
        .from
        .as_deref()
        .map_or_else(String::new, |p| format!(" (from {})", shown(p)));
    out.push_str(&format!(
        "{} {}{from}: {}\n",
        shown(&f.path),
        f.kind.as_deref().unwrap_or("-"),
        status(f)
    ));
    if !f.via.is_empty() {
        let via: Vec<_> = f.via.iter().map(|v| shown(v).into_owned()).collect();
        out.push_str(&format!("  reads changed {}\n", via.join(", ")));
    }
    if let Some(e) = &f.load_error {
        out.push_str(&format!("  does not load in head: {}\n", shown(e)));
    }
    if f.before.is_some() || f.after.is_some() {
        out.push_str(&format!("  {}\n", metrics(f)));
    }
    for l in &f.changes {
        out.push_str(&format!("  {}\n", shown(l)));
    }
    if f.changes_total > f.changes.len() {
        out.push_str(&format!(
            "  … and {} more changes\n",
            f.changes_total - f.changes.len()
        ));
    }
    for n in &f.new_findings {
        let line = n.line.map_or_else(String::new, |l| format!(":{l}"));
        out.push_str(&format!(
            "  new {}[{}] {}{line} at {}: {}\n",
            n.level,
            n.code,
            shown(&n.file),
            shown(&n.at),
            shown(&n.message)
        ));
    }
    if f.fixed_findings > 0 {
        out.push_str(&format!("  {} finding(s) fixed\n", f.fixed_findings));
    }
}

/// `vertices 10 → 12 (+2), ...`, then GED and TED.
fn metrics(f: &FileReview) -> String {
    let one = |name: &str, get: fn(&Metrics) -> i64| match (&f.before, &f.after) {
        (Some(a), Some(b)) if get(a) != get(b) => {
            format!(
                "{name} {} → {} ({:+})",
                get(a),
                get(b),
                get(b).saturating_sub(get(a))
            )
        }
        (_, Some(b)) => format!("{name} {}", get(b)),
        (Some(a), None) => format!("{name} {} (gone)", get(a)),
        (None, None) => String::new(),
    };
    let mut parts = vec![
        one("vertices", |m| m.vertices),
        one("edges", |m| m.edges),
        one("cc", |m| m.cc),
        one("essential cc", |m| m.essential_cc),
    ];
    if let Some(g) = f.ged {
        parts.push(format!("GED {g}"));
    }
    if let Some(t) = &f.ted {
        parts.push(format!(
            "TED {}{}",
            t.distance,
            if t.exact { "" } else { " (bound)" }
        ));
    }
    parts.join(", ")
}
