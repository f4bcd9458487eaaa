//! Reports: what `analyze` prints per policy, in table, JSON (the stable contract
//! of SPEC §7) or CSV form, and the safe writing of output files (`output`).

pub mod compare;
pub mod effort;
pub mod gate;
pub mod output;
pub mod paper;
use btfsm_core::table;

use btfsm_format::Loaded;
use btfsm_metrics::complexity::{cyclomatic, essential};
use btfsm_metrics::counts::{TableOne, counts, fully_connected_states, table_one};
use btfsm_model::graph::policy_graph;
use btfsm_model::{PolicyBody, PolicyKind};
use std::collections::BTreeMap;

pub use btfsm_core::output::{Format, Report};
pub use output::write_atomically;

/// `btfsm analyze`'s report: one row per policy.
pub struct Analysis<'a>(pub &'a [PolicyReport]);

impl Report for Analysis<'_> {
    const FORMATS: &'static [Format] = &[Format::Table, Format::Json, Format::Csv];

    fn write(&self, format: Format) -> String {
        render_analysis(self.0, format)
    }
}

/// One row of `btfsm analyze` (SPEC §7's JSON contract).
#[derive(Debug, Clone, serde::Serialize)]
pub struct PolicyReport {
    pub file: String,
    pub name: String,
    pub kind: PolicyKind,
    pub vertices: usize,
    pub edges: usize,
    pub graphical_elements: usize,
    pub active_elements: usize,
    pub cc: i64,
    pub essential_cc: i64,
    pub counts: BTreeMap<&'static str, usize>,
    pub table1: TableOne,
}

/// Computes every metric of one loaded policy.
pub fn analyze(loaded: &Loaded) -> PolicyReport {
    let p = &loaded.policy;
    let g = policy_graph(p);
    let kind = p.kind();
    let c = counts(kind, &g);
    let m_fc = match &p.body {
        PolicyBody::Machine(m) => fully_connected_states(m).len(),
        PolicyBody::Bt(_) => 0,
    };
    PolicyReport {
        file: loaded.path.clone(),
        name: p.name.clone(),
        kind,
        vertices: c.vertices,
        edges: c.edges,
        graphical_elements: c.graphical_elements,
        active_elements: c.active_elements,
        cc: cyclomatic(&g),
        essential_cc: essential(p),
        counts: c.by_type,
        table1: table_one(kind, &g, m_fc),
    }
}

/// Renders `analyze` results.
pub fn render_analysis(reports: &[PolicyReport], format: Format) -> String {
    match Analysis::supported(format) {
        Format::Json => {
            #[derive(serde::Serialize)]
            struct Out<'a> {
                policies: &'a [PolicyReport],
            }
            let mut s = btfsm_core::sanitize::json(
                serde_json::to_string_pretty(&Out { policies: reports }).expect("serializable"),
            );
            s.push('\n');
            s
        }
        Format::Csv => {
            let mut s = String::from(
                "file,name,kind,vertices,edges,graphical_elements,active_elements,cc,essential_cc,m,m_fc,graphical_estimate,active_estimate\n",
            );
            for r in reports {
                s.push_str(&format!(
                    "{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
                    csv_field(&r.file),
                    csv_field(&r.name),
                    r.kind,
                    r.vertices,
                    r.edges,
                    r.graphical_elements,
                    r.active_elements,
                    r.cc,
                    r.essential_cc,
                    r.table1.m,
                    r.table1.m_fc,
                    r.table1.graphical_estimate,
                    r.table1.active_estimate
                ));
            }
            s
        }
        _ => {
            let mut t = table::Table::new(&[
                "file",
                "kind",
                "V",
                "E",
                "graphical",
                "active",
                "cc",
                "ess.cc",
                "M",
                "M_fc",
                "T.I graph.",
                "T.I active",
            ]);
            for r in reports {
                t.row(vec![
                    r.file.clone(),
                    r.kind.to_string(),
                    r.vertices.to_string(),
                    r.edges.to_string(),
                    r.graphical_elements.to_string(),
                    r.active_elements.to_string(),
                    r.cc.to_string(),
                    r.essential_cc.to_string(),
                    r.table1.m.to_string(),
                    r.table1.m_fc.to_string(),
                    fmt_num(r.table1.graphical_estimate),
                    fmt_num(r.table1.active_estimate),
                ]);
            }
            t.render()
        }
    }
}

fn fmt_num(x: f64) -> String {
    if x.fract() == 0.0 {
        format!("{x:.0}")
    } else {
        format!("{x:.1}")
    }
}

/// A CSV field from input: quoted when needed (RFC 4180), control characters
/// escaped, formulas neutralised ([`btfsm_core::sanitize::csv_cell`]).
pub fn csv_field(s: &str) -> String {
    btfsm_core::sanitize::csv_cell(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stale_temporaries_of_dead_runs_are_removed() {
        let dir = std::env::temp_dir().join(format!("btfsm-stale-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // No process has pid 4294967295 (above Linux's pid_max).
        let dead = dir.join(".x.txt.btfsm-4294967295.tmp");
        let mine = dir.join(format!(".y.txt.btfsm-{}.tmp", std::process::id()));
        for f in [&dead, &mine] {
            std::fs::write(f, b"partial").unwrap();
        }
        write_atomically(&dir.join("x.txt"), b"whole").unwrap();
        if std::path::Path::new("/proc/self").exists() {
            assert!(!dead.exists());
        }
        assert!(mine.exists(), "another target's temporary is kept");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn csv_quoting() {
        assert_eq!(csv_field("a,b"), "\"a,b\"");
        assert_eq!(csv_field("say \"hi\""), "\"say \"\"hi\"\"\"");
        assert_eq!(csv_field("plain"), "plain");
    }

    #[test]
    fn atomic_write_replaces_whole_file() {
        let dir = std::env::temp_dir().join(format!("btfsm-aw-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("x.txt");
        write_atomically(&p, b"one").unwrap();
        write_atomically(&p, b"two").unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "two");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
