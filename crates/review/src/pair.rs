//! One file's review from its two [`Side`]s: the metrics before and after
//! (`report::analyze`, SPEC §7) and their deltas, the paper's named GED
//! (Eq. 2, `report::compare`, the engineer's own edits) with its Mermaid
//! diff drawing (`compare --format markdown`'s, Figs. 7 and 8), the
//! ordered tree edit distance and its script for two BTs (`compare --mode
//! tree`), the change list (the tree script for BTs, the named edit
//! script for machines), and the lint findings new in head
//! ([`super::findings`]).

use super::findings::new_in_head;
use super::side::{Holds, Side};
use super::{FileReview, Metrics, Ted};
use btfsm_metrics::ged::{GedMode, GedOptions};
use btfsm_metrics::ted::TedOptions;
use btfsm_model::PolicyBody;
use btfsm_report::compare::{self, Pair, Script};

/// Change lines kept per file (the rest counted).
pub(crate) const MAX_CHANGES: usize = 200;

/// Most nodes of a policy drawn whole (an added file).
const MAX_DRAWN: usize = 150;

impl Metrics {
    pub(crate) fn of(r: &btfsm_report::PolicyReport) -> Metrics {
        let n = |x: usize| i64::try_from(x).unwrap_or(i64::MAX);
        Metrics {
            vertices: n(r.vertices),
            edges: n(r.edges),
            graphical_elements: n(r.graphical_elements),
            active_elements: n(r.active_elements),
            cc: r.cc,
            essential_cc: r.essential_cc,
        }
    }

    fn minus(&self, o: &Metrics) -> Metrics {
        Metrics {
            vertices: self.vertices.saturating_sub(o.vertices),
            edges: self.edges.saturating_sub(o.edges),
            graphical_elements: self.graphical_elements.saturating_sub(o.graphical_elements),
            active_elements: self.active_elements.saturating_sub(o.active_elements),
            cc: self.cc.saturating_sub(o.cc),
            essential_cc: self.essential_cc.saturating_sub(o.essential_cc),
        }
    }
}

/// What is compared of a file: `before` and `after` fill the review's
/// metrics, findings and drawings.
pub(crate) fn fill(
    r: &mut FileReview,
    before: Option<&Side>,
    after: Option<&Side>,
    opts: &super::Options,
) {
    let holds = after.or(before).map_or(Holds::Other, |s| s.holds);
    r.holds = holds;
    r.before = before.and_then(|s| s.metrics.as_ref()).map(Metrics::of);
    r.after = after.and_then(|s| s.metrics.as_ref()).map(Metrics::of);
    if let (Some(a), Some(b)) = (&r.before, &r.after) {
        r.delta = Some(b.minus(a));
    }
    r.kind = after
        .or(before)
        .and_then(|s| s.loaded.as_ref())
        .map(|l| l.policy.kind().as_str().to_string());
    r.load_error = after.and_then(|s| s.load_error.clone());
    let empty = Vec::new();
    let base_findings = before.map_or(&empty, |s| &s.findings);
    if let Some(head) = after {
        let (new, fixed) = new_in_head(base_findings, &head.findings, &r.path);
        r.new_findings = new;
        r.fixed_findings = fixed;
    } else {
        r.fixed_findings = base_findings.len();
    }
    let (la, lb) = (
        before.and_then(|s| s.loaded.as_ref()),
        after.and_then(|s| s.loaded.as_ref()),
    );
    match (la, lb) {
        (Some(a), Some(b)) => compare_pair(r, a, b, opts),
        (None, Some(b)) if b.policy_size() <= MAX_DRAWN => {
            r.diagram = Some(Ok(btfsm_render::mermaid::policy_mermaid(&b.policy)));
        }
        (None, None) => {
            r.unchanged = before.map(|s| &s.load_error) == after.map(|s| &s.load_error);
        }
        _ => {}
    }
}

/// Size of a loaded policy (nodes or states).
trait Size {
    fn policy_size(&self) -> usize;
}

impl Size for btfsm_format::Loaded {
    fn policy_size(&self) -> usize {
        match &self.policy.body {
            PolicyBody::Bt(bt) => bt.nodes.len(),
            PolicyBody::Machine(m) => m.states.len(),
        }
    }
}

/// Named GED, tree distance, change list and drawings of two loaded sides.
fn compare_pair(
    r: &mut FileReview,
    a: &btfsm_format::Loaded,
    b: &btfsm_format::Loaded,
    opts: &super::Options,
) {
    let old = r.from.clone().unwrap_or_else(|| r.path.clone());
    let topts = TedOptions {
        max_work: opts.tree_max_work,
        ..TedOptions::default()
    };
    let pair = Pair::with_tree_options(
        compare::Side {
            file: &old,
            policy: &a.policy,
        },
        compare::Side {
            file: &r.path,
            policy: &b.policy,
        },
        &topts,
        true,
    );
    let mut gopts = GedOptions::with_work(btfsm_metrics::ged::DEFAULT_WORK);
    if let Some(t) = opts.timeout {
        gopts.timeout = t;
    }
    let named = pair.run(GedMode::Named, &gopts);
    r.ged = Some(named.ged);
    let tree = pair.tree_report();
    r.ted = tree.as_ref().map(|t| Ted {
        distance: t.ted,
        exact: t.exact,
    });
    let mut lines = match &tree {
        Some(t) => compare::tree::script_lines(t),
        None => script_lines(&named.edit_script),
    };
    r.changes_total = lines.len();
    lines.truncate(MAX_CHANGES);
    r.changes = lines;
    let unchanged = named.edit_script.is_unchanged() && tree.as_ref().is_none_or(|t| t.ted == 0);
    r.unchanged = unchanged;
    if !unchanged {
        if opts.dot {
            let dopts = pair.dot_options(&named.edit_script);
            r.dot = Some(btfsm_render::dot::policy_dot(&b.policy, &dopts));
        }
        r.diagram = pair.report(vec![named]).diagram;
    }
}

/// A machine's named edit script, one line per edit (signs `+`, `-`, `~`).
fn script_lines(s: &Script) -> Vec<String> {
    use btfsm_core::sanitize::shown;
    let mut out = Vec::new();
    for v in &s.vertices_removed {
        out.push(format!("- {} `{}`", v.vtype.as_str(), shown(&v.key)));
    }
    for v in &s.vertices_added {
        out.push(format!("+ {} `{}`", v.vtype.as_str(), shown(&v.key)));
    }
    let arc = |sign: char, a: &compare::ArcRef| {
        let label = if a.label.is_empty() {
            String::new()
        } else {
            format!(" [{}]", shown(&a.label))
        };
        format!(
            "{sign} arc `{}` -> `{}`{label}",
            shown(&a.from),
            shown(&a.to)
        )
    };
    out.extend(s.arcs_removed.iter().map(|a| arc('-', a)));
    out.extend(s.arcs_added.iter().map(|a| arc('+', a)));
    for a in s.arcs_kept.iter().filter(|a| a.label_in_a.is_some()) {
        out.push(format!(
            "~ arc `{}` -> `{}` relabelled [{}] -> [{}]",
            shown(&a.from),
            shown(&a.to),
            shown(a.label_in_a.as_deref().unwrap_or_default()),
            shown(&a.label)
        ));
    }
    for l in &s.relabelled {
        out.push(format!(
            "~ `{}` {}: {} -> {}",
            shown(&l.key),
            l.what,
            shown(&l.before),
            shown(&l.after)
        ));
    }
    for o in &s.reordered {
        out.push(format!("~ `{}` {} reordered", shown(&o.key), o.of));
    }
    out
}
