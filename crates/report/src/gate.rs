//! The complexity gate of `btfsm analyze` for CI (SPEC §1's users: "CI
//! pipelines that must fail when a policy's complexity regresses"): absolute
//! ceilings (`--max cc=30`) and growth over a baseline, a previous
//! `analyze --format json` (`--baseline OLD.json --max-increase cc=0`). The
//! metrics are those of the report (SPEC §3, the paper's sec. V): counts of
//! vertices, edges and elements, cyclomatic and essential complexity.

use super::PolicyReport;
use btfsm_core::diagnostic::{Diagnostic, SourceFile, suggest};
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
        let count = |n: usize| i64::try_from(n).unwrap_or(i64::MAX);
        match self {
            Metric::Vertices => count(r.vertices),
            Metric::Edges => count(r.edges),
            Metric::GraphicalElements => count(r.graphical_elements),
            Metric::ActiveElements => count(r.active_elements),
            Metric::Cc => r.cc,
            Metric::EssentialCc => r.essential_cc,
        }
    }

    fn from_key(key: &str) -> Option<Metric> {
        Metric::ALL.into_iter().find(|m| m.key() == key)
    }
}

/// The largest metric a baseline may hold: 2^53, the largest integer every
/// JSON reader keeps exactly (no policy within the input limits comes near).
/// Every metric counts something, so none is negative.
pub const MAX_BASELINE_METRIC: i64 = 1 << 53;

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
        check_ranges(&file, text)?;
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

/// Refuses, at its position, a metric of a policy that is not a whole
/// number from 0 to [`MAX_BASELINE_METRIC`] (a hostile `cc = i64::MIN` would
/// otherwise wrap the growth computed from it). `text` is valid JSON; other
/// shapes are left to [`Baseline::parse`]'s own messages.
fn check_ranges(file: &Arc<SourceFile>, text: &str) -> Result<(), Diagnostic> {
    use serde::de::DeserializeSeed;
    let mut de = serde_json::Deserializer::from_str(text);
    let Err(e) = Walk(Level::Top).deserialize(&mut de) else {
        return Ok(());
    };
    // serde_json appends the position to the message; it is shown apart.
    let full = e.to_string();
    let suffix = format!(" at line {} column {}", e.line(), e.column());
    let message = full.strip_suffix(&suffix).unwrap_or(&full).to_string();
    // The position is just past the number: the span is the number.
    let end = offset(file, e.line(), e.column()).min(text.len());
    let bytes = text.as_bytes();
    let mut start = end;
    while start > 0
        && matches!(
            bytes[start - 1],
            b'0'..=b'9' | b'-' | b'+' | b'.' | b'e' | b'E'
        )
    {
        start -= 1;
    }
    Err(Diagnostic::error(message)
        .at(file, start..end.max(start + 1).min(text.len()))
        .hint(format!(
            "a baseline is an `analyze --format json` output: its metrics are counts from 0 to {MAX_BASELINE_METRIC}"
        )))
}

/// Where [`Walk`] is in the baseline JSON.
#[derive(Debug, Clone, Copy)]
enum Level {
    Top,
    /// The `policies` list.
    List,
    /// One policy; its index (from 1).
    Policy(usize),
    /// A metric of a policy.
    Metric(Metric, usize),
    Other,
}

/// A serde visitor over the whole baseline that fails, at serde_json's
/// position, on the first metric out of range.
struct Walk(Level);

impl Walk {
    fn check<E: serde::de::Error>(self, n: i128, shown: &dyn fmt::Display) -> Result<(), E> {
        match self.0 {
            Level::Metric(m, i) if !(0..=MAX_BASELINE_METRIC as i128).contains(&n) => {
                Err(E::custom(format!(
                    "`{}` of baseline policy {i} is {shown}, out of range (0 to {MAX_BASELINE_METRIC})",
                    m.key()
                )))
            }
            _ => Ok(()),
        }
    }
}

impl<'de> serde::de::DeserializeSeed<'de> for Walk {
    type Value = ();

    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> serde::de::Visitor<'de> for Walk {
    type Value = ();

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a JSON value")
    }

    fn visit_bool<E>(self, _: bool) -> Result<(), E> {
        Ok(())
    }

    fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<(), E> {
        self.check(v.into(), &v)
    }

    fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<(), E> {
        self.check(v.into(), &v)
    }

    fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<(), E> {
        match self.0 {
            // Fractions, and integers too large for 64 bits.
            Level::Metric(..) => self.check(i128::MAX, &v),
            _ => Ok(()),
        }
    }

    fn visit_str<E>(self, _: &str) -> Result<(), E> {
        Ok(())
    }

    fn visit_unit<E>(self) -> Result<(), E> {
        Ok(())
    }

    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<(), A::Error> {
        let mut i = 0;
        loop {
            i += 1;
            let next = match self.0 {
                Level::List => Level::Policy(i),
                _ => Level::Other,
            };
            if seq.next_element_seed(Walk(next))?.is_none() {
                return Ok(());
            }
        }
    }

    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<(), A::Error> {
        while let Some(key) = map.next_key::<std::borrow::Cow<'de, str>>()? {
            let next = match (self.0, Metric::from_key(&key)) {
                (Level::Top, _) if key == "policies" => Level::List,
                (Level::Policy(i), Some(m)) => Level::Metric(m, i),
                _ => Level::Other,
            };
            map.next_value_seed(Walk(next))?;
        }
        Ok(())
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
                i128::from(self.value) - i128::from(b),
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
                // In i128: no limit or value given can wrap it.
                if i128::from(l.metric.of(r)) - i128::from(before) > i128::from(l.value) {
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
    use btfsm_model::PolicyKind;

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
            table1: btfsm_metrics::counts::TableOne {
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

    fn policy_json(cc: &str) -> String {
        format!(
            "{{\"policies\": [\n  {{\"file\": \"a.toml\", \"name\": \"A\", \"vertices\": 5, \"edges\": 4,\n   \"graphical_elements\": 9, \"active_elements\": 5,\n   \"cc\": {cc}, \"essential_cc\": 1}}]}}"
        )
    }

    #[test]
    fn baseline_numbers_out_of_range_are_positioned_errors() {
        for bad in [
            "-9223372036854775808",
            "9223372036854775807",
            "18446744073709551615",
            "9007199254740993",
            "1e300",
            "2.5",
            "-1",
        ] {
            let text = policy_json(bad);
            let e = Baseline::parse("b.json", &text).unwrap_err();
            assert!(e.message.contains("out of range"), "{bad}: {}", e.message);
            assert!(
                e.message.contains("`cc` of baseline policy 1"),
                "{}",
                e.message
            );
            let (_, line, col) = e.location().unwrap();
            assert_eq!(line, 4, "{bad}");
            let at = text.lines().nth(3).unwrap().find(bad).unwrap() + 1;
            assert_eq!(col, at, "{bad}: the caret is on the number");
        }
        // The largest count allowed, and the gate's arithmetic on extremes.
        let b = Baseline::parse("b.json", &policy_json("9007199254740992")).unwrap();
        let now = [report("a.toml", "A", i64::MAX, 5)];
        for (limit, violations) in [(i64::MIN, 1), (i64::MAX, 0), (0, 1)] {
            let gate = Gate {
                max: vec![Limit {
                    metric: Metric::Cc,
                    value: limit,
                }],
                baseline: Some(Baseline::parse("b.json", &policy_json("0")).unwrap()),
                max_increase: vec![Limit {
                    metric: Metric::Cc,
                    value: limit,
                }],
            };
            let r = gate.check(&now);
            let grew = r.violations.iter().filter(|v| v.before.is_some()).count();
            assert_eq!(grew, violations, "--max-increase cc={limit}");
            for v in &r.violations {
                assert!(!v.to_string().is_empty());
            }
        }
        let gate = Gate {
            baseline: Some(b),
            ..Gate::default()
        };
        assert!(
            gate.check(&[report("a.toml", "A", 0, 5)])
                .violations
                .is_empty()
        );
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
