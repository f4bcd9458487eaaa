//! The relabels and reorders of an edit script (`changes.rs`) as lines of
//! the table's script and of the markdown report's "what changed" summary,
//! which opens the markdown so that a reviewer reads first what the
//! distance does not count (issue 15, point 1).

use super::{CompareReport, Relabel, Reorder, Script, Text};

/// How strings from input are shown: keys (identifiers) and values.
pub(super) struct Style {
    pub key: fn(&str) -> String,
    pub value: fn(&str) -> String,
    /// An item of a list of children or guards.
    pub item: fn(&str) -> String,
}

impl Style {
    /// The table's: `` `key` ``, values as they are, escaped onto one line.
    pub(super) fn plain() -> Style {
        Style {
            key: |s| format!("`{}`", btfsm_core::sanitize::shown(s)),
            value: |s| btfsm_core::sanitize::shown(s).into_owned(),
            item: |s| btfsm_core::sanitize::shown(s).into_owned(),
        }
    }

    /// Markdown prose: keys as code spans, values escaped for markdown.
    pub(super) fn markdown() -> Style {
        Style {
            key: btfsm_core::sanitize::markdown_code,
            value: btfsm_core::sanitize::markdown_cell,
            item: btfsm_core::sanitize::markdown_code,
        }
    }
}

/// The part of two orders that differs: both without their common prefix
/// and suffix (`held, reached-delivery, place → reached-delivery, held,
/// place` reads `held, reached-delivery → reached-delivery, held`).
pub(super) fn changed_window<'t>(a: &'t [Text], b: &'t [Text]) -> (&'t [Text], &'t [Text]) {
    let pre = a.iter().zip(b).take_while(|(x, y)| x == y).count();
    let (a, b) = (&a[pre..], &b[pre..]);
    let suf = a
        .iter()
        .rev()
        .zip(b.iter().rev())
        .take_while(|(x, y)| x == y)
        .count();
    (&a[..a.len() - suf], &b[..b.len() - suf])
}

/// Most items of an order a line shows; the rest are counted.
pub(super) const ORDER_ITEMS: usize = 8;

/// `a, b, c` of at most [`ORDER_ITEMS`] items, then `… (N more)`.
pub(super) fn list_items(l: &[Text], item: fn(&str) -> String) -> String {
    let mut names: Vec<String> = l.iter().take(ORDER_ITEMS).map(|t| item(t)).collect();
    if l.len() > ORDER_ITEMS {
        names.push(format!("… ({} more)", l.len() - ORDER_ITEMS));
    }
    names.join(", ")
}

/// One reorder, without its sign.
pub(super) fn reorder_line(r: &Reorder, st: &Style) -> String {
    let (before, after) = changed_window(&r.before, &r.after);
    let list = |l: &[Text]| list_items(l, st.item);
    let (what, whose) = match r.of {
        "guards" => ("order of guards of", "its guards"),
        _ => ("order of", "its children"),
    };
    format!(
        "{what} {}: {} → {} (the priority of {whose} changed)",
        (st.key)(&r.key),
        list(before),
        list(after)
    )
}

/// One relabel, without its sign.
pub(super) fn relabel_line(r: &Relabel, st: &Style) -> String {
    let (b, a) = ((st.value)(&r.before), (st.value)(&r.after));
    match (r.what, &r.to) {
        ("initial", _) if r.key.is_empty() => format!("initial state: {b} → {a}"),
        ("initial", _) => format!("initial state of {}: {b} → {a}", (st.key)(&r.key)),
        ("guard", Some(to)) => format!(
            "guard of {} -> {}: {b} → {a}",
            (st.key)(&r.key),
            (st.key)(to)
        ),
        ("name", _) => format!("name of {}: \"{b}\" → \"{a}\"", (st.key)(&r.key)),
        (what, _) => format!("{what} of {}: {b} → {a}", (st.key)(&r.key)),
    }
}

/// Every reorder, then every relabel of `s`, one line each (no sign);
/// with `arcs`, the kept arcs whose label changed too.
pub(super) fn change_lines(s: &Script, st: &Style, arcs: bool) -> Vec<String> {
    let mut out: Vec<String> = s.reordered.iter().map(|r| reorder_line(r, st)).collect();
    out.extend(s.relabelled.iter().map(|r| relabel_line(r, st)));
    for a in s
        .arcs_kept
        .iter()
        .filter(|a| arcs && a.label_in_a.is_some())
    {
        out.push(format!(
            "label of arc {} -> {}: {} → {}",
            (st.key)(&a.from),
            (st.key)(&a.to),
            (st.value)(a.label_in_a.as_deref().unwrap_or_default()),
            (st.value)(&a.label)
        ));
    }
    out
}

/// `1 reorder, 2 relabels, 1 vertex and 3 arcs added, 1 arc removed`:
/// the kinds of change a mode's script holds, zeros left out.
pub(super) fn counts(p: &super::ModeReport) -> String {
    let s = &p.edit_script;
    let arcs = |l: &[super::ArcRef]| l.iter().map(|a| u64::from(a.count)).sum::<u64>();
    let plural = |n: u64, one: &str, many: &str| {
        (n > 0).then(|| format!("{n} {}", if n == 1 { one } else { many }))
    };
    let both = |v: usize, a: u64| {
        let parts: Vec<String> = [
            plural(v as u64, "vertex", "vertices"),
            plural(a, "arc", "arcs"),
        ]
        .into_iter()
        .flatten()
        .collect();
        (!parts.is_empty()).then(|| parts.join(" and "))
    };
    let parts: Vec<String> = [
        plural(p.reorders, "reorder", "reorders"),
        plural(p.relabels, "relabel", "relabels"),
        both(s.vertices_added.len(), arcs(&s.arcs_added)).map(|x| format!("{x} added")),
        both(s.vertices_removed.len(), arcs(&s.arcs_removed)).map(|x| format!("{x} removed")),
        plural(
            s.rematched().count() as u64,
            "vertex matched to another key",
            "vertices matched to other keys",
        ),
    ]
    .into_iter()
    .flatten()
    .collect();
    parts.join(", ")
}

/// Most changes the markdown summary lists before it points at the script.
const SUMMARY_LINES: usize = 12;

/// The markdown report's opening: what the primary mode's script changed,
/// reorders and relabels first (the GED does not count them), then how
/// many vertices and arcs were added and removed, and which vertices.
pub(super) fn summary_markdown(r: &CompareReport) -> String {
    let Some(p) = r.primary() else {
        return String::new();
    };
    let s = &p.edit_script;
    // BehaviorTree.CPP nodes without an id of their own were paired by
    // the ordered tree mapping: said, since their keys then change.
    let in_tree_order = s.vertices_kept.iter().any(|k| k.derived && k.a != k.b);
    let how = if in_tree_order {
        "; nodes without an id matched in tree order"
    } else {
        ""
    };
    let mut out = format!("**What changed** ({} mapping{how}): ", p.mode.as_str());
    if s.is_unchanged() {
        out.push_str(
            "nothing; the policies are the same graph with the same types, bindings and orders.\n",
        );
        return out;
    }
    out.push_str(&counts(p));
    out.push_str(".\n");
    let mut lines = change_lines(s, &Style::markdown(), true);
    let code = btfsm_core::sanitize::markdown_code;
    for (sign, list) in [
        ("added", &s.vertices_added),
        ("removed", &s.vertices_removed),
    ] {
        for v in list {
            // The display name too, when the key does not say it (a
            // derived BehaviorTree.CPP id such as `Main/0/1`).
            let name = if v.name == v.key || v.name.is_empty() {
                String::new()
            } else {
                format!(" \"{}\"", btfsm_core::sanitize::markdown_cell(&v.name))
            };
            lines.push(format!(
                "{sign} {} {}{name}",
                v.vtype.as_str(),
                code(&v.key)
            ));
        }
    }
    if !lines.is_empty() {
        out.push('\n');
    }
    for l in lines.iter().take(SUMMARY_LINES) {
        out.push_str(&format!("- {l}\n"));
    }
    if lines.len() > SUMMARY_LINES {
        out.push_str(&format!(
            "- … and {} more (see the edit script below)\n",
            lines.len() - SUMMARY_LINES
        ));
    }
    if p.reorders + p.relabels > 0 {
        out.push_str("\nThe graph edit distance below counts neither reorders nor relabels (the paper's GED is on unordered graphs with unlabelled arcs).\n");
    }
    out
}
