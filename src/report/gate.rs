//! The complexity gate of `btfsm analyze` for CI (SPEC §1's users: "CI
//! pipelines that must fail when a policy's complexity regresses"): absolute
//! ceilings (`--max cc=30`) and growth over a baseline, a previous
//! `analyze --format json` (`--baseline OLD.json --max-increase cc=0`). The
//! metrics are those of the report (SPEC §3, the paper's sec. V): counts of
//! vertices, edges and elements, cyclomatic and essential complexity.

use super::PolicyReport;
use crate::diagnostic::{Diagnostic, SourceFile, suggest};
use std::collections::BTreeMap;
use std::fmt;
use std::str::FromStr;
use std::sync::Arc;

/// A gated metric: a top-level number of the `analyze` JSON.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Metric {
    Vertices,
    Edges,
    GraphicalElements,
    ActiveElements,
    Cc,
    EssentialCc,
}

impl Metric {
    pub const ALL: [Metric; 6] = [
        Metric::Vertices,
        Metric::Edges,
        Metric::GraphicalElements,
        Metric::ActiveElements,
        Metric::Cc,
        Metric::EssentialCc,
    ];

    /// Its key in the `analyze` JSON.
    pub fn key(self) -> &'static str {
        match self {
            Metric::Vertices => "vertices",
            Metric::Edges => "edges",
            Metric::GraphicalElements => "graphical_elements",
            Metric::ActiveElements => "active_elements",
            Metric::Cc => "cc",
            Metric::EssentialCc => "essential_cc",
        }
    }

    /// Its value in a report.
    pub fn of(self, r: &PolicyReport) -> i64 {
        match self {
            Metric::Vertices => r.vertices as i64,
            Metric::Edges => r.edges as i64,
            Metric::GraphicalElements => r.graphical_elements as i64,
            Metric::ActiveElements => r.active_elements as i64,
            Metric::Cc => r.cc,
            Metric::EssentialCc => r.essential_cc,
        }
    }
}

/// `METRIC=N`, as given to `--max` and `--max-increase`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limit {
    pub metric: Metric,
    pub value: i64,
}

impl FromStr for Limit {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let keys = || Metric::ALL.iter().map(|m| m.key());
        let Some((name, n)) = s.split_once('=') else {
            return Err(format!(
                "expected METRIC=N, such as `cc=30`; metrics: {}",
                keys().collect::<Vec<_>>().join(", ")
            ));
        };
        let name = name.trim();
        let Some(&metric) = Metric::ALL.iter().find(|m| m.key() == name) else {
            return Err(format!(
                "unknown metric `{name}`: {}",
                suggest(name, keys())
            ));
        };
        let value = n
            .trim()
            .parse::<i64>()
            .map_err(|_| format!("`{}` is not a whole number (in `{s}`)", n.trim()))?;
        Ok(Limit { metric, value })
    }
}

impl fmt::Display for Limit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}={}", self.metric.key(), self.value)
    }
}

/// A previous `analyze --format json`: each policy's metrics by file and by
/// name.
#[derive(Debug, Default)]
pub struct Baseline {
    pub path: String,
    by_file: BTreeMap<String, BTreeMap<Metric, i64>>,
    by_name: BTreeMap<String, Vec<BTreeMap<Metric, i64>>>,
}

impl Baseline {
    /// Reads a baseline from the text of an `analyze --format json` output.
    pub fn parse(path: &str, text: &str) -> Result<Baseline, Diagnostic> {
        let file = SourceFile::new(path, text);
        let hint =
            "write one with `btfsm analyze FILE... --format json > OLD.json` on the base revision";
        let v: serde_json::Value = serde_json::from_str(text).map_err(|e| {
            let at = offset(&file, e.line(), e.column());
            Diagnostic::error(format!("invalid JSON in the baseline: {e}"))
                .at(&file, at..at + 1)
                .hint(hint)
        })?;
        let not_analysis = |what: &str| {
            Diagnostic::error(format!(
                "the baseline is not an `analyze --format json` output: {what}"
            ))
            .in_file(&file)
            .hint(hint)
        };
        let Some(list) = v.get("policies").and_then(|p| p.as_array()) else {
            return Err(not_analysis("no `policies` list"));
        };
        let mut b = Baseline {
            path: path.to_string(),
            ..Default::default()
        };
        for (i, p) in list.iter().enumerate() {
            let mut m = BTreeMap::new();
            for metric in Metric::ALL {
                let Some(x) = p.get(metric.key()).and_then(|x| x.as_i64()) else {
                    return Err(not_analysis(&format!(
                        "policy {} has no whole number `{}`",
                        i + 1,
                        metric.key()
                    )));
                };
                m.insert(metric, x);
            }
            if let Some(f) = p.get("file").and_then(|f| f.as_str()) {
                b.by_file.insert(f.to_string(), m.clone());
            }
            if let Some(n) = p.get("name").and_then(|n| n.as_str()) {
                b.by_name.entry(n.to_string()).or_default().push(m);
            }
        }
        Ok(b)
    }

    /// The baseline metrics of a policy: by file, else by a name unique in
    /// the baseline (a renamed or moved file).
    fn find(&self, r: &PolicyReport) -> Option<&BTreeMap<Metric, i64>> {
        self.by_file
            .get(&r.file)
            .or_else(|| match self.by_name.get(&r.name) {
                Some(v) if v.len() == 1 => v.first(),
                _ => None,
            })
    }
}

/// Byte offset of serde_json's 1-based line and column.
fn offset(file: &Arc<SourceFile>, line: usize, col: usize) -> usize {
    let start: usize = file
        .text
        .split_inclusive('\n')
        .take(line.saturating_sub(1))
        .map(str::len)
        .sum();
    (start + col.saturating_sub(1)).min(file.text.len())
}

/// What the gate checks.
#[derive(Debug, Default)]
pub struct Gate {
    pub max: Vec<Limit>,
    pub baseline: Option<Baseline>,
    /// Allowed growth over the baseline; empty means `cc=0` and
    /// `essential_cc=0`.
    pub max_increase: Vec<Limit>,
}

/// One metric of one policy over its limit.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Violation {
    pub file: String,
    pub name: String,
    pub metric: Metric,
    pub value: i64,
    /// `None` for a ceiling; the baseline value for a growth limit.
    pub before: Option<i64>,
    pub limit: i64,
}

impl fmt::Display for Violation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (file, name, m) = (&self.file, &self.name, self.metric.key());
        match self.before {
            None => write!(
                f,
                "`{name}` ({file}): {m} is {}, above the limit {} (--max {m}={})",
                self.value, self.limit, self.limit
            ),
            Some(b) => write!(
                f,
                "`{name}` ({file}): {m} grew from {b} to {} (+{}), more than the allowed +{} (--max-increase {m}={})",
                self.value,
                self.value - b,
                self.limit,
                self.limit
            ),
        }
    }
}

/// The outcome of the gate over a set of reports.
#[derive(Debug, Default)]
pub struct GateReport {
    pub violations: Vec<Violation>,
    /// Policies the baseline does not have (not checked for growth).
    pub new_policies: Vec<String>,
}

impl Gate {
    pub fn is_empty(&self) -> bool {
        self.max.is_empty() && self.baseline.is_none()
    }

    /// The growth limits in force.
    pub fn increase_limits(&self) -> Vec<Limit> {
        if self.max_increase.is_empty() {
            vec![
                Limit {
                    metric: Metric::Cc,
                    value: 0,
                },
                Limit {
                    metric: Metric::EssentialCc,
                    value: 0,
                },
            ]
        } else {
            self.max_increase.clone()
        }
    }

    /// Checks every report, in report order, limits in the order given.
    pub fn check(&self, reports: &[PolicyReport]) -> GateReport {
        let mut out = GateReport::default();
        let grow = self.increase_limits();
        for r in reports {
            let violation = |l: &Limit, before: Option<i64>| Violation {
                file: r.file.clone(),
                name: r.name.clone(),
                metric: l.metric,
                value: l.metric.of(r),
                before,
                limit: l.value,
            };
            for l in &self.max {
                if l.metric.of(r) > l.value {
                    out.violations.push(violation(l, None));
                }
            }
            let Some(b) = &self.baseline else { continue };
            let Some(old) = b.find(r) else {
                out.new_policies.push(r.file.clone());
                continue;
            };
            for l in &grow {
                let before = old[&l.metric];
                if l.metric.of(r) - before > l.value {
                    out.violations.push(violation(l, Some(before)));
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::PolicyKind;

    fn report(file: &str, name: &str, cc: i64, vertices: usize) -> PolicyReport {
        PolicyReport {
            file: file.into(),
            name: name.into(),
            kind: PolicyKind::Fsm,
            vertices,
            edges: 0,
            graphical_elements: 0,
            active_elements: 0,
            cc,
            essential_cc: 1,
            counts: BTreeMap::new(),
            table1: crate::metrics::counts::TableOne {
                m: 0,
                m_fc: 0,
                t_fc: 0,
                graphical_estimate: 0.0,
                active_estimate: 0.0,
            },
        }
    }

    #[test]
    fn limits_parse_with_helpful_errors() {
        assert_eq!(
            "cc=30".parse::<Limit>(),
            Ok(Limit {
                metric: Metric::Cc,
                value: 30
            })
        );
        let e = "cx=3".parse::<Limit>().unwrap_err();
        assert!(
            e.contains("unknown metric `cx`") && e.contains("`cc`"),
            "{e}"
        );
        assert!("cc".parse::<Limit>().unwrap_err().contains("METRIC=N"));
        assert!("cc=many".parse::<Limit>().unwrap_err().contains("`many`"));
    }

    #[test]
    fn ceilings_and_growth_over_the_baseline() {
        let base = r#"{"policies": [
          {"file": "a.toml", "name": "A", "vertices": 5, "edges": 4, "graphical_elements": 9,
           "active_elements": 5, "cc": 10, "essential_cc": 1},
          {"file": "old-b.toml", "name": "B", "vertices": 5, "edges": 4, "graphical_elements": 9,
           "active_elements": 5, "cc": 10, "essential_cc": 1}]}"#;
        let gate = Gate {
            max: vec!["vertices=6".parse().unwrap()],
            baseline: Some(Baseline::parse("base.json", base).unwrap()),
            max_increase: vec![],
        };
        let now = [
            report("a.toml", "A", 12, 7),
            report("b.toml", "B", 10, 5),
            report("c.toml", "C", 99, 1),
        ];
        let g = gate.check(&now);
        let msgs: Vec<String> = g.violations.iter().map(|v| v.to_string()).collect();
        assert_eq!(
            msgs,
            vec![
                "`A` (a.toml): vertices is 7, above the limit 6 (--max vertices=6)",
                "`A` (a.toml): cc grew from 10 to 12 (+2), more than the allowed +0 (--max-increase cc=0)",
            ]
        );
        // B is found by its name after a move; C is new.
        assert_eq!(g.new_policies, vec!["c.toml"]);
        let lenient = Gate {
            max_increase: vec!["cc=2".parse().unwrap()],
            ..gate
        };
        assert_eq!(lenient.check(&now).violations.len(), 1);
    }

    #[test]
    fn a_bad_baseline_is_positioned() {
        let e = Baseline::parse("b.json", "{\"policies\": [\n  {\"cc\": }\n]}").unwrap_err();
        let (_, line, _) = e.location().unwrap();
        assert_eq!(line, 2);
        let e = Baseline::parse("b.json", "{\"rows\": []}").unwrap_err();
        assert!(e.message.contains("no `policies` list"), "{}", e.message);
    }
}
