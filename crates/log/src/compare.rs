//! `btfsm log compare A B`: the first divergence between two runs'
//! sequences of executed actions, each run a BehaviorTree.CPP log (its
//! executions, `actions.rs`) or a run of btfsm's simulator (the `skills` of
//! one policy in what `btfsm sim --format json` or `--trace` writes). The
//! comparison is the simulator verdict's own
//! (`sim::trace::first_divergence`): skill, arguments and outcome in order,
//! and with a tolerance, start times.

use super::actions::Executions;
use super::btlog::{LogError, Records, read_header};
use super::tree::parse;
use btfsm_sim::trace::{Divergence, SkillRecord, SkillSeq, first_divergence};
use std::collections::BTreeMap;
use std::io::{BufRead, BufReader, Read};

/// Why a comparison cannot be made.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CompareError {
    #[error("{file}: {err}")]
    Log { file: String, err: LogError },
    #[error("{file}: {what}")]
    Input { file: String, what: String },
}

/// One side of the comparison.
pub struct Side {
    file: String,
    policy: Option<String>,
    src: Source,
    ignore_args: bool,
    yielded: u64,
    last_node: Option<String>,
}

enum Source {
    Log(Box<Executions<Box<dyn BufRead>>>),
    Sim {
        skills: std::vec::IntoIter<SkillRecord>,
        end_s: f64,
    },
}

/// A run of the simulator as its JSON gives it (the fields read; the rest,
/// a trace's steps included, are skipped unread).
#[derive(serde::Deserialize)]
struct SimFile {
    policies: Vec<SimRun>,
}

#[derive(serde::Deserialize)]
struct SimRun {
    policy: String,
    duration_s: f64,
    skills: Vec<SkillIn>,
}

#[derive(serde::Deserialize)]
struct SkillIn {
    skill: String,
    #[serde(default)]
    args: BTreeMap<String, String>,
    outcome: String,
    start: f64,
    end: Option<f64>,
}

/// Opens a run: a `.btlog` (either layout) or a simulator JSON, told by
/// its content. `policy` picks the simulator's run (needed when the file
/// has several); `max_bytes` bounds a log's tree XML and a JSON file.
pub fn open(
    file: &str,
    r: impl Read + 'static,
    policy: Option<&str>,
    max_bytes: u64,
) -> Result<Side, CompareError> {
    let input = |what: String| CompareError::Input {
        file: file.to_string(),
        what,
    };
    let mut r: Box<dyn BufRead> = Box::new(BufReader::with_capacity(1 << 16, r));
    let head = r
        .fill_buf()
        .map_err(|e| input(format!("cannot read: {e}")))?;
    // JSON opens with `{`; an older-layout log opens with its XML's length,
    // whose low byte may be `{` but whose high bytes are zeros.
    let json = head
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .is_some_and(|i| head[i] == b'{' && !head[i..(i + 4).min(head.len())].contains(&0));
    let side = |src, policy| Side {
        file: file.to_string(),
        policy,
        src,
        ignore_args: false,
        yielded: 0,
        last_node: None,
    };
    if json {
        let mut bytes = Vec::new();
        r.take(max_bytes.saturating_add(1))
            .read_to_end(&mut bytes)
            .map_err(|e| input(format!("cannot read: {e}")))?;
        if bytes.len() as u64 > max_bytes {
            return Err(input(format!(
                "more than {max_bytes} bytes (raise --max-file-bytes)"
            )));
        }
        let f: SimFile = serde_json::from_slice(&bytes).map_err(|e| {
            input(format!(
                "{}:{}: not a btfsm simulator JSON (`sim --format json` or `--trace`): {e}",
                e.line(),
                e.column()
            ))
        })?;
        let names = || {
            let v: Vec<String> = (f.policies.iter())
                .map(|p| format!("`{}`", btfsm_core::sanitize::shown(&p.policy)))
                .collect();
            v.join(", ")
        };
        let run = match policy {
            Some(p) => f
                .policies
                .iter()
                .position(|r| r.policy == p)
                .ok_or_else(|| {
                    input(format!(
                        "no policy `{}` (the file has {})",
                        btfsm_core::sanitize::shown(p),
                        names()
                    ))
                })?,
            None if f.policies.len() == 1 => 0,
            None => {
                return Err(input(format!(
                    "{} policies ({}): name one with --policy",
                    f.policies.len(),
                    names()
                )));
            }
        };
        let run = f.policies.into_iter().nth(run).expect("found");
        let skills: Vec<SkillRecord> = run
            .skills
            .into_iter()
            .map(|s| SkillRecord {
                skill: s.skill,
                args: s.args,
                outcome: s.outcome,
                start: s.start,
                end: s.end,
            })
            .collect();
        return Ok(side(
            Source::Sim {
                skills: skills.into_iter(),
                end_s: run.duration_s,
            },
            Some(run.policy),
        ));
    }
    let log = |err| CompareError::Log {
        file: file.to_string(),
        err,
    };
    let h = read_header(&mut r, max_bytes).map_err(log)?;
    let tree = parse(&h.xml).map_err(|what| {
        log(LogError::Bad {
            offset: 23.min(h.records_at),
            what,
        })
    })?;
    let ex = Executions::new(Records::new(r, &h), tree);
    Ok(side(Source::Log(Box::new(ex)), None))
}

impl Side {
    fn kind(&self) -> &'static str {
        match self.src {
            Source::Log(_) => "btlog",
            Source::Sim { .. } => "sim",
        }
    }
}

impl SkillSeq for Side {
    type Error = CompareError;

    fn next_skill(&mut self) -> Option<Result<SkillRecord, CompareError>> {
        let next = match &mut self.src {
            Source::Log(ex) => {
                let n = ex.next();
                self.last_node = ex.last_node.take();
                n.map(|r| {
                    r.map_err(|err| CompareError::Log {
                        file: self.file.clone(),
                        err,
                    })
                })
            }
            Source::Sim { skills, .. } => {
                self.last_node = None;
                skills.next().map(Ok)
            }
        };
        match next {
            Some(Ok(mut s)) => {
                self.yielded += 1;
                if self.ignore_args {
                    s.args.clear();
                }
                Some(Ok(s))
            }
            other => {
                self.last_node = None;
                other
            }
        }
    }

    fn end_s(&self) -> f64 {
        match &self.src {
            Source::Log(ex) => ex.end_usec() as f64 / 1e6,
            Source::Sim { end_s, .. } => *end_s,
        }
    }
}

/// One run's figures.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SideReport {
    pub file: String,
    /// `btlog` or `sim`.
    pub kind: &'static str,
    /// The simulator's policy.
    pub policy: Option<String>,
    /// Actions executed.
    pub actions: u64,
    pub duration_s: f64,
    /// For a log, the node of the diverging action: `name (uid N)`.
    pub node: Option<String>,
}

/// What `log compare` reports.
#[derive(Debug, Clone, serde::Serialize)]
pub struct CompareReport {
    pub a: SideReport,
    pub b: SideReport,
    /// The same actions in the same order (and starts within the tolerance).
    pub same: bool,
    /// Start times compared within this many seconds (`None`: order only).
    pub tolerance_s: Option<f64>,
    pub ignore_args: bool,
    pub first_divergence: Option<Divergence>,
}

/// Compares two runs; both are read to their end (their figures).
pub fn compare(
    mut a: Side,
    mut b: Side,
    tolerance_s: Option<f64>,
    ignore_args: bool,
) -> Result<CompareReport, CompareError> {
    a.ignore_args = ignore_args;
    b.ignore_args = ignore_args;
    let d = first_divergence(&mut a, &mut b, tolerance_s.unwrap_or(f64::INFINITY))?;
    let (na, nb) = (a.last_node.take(), b.last_node.take());
    let rep = |s: &mut Side, node| -> Result<SideReport, CompareError> {
        while let Some(x) = s.next_skill() {
            x?;
        }
        Ok(SideReport {
            file: s.file.clone(),
            kind: s.kind(),
            policy: s.policy.clone(),
            actions: s.yielded,
            duration_s: (s.end_s() * 1e6).round() / 1e6,
            node,
        })
    };
    let (ra, rb) = (rep(&mut a, na)?, rep(&mut b, nb)?);
    Ok(CompareReport {
        a: ra,
        b: rb,
        same: d.is_none(),
        tolerance_s,
        ignore_args,
        first_divergence: d,
    })
}

fn side_line(s: &SideReport) -> String {
    use btfsm_core::sanitize::shown;
    let what = match (&s.policy, s.kind) {
        (Some(p), _) => format!("simulator run of `{}`", shown(p)),
        (None, "sim") => "simulator run".to_string(),
        _ => "BehaviorTree.CPP log".to_string(),
    };
    format!(
        "{} ({what}): {} actions executed in {:.3} s",
        shown(&s.file),
        s.actions,
        s.duration_s
    )
}

fn verdict_line(r: &CompareReport) -> String {
    use btfsm_core::sanitize::shown;
    match &r.first_divergence {
        None => format!(
            "same: {} actions in the same order with the same outcomes{}",
            r.a.actions,
            match r.tolerance_s {
                Some(t) => format!(", starts within {t} s"),
                None => String::new(),
            }
        ),
        Some(d) => {
            let mut s = format!(
                "diverged {}",
                shown(&d.summary()).replace("skill ", "action ")
            );
            let nodes: Vec<String> = [("a", &r.a.node), ("b", &r.b.node)]
                .iter()
                .filter_map(|(k, n)| n.as_ref().map(|n| format!("{k}: node {}", shown(n))))
                .collect();
            if !nodes.is_empty() {
                s.push_str(&format!(" [{}]", nodes.join(", ")));
            }
            s
        }
    }
}

/// The report as text.
pub fn render_table(r: &CompareReport) -> String {
    format!(
        "a: {}\nb: {}\n{}\n",
        side_line(&r.a),
        side_line(&r.b),
        verdict_line(r)
    )
}

/// The report as markdown.
pub fn render_markdown(r: &CompareReport) -> String {
    use btfsm_core::sanitize::markdown_cell as md;
    let mut out =
        String::from("| run | file | kind | actions | duration (s) |\n|---|---|---|---:|---:|\n");
    for (k, s) in [("a", &r.a), ("b", &r.b)] {
        let kind = match &s.policy {
            Some(p) => format!("simulator, {}", md(p)),
            None => s.kind.to_string(),
        };
        out.push_str(&format!(
            "| {k} | {} | {kind} | {} | {:.3} |\n",
            md(&s.file),
            s.actions,
            s.duration_s
        ));
    }
    out.push('\n');
    match &r.first_divergence {
        None => out.push_str(&format!("**Same**: {}\n", md(&verdict_line(r)))),
        Some(d) => {
            out.push_str(&format!(
                "**Diverged** at {} s, action {} ({}):\n\n| run | action | node |\n|---|---|---|\n",
                d.t,
                d.index + 1,
                d.kind
            ));
            for (k, x, n) in [("a", &d.a, &r.a.node), ("b", &d.b, &r.b.node)] {
                out.push_str(&format!(
                    "| {k} | {} | {} |\n",
                    md(x.as_deref().unwrap_or("(none)")),
                    md(n.as_deref().unwrap_or(""))
                ));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    /// An older-layout log whose XML length's low byte is `{` is a log.
    #[test]
    fn a_legacy_log_opening_with_a_brace_is_not_json() {
        let xml = format!(
            r#"<root><BehaviorTree ID="M" _fullpath=""><Go _uid="1"/></BehaviorTree></root>{}"#,
            " ".repeat(0x7b - 76)
        );
        assert_eq!(xml.len(), 0x7b);
        let mut b = (xml.len() as i32).to_le_bytes().to_vec();
        b.extend(xml.as_bytes());
        b.extend(0i64.to_le_bytes());
        b.extend((5u64 | (1u64 << 45) | (2u64 << 61)).to_le_bytes());
        let a = super::open("old", std::io::Cursor::new(b.clone()), None, 1 << 20).unwrap();
        let c = super::open("old", std::io::Cursor::new(b), None, 1 << 20).unwrap();
        let r = super::compare(a, c, None, false).unwrap();
        assert_eq!((r.a.kind, r.a.actions, r.same), ("btlog", 1, true));
    }
}
