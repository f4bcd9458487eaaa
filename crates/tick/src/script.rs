//! Leaf scripts of `btfsm tick` (docs/bt-semantics.md, "Scripts"): what
//! each leaf of a BT returns on its 1st, 2nd, ... tick, read from TOML and
//! validated against the tree; every problem is a positioned
//! [`Diagnostic`].

use btfsm_core::diagnostic::{Diagnostic, SourceFile, suggest};
use btfsm_model::BtNodeKind;
use btfsm_model::bt::Bt;
use btfsm_sim::skills::Status;
use std::collections::HashMap;
use std::ops::Range;
use std::sync::Arc;
use toml::Spanned;
use toml::de::{DeTable, DeValue};

type Val<'i> = Spanned<DeValue<'i>>;

/// Most ticks a script may ask for.
pub const MAX_TICKS: u64 = 100_000;

/// What a leaf returns once its list is used up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Then {
    /// The script's default for its kind of leaf.
    Default,
    /// The last status of its list, again and again.
    Last,
    /// Its list again from the start.
    Cycle,
}

/// One leaf's answers.
#[derive(Debug, Clone)]
pub struct LeafScript {
    pub statuses: Vec<Status>,
    pub then: Then,
}

/// A validated script, its leaves by node index.
#[derive(Debug, Clone)]
pub struct Script {
    pub ticks: u64,
    pub default: Status,
    pub condition_default: Status,
    pub halt: bool,
    pub leaves: HashMap<usize, LeafScript>,
}

impl Script {
    /// What leaf `n` (an action when `action`) returns on its `k`-th tick
    /// (from 0).
    pub fn answer(&self, n: usize, k: u64, action: bool) -> Status {
        let default = if action {
            self.default
        } else {
            self.condition_default
        };
        let Some(l) = self.leaves.get(&n) else {
            return default;
        };
        let len = l.statuses.len() as u64;
        if k < len {
            return l.statuses[k as usize];
        }
        match (l.then, l.statuses.last()) {
            (Then::Last, Some(&s)) => s,
            (Then::Cycle, Some(_)) => l.statuses[(k % len) as usize],
            _ => default,
        }
    }
}

struct Reader {
    file: Arc<SourceFile>,
    diags: Vec<Diagnostic>,
}

const HINT: &str = "see the script format in docs/bt-semantics.md";

impl Reader {
    fn err(&mut self, span: Range<usize>, msg: impl Into<String>, hint: impl Into<String>) {
        self.diags
            .push(Diagnostic::error(msg).at(&self.file, span).hint(hint));
    }

    fn status(&mut self, v: &Val<'_>, condition: bool) -> Option<Status> {
        let s = match v.get_ref().as_str() {
            Some("success") => Status::Success,
            Some("failure") => Status::Failure,
            Some("running") if !condition => Status::Running,
            Some("running") => {
                self.err(
                    v.span(),
                    "a condition cannot return `running`",
                    "conditions return `success` or `failure`",
                );
                return None;
            }
            Some(other) => {
                let h = suggest(other, ["success", "failure", "running"]);
                self.err(v.span(), format!("unknown status `{other}`"), h);
                return None;
            }
            None => {
                self.err(
                    v.span(),
                    "a status must be a string",
                    "write \"success\", \"failure\" or \"running\"",
                );
                return None;
            }
        };
        Some(s)
    }
}

/// Parses and validates a script for `bt`.
pub fn parse(file: &Arc<SourceFile>, bt: &Bt) -> Result<Script, Vec<Diagnostic>> {
    btfsm_core::toml_budget::check(
        file,
        btfsm_core::toml_budget::DEFAULT_MAX_TOKENS,
        "a script's counts are capped (docs/guide/tick.md)",
    )
    .map_err(|d| vec![d])?;
    let doc = match DeTable::parse(&file.text) {
        Ok(doc) => doc,
        Err(e) => {
            return Err(vec![
                Diagnostic::error(format!(
                    "invalid TOML: {}",
                    e.message().trim().trim_end_matches('.')
                ))
                .at(file, e.span().unwrap_or(0..0))
                .hint(HINT),
            ]);
        }
    };
    let mut r = Reader {
        file: file.clone(),
        diags: Vec::new(),
    };
    let t = doc.get_ref();
    let mut s = Script {
        ticks: 10,
        default: Status::Success,
        condition_default: Status::Success,
        halt: false,
        leaves: HashMap::new(),
    };
    let ids: HashMap<&str, usize> = (bt.nodes.iter().enumerate())
        .map(|(i, n)| (n.id.as_str(), i))
        .collect();
    for (k, v) in t.iter() {
        match k.get_ref().as_ref() {
            "ticks" => match v.get_ref() {
                DeValue::Integer(i) => {
                    match i64::from_str_radix(&i.as_str().replace('_', ""), i.radix()) {
                        Ok(n) if (1..=MAX_TICKS as i64).contains(&n) => s.ticks = n as u64,
                        _ => r.err(
                            v.span(),
                            format!("`ticks` must be from 1 to {MAX_TICKS}"),
                            "a fixed limit: split a longer script",
                        ),
                    }
                }
                _ => r.err(v.span(), "`ticks` must be an integer", "write `ticks = 10`"),
            },
            "default" => {
                if let Some(x) = r.status(v, false) {
                    s.default = x;
                }
            }
            "condition_default" => {
                if let Some(x) = r.status(v, true) {
                    s.condition_default = x;
                }
            }
            "halt" => match v.get_ref() {
                DeValue::Boolean(b) => s.halt = *b,
                _ => r.err(
                    v.span(),
                    "`halt` must be true or false",
                    "write `halt = true`",
                ),
            },
            "leaves" => match v.get_ref().as_table() {
                Some(lt) => leaves(&mut r, lt, bt, &ids, &mut s),
                None => r.err(v.span(), "`leaves` must be a table", "write `[leaves]`"),
            },
            other => {
                let h = suggest(
                    other,
                    ["ticks", "default", "condition_default", "halt", "leaves"],
                );
                r.err(k.span(), format!("unknown script key `{other}`"), h);
            }
        }
    }
    if r.diags.is_empty() {
        Ok(s)
    } else {
        Err(r.diags)
    }
}

/// The `[leaves]` table: `id = [statuses]` or `id = { statuses = [...],
/// then = "default" | "last" | "cycle" }`.
fn leaves(r: &mut Reader, lt: &DeTable<'_>, bt: &Bt, ids: &HashMap<&str, usize>, s: &mut Script) {
    for (k, v) in lt.iter() {
        let id = k.get_ref().as_ref();
        let Some(&n) = ids.get(id) else {
            let leaf_ids = (bt.nodes.iter())
                .filter(|n| n.children.is_empty())
                .map(|n| n.id.as_str());
            let h = suggest(id, leaf_ids);
            r.err(k.span(), format!("no node `{id}` in the tree"), h);
            continue;
        };
        let kind = bt.nodes[n].kind;
        if !matches!(kind, BtNodeKind::Action | BtNodeKind::Condition) {
            r.err(
                k.span(),
                format!("`{id}` is a {} node, not a leaf", kind.keyword()),
                "only actions and conditions are scripted",
            );
            continue;
        }
        let condition = kind == BtNodeKind::Condition;
        let (list, then) = match v.get_ref() {
            DeValue::Array(a) => (Some(a), Then::Default),
            DeValue::Table(t) => {
                let mut list = None;
                let mut then = Then::Default;
                for (tk, tv) in t.iter() {
                    match (tk.get_ref().as_ref(), tv.get_ref()) {
                        ("statuses", DeValue::Array(a)) => list = Some(a),
                        ("then", DeValue::String(x)) => {
                            then = match x.as_ref() {
                                "default" => Then::Default,
                                "last" => Then::Last,
                                "cycle" => Then::Cycle,
                                other => {
                                    let h = suggest(other, ["default", "last", "cycle"]);
                                    r.err(tv.span(), format!("unknown `then` `{other}`"), h);
                                    Then::Default
                                }
                            }
                        }
                        (other, _) => r.err(
                            tk.span(),
                            format!("unexpected `{other}` in the script of `{id}`"),
                            "write `{ statuses = [\"failure\", \"success\"], then = \"last\" }`",
                        ),
                    }
                }
                if list.is_none() {
                    r.err(v.span(), format!("no `statuses` for `{id}`"), HINT);
                }
                (list, then)
            }
            _ => {
                r.err(
                    v.span(),
                    format!("the script of `{id}` must be a list of statuses or a table"),
                    HINT,
                );
                (None, Then::Default)
            }
        };
        let Some(list) = list else { continue };
        let statuses: Vec<Status> = list.iter().filter_map(|x| r.status(x, condition)).collect();
        s.leaves.insert(n, LeafScript { statuses, then });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use btfsm_format::Limits;
    use btfsm_model::PolicyBody;
    use std::path::Path;

    /// No input panics: byte mutations of a valid script parse or give
    /// positioned errors, and every script that parses runs.
    #[test]
    fn mutated_scripts_never_panic() {
        let tree = "kind = \"bt\"\nroot = \"r\"\n[nodes]\nr = { sequence = [\"c\", \"a\"] }\nc = { condition = \"C?\" }\na = { action = \"A!\" }\n";
        let l = btfsm_format::toml::parse_str("t.toml", tree, Path::new("."), &Limits::default())
            .unwrap();
        let PolicyBody::Bt(bt) = &l.policy.body else {
            panic!()
        };
        let good = "ticks = 3\ndefault = \"running\"\ncondition_default = \"failure\"\nhalt = true\n[leaves]\nc = [\"success\", \"failure\"]\na = { statuses = [\"running\", \"success\"], then = \"cycle\" }\n";
        let mut rng = btfsm_sim::rng::SimRng::named(3, "tick-script");
        let alphabet = b"\"[]{}=,\n abcdefghilnrstuy0123456789-_#.";
        for _ in 0..3000 {
            let mut b = good.as_bytes().to_vec();
            for _ in 0..1 + rng.next_u64() % 4 {
                let i = (rng.next_u64() % b.len() as u64) as usize;
                let c = alphabet[(rng.next_u64() % alphabet.len() as u64) as usize];
                match rng.next_u64() % 3 {
                    0 => b[i] = c,
                    1 => b.insert(i, c),
                    _ => {
                        b.remove(i);
                    }
                }
            }
            let text = String::from_utf8_lossy(&b).into_owned();
            match parse(&SourceFile::new("s.toml", text), bt) {
                Ok(s) => {
                    let r = crate::run(bt, &s);
                    assert_eq!(r.ticks.len() as u64, s.ticks);
                }
                Err(d) => assert!(d.iter().all(|d| d.span.is_some()), "{d:?}"),
            }
        }
    }
}
