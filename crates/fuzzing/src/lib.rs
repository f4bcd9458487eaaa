//! The no-panic harness (issue 7; SPEC §1 "bad input never panics"): drives
//! arbitrary bytes through every stage of the pipeline — parse and validate,
//! graph, metrics, analyze report, DOT, TOML write-back, the paper's
//! transforms, effort and GED — and checks the laws that must hold on any
//! input (a written policy reads back to itself; a GED result is a certified
//! interval whose edit script costs its upper bound).
//!
//! Targets: `toml_policy`, `btcpp_xml`, `scxml` (bytes → `Loaded` →
//! [`exercise`]), `scenario` (bytes → scenario → a short simulation) and
//! `compare` (two policies → every GED mode). It is the body of the
//! coverage-guided fuzz targets in `fuzz/` (one line each) and of the no-panic property tests of the normal suite, so that what
//! fuzzing finds is guarded by `cargo test`. A new input format gets one
//! function here (bytes → `Loaded` → [`exercise`]) and a fuzz target calling
//! it; see docs/robustness.md.

use btfsm_core::diagnostic::Diagnostic;
use btfsm_format::{Limits, Loaded};
use btfsm_metrics::ged::{GedMode, GedOptions, GedResult};
use btfsm_model::Policy;
use btfsm_report::compare::{self, Pair, Side};
use std::path::Path;
use std::time::Duration;

/// Small limits, so that every input runs in milliseconds.
pub fn limits() -> Limits {
    Limits {
        max_file_bytes: 1 << 20,
        max_nodes: 2_000,
        max_include_depth: 8,
        max_depth: 200,
        max_name_bytes: 4096,
        ..Limits::default()
    }
}

/// A tiny GED budget: the certificate must hold however early the search stops.
pub fn ged_options() -> GedOptions {
    GedOptions {
        timeout: Duration::from_millis(20),
        work: 200_000,
    }
}

/// Where subtree includes of fuzzed policies resolve: the paper's policies,
/// so that `subtree = "lib/dock.toml"` finds a file.
fn include_base() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../policies/paper"))
}

/// Parses bytes as a TOML policy; `None` when the bytes are not a policy (the
/// diagnostics are checked and rendered).
pub fn parse_toml(data: &[u8]) -> Option<Loaded> {
    let text = std::str::from_utf8(data).ok()?;
    let limits = limits();
    match btfsm_format::toml::parse_str("fuzz.toml", text, include_base(), &limits) {
        Ok(l) => Some(l),
        Err(diags) => {
            check_diagnostics(&diags);
            None
        }
    }
}

/// Fuzz target `toml_policy`: any bytes through the TOML reader and, when
/// they are a policy, through everything downstream.
pub fn toml_policy(data: &[u8]) {
    if let Some(l) = parse_toml(data) {
        exercise(&l);
    }
}

/// Fuzz target `btcpp_xml`: any bytes through the BehaviorTree.CPP XML
/// importer (includes resolve against `tests/fixtures/`) and downstream.
pub fn btcpp_xml(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let base = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/fixtures"));
    accepted(btfsm_format::btcpp_xml::parse_str(
        "fuzz.xml",
        text,
        base,
        &limits(),
    ));
}

/// Fuzz target `scxml`: any bytes through the SCXML importer and downstream.
pub fn scxml(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    accepted(btfsm_format::scxml::parse_str(
        "fuzz.scxml",
        text,
        &limits(),
    ));
}

/// Fuzz target `yasmin`: any bytes through the yasmin importer and
/// downstream (a `file_path` resolves against the current directory).
pub fn yasmin(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    accepted(btfsm_format::yasmin::parse_str("fuzz.xml", text, &limits()));
}

/// Fuzz target `flexbe`: any bytes through the FlexBE behavior reader
/// (Python parsed, never run) and downstream.
pub fn flexbe(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    accepted(btfsm_format::flexbe::parse_str(
        "fuzz_sm.py",
        text,
        &limits(),
    ));
}

/// Fuzz target `py_trees_dot`: any bytes through the py_trees DOT render
/// reader and downstream.
pub fn py_trees_dot(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    accepted(btfsm_format::py_trees_dot::parse_str(
        "fuzz.dot",
        text,
        &limits(),
    ));
}

/// Fuzz target `scenario`: any bytes as a simulator scenario (policies
/// resolve against `policies/scenarios/`); an accepted one is run for at most
/// 2000 steps per policy.
pub fn scenario(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let base = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../policies/scenarios"
    ));
    let file = btfsm_core::diagnostic::SourceFile::new("fuzz-scenario.toml", text);
    match btfsm_sim::scenario::parse(&file, base, &limits()) {
        Ok(mut s) => {
            s.max_steps = s.max_steps.min(2000);
            let _ = btfsm_sim::run::run_scenario(&s, true);
        }
        Err(diags) => check_diagnostics(&diags),
    }
}

/// Fuzz target `domain`: any bytes as an action domain; an accepted one is
/// planned (at most 2000 nodes) into a BT, its FSM and HFSM, each through
/// [`exercise`], and with `--no-reorder` too. A planning error is a
/// clear refusal (the tree would be too large), never a panic.
pub fn domain(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let file = btfsm_core::diagnostic::SourceFile::new("fuzz-domain.toml", text);
    let d = match btfsm_plan::load(&file) {
        Ok(d) => d,
        Err(diags) => return check_diagnostics(&diags),
    };
    for reorder in [true, false] {
        let opts = btfsm_plan::Options {
            reorder,
            max_nodes: 2000,
            ..Default::default()
        };
        let Ok(p) = btfsm_plan::plan_bt(&d, &opts) else {
            continue;
        };
        let mut policies = vec![btfsm_model::Policy {
            name: "planned".into(),
            description: None,
            body: btfsm_model::PolicyBody::Bt(p.bt.clone()),
        }];
        if let Ok(m) = btfsm_plan::fsm::plan_fsm(&d, &p) {
            policies.push(btfsm_model::Policy {
                name: "planned fsm".into(),
                description: None,
                body: btfsm_model::PolicyBody::Machine(m),
            });
        }
        for policy in policies {
            if btfsm_format::check_shape(&policy, &limits()).is_some() {
                continue;
            }
            exercise(&Loaded {
                path: "planned".into(),
                policy,
                warnings: Vec::new(),
                dataflow: None,
            });
        }
    }
}

/// Fuzz target `project`: several files that name each other (TOML
/// subtrees with `with` parameters, BehaviorTree.CPP includes, a scenario
/// and its policies). The bytes split at `\n%%\n` into at most six files,
/// written to a scratch folder of this process: the first as `top.toml`
/// (`top.xml` when it starts with `<`), the others as `f1.toml`, ...
/// (`fN.xml` likewise) and the last also as `sub/f.toml`, so that paths
/// with `..`, into `sub/` and out of the folder are all reachable. The
/// first file is read as `btfsm` would (a scenario when it looks like one)
/// under the confinement rule; an accepted policy goes through
/// [`exercise`], a scenario runs 2000 steps.
pub fn project(data: &[u8]) {
    let dir = std::env::temp_dir().join(format!("btfsm-fuzz-project-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    if std::fs::create_dir_all(dir.join("sub")).is_err() {
        return;
    }
    let mut parts: Vec<&[u8]> = Vec::new();
    let mut rest = data;
    loop {
        let (a, b) = split_pair(rest);
        parts.push(a);
        if b.is_empty() || parts.len() == 6 {
            break;
        }
        rest = b;
    }
    let ext = |p: &[u8]| {
        if p.trim_ascii_start().starts_with(b"<") {
            "xml"
        } else {
            "toml"
        }
    };
    let mut top = None;
    for (i, p) in parts.iter().enumerate() {
        let name = if i == 0 {
            format!("top.{}", ext(p))
        } else {
            format!("f{i}.{}", ext(p))
        };
        let path = dir.join(&name);
        if std::fs::write(&path, p).is_err() {
            return;
        }
        if i == 0 {
            top = Some(path);
        }
    }
    if let Some(last) = parts.last() {
        let _ = std::fs::write(dir.join("sub/f.toml"), last);
    }
    let Some(top) = top else { return };
    let limits = limits();
    match btfsm_format::read_input(&top, &limits) {
        Ok((file, btfsm_format::Input::Scenario)) => {
            match btfsm_sim::scenario::parse(&file, &dir, &limits) {
                Ok(mut s) => {
                    s.max_steps = s.max_steps.min(2000);
                    let _ = btfsm_sim::run::run_scenario(&s, true);
                }
                Err(diags) => check_diagnostics(&diags),
            }
        }
        Ok((file, btfsm_format::Input::Policy(f))) => {
            accepted(btfsm_format::load_read(file, &top, f, &limits));
        }
        Ok((file, btfsm_format::Input::Domain)) => domain(file.text.as_bytes()),
        Err(diags) => check_diagnostics(&diags),
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// An importer's result: checked diagnostics, or [`exercise`] when the
/// policy is within the shape limits `format::load` enforces for every
/// format.
fn accepted(r: Result<Loaded, Vec<Diagnostic>>) {
    match r {
        Ok(l) if btfsm_format::check_shape(&l.policy, &limits()).is_none() => exercise(&l),
        Ok(_) => {}
        Err(diags) => check_diagnostics(&diags),
    }
}

/// Splits one input into two at the first `\n%%\n`.
pub fn split_pair(data: &[u8]) -> (&[u8], &[u8]) {
    const SEP: &[u8] = b"\n%%\n";
    match data.windows(SEP.len()).position(|w| w == SEP) {
        Some(i) => (&data[..i], &data[i + SEP.len()..]),
        None => (data, &[]),
    }
}

/// Fuzz target `compare`: two policies split from one input (`A\n%%\nB`),
/// compared in every mode with a tiny budget.
pub fn compare(data: &[u8]) {
    let (a, b) = split_pair(data);
    let (Some(la), Some(lb)) = (parse_toml(a), parse_toml(b)) else {
        return;
    };
    compare_policies(&la.policy, &lb.policy, &ged_options());
}

/// Every GED mode between two policies, with the report, the table, the JSON
/// and the diff drawing; checks each certificate.
pub fn compare_policies(a: &Policy, b: &Policy, opts: &GedOptions) {
    let pair = Pair::new(
        Side {
            file: "a.toml",
            policy: a,
        },
        Side {
            file: "b.toml",
            policy: b,
        },
    );
    let mut reports = Vec::new();
    for mode in compare::modes_of(None) {
        let raw = btfsm_metrics::ged::ged(&pair_graph(a), &pair_graph(b), mode, opts);
        check_ged(&raw, mode);
        let r = pair.run(mode, opts);
        assert!(r.lower_bound <= r.upper_bound, "{mode:?}: lower > upper");
        assert_eq!(r.ged, r.upper_bound, "{mode:?}: ged is not the upper bound");
        assert_eq!(
            r.edit_script.cost(),
            r.upper_bound,
            "{mode:?}: the labelled script does not cost the upper bound"
        );
        // Relabels and reorders: counted as listed, each reorder a
        // permutation of the same kept children (or guards).
        let s = &r.edit_script;
        assert_eq!(r.reorders, s.reordered.len() as u64);
        assert!(r.relabels >= s.relabelled.len() as u64);
        for o in &s.reordered {
            let (mut x, mut y) = (o.before.clone(), o.after.clone());
            assert_ne!(x, y, "{mode:?}: a reorder that keeps the order");
            x.sort();
            y.sort();
            assert_eq!(x, y, "{mode:?}: a reorder that is no permutation");
        }
        reports.push(r);
    }
    let report = pair.report(reports);
    let _ = compare::render_json(&report);
    let _ = compare::render_table(&report);
    let _ = compare::render_markdown(&report);
    if let Some(primary) = report.primary() {
        let dot = pair.dot_options(&primary.edit_script);
        let _ = btfsm_render::dot::policy_dot(b, &dot);
    }
}

fn pair_graph(p: &Policy) -> btfsm_model::graph::PolicyGraph {
    btfsm_model::graph::policy_graph(p)
}

/// The laws of a GED result: a certified interval, the script costs the
/// upper bound, `exact` exactly when the interval is closed, named is exact.
pub fn check_ged(r: &GedResult, mode: GedMode) {
    assert!(
        r.lower_bound <= r.upper_bound,
        "{mode:?}: lower {} > upper {}",
        r.lower_bound,
        r.upper_bound
    );
    assert_eq!(r.ged, r.upper_bound, "{mode:?}: ged is not the upper bound");
    assert_eq!(
        r.edit_script.cost(),
        r.upper_bound,
        "{mode:?}: the edit script does not cost the upper bound"
    );
    assert_eq!(
        r.exact,
        r.lower_bound == r.upper_bound,
        "{mode:?}: exact flag"
    );
    if mode == GedMode::Named {
        assert!(r.exact, "named GED is always exact");
    }
}

/// Every diagnostic renders, and a failed read has at least one error.
pub fn check_diagnostics(diags: &[Diagnostic]) {
    assert!(
        diags.iter().any(Diagnostic::is_error),
        "a rejected input has no error"
    );
    for d in diags {
        let _ = d.to_string();
    }
}

/// Everything downstream of a successful parse: graph, metrics, analyze
/// (table, JSON, CSV), DOT, the TOML write-back (a fixpoint), the BT → HFSM
/// and fault-tolerant transforms and effort.
pub fn exercise(l: &Loaded) {
    use btfsm_report::{Analysis, Report};
    let g = btfsm_model::graph::policy_graph(&l.policy);
    let _ = btfsm_metrics::complexity::cyclomatic(&g);
    let _ = btfsm_metrics::complexity::essential(&l.policy);
    let row = btfsm_report::analyze(l);
    for &f in Analysis::FORMATS {
        let _ = Analysis(std::slice::from_ref(&row)).write(f);
    }
    let _ = btfsm_render::dot::policy_dot(&l.policy, &Default::default());
    // Folded, with ports, in both directions: every drawing path.
    if let btfsm_model::PolicyBody::Bt(bt) = &l.policy.body {
        let folded = btfsm_render::dot::DotOptions {
            ports: true,
            depth: Some(2),
            fold_subtrees: true,
            collapse: bt.nodes.iter().step_by(3).map(|n| n.id.clone()).collect(),
            rankdir: btfsm_render::dot::RankDir::LeftRight,
            ..Default::default()
        };
        assert!(btfsm_render::dot::check_fold(&l.policy, &folded).is_ok());
        let _ = btfsm_render::dot::policy_dot(&l.policy, &folded);
    }
    // Every lint rule, the dataflow ones on a BehaviorTree.CPP tree's ports.
    let subject = btfsm_lint::Subject {
        policy: &l.policy,
        dataflow: l.dataflow.as_deref(),
    };
    let _ = btfsm_lint::lint_subject(&subject, None, "fuzzed", &Default::default());
    let text = btfsm_format::toml_write::write_policy(&l.policy);
    let again = btfsm_format::toml::parse_str("written.toml", &text, include_base(), &limits())
        .unwrap_or_else(|e| panic!("written TOML does not read back: {}\n{text}", e[0]));
    assert_eq!(
        btfsm_format::toml_write::write_policy(&again.policy),
        text,
        "the written form is not a fixpoint"
    );
    if let Ok(h) = btfsm_transform::bt_to_hfsm::bt_policy_to_hfsm(&l.policy) {
        let _ = btfsm_metrics::complexity::essential(&h);
        let _ = btfsm_render::dot::policy_dot(&h, &Default::default());
    }
    let (effort, _) = btfsm_report::effort::effort(&l.policy, &ged_options());
    for r in effort.named.iter() {
        check_ged(r, GedMode::Named);
    }
    for r in effort.structural.iter() {
        check_ged(r, GedMode::Structural);
    }
}

#[cfg(test)]
mod format_tests;

#[cfg(test)]
mod tests {
    use super::*;

    /// Every input a fuzz run once failed on (tests/fixtures/fuzz-regressions/,
    /// named after its target) goes through that target's body again.
    #[test]
    fn fuzz_regressions_stay_fixed() {
        let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
            .join("tests/fixtures/fuzz-regressions");
        let Ok(entries) = std::fs::read_dir(&dir) else {
            return;
        };
        let mut files: Vec<_> = entries.flatten().map(|e| e.path()).collect();
        files.sort();
        for f in files {
            let name = f.file_name().map(|n| n.to_string_lossy().into_owned());
            let data = std::fs::read(&f).expect("readable");
            match name.as_deref().and_then(|n| n.split('-').next()) {
                Some("toml_policy") => toml_policy(&data),
                Some("compare") => compare(&data),
                Some("btcpp_xml") => btcpp_xml(&data),
                Some("scxml") => scxml(&data),
                Some("yasmin") => yasmin(&data),
                Some("flexbe") => flexbe(&data),
                Some("py_trees_dot") => py_trees_dot(&data),
                Some("scenario") => scenario(&data),
                Some("project") => project(&data),
                Some("domain") => domain(&data),
                other => panic!("{}: no fuzz target `{other:?}`", f.display()),
            }
        }
    }

    #[test]
    fn pairs_split_at_the_separator() {
        assert_eq!(split_pair(b"a\n%%\nb"), (&b"a"[..], &b"b"[..]));
        assert_eq!(split_pair(b"ab"), (&b"ab"[..], &b""[..]));
    }

    #[test]
    fn paper_pairs_compare_with_a_tiny_budget() {
        let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("policies/paper");
        let a = std::fs::read(dir.join("fig01-bt.toml")).expect("fig01");
        let b = std::fs::read(dir.join("fig07c-bt.toml")).expect("fig07c");
        let mut pair = a.clone();
        pair.extend_from_slice(b"\n%%\n");
        pair.extend_from_slice(&b);
        compare(&pair);
        toml_policy(&a);
    }

    #[test]
    fn project_files_name_each_other() {
        // A top file including f1 with a parameter, f1 including sub/f.toml
        // through `..`-free and `..` paths; then a scenario with a policy.
        project(
            b"kind = \"bt\"\nroot = \"s\"\n[nodes]\ns = { subtree = \"f1.toml\", with = { v = \"x\" } }\n%%\nkind = \"bt\"\nroot = \"a\"\n[params]\nv = \"\"\n[nodes]\na = { action = \"{v}\", skill = \"Dock\" }\n",
        );
        project(b"kind = \"bt\"\nroot = \"s\"\n[nodes]\ns = { subtree = \"../../etc/passwd\" }\n");
        project(b"name = \"s\"\n[world]\n[[policies]]\nfile = \"f1.toml\"\n%%\nkind = \"bt\"\nroot = \"a\"\n[nodes]\na = { action = \"D\", skill = \"Dock\" }\n");
    }
}
