//! The actions a BehaviorTree.CPP log executed, in start order, as the
//! simulator records its skills (`sim::trace::SkillRecord`): what
//! `btfsm log compare` compares (docs/logs.md states the definition).
//!
//! An *action* is a leaf of the log's tree that is not one of
//! BehaviorTree.CPP's built-in nodes and whose type the log's
//! `<TreeNodesModel>` calls an `Action` (or does not declare); its skill is
//! its type (the registration ID, the element's tag) and its arguments its
//! ports. A log records status changes, so an *execution* of an action is:
//! - a change into RUNNING from IDLE (or from SUCCESS or FAILURE: a finished
//!   action ticked again without being reset) starts one, which the next
//!   change into SUCCESS or FAILURE ends with that outcome, or a change into
//!   IDLE (halted) ends as `cancelled`; still open at the end of the log, its
//!   outcome is `running`;
//! - a change into SUCCESS or FAILURE with no execution open is an execution
//!   that starts and ends there (a synchronous action).
//!
//! A synchronous action ticked twice with the same result and no reset in
//! between changes no status and is one execution: the log cannot tell.
//! Executions come out in the order of their start records, streamed: the
//! ones that ended behind one still open wait for it, at most
//! [`MAX_PENDING`] of them.

use super::btlog::{LogError, Records, Status};
use super::tree::Tree;
use btfsm_format::btcpp_xml::{Category, builtin};
use btfsm_sim::trace::SkillRecord;
use std::collections::{BTreeMap, VecDeque};
use std::io::Read;

/// Most executions that ended while an earlier one is still open.
pub const MAX_PENDING: usize = 1 << 20;

/// One action node: its skill, arguments and name.
#[derive(Debug, Clone)]
struct Action {
    skill: String,
    args: BTreeMap<String, String>,
    name: String,
    /// The sequence number of its open execution.
    open: Option<u64>,
}

#[derive(Debug, Clone, Copy)]
struct Pending {
    uid: u16,
    start: u64,
    end: Option<u64>,
    outcome: Option<&'static str>,
}

/// Whether a node of the log's tree is an action in the sense above.
pub fn is_action(t: &Tree, uid: u16) -> bool {
    let n = &t.nodes[&uid];
    n.children.is_empty()
        && builtin(&n.tag).is_none()
        && n.tag != "SubTree"
        && matches!(n.category, None | Some(Category::Action))
}

/// A log's executions, in start order.
pub struct Executions<R> {
    records: Records<R>,
    tree: Tree,
    actions: BTreeMap<u16, Action>,
    pending: VecDeque<Pending>,
    /// The sequence number of `pending[0]`.
    base: u64,
    end_usec: u64,
    done: bool,
    /// The node (`name` (uid N)) of the execution last returned.
    pub last_node: Option<String>,
}

impl<R: Read> Executions<R> {
    pub fn new(records: Records<R>, tree: Tree) -> Self {
        let actions = tree
            .nodes
            .values()
            .filter(|n| is_action(&tree, n.uid))
            .map(|n| {
                (
                    n.uid,
                    Action {
                        skill: n.tag.clone(),
                        args: n.ports.clone(),
                        name: n.name.clone(),
                        open: None,
                    },
                )
            })
            .collect();
        Executions {
            records,
            tree,
            actions,
            pending: VecDeque::new(),
            base: 0,
            end_usec: 0,
            done: false,
            last_node: None,
        }
    }

    /// The time of the last record read, µs after the first timestamp.
    pub fn end_usec(&self) -> u64 {
        self.end_usec
    }

    fn push(&mut self, p: Pending, at: u64) -> Result<u64, LogError> {
        if self.pending.len() >= MAX_PENDING {
            let open = self.pending.front().map(|p| p.uid).unwrap_or_default();
            return Err(LogError::Bad {
                offset: at,
                what: format!(
                    "more than {MAX_PENDING} executions ended while action `{}` (uid {open}) kept RUNNING: too many to order by start",
                    self.actions
                        .get(&open)
                        .map(|a| a.name.as_str())
                        .unwrap_or("?")
                ),
            });
        }
        self.pending.push_back(p);
        Ok(self.base + self.pending.len() as u64 - 1)
    }

    fn close(&mut self, seq: u64, t: u64, outcome: &'static str) {
        let p = &mut self.pending[(seq - self.base) as usize];
        p.end = Some(t);
        p.outcome = Some(outcome);
    }

    /// Reads one record; false at the end of the log.
    fn read_one(&mut self) -> Result<bool, LogError> {
        let at = self.records.offset();
        let Some(rec) = self.records.next() else {
            return Ok(false);
        };
        let rec = rec?;
        if !self.tree.nodes.contains_key(&rec.uid) {
            return Err(LogError::Bad {
                offset: at,
                what: format!("node UID {}, which the log's tree does not have", rec.uid),
            });
        }
        self.end_usec = self.end_usec.max(rec.t_usec);
        let Some(open) = self.actions.get(&rec.uid).map(|a| a.open) else {
            return Ok(true);
        };
        let t = rec.t_usec;
        let set_open = |s: &mut Self, v| {
            if let Some(a) = s.actions.get_mut(&rec.uid) {
                a.open = v;
            }
        };
        match (rec.status, open) {
            (Status::Running, None) => {
                let p = Pending {
                    uid: rec.uid,
                    start: t,
                    end: None,
                    outcome: None,
                };
                let seq = self.push(p, at)?;
                set_open(self, Some(seq));
            }
            (Status::Running, Some(_)) => {}
            (Status::Success | Status::Failure, Some(seq)) => {
                let o = if rec.status == Status::Success {
                    "success"
                } else {
                    "failure"
                };
                self.close(seq, t, o);
                set_open(self, None);
            }
            (Status::Success | Status::Failure, None) => {
                let o = if rec.status == Status::Success {
                    "success"
                } else {
                    "failure"
                };
                let p = Pending {
                    uid: rec.uid,
                    start: t,
                    end: Some(t),
                    outcome: Some(o),
                };
                self.push(p, at)?;
            }
            (Status::Idle | Status::Skipped, Some(seq)) => {
                self.close(seq, t, "cancelled");
                set_open(self, None);
            }
            (Status::Idle | Status::Skipped, None) => {}
        }
        Ok(true)
    }

    fn record(&mut self, p: Pending) -> SkillRecord {
        let a = &self.actions[&p.uid];
        self.last_node = Some(format!("{} (uid {})", a.name, p.uid));
        SkillRecord {
            skill: a.skill.clone(),
            args: a.args.clone(),
            outcome: p.outcome.unwrap_or("running").to_string(),
            start: p.start as f64 / 1e6,
            end: p.end.map(|e| e as f64 / 1e6),
        }
    }
}

impl<R: Read> Iterator for Executions<R> {
    type Item = Result<SkillRecord, LogError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(p) = self.pending.front().copied()
                && (p.outcome.is_some() || self.done)
            {
                self.pending.pop_front();
                self.base += 1;
                if p.outcome.is_none()
                    && let Some(a) = self.actions.get_mut(&p.uid)
                {
                    a.open = None;
                }
                return Some(Ok(self.record(p)));
            }
            if self.done {
                return None;
            }
            match self.read_one() {
                Ok(true) => {}
                Ok(false) => self.done = true,
                Err(e) => {
                    self.done = true;
                    self.pending.clear();
                    return Some(Err(e));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::btlog::{MAGIC, read_header};
    use super::*;

    const XML: &str = r#"<root BTCPP_format="4"><BehaviorTree ID="M" _fullpath=""><Sequence _uid="1"><IsOk _uid="2"/><Go _uid="3" to="a"/><AlwaysSuccess _uid="4"/><Go _uid="5" to="b"/></Sequence></BehaviorTree><TreeNodesModel><Condition ID="IsOk"/><Action ID="Go"/></TreeNodesModel></root>"#;

    fn log(records: &[(u64, u16, u8)]) -> Vec<u8> {
        let mut b = MAGIC.to_vec();
        b.push(1);
        b.extend((XML.len() as i32).to_le_bytes());
        b.extend(XML.as_bytes());
        b.extend(0i64.to_le_bytes());
        for &(t, u, s) in records {
            b.extend(&t.to_le_bytes()[..6]);
            b.extend(u.to_le_bytes());
            b.push(s);
        }
        b
    }

    fn texts(records: &[(u64, u16, u8)]) -> Vec<(String, f64, Option<f64>)> {
        let b = log(records);
        let mut r = &b[..];
        let h = read_header(&mut r, 1 << 20).unwrap();
        let tree = super::super::tree::parse(&h.xml).unwrap();
        Executions::new(Records::new(r, &h), tree)
            .map(|x| x.unwrap())
            .map(|s| (s.text(), s.start, s.end))
            .collect()
    }

    #[test]
    fn executions_are_told_from_status_changes_in_start_order() {
        let got = texts(&[
            (0, 1, 1),
            (0, 2, 2), // a condition: not an action
            (10, 3, 1),
            (20, 4, 2), // a built-in: not an action
            (30, 5, 3), // synchronous, while uid 3 is open
            (40, 3, 2),
            (50, 3, 0),
            (60, 3, 1),
            (70, 3, 0), // halted
            (80, 5, 2), // FAILURE to SUCCESS: ticked again
            (90, 3, 1), // open at the end
        ]);
        assert_eq!(
            got,
            vec![
                ("Go(to=a) -> success".into(), 10e-6, Some(40e-6)),
                ("Go(to=b) -> failure".into(), 30e-6, Some(30e-6)),
                ("Go(to=a) -> cancelled".into(), 60e-6, Some(70e-6)),
                ("Go(to=b) -> success".into(), 80e-6, Some(80e-6)),
                ("Go(to=a) -> running".into(), 90e-6, None),
            ]
        );
    }

    #[test]
    fn an_unknown_uid_is_an_error_at_its_offset() {
        let b = log(&[(0, 9, 1)]);
        let mut r = &b[..];
        let h = read_header(&mut r, 1 << 20).unwrap();
        let tree = super::super::tree::parse(&h.xml).unwrap();
        let e = Executions::new(Records::new(r, &h), tree).next().unwrap();
        assert!(
            matches!(e, Err(LogError::Bad { offset, .. }) if offset == h.records_at),
            "{e:?}"
        );
    }
}
