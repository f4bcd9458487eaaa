//! `btfsm log report`: per node of a BehaviorTree.CPP log, its activations
//! (changes from IDLE to another status: a log records status changes, not
//! ticks, so a node RUNNING for ten ticks is one activation), its status
//! changes by status, and the time it spent RUNNING; node coverage (nodes
//! activated at least once) and branch coverage (every child of a Fallback
//! activated, every condition seen both SUCCESS and FAILURE), as test
//! coverage tools report lines and branches.

use super::btlog::{LogError, Record, Records, Status, read_header};
use super::tree::{Tree, parse};
use btfsm_format::btcpp_xml::Category;
use std::collections::BTreeMap;
use std::io::Read;

/// One node's figures.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct NodeStats {
    pub uid: u16,
    pub name: String,
    #[serde(rename = "type")]
    pub tag: String,
    pub activations: u64,
    /// Status changes into each status.
    pub statuses: BTreeMap<&'static str, u64>,
    /// µs spent RUNNING.
    pub running_usec: u64,
    #[serde(skip)]
    running_since: Option<u64>,
    #[serde(skip)]
    last: Option<Status>,
}

/// A log's report.
#[derive(Debug, Clone, serde::Serialize)]
pub struct LogReport {
    pub file: String,
    pub layout: super::btlog::Layout,
    pub first_timestamp_usec: i64,
    pub records: u64,
    pub duration_usec: u64,
    pub nodes: Vec<NodeStats>,
    pub node_coverage: Coverage,
    pub branch_coverage: Coverage,
    /// Branches not covered, as `Fallback name -> child name` or
    /// `condition name: SUCCESS|FAILURE`.
    pub uncovered: Vec<String>,
    /// For a `.db3`: the session read, and the file's sessions.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub session: Option<i64>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub sessions: Vec<super::Session>,
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub more_sessions: bool,
}

/// Covered items out of all.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Coverage {
    pub covered: u64,
    pub total: u64,
    pub ratio: f64,
}

impl Coverage {
    fn of(covered: u64, total: u64) -> Coverage {
        Coverage {
            covered,
            total,
            ratio: if total == 0 {
                1.0
            } else {
                covered as f64 / total as f64
            },
        }
    }
}

/// Reads a whole log, streaming its records; `max_xml` bounds its tree XML.
pub fn report(file: &str, r: impl Read, max_xml: u64) -> Result<LogReport, LogError> {
    let mut r = std::io::BufReader::with_capacity(1 << 16, r);
    let h = read_header(&mut r, max_xml)?;
    let tree: Tree = parse(&h.xml).map_err(|what| LogError::Bad {
        offset: 23.min(h.records_at),
        what,
    })?;
    let mut stats: BTreeMap<u16, NodeStats> = tree
        .nodes
        .values()
        .map(|n| {
            (
                n.uid,
                NodeStats {
                    uid: n.uid,
                    name: n.name.clone(),
                    tag: n.tag.clone(),
                    ..NodeStats::default()
                },
            )
        })
        .collect();
    let (count, end) = tally(Records::new(r, &h), &mut stats)?;
    let nodes_cov = Coverage::of(
        stats.values().filter(|s| s.activations > 0).count() as u64,
        stats.len() as u64,
    );
    let (branch_coverage, uncovered) = branches(&tree, &stats);
    Ok(LogReport {
        file: file.to_string(),
        layout: h.layout,
        first_timestamp_usec: h.t0_usec,
        records: count,
        duration_usec: end,
        nodes: stats.into_values().collect(),
        node_coverage: nodes_cov,
        branch_coverage,
        uncovered,
        session: None,
        sessions: Vec::new(),
        more_sessions: false,
    })
}

/// Counts every record into its node's figures (activations, status
/// changes, time RUNNING, until the log's end for a node still RUNNING);
/// the number of records and the last time, µs.
fn tally<R: Read>(
    mut records: Records<R>,
    stats: &mut BTreeMap<u16, NodeStats>,
) -> Result<(u64, u64), LogError> {
    let mut count = 0u64;
    let mut end = 0u64;
    loop {
        let at = records.offset();
        let Some(rec) = records.next() else { break };
        let Record {
            t_usec,
            uid,
            status,
        } = rec?;
        let Some(s) = stats.get_mut(&uid) else {
            return Err(LogError::Bad {
                offset: at,
                what: format!("node UID {uid}, which the log's tree does not have"),
            });
        };
        count += 1;
        end = end.max(t_usec);
        if status != Status::Idle && s.last.is_none_or(|l| l == Status::Idle) {
            s.activations += 1;
        }
        *s.statuses.entry(status.as_str()).or_default() += 1;
        if let Some(since) = s.running_since.take() {
            s.running_usec += t_usec.saturating_sub(since);
        }
        if status == Status::Running {
            s.running_since = Some(t_usec);
        }
        s.last = Some(status);
    }
    for s in stats.values_mut() {
        if let Some(since) = s.running_since.take() {
            s.running_usec += end.saturating_sub(since);
        }
    }
    Ok((count, end))
}

/// Branch coverage: every child of a Fallback activated, every condition
/// seen both SUCCESS and FAILURE; and the branches not covered.
fn branches(tree: &Tree, stats: &BTreeMap<u16, NodeStats>) -> (Coverage, Vec<String>) {
    let activated = |u: u16| stats.get(&u).is_some_and(|s| s.activations > 0);
    let (mut covered, mut total) = (0u64, 0u64);
    let mut uncovered = Vec::new();
    for n in tree.nodes.values() {
        let fallback = matches!(
            n.tag.as_str(),
            "Fallback" | "ReactiveFallback" | "AsyncFallback"
        );
        if fallback {
            for &c in &n.children {
                total += 1;
                if activated(c) {
                    covered += 1;
                } else {
                    uncovered.push(format!("{} -> {}", n.name, tree.nodes[&c].name));
                }
            }
        }
        if n.category == Some(Category::Condition) {
            let seen = &stats[&n.uid].statuses;
            for st in ["SUCCESS", "FAILURE"] {
                total += 1;
                if seen.get(st).is_some_and(|&k| k > 0) {
                    covered += 1;
                } else {
                    uncovered.push(format!("{}: {st}", n.name));
                }
            }
        }
    }
    (Coverage::of(covered, total), uncovered)
}

/// The report as a table.
pub fn render_table(r: &LogReport) -> String {
    use btfsm_core::sanitize::shown;
    let mut out = format!(
        "log {} ({} records, {:.3} s)\n",
        shown(&r.file),
        r.records,
        r.duration_usec as f64 / 1e6
    );
    out.push_str(&sessions_line(r));
    out.push('\n');
    let mut t = btfsm_core::table::Table::new(&[
        "uid",
        "node",
        "type",
        "activations",
        "RUNNING",
        "SUCCESS",
        "FAILURE",
        "IDLE",
        "SKIPPED",
        "running s",
    ]);
    for n in &r.nodes {
        let k = |s: &str| n.statuses.get(s).copied().unwrap_or(0).to_string();
        t.row(vec![
            n.uid.to_string(),
            shown(&n.name).into_owned(),
            shown(&n.tag).into_owned(),
            n.activations.to_string(),
            k("RUNNING"),
            k("SUCCESS"),
            k("FAILURE"),
            k("IDLE"),
            k("SKIPPED"),
            format!("{:.3}", n.running_usec as f64 / 1e6),
        ]);
    }
    out.push_str(&t.render());
    out.push_str(&format!(
        "\nnode coverage {}/{} ({:.1} %), branch coverage {}/{} ({:.1} %)\n",
        r.node_coverage.covered,
        r.node_coverage.total,
        100.0 * r.node_coverage.ratio,
        r.branch_coverage.covered,
        r.branch_coverage.total,
        100.0 * r.branch_coverage.ratio
    ));
    for u in r.uncovered.iter().take(50) {
        out.push_str(&format!("  not covered: {}\n", shown(u)));
    }
    if r.uncovered.len() > 50 {
        out.push_str(&format!("  ... and {} more\n", r.uncovered.len() - 50));
    }
    out
}

/// The per-node figures as CSV (the coverage is in table and JSON).
pub fn render_csv(r: &LogReport) -> String {
    let mut out =
        String::from("uid,node,type,activations,RUNNING,SUCCESS,FAILURE,IDLE,SKIPPED,running_s\n");
    for n in &r.nodes {
        out.push_str(&node_cells(n, btfsm_core::sanitize::csv_cell, 6).join(","));
        out.push('\n');
    }
    out
}

/// One node's cells in the column order of the CSV and markdown tables:
/// strings from the log through `esc`, the time RUNNING with `digits`
/// decimals.
fn node_cells(n: &NodeStats, esc: fn(&str) -> String, digits: usize) -> Vec<String> {
    let k = |s: &str| n.statuses.get(s).copied().unwrap_or(0).to_string();
    vec![
        n.uid.to_string(),
        esc(&n.name),
        esc(&n.tag),
        n.activations.to_string(),
        k("RUNNING"),
        k("SUCCESS"),
        k("FAILURE"),
        k("IDLE"),
        k("SKIPPED"),
        format!("{:.digits$}", n.running_usec as f64 / 1e6),
    ]
}

/// For a `.db3`: `session 2 (sessions: 1 (2026-01-01 10:00:00), 2 (...))`.
fn sessions_line(r: &LogReport) -> String {
    let Some(s) = r.session else {
        return String::new();
    };
    let list: Vec<String> = (r.sessions.iter())
        .map(|x| format!("{} ({})", x.id, btfsm_core::sanitize::shown(&x.date)))
        .collect();
    format!(
        "session {s} (sessions: {}{})\n",
        list.join(", "),
        if r.more_sessions { ", ..." } else { "" }
    )
}

/// The report as GitHub-flavoured markdown: the coverage first (what a
/// pull request's reviewer reads), then the per-node table.
pub fn render_markdown(r: &LogReport) -> String {
    use btfsm_core::sanitize::{markdown_cell as md, markdown_code};
    let pct = |c: &Coverage| format!("{}/{} ({:.1} %)", c.covered, c.total, 100.0 * c.ratio);
    let mut out = format!(
        "### Log {}\n\n{} records, {:.3} s{}\n\n| coverage | covered |\n|---|---:|\n| nodes | {} |\n| branches | {} |\n\n",
        markdown_code(&r.file),
        r.records,
        r.duration_usec as f64 / 1e6,
        match r.session {
            Some(s) => format!(", session {s} of {}", r.sessions.len()),
            None => String::new(),
        },
        pct(&r.node_coverage),
        pct(&r.branch_coverage)
    );
    if !r.uncovered.is_empty() {
        out.push_str("Not covered:\n\n");
        for u in r.uncovered.iter().take(50) {
            out.push_str(&format!("- {}\n", md(u)));
        }
        if r.uncovered.len() > 50 {
            out.push_str(&format!("- ... and {} more\n", r.uncovered.len() - 50));
        }
        out.push('\n');
    }
    out.push_str("| uid | node | type | activations | RUNNING | SUCCESS | FAILURE | IDLE | SKIPPED | running s |\n|---:|---|---|---:|---:|---:|---:|---:|---:|---:|\n");
    for n in &r.nodes {
        out.push_str(&format!("| {} |\n", node_cells(n, md, 3).join(" | ")));
    }
    out
}
