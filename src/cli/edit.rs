//! `btfsm edit`: the paper's edit operations (`transform::edit`) on a policy
//! file. The edited policy is written as TOML (to `-o` or stdout), after
//! checking that it reads back as a valid policy; what the edit touched goes
//! to stderr.

use super::args::{AddKind, AddStateArgs, EditArgs, EditOp, WrapKind};
use super::io::{emit_text, fail, load_one};
use super::{EXIT_BAD_INPUT, EXIT_OK};
use btfsm_core::diagnostic::Diagnostic;
use btfsm_core::sanitize::shown;
use btfsm_model::{BtNodeKind, PolicyBody, SkillCall};
use btfsm_transform::edit::{self, AddState, EditError, Touched};
use std::collections::BTreeMap;

pub(super) fn edit(a: &EditArgs) -> u8 {
    let limits = a.limits.limits();
    let Some(loaded) = load_one(&a.file, &limits) else {
        return EXIT_BAD_INPUT;
    };
    let mut policy = loaded.policy;
    let kind = policy.kind();
    let edit_failed = |e: EditError| {
        let d = Diagnostic::error(format!("{}: {}", shown(&loaded.path), e.message));
        super::io::fail(match e.hint {
            Some(h) => d.hint(h),
            None => d,
        })
    };
    let wrong_kind = |op: &str, want: &str| {
        eprint!(
            "{}",
            Diagnostic::error(format!(
                "{}: {op} edits {want}, and this policy is a {kind}",
                shown(&loaded.path)
            ))
        );
        EXIT_BAD_INPUT
    };
    let touched: Touched = match (&a.op, &mut policy.body) {
        (
            EditOp::InsertSubtree {
                parent,
                index,
                subtree,
                prefix,
            },
            PolicyBody::Bt(bt),
        ) => {
            let Some(sub) = load_one(subtree, &limits) else {
                return EXIT_BAD_INPUT;
            };
            let PolicyBody::Bt(sub_bt) = &sub.policy.body else {
                return fail(Diagnostic::error(format!(
                    "{}: the subtree must be a BT, and this is a {}",
                    shown(&sub.path),
                    sub.policy.kind()
                )));
            };
            match edit::insert_subtree(bt, parent, *index, sub_bt, prefix.as_deref()) {
                Ok(t) => t,
                Err(e) => return edit_failed(e),
            }
        }
        (EditOp::WrapRoot { kind, id, name }, PolicyBody::Bt(bt)) => {
            let k = match kind {
                WrapKind::Sequence => BtNodeKind::Sequence,
                WrapKind::Fallback => BtNodeKind::Fallback,
            };
            match edit::wrap_root(bt, k, id, name.as_deref()) {
                Ok(t) => t,
                Err(e) => return edit_failed(e),
            }
        }
        (EditOp::AddState(s), PolicyBody::Machine(m)) => {
            let spec = match add_state_spec(s) {
                Ok(spec) => spec,
                Err(Ok(d)) => return fail(d),
                Err(Err(e)) => return edit_failed(e),
            };
            match edit::add_state(m, &spec) {
                Ok(t) => t,
                Err(e) => return edit_failed(e),
            }
        }
        (EditOp::AddState(_), _) => return wrong_kind("add-state", "FSMs and HFSMs"),
        (_, _) => return wrong_kind("insert-subtree and wrap-root", "BTs"),
    };
    let text = match btfsm_format::toml_write::write_policy_within(&policy, limits.max_file_bytes) {
        Ok(t) => t,
        Err(e) => {
            return fail(Diagnostic::error(format!("{e}")));
        }
    };
    // The result must read back: an edit never writes an invalid file.
    let base = a.file.parent().unwrap_or(std::path::Path::new(""));
    if let Err(diags) = btfsm_format::toml::parse_str("edited policy", &text, base, &limits) {
        eprint!("{}", Diagnostic::error("the edited policy is not valid:"));
        for d in diags {
            eprint!("{d}");
        }
        return EXIT_BAD_INPUT;
    }
    let code = emit_text(a.output.as_deref(), text);
    if code == EXIT_OK {
        eprintln!(
            "edit: {} added, {} modified, transitions +{} -{} ({} unit edits)",
            touched.added,
            touched.modified,
            touched.transitions_added,
            touched.transitions_removed,
            touched.edits()
        );
    }
    code
}

/// The `add-state` operation from its flags: its skill call with the
/// `--arg`s, its guards parsed. A bad `--arg` is a usage error (`Ok`), a
/// bad guard an edit error (`Err`).
fn add_state_spec(s: &AddStateArgs) -> Result<AddState, Result<Diagnostic, EditError>> {
    let mut call = SkillCall {
        skill: s.skill.clone(),
        args: BTreeMap::new(),
    };
    for kv in &s.args {
        let Some((k, v)) = kv.split_once('=') else {
            return Err(Ok(Diagnostic::error(format!("invalid --arg `{kv}`"))
                .hint("write key=value, e.g. --arg target=cube2")));
        };
        call.args
            .insert(k.trim().to_string(), edit::parse_value(v.trim()));
    }
    let parse = |g: &Option<String>, l: &Option<String>| match g {
        Some(text) => edit::parse_guard(text, l.as_deref()).map(Some),
        None => Ok(None),
    };
    let guard = parse(&s.guard, &s.guard_label).map_err(Err)?;
    let selector_guard = parse(&s.selector_guard, &s.selector_guard_label).map_err(Err)?;
    Ok(AddState {
        kind: match s.kind {
            AddKind::Sequential => edit::AddKind::Sequential,
            AddKind::Alternative => edit::AddKind::Alternative,
            AddKind::Connected => edit::AddKind::Connected,
        },
        name: s.name.clone(),
        after: s.after.clone(),
        within: s.within.clone(),
        skill: call,
        guard,
        selector_guard,
        selector_guard_index: s.selector_guard_index,
    })
}
