//! The replay of a BehaviorTree.CPP `FileLogger2` log (`.btlog`, read by
//! `log::replay`): one step per record (a status change of one node, as
//! `btfsm log dot --step K` counts them), the log's own timestamps, and a
//! timeline of its leaf nodes: RUNNING spans, marks where they returned
//! SUCCESS or FAILURE, grey where they were halted (back to IDLE).

use super::{Panel, Recorder, Replay, Row, Span, ViewError, code, drawn_keys};
use btfsm_format::Limits;
use btfsm_log::btlog::Status as LogStatus;
use btfsm_log::replay::{Opened, ReplayError, open};
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
#[expect(clippy::too_many_lines, reason = "to be split: issue 28")]
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
    // Leaves in pre-order: the timeline's rows, when they ever change.
    let leaf_row: HashMap<&str, usize> = bt
        .preorder()
        .into_iter()
        .filter(|&n| bt.nodes[n].children.is_empty())
        .enumerate()
        .map(|(i, n)| (bt.nodes[n].id.as_str(), i))
        .collect();
    let mut rows: Vec<Row> = bt
        .preorder()
        .into_iter()
        .filter(|&n| bt.nodes[n].children.is_empty())
        .map(|n| Row {
            label: bt.nodes[n].label.clone(),
            spans: Vec::new(),
        })
        .collect();
    let mut open_span: Vec<Option<usize>> = vec![None; rows.len()];
    let (keys, alias) = drawn_keys(&policy);
    let mut rec = Recorder::new(keys, &alias);
    let name = shown.to_string();
    let mut spans = 0usize;
    let mut t = 0.0;
    for r in records {
        let r = r.map_err(|e| fail(e.into()))?;
        t = r.t_usec as f64 / 1e6;
        let Some(id) = id_of.get(&r.uid) else {
            rec.nothing(&name, t)?;
            continue;
        };
        rec.change(&name, t, id, drawn(r.status))?;
        let Some(&row) = leaf_row.get(id.as_str()) else {
            continue;
        };
        let spans_of = &mut rows[row].spans;
        match (r.status, open_span[row]) {
            (LogStatus::Running, None) => {
                spans_of.push(Span {
                    start: t,
                    end: None,
                    outcome: "running".into(),
                    index: spans,
                });
                spans += 1;
                open_span[row] = Some(spans_of.len() - 1);
            }
            (LogStatus::Success | LogStatus::Failure, open) => {
                let outcome = if r.status == LogStatus::Success {
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
                            index: spans,
                        });
                        spans += 1;
                    }
                }
                open_span[row] = None;
            }
            (LogStatus::Idle | LogStatus::Skipped, Some(k)) => {
                spans_of[k].end = Some(t);
                spans_of[k].outcome = "cancelled".into();
                open_span[row] = None;
            }
            _ => {}
        }
    }
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
    })
}
