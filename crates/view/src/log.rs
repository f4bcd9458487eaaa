//! The replay of a BehaviorTree.CPP `FileLogger2` log (`.btlog`, read by
//! `log::replay`): one step per record (a status change of one node, as
//! `btfsm log dot --step K` counts them), the log's own timestamps, and a
//! timeline of its leaf nodes: RUNNING spans, marks where they returned
//! SUCCESS or FAILURE, grey where they were halted (back to IDLE).

use super::{Panel, Recorder, Replay, Row, Span, ViewError, code, drawn_keys};
use btfsm_format::Limits;
use btfsm_log::btlog::Status as LogStatus;
use btfsm_log::replay::{Opened, ReplayError, open};
use btfsm_model::bt::Bt;
use btfsm_render::dot::Status;
use std::collections::HashMap;

fn drawn(s: LogStatus) -> u8 {
    code(match s {
        LogStatus::Running => Some(Status::Running),
        LogStatus::Success => Some(Status::Success),
        LogStatus::Failure => Some(Status::Failure),
        LogStatus::Idle | LogStatus::Skipped => None,
    })
}

/// Replays a log read from `r` (shown as `shown`).
pub fn from_log(r: impl std::io::Read, shown: &str, limits: &Limits) -> Result<Replay, ViewError> {
    let fail = |e: ReplayError| ViewError::Input(format!("{shown}: {e}"));
    let Opened {
        policy,
        id_of,
        records,
    } = open(r, limits).map_err(fail)?;
    let btfsm_model::PolicyBody::Bt(bt) = &policy.body else {
        return Err(ViewError::Input(format!("{shown}: not a behavior tree")));
    };
    let (leaf_row, mut leaves) = LeafSpans::of(bt);
    let (keys, alias) = drawn_keys(&policy);
    let mut rec = Recorder::new(keys, &alias);
    let name = shown.to_string();
    let mut t = 0.0;
    for r in records {
        let r = r.map_err(|e| fail(e.into()))?;
        t = r.t_usec as f64 / 1e6;
        let Some(id) = id_of.get(&r.uid) else {
            rec.nothing(&name, t)?;
            continue;
        };
        rec.change(&name, t, id, drawn(r.status))?;
        if let Some(&row) = leaf_row.get(id.as_str()) {
            leaves.change(row, r.status, t);
        }
    }
    let mut rows = leaves.rows;
    rows.retain(|r| !r.spans.is_empty());
    let steps = rec.times.len();
    let title = policy.name.clone();
    Ok(Replay {
        title: format!("{shown}: {title}"),
        subtitle: format!(
            "BehaviorTree.CPP log, {steps} status changes over {} s",
            (t * 1e6).round() / 1e6
        ),
        step_name: "status change".into(),
        panels: vec![Panel {
            title,
            subtitle: format!("{shown} · {steps} records"),
            policy,
            rec,
            rows,
            marks: Vec::new(),
        }],
        divergences: Vec::new(),
        compared_all: true,
        map: None,
    })
}

/// The timeline rows of a tree's leaves as the log is replayed, with the
/// span each has open.
struct LeafSpans {
    rows: Vec<Row>,
    /// Per row, its span still RUNNING.
    open: Vec<Option<usize>>,
    /// Spans made so far (a span's index).
    spans: usize,
}

impl LeafSpans {
    /// The rows of `bt`'s leaves, in pre-order, and each leaf's row by id.
    fn of(bt: &Bt) -> (HashMap<&str, usize>, Self) {
        // Leaves in pre-order: the timeline's rows, when they ever change.
        let leaf_row: HashMap<&str, usize> = bt
            .preorder()
            .into_iter()
            .filter(|&n| bt.nodes[n].children.is_empty())
            .enumerate()
            .map(|(i, n)| (bt.nodes[n].id.as_str(), i))
            .collect();
        let rows: Vec<Row> = bt
            .preorder()
            .into_iter()
            .filter(|&n| bt.nodes[n].children.is_empty())
            .map(|n| Row {
                label: bt.nodes[n].label.clone(),
                spans: Vec::new(),
            })
            .collect();
        let open = vec![None; rows.len()];
        (
            leaf_row,
            LeafSpans {
                rows,
                open,
                spans: 0,
            },
        )
    }

    /// The leaf of row `row` changed to `status` at `t`: RUNNING opens a
    /// span, SUCCESS and FAILURE end it (or make an instant one), IDLE
    /// cancels it (halted).
    fn change(&mut self, row: usize, status: LogStatus, t: f64) {
        let spans_of = &mut self.rows[row].spans;
        match (status, self.open[row]) {
            (LogStatus::Running, None) => {
                spans_of.push(Span {
                    start: t,
                    end: None,
                    outcome: "running".into(),
                    index: self.spans,
                });
                self.spans += 1;
                self.open[row] = Some(spans_of.len() - 1);
            }
            (LogStatus::Success | LogStatus::Failure, open) => {
                let outcome = if status == LogStatus::Success {
                    "success"
                } else {
                    "failure"
                };
                match open {
                    Some(k) => {
                        spans_of[k].end = Some(t);
                        spans_of[k].outcome = outcome.into();
                    }
                    None => {
                        spans_of.push(Span {
                            start: t,
                            end: Some(t),
                            outcome: outcome.into(),
                            index: self.spans,
                        });
                        self.spans += 1;
                    }
                }
                self.open[row] = None;
            }
            (LogStatus::Idle | LogStatus::Skipped, Some(k)) => {
                spans_of[k].end = Some(t);
                spans_of[k].outcome = "cancelled".into();
                self.open[row] = None;
            }
            _ => {}
        }
    }
}
