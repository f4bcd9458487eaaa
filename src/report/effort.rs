//! What `btfsm effort` prints: Eq. 4/5 at the detected M_s and M_fc beside
//! the measured effort (named and structural GED to the generated
//! fault-tolerant FSM; paper sec. IV-B), as a table, JSON or CSV.

use super::{OutputFormat, csv_field, table::Table};
use crate::metrics::effort::Effort;

/// One policy's effort, for output.
#[derive(Debug, Clone, serde::Serialize)]
pub struct EffortRow {
    pub file: String,
    pub name: String,
    pub kind: crate::model::PolicyKind,
    pub m_s: usize,
    pub m_fc: usize,
    pub sequential: Vec<String>,
    pub connected: Vec<String>,
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

/// Renders `effort` results.
pub fn render_effort(rows: &[EffortRow], format: OutputFormat) -> String {
    match format {
        OutputFormat::Json => {
            #[derive(serde::Serialize)]
            struct Out<'a> {
                policies: &'a [EffortRow],
            }
            let mut s = crate::sanitize::json(
                serde_json::to_string_pretty(&Out { policies: rows }).expect("serializable"),
            );
            s.push('\n');
            s
        }
        OutputFormat::Csv => {
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
        OutputFormat::Table => {
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
                    s.push_str(&format!(
                        "{}: sequential [{}]; connected [{}]\n",
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
