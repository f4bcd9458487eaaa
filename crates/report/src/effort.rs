//! What `btfsm effort` prints: Eq. 4/5 at the detected M_s and M_fc beside
//! the measured effort (named and structural GED to the generated
//! fault-tolerant FSM; paper sec. IV-B), as a table, JSON or CSV.

use super::{Format, Report, csv_field, table::Table};
use btfsm_metrics::effort::{detect, effort_formula};
use btfsm_metrics::ged::{GedMode, GedOptions, GedResult, ged};
use btfsm_model::graph::policy_graph;
use btfsm_model::{Policy, PolicyBody, PolicyKind};
use btfsm_transform::fault_tolerant::{FaultTolerantError, fault_tolerant_policy};

/// The effort of one policy.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Effort {
    pub kind: PolicyKind,
    /// Sequential action states (M_s), by name.
    pub sequential: Vec<String>,
    /// Fully connected states (M_fc), by name.
    pub connected: Vec<String>,
    /// Side states (recoveries some states enter on a guard, off the
    /// task's chain), by name: neither M_s nor M_fc, which Eq. 4 assumes
    /// are all there is; the generated FSM treats them as connected ones.
    pub side: Vec<String>,
    pub m_s: usize,
    pub m_fc: usize,
    /// Eq. 4 at (M_s, M_fc); 0 for BTs and HFSMs.
    pub formula: u64,
    /// Named GED between the policy and its generated fault-tolerant FSM.
    pub named: Option<GedResult>,
    /// Structural GED between the same two graphs.
    pub structural: Option<GedResult>,
    /// Why the measured value is absent or means something else.
    pub note: Option<String>,
}

/// The effort of a policy, with its generated fault-tolerant FSM (FSMs only).
pub fn effort(p: &Policy, opts: &GedOptions) -> (Effort, Option<Policy>) {
    let kind = p.kind();
    let m = match &p.body {
        PolicyBody::Machine(m) if !m.hierarchical => m,
        _ => {
            let why = match kind {
                PolicyKind::Bt => {
                    "a BT is reactive by construction (ticked from the root every step): effort 0"
                }
                _ => "an HFSM built like a BT is reactive by construction: effort 0",
            };
            return (
                Effort {
                    kind,
                    sequential: Vec::new(),
                    connected: Vec::new(),
                    side: Vec::new(),
                    m_s: 0,
                    m_fc: 0,
                    formula: 0,
                    named: None,
                    structural: None,
                    note: Some(why.to_string()),
                },
                None,
            );
        }
    };
    let d = detect(m);
    let names = |v: &[usize]| v.iter().map(|&i| m.states[i].name.clone()).collect();
    let mut e = Effort {
        kind,
        sequential: names(&d.sequential),
        connected: names(&d.connected),
        side: names(&d.side),
        m_s: d.sequential.len(),
        m_fc: d.connected.len(),
        formula: effort_formula(d.sequential.len() as u64, d.connected.len() as u64),
        named: None,
        structural: None,
        note: None,
    };
    if let Some(s) = d.selector {
        e.note = Some(format!(
            "already has a decision state (`{}`): Eq. 4 counts the edits from a sequential design; the measured value counts only what is missing",
            m.states[s].name
        ));
    } else if !d.side.is_empty() {
        e.note = Some(format!(
            "side states [{}] (entered on a guard by some states, off the task's chain) are neither sequential nor fully connected: Eq. 4 does not count them, the measured value does",
            e.side.join(", ")
        ));
    }
    match fault_tolerant_policy(p) {
        Ok(ft) => {
            let (ga, gb) = (policy_graph(p), policy_graph(&ft));
            e.named = Some(ged(&ga, &gb, GedMode::Named, opts));
            e.structural = Some(ged(&ga, &gb, GedMode::Structural, opts));
            (e, Some(ft))
        }
        Err(errs) => {
            let msg: Vec<String> = errs.iter().map(FaultTolerantError::to_string).collect();
            e.note = Some(format!(
                "no fault-tolerant FSM generated: {}",
                msg.join("; ")
            ));
            (e, None)
        }
    }
}

/// One policy's effort, for output.
#[derive(Debug, Clone, serde::Serialize)]
pub struct EffortRow {
    pub file: String,
    pub name: String,
    pub kind: btfsm_model::PolicyKind,
    pub m_s: usize,
    pub m_fc: usize,
    pub sequential: Vec<String>,
    pub connected: Vec<String>,
    /// Side states (see [`Effort::side`]); left out when there are none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub side: Vec<String>,
    /// Eq. 4 at (M_s, M_fc).
    pub formula: u64,
    /// Named GED to the generated fault-tolerant FSM (`null` if none).
    pub named_ged: Option<u64>,
    pub structural_ged: Option<u64>,
    pub structural_exact: Option<bool>,
    pub note: Option<String>,
}

impl EffortRow {
    pub fn new(file: &str, name: &str, e: &Effort) -> EffortRow {
        EffortRow {
            file: file.to_string(),
            name: name.to_string(),
            kind: e.kind,
            m_s: e.m_s,
            m_fc: e.m_fc,
            sequential: e.sequential.clone(),
            connected: e.connected.clone(),
            side: e.side.clone(),
            formula: e.formula,
            named_ged: e.named.as_ref().map(|g| g.ged),
            structural_ged: e.structural.as_ref().map(|g| g.ged),
            structural_exact: e.structural.as_ref().map(|g| g.exact),
            note: e.note.clone(),
        }
    }
}

fn opt(v: Option<u64>) -> String {
    v.map_or_else(|| "-".to_string(), |x| x.to_string())
}

fn structural(r: &EffortRow) -> String {
    match (r.structural_ged, r.structural_exact) {
        (Some(g), Some(false)) => format!("<= {g}"),
        (g, _) => opt(g),
    }
}

/// `btfsm effort`'s report: one row per policy.
pub struct EffortTable<'a>(pub &'a [EffortRow]);

impl Report for EffortTable<'_> {
    const FORMATS: &'static [Format] = &[Format::Table, Format::Json, Format::Csv];

    fn write(&self, format: Format) -> String {
        render_effort(self.0, format)
    }
}

/// Renders `effort` results.
pub fn render_effort(rows: &[EffortRow], format: Format) -> String {
    match EffortTable::supported(format) {
        Format::Json => {
            #[derive(serde::Serialize)]
            struct Out<'a> {
                policies: &'a [EffortRow],
            }
            let mut s = btfsm_core::sanitize::json(
                serde_json::to_string_pretty(&Out { policies: rows }).expect("serializable"),
            );
            s.push('\n');
            s
        }
        Format::Csv => {
            let mut s =
                String::from("file,name,kind,m_s,m_fc,formula,named_ged,structural_ged,note\n");
            for r in rows {
                s.push_str(&format!(
                    "{},{},{},{},{},{},{},{},{}\n",
                    csv_field(&r.file),
                    csv_field(&r.name),
                    r.kind,
                    r.m_s,
                    r.m_fc,
                    r.formula,
                    r.named_ged.map_or(String::new(), |g| g.to_string()),
                    r.structural_ged.map_or(String::new(), |g| g.to_string()),
                    csv_field(r.note.as_deref().unwrap_or(""))
                ));
            }
            s
        }
        _ => {
            let mut t = Table::new(&[
                "file",
                "kind",
                "M_s",
                "M_fc",
                "Eq. 4",
                "named GED",
                "structural GED",
            ]);
            for r in rows {
                t.row(vec![
                    r.file.clone(),
                    r.kind.to_string(),
                    r.m_s.to_string(),
                    r.m_fc.to_string(),
                    r.formula.to_string(),
                    opt(r.named_ged),
                    structural(r),
                ]);
            }
            let mut s = t.render();
            s.push_str(
                "\nEq. 4: E = 3(M_s + 1) + M_fc[(M_s + M_fc - 1) + 3]; GED between the policy and its generated fault-tolerant FSM (`btfsm convert --to fault-tolerant`)\n",
            );
            for r in rows {
                if !r.sequential.is_empty() || !r.connected.is_empty() {
                    let side = if r.side.is_empty() {
                        String::new()
                    } else {
                        format!("; side [{}]", r.side.join(", "))
                    };
                    s.push_str(&format!(
                        "{}: sequential [{}]; connected [{}]{side}\n",
                        r.file,
                        r.sequential.join(", "),
                        r.connected.join(", ")
                    ));
                }
                if let Some(n) = &r.note {
                    s.push_str(&format!("{}: {n}\n", r.file));
                }
            }
            s
        }
    }
}
#[cfg(test)]
mod tests {
    use super::*;

    fn paper(name: &str) -> Policy {
        let p = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../policies/paper"))
            .join(format!("{name}.toml"));
        btfsm_format::load(&p, &btfsm_format::Limits::default())
            .unwrap()
            .policy
    }

    #[test]
    fn formula_and_named_ged_agree_on_the_papers_examples() {
        for (f, m_s, m_fc) in [("fig02-fsm", 4, 0), ("fig10-fsm", 4, 1)] {
            let (e, ft) = effort(&paper(f), &GedOptions::default());
            assert!(ft.is_some());
            assert_eq!((e.m_s, e.m_fc), (m_s, m_fc), "{f}");
            assert_eq!(e.named.as_ref().map(|g| g.ged), Some(e.formula), "{f}");
            assert!(e.structural.as_ref().is_some_and(|g| g.exact));
        }
    }

    #[test]
    fn bts_and_hfsms_need_no_effort() {
        let (e, ft) = effort(&paper("fig01-bt"), &GedOptions::default());
        assert_eq!(e.formula, 0);
        assert!(ft.is_none() && e.note.is_some());
        let (e, _) = effort(&paper("fig06-hfsm"), &GedOptions::default());
        assert_eq!((e.kind, e.formula), (PolicyKind::Hfsm, 0));
    }
}
