//! BehaviorTree.CPP XML and SCXML through the binary: the corpus of real
//! files in tests/fixtures/corpus, round trips at named GED 0, cross-format compare.

use super::*;
use common::scratch;

const CORPUS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/corpus");

fn nav2_model() -> String {
    format!("{CORPUS}/bt-xml/nav2/nav2_tree_nodes.xml")
}

/// Every file of the corpus with a given extension, recursively, sorted.
fn corpus_files(ext: &str) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut dirs = vec![PathBuf::from(CORPUS)];
    while let Some(d) = dirs.pop() {
        for e in std::fs::read_dir(&d).expect("corpus dir (tests/fixtures/corpus)") {
            let p = e.expect("entry").path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|e| e == ext) {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// Corpus XML files that hold behavior trees (not the nodes model).
fn corpus_trees() -> Vec<PathBuf> {
    let trees: Vec<PathBuf> = corpus_files("xml")
        .into_iter()
        .filter(|p| {
            std::fs::read_to_string(p)
                .expect("read")
                .contains("<BehaviorTree")
        })
        .collect();
    assert!(trees.len() >= 8, "corpus trees: {trees:?}");
    trees
}

/// A tag: name (`/name` for an end tag), attributes, self-closing.
type Tag = (String, Vec<(String, String)>, bool);

/// An XML tag found by the test's own scanner (independent of the reader):
/// `(name, attributes, self-closing)` for a start tag, `("/name", ..)` for an
/// end tag. Comments, declarations and processing instructions are skipped.
fn scan_tags(text: &str) -> Vec<Tag> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find('<') {
        rest = &rest[i..];
        let skip_to = |r: &str, end: &str| r.find(end).map_or(r.len(), |j| j + end.len());
        if rest.starts_with("<!--") {
            rest = &rest[skip_to(rest, "-->")..];
            continue;
        }
        if rest.starts_with("<?") {
            rest = &rest[skip_to(rest, "?>")..];
            continue;
        }
        if rest.starts_with("<!") {
            rest = &rest[skip_to(rest, ">")..];
            continue;
        }
        // Up to the closing '>' outside quotes.
        let mut quote = None;
        let mut end = rest.len();
        for (j, c) in rest.char_indices().skip(1) {
            match (quote, c) {
                (None, '"' | '\'') => quote = Some(c),
                (Some(q), c) if c == q => quote = None,
                (None, '>') => {
                    end = j;
                    break;
                }
                _ => {}
            }
        }
        let inner = &rest[1..end];
        rest = &rest[(end + 1).min(rest.len())..];
        let self_closing = inner.ends_with('/');
        let inner = inner.trim_end_matches('/');
        let name_end = inner
            .find(|c: char| c.is_whitespace())
            .unwrap_or(inner.len());
        let name = inner[..name_end].to_string();
        let mut attrs = Vec::new();
        let mut a = inner[name_end..].trim_start();
        while let Some(eq) = a.find('=') {
            let key = a[..eq].trim().to_string();
            let v = a[eq + 1..].trim_start();
            let q = v.chars().next().unwrap_or('"');
            let close = v[1..].find(q).map_or(v.len(), |k| k + 1);
            attrs.push((key, v[1..close].to_string()));
            a = v[(close + 1).min(v.len())..].trim_start();
        }
        out.push((name, attrs, self_closing));
    }
    out
}

fn attr<'a>(attrs: &'a [(String, String)], k: &str) -> Option<&'a str> {
    attrs.iter().find(|(n, _)| n == k).map(|(_, v)| v.as_str())
}

/// Tree nodes of the tree a BehaviorTree.CPP file runs, counted by the test's
/// own scanner: start tags inside `<BehaviorTree>`, each `<SubTree ID>` replaced
/// by the count of the tree it names (trees of included files too).
fn count_tree_nodes(path: &Path) -> usize {
    // tree ID -> (own nodes, SubTree IDs used)
    let mut trees: std::collections::HashMap<String, (usize, Vec<String>)> = Default::default();
    let mut main: Option<String> = None;
    let mut first_local: Vec<String> = Vec::new();
    let mut files = vec![(path.to_path_buf(), true)];
    while let Some((f, is_main)) = files.pop() {
        let text = std::fs::read_to_string(&f).expect("read");
        let mut current: Option<String> = None;
        for (name, attrs, _) in scan_tags(&text) {
            match name.as_str() {
                "root" if is_main => main = attr(&attrs, "main_tree_to_execute").map(String::from),
                "include" => files.push((
                    f.parent()
                        .expect("dir")
                        .join(attr(&attrs, "path").expect("path")),
                    false,
                )),
                "BehaviorTree" => {
                    let id = attr(&attrs, "ID").expect("ID").to_string();
                    if is_main {
                        first_local.push(id.clone());
                    }
                    trees.insert(id.clone(), (0, vec![]));
                    current = Some(id);
                }
                "/BehaviorTree" => current = None,
                n if n.starts_with('/') => {}
                _ => {
                    if let Some(t) = &current {
                        let e = trees.get_mut(t).expect("tree");
                        if name == "SubTree" {
                            e.1.push(attr(&attrs, "ID").expect("ID").to_string());
                        } else {
                            e.0 += 1;
                        }
                    }
                }
            }
        }
    }
    let main = main.unwrap_or_else(|| first_local[0].clone());
    let mut total = 0;
    let mut todo = vec![main];
    while let Some(t) = todo.pop() {
        let (own, subs) = &trees[&t];
        total += own;
        todo.extend(subs.iter().cloned());
    }
    total
}

/// Vertices and arcs of an SCXML file's HFSM graph by the test's own scanner:
/// every `<state>`, `<parallel>` and `<history>`, plus the `<final>` states of
/// the top level (the machine's outcomes; nested finals are their
/// container's outcomes, not vertices); one arc per `<transition>` with a
/// target (not the one of an `<initial>`, which is the container's arc),
/// plus one per state holding states (to its initial child; a state holding
/// only finals starts in one: no arc), and one per region of a `<parallel>`
/// (each `<state>` or `<parallel>` directly inside it: all are entered). A
/// machine embedded in `<invoke>` is another machine: not counted.
fn count_scxml_graph(path: &Path) -> (usize, usize) {
    let text = std::fs::read_to_string(path).expect("read");
    // (element name, arcs it adds when closed)
    let mut stack: Vec<(String, usize)> = Vec::new();
    let (mut n, mut arcs) = (0, 0);
    for (name, attrs, self_closing) in scan_tags(&text) {
        if let Some(closed) = name.strip_prefix('/') {
            let (open, initial_arcs) = stack.pop().expect("balanced");
            assert_eq!(open, closed);
            arcs += initial_arcs;
            continue;
        }
        let inside = |tag: &str| stack.iter().any(|(p, _)| p == tag);
        if inside("invoke") {
            if !self_closing {
                stack.push((name, 0));
            }
            continue;
        }
        match name.as_str() {
            "transition" if stack.last().map(|(p, _)| p.as_str()) == Some("initial") => {}
            "state" | "history" | "parallel" => {
                n += 1;
                match stack.last_mut() {
                    Some((p, k)) if p == "state" => *k = 1,
                    Some((p, k)) if p == "parallel" && name != "history" => *k += 1,
                    _ => {}
                }
            }
            "final" if stack.last().map(|(p, _)| p.as_str()) == Some("scxml") => n += 1,
            "transition" if attr(&attrs, "target").is_some() => arcs += 1,
            _ => {}
        }
        if !self_closing {
            stack.push((name, 0));
        }
    }
    (n, arcs)
}

#[test]
fn corpus_trees_import_analyze_draw_and_validate() {
    let model = nav2_model();
    for f in corpus_trees() {
        let file = f.display().to_string();
        let base = ["--nodes-model", model.as_str(), file.as_str()];
        let (code, stdout, stderr) =
            btfsm(&[&["analyze", "--format", "json"][..], &base[..]].concat());
        assert_eq!(code, 0, "{file}: {stderr}");
        let v: serde_json::Value = serde_json::from_str(&stdout).expect("json");
        let p = &v["policies"][0];
        assert_eq!(p["kind"], "bt", "{file}");
        let expected = count_tree_nodes(&f) as u64;
        assert_eq!(p["vertices"], expected, "{file}: vertices");
        assert_eq!(p["edges"], expected - 1, "{file}: a tree has V - 1 edges");
        assert_eq!(p["essential_cc"], 1, "{file}");
        let (code, dot, stderr) = btfsm(&[&["dot"][..], &base[..]].concat());
        assert_eq!(code, 0, "{file}: {stderr}");
        assert!(dot.starts_with("digraph"));
        assert_eq!(dot.matches(" -> ").count() as u64, expected - 1, "{file}");
        let (code, _, stderr) = btfsm(&[&["validate"][..], &base[..]].concat());
        assert_eq!(code, 0, "{file}: {stderr}");
        assert!(stderr.contains(": ok (bt"), "{stderr}");
    }
}

#[test]
fn corpus_scxml_imports_analyzes_draws_and_validates() {
    let files = corpus_files("scxml");
    assert!(!files.is_empty());
    for f in files {
        let file = f.display().to_string();
        let (code, stdout, stderr) = btfsm(&["analyze", "--format", "json", &file]);
        assert_eq!(code, 0, "{file}: {stderr}");
        let v: serde_json::Value = serde_json::from_str(&stdout).expect("json");
        let p = &v["policies"][0];
        let (vertices, arcs) = count_scxml_graph(&f);
        assert_eq!(p["vertices"], vertices as u64, "{file}");
        assert_eq!(p["edges"], arcs as u64, "{file}");
        let (code, dot, stderr) = btfsm(&["dot", &file]);
        assert_eq!(code, 0, "{file}: {stderr}");
        assert!(dot.starts_with("digraph"));
        let (code, _, stderr) = btfsm(&["validate", &file]);
        assert_eq!(code, 0, "{file}: {stderr}");
    }
    // The PackML machine: nested states make it an HFSM; its history state
    // and the Qt editor data do not break the import.
    let (_, stdout, _) = btfsm(&[
        "analyze",
        "--format",
        "json",
        &format!("{CORPUS}/scxml/packml_demo_sm.scxml"),
    ]);
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("json");
    assert_eq!(v["policies"][0]["kind"], "hfsm");
}

#[test]
fn nav2_trees_need_their_nodes_model_or_assume_leaf() {
    let f = format!("{CORPUS}/bt-xml/nav2/follow_point.xml");
    let (code, _, stderr) = btfsm(&["validate", &f]);
    assert_eq!(code, 2);
    assert!(
        stderr.contains("unknown node type `PipelineSequence` (4 children)"),
        "{stderr}"
    );
    assert!(stderr.contains("--nodes-model FILE"), "{stderr}");
    // A leaf-only unknown type is settled by --assume-leaf.
    let f = format!("{CORPUS}/bt-xml/nav2/odometry_calibration.xml");
    let (code, _, stderr) = btfsm(&["validate", &f]);
    assert_eq!(code, 2, "{stderr}");
    let (code, _, stderr) = btfsm(&["validate", "--assume-leaf", "action", &f]);
    assert_eq!(code, 0, "{stderr}");
}

#[test]
fn lowercase_builtin_in_nav2_example_is_a_warning() {
    let f = format!("{CORPUS}/bt-xml/nav2/docking_application_example.xml");
    let (code, _, stderr) = btfsm(&["validate", "--nodes-model", &nav2_model(), &f]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stderr.contains("warning: `inverter` is not a BehaviorTree.CPP node type"),
        "{stderr}"
    );
    assert!(
        stderr.contains("docking_application_example.xml:22:13"),
        "{stderr}"
    );
}

/// `btfsm convert FILE --to TARGET -o OUT` (with the Nav2 model).
fn convert(file: &Path, to: &str, out: &Path) {
    let (code, _, stderr) = btfsm(&[
        "convert",
        "--nodes-model",
        &nav2_model(),
        &file.display().to_string(),
        "--to",
        to,
        "-o",
        &out.display().to_string(),
    ]);
    assert_eq!(code, 0, "convert {} --to {to}: {stderr}", file.display());
}

fn load(p: &Path) -> btfsm_model::Policy {
    let limits = btfsm_format::Limits {
        nodes_models: vec![PathBuf::from(nav2_model())],
        ..Default::default()
    };
    match btfsm_format::load(p, &limits) {
        Ok(l) => l.policy,
        Err(d) => panic!("{}: {d:?}", p.display()),
    }
}

/// Named GED between two policies, with the edit script on failure.
fn named_ged(a: &btfsm_model::Policy, b: &btfsm_model::Policy) -> (u64, String) {
    use btfsm_metrics::ged::{GedMode, GedOptions, ged};
    let (ga, gb) = (
        btfsm_model::graph::policy_graph(a),
        btfsm_model::graph::policy_graph(b),
    );
    assert_eq!(ga.vertex_count(), gb.vertex_count());
    let r = ged(&ga, &gb, GedMode::Named, &GedOptions::default());
    (r.ged, format!("{:?}", r.edit_script))
}

/// A -> X -> A through two converters gives named GED 0 at every step.
fn round_trip(src: &Path, via: &str, back: &str, ext_via: &str, ext_back: &str, dir: &Path) {
    let stem = src.file_stem().expect("stem").to_string_lossy();
    let mid = dir.join(format!("{stem}.{ext_via}"));
    let end = dir.join(format!("{stem}.back.{ext_back}"));
    convert(src, via, &mid);
    convert(&mid, back, &end);
    let (a, b, c) = (load(src), load(&mid), load(&end));
    for (x, y, what) in [(&a, &b, via), (&a, &c, back)] {
        let (d, script) = named_ged(x, y);
        assert_eq!(d, 0, "{} -> {what}: named GED {d}\n{script}", src.display());
    }
    assert_eq!(a.kind(), c.kind());
    if let Err(e) = same_model(&a, &c) {
        panic!("{} -> {via} -> {back}: {e}", src.display());
    }
}

/// [`same_model`] for two BTs: nodes compared by id.
fn same_bt(x: &btfsm_model::Bt, y: &btfsm_model::Bt) -> Result<(), String> {
    let kids = |t: &btfsm_model::Bt, i: usize| -> Vec<String> {
        t.nodes[i]
            .children
            .iter()
            .map(|&c| t.nodes[c].id.clone())
            .collect()
    };
    if x.nodes[x.root].id != y.nodes[y.root].id {
        return Err("different roots".into());
    }
    for (i, n) in x.nodes.iter().enumerate() {
        let j = y
            .nodes
            .iter()
            .position(|m| m.id == n.id)
            .ok_or(format!("node `{}` lost", n.id))?;
        let m = &y.nodes[j];
        let l = (
            &n.label,
            n.kind,
            &n.skill,
            &n.type_name,
            &n.ports,
            kids(x, i),
        );
        let r = (
            &m.label,
            m.kind,
            &m.skill,
            &m.type_name,
            &m.ports,
            kids(y, j),
        );
        // Format 3's BlackboardCheck* is written as format 4's
        // Precondition (docs/guide/btcpp-xml.md): same node, kind
        // and children; the type and ports are format 4's.
        let v3_check = n
            .type_name
            .as_deref()
            .is_some_and(|t| t.starts_with("BlackboardCheck"))
            && m.type_name.as_deref() == Some("Precondition")
            && m.ports.contains_key("if");
        if v3_check && (&l.0, l.1, &l.5) == (&r.0, r.1, &r.5) {
            continue;
        }
        if l != r {
            return Err(format!("node `{}`: {l:?} != {r:?}", n.id));
        }
    }
    Ok(())
}

/// The same policy up to source positions and arena order: BT nodes compared
/// by id (label, kind, skill, type, ports, children), states by path (label,
/// body, transitions in order).
fn same_model(a: &btfsm_model::Policy, b: &btfsm_model::Policy) -> Result<(), String> {
    use btfsm_model::{PolicyBody, StateBody, Target};
    match (&a.body, &b.body) {
        (PolicyBody::Bt(x), PolicyBody::Bt(y)) => same_bt(x, y),
        (PolicyBody::Machine(x), PolicyBody::Machine(y)) => {
            // Where a region starts: a state's path or an outcome.
            let start = |m: &btfsm_model::StateMachine, t: &Target| match t {
                Target::State(j) => m.path(*j),
                Target::Outcome(o) | Target::OuterOutcome { outcome: o, .. } => {
                    format!("outcome {o}")
                }
            };
            let desc = |m: &btfsm_model::StateMachine, i: usize| {
                let s = &m.states[i];
                let body = match &s.body {
                    StateBody::Container(r) => format!(
                        "container initial={} parallel={} outcomes={:?}",
                        start(m, &r.initial),
                        r.parallel,
                        r.outcomes
                    ),
                    other => format!("{other:?}"),
                };
                let trs: Vec<String> = s
                    .transitions
                    .iter()
                    .map(|t| {
                        let to = match &t.target {
                            Target::State(j) => m.path(*j),
                            Target::Outcome(o) => format!("outcome {o}"),
                            Target::OuterOutcome { owner, outcome } => format!(
                                "outcome {outcome} of {}",
                                owner.map_or("the machine".into(), |c| m.path(c))
                            ),
                        };
                        format!("{:?} -> {to}", t.trigger)
                    })
                    .collect();
                format!("{} {body} {:?} {trs:?}", s.label, s.pseudo)
            };
            if (x.top.outcomes.clone(), start(x, &x.top.initial))
                != (y.top.outcomes.clone(), start(y, &y.top.initial))
            {
                return Err("different top level".into());
            }
            for i in 0..x.states.len() {
                let p = x.path(i);
                let j = (0..y.states.len())
                    .find(|&j| y.path(j) == p)
                    .ok_or(format!("state `{p}` lost"))?;
                let (l, r) = (desc(x, i), desc(y, j));
                if l != r {
                    return Err(format!("state `{p}`:\n  {l}\n  {r}"));
                }
            }
            Ok(())
        }
        _ => Err("different kinds".into()),
    }
}

#[test]
fn bundled_bts_round_trip_through_btcpp_xml_at_named_ged_0() {
    let dir = scratch("bt-rt");
    let mut n = 0;
    for f in fixtures_in("policies/paper") {
        if load(&f).kind() == btfsm_model::PolicyKind::Bt {
            round_trip(&f, "btcpp-xml", "toml", "xml", "toml", &dir);
            n += 1;
        }
    }
    assert!(n >= 14, "{n} BTs");
    std::fs::remove_dir_all(&dir).expect("cleanup");
}

#[test]
fn corpus_trees_round_trip_through_toml_at_named_ged_0() {
    let dir = scratch("xml-rt");
    for f in corpus_trees() {
        round_trip(&f, "toml", "btcpp-xml", "toml", "xml", &dir);
    }
    std::fs::remove_dir_all(&dir).expect("cleanup");
}

#[test]
fn machines_round_trip_through_scxml_at_named_ged_0() {
    let dir = scratch("scxml-rt");
    let mut n = 0;
    for f in fixtures_in("policies/paper") {
        if load(&f).kind() != btfsm_model::PolicyKind::Bt {
            round_trip(&f, "scxml", "toml", "scxml", "toml", &dir);
            n += 1;
        }
    }
    assert!(n >= 12, "{n} machines");
    for f in corpus_files("scxml") {
        round_trip(&f, "toml", "scxml", "toml", "scxml", &dir);
    }
    std::fs::remove_dir_all(&dir).expect("cleanup");
}

#[test]
fn converting_to_the_wrong_family_is_a_clear_error() {
    let (code, _, stderr) = btfsm(&[
        "convert",
        "policies/paper/fig04-fsm.toml",
        "--to",
        "btcpp-xml",
    ]);
    assert_eq!(code, 2);
    assert!(stderr.contains("holds behavior trees only"), "{stderr}");
    let (code, _, stderr) = btfsm(&["convert", "policies/paper/fig01-bt.toml", "--to", "scxml"]);
    assert_eq!(code, 2);
    assert!(stderr.contains("--to hfsm first"), "{stderr}");
}

fn fixtures_in(dir: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(dir))
        .expect("dir")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    v.sort();
    v
}

#[test]
fn compare_works_across_formats() {
    let dir = scratch("cmp");
    let xml = dir.join("fig07c.xml");
    convert(
        Path::new("policies/paper/fig07c-bt.toml"),
        "btcpp-xml",
        &xml,
    );
    let (code, stdout, stderr) = btfsm(&[
        "compare",
        "--format",
        "json",
        "policies/paper/fig01-bt.toml",
        &xml.display().to_string(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("json");
    // SPEC §5: Fig. 1 -> Fig. 7c is 8 edits, whichever format B is in.
    assert_eq!(v["named"]["ged"], 8, "{stdout}");
    std::fs::remove_dir_all(&dir).expect("cleanup");
}

/// Vertices and arcs of a yasmin file by the test's own tag scanner: every
/// `<State>`, `<JoinState>` and nested `<StateMachine>` is a vertex (an included file's
/// states too), so is each top-level outcome; every `<Transition>` is an
/// arc, and so is each container's arc to its start state.
fn count_yasmin_graph(path: &Path) -> (usize, usize) {
    let text = std::fs::read_to_string(path).expect("read");
    let tags = scan_tags(&text);
    let (mut v, mut e) = (0, 0);
    let mut first = true;
    for (name, attrs, _) in &tags {
        match name.as_str() {
            "StateMachine" if first => {
                first = false;
                v += attr(attrs, "outcomes").map_or(0, |o| o.split_whitespace().count());
            }
            "StateMachine" => {
                v += 1;
                e += 1;
                if let Some(inc) = attr(attrs, "file_path") {
                    let (iv, ie) = count_yasmin_graph(&path.parent().expect("dir").join(inc));
                    let inner = std::fs::read_to_string(path.parent().expect("dir").join(inc))
                        .expect("read");
                    let top = scan_tags(&inner)
                        .into_iter()
                        .find(|t| t.0 == "StateMachine")
                        .and_then(|t| attr(&t.1, "outcomes").map(|o| o.split_whitespace().count()))
                        .unwrap_or(0);
                    v += iv - top;
                    e += ie;
                }
            }
            // A JoinState (a barrier between regions) is a state too.
            "State" | "JoinState" => v += 1,
            // A parallel state: one vertex, its arcs are its regions'.
            "OrthogonalState" => v += 1,
            // A region: one vertex, the arc to it from its orthogonal
            // state and the arc to its start state.
            "Region" => {
                v += 1;
                e += 2;
            }
            "Transition" => e += 1,
            _ => {}
        }
    }
    (v, e)
}

#[test]
fn corpus_yasmin_imports_analyzes_and_draws_orthogonal_states_as_parallel_regions() {
    let files: Vec<PathBuf> = corpus_files("xml")
        .into_iter()
        .filter(|p| p.components().any(|c| c.as_os_str() == "yasmin"))
        .collect();
    assert!(files.len() >= 10, "{files:?}");
    let mut loaded = 0;
    for f in files {
        let file = f.display().to_string();
        let text = std::fs::read_to_string(&f).expect("read");
        let (code, stdout, stderr) = btfsm(&["analyze", "--format", "json", &file]);
        assert_eq!(code, 0, "{file}: {stderr}");
        let v: serde_json::Value = serde_json::from_str(&stdout).expect("json");
        let p = &v["policies"][0];
        let (vertices, arcs) = count_yasmin_graph(&f);
        assert_eq!(p["vertices"], vertices as u64, "{file}");
        assert_eq!(p["edges"], arcs as u64, "{file}");
        let nested = text.matches("<StateMachine").count() > 1 || text.contains("<OrthogonalState");
        assert_eq!(
            p["counts"]["parallel_state"].as_u64().unwrap_or(0) as usize,
            text.matches("<OrthogonalState").count(),
            "{file}"
        );
        assert_eq!(p["kind"], if nested { "hfsm" } else { "fsm" }, "{file}");
        let (code, dot, stderr) = btfsm(&["dot", &file]);
        assert_eq!(code, 0, "{file}: {stderr}");
        assert!(dot.starts_with("digraph"));
        loaded += 1;
    }
    assert!(loaded >= 10, "{loaded}");
}

#[test]
fn yasmin_machines_round_trip_through_toml_and_scxml_at_named_ged_0() {
    let dir = scratch("yasmin-rt");
    let mut orthogonal = 0;
    for f in corpus_files("xml") {
        if f.components().any(|c| c.as_os_str() == "yasmin") {
            let text = std::fs::read_to_string(&f).expect("read");
            orthogonal += usize::from(text.contains("<OrthogonalState"));
            round_trip(&f, "toml", "scxml", "toml", "scxml", &dir);
        }
    }
    assert!(orthogonal >= 2, "{orthogonal} orthogonal machines");
    std::fs::remove_dir_all(&dir).expect("cleanup");
}

#[test]
fn a_yasmin_file_path_outside_the_root_is_refused() {
    let dir = scratch("yasmin-root");
    std::fs::create_dir_all(dir.join("repo/.git")).expect("mkdir");
    std::fs::write(
        dir.join("outside.xml"),
        "<StateMachine outcomes=\"end\"><State name=\"s\"><Transition from=\"ok\" to=\"end\"/></State></StateMachine>",
    )
    .expect("write");
    let main = dir.join("repo/main.xml");
    std::fs::write(
        &main,
        "<StateMachine outcomes=\"end\">\n  <StateMachine name=\"In\" file_path=\"../outside.xml\"><Transition from=\"end\" to=\"end\"/></StateMachine>\n</StateMachine>\n",
    )
    .expect("write");
    let (code, _, stderr) = btfsm(&["analyze", &main.display().to_string()]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("cannot include this file"), "{stderr}");
    assert!(stderr.contains(":2:"), "positioned: {stderr}");
    assert!(!stderr.contains("outside.xml\n"), "{stderr}");
    std::fs::remove_dir_all(&dir).expect("cleanup");
}

#[test]
fn the_render_format_follows_the_output_extension() {
    if !crate::common::graphviz("the_render_format_follows_the_output_extension") {
        return;
    }
    let dir = scratch("render-ext");
    let fig = concat!(env!("CARGO_MANIFEST_DIR"), "/policies/paper/fig01-bt.toml");
    let out = |name: &str| dir.join(name).display().to_string();
    // `.dot`, `.gv` and no extension: DOT text.
    for name in ["a.dot", "a.gv", "a"] {
        let (code, _, stderr) = btfsm(&["dot", fig, "-o", &out(name)]);
        assert_eq!(code, 0, "{stderr}");
        let text = std::fs::read_to_string(dir.join(name)).expect("written");
        assert!(text.starts_with("digraph"), "{name}");
    }
    // `.svg`, `.PNG`: rendered through Graphviz (make test installs it).
    let (code, _, stderr) = btfsm(&["dot", fig, "-o", &out("a.svg")]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        std::fs::read_to_string(dir.join("a.svg"))
            .expect("svg")
            .contains("<svg")
    );
    let (code, _, stderr) = btfsm(&["dot", fig, "-o", &out("a.PNG")]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        std::fs::read(dir.join("a.PNG"))
            .expect("png")
            .starts_with(b"\x89PNG")
    );
    // An explicit --render wins over the extension.
    let (code, _, stderr) = btfsm(&["dot", fig, "--render", "svg", "-o", &out("b.png")]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        std::fs::read_to_string(dir.join("b.png"))
            .expect("svg")
            .contains("<svg")
    );
    // compare --dot follows its own extension the same way.
    let fig3 = concat!(env!("CARGO_MANIFEST_DIR"), "/policies/paper/fig03-bt.toml");
    let (code, _, stderr) = btfsm(&["compare", fig, fig3, "--dot", &out("d.svg")]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        std::fs::read_to_string(dir.join("d.svg"))
            .expect("svg")
            .contains("<svg")
    );
    std::fs::remove_dir_all(&dir).expect("cleanup");
}

#[test]
fn a_directory_is_every_policy_below_it_and_a_bad_file_hides_no_report() {
    let dir = scratch("dir-input");
    let paper = concat!(env!("CARGO_MANIFEST_DIR"), "/policies/paper");
    std::fs::create_dir_all(dir.join("sub/.hidden")).expect("mkdir");
    std::fs::copy(format!("{paper}/fig01-bt.toml"), dir.join("b-fig01.toml")).expect("copy");
    std::fs::copy(
        format!("{paper}/fig04-fsm.toml"),
        dir.join("sub/a-fig04.toml"),
    )
    .expect("copy");
    std::fs::copy(
        format!("{paper}/fig02-fsm.toml"),
        dir.join("sub/.hidden/x.toml"),
    )
    .expect("copy");
    std::fs::write(dir.join("Cargo.toml"), "[package]\nname = \"x\"\n").expect("write");
    std::fs::write(dir.join("package.xml"), "<package><name>x</name></package>").expect("write");
    std::fs::write(
        dir.join("bad.toml"),
        "kind = \"bt\"\nroot = \"nope\"\n[nodes]\n",
    )
    .expect("write");
    let d = dir.display().to_string();
    let (code, stdout, stderr) = btfsm(&["analyze", &d, "--format", "json"]);
    assert_eq!(code, 2, "a bad file makes exit 2: {stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("the good files' report");
    let files: Vec<&str> = v["policies"]
        .as_array()
        .expect("policies")
        .iter()
        .map(|p| p["file"].as_str().expect("file"))
        .collect();
    assert_eq!(files.len(), 2, "{files:?}");
    assert!(files[0].ends_with("b-fig01.toml") && files[1].ends_with("sub/a-fig04.toml"));
    assert!(stderr.contains("bad.toml"), "{stderr}");
    assert!(stderr.contains("skipped 2 files"), "{stderr}");
    // Without the bad file: exit 0, and `validate` also checks scenarios.
    std::fs::remove_file(dir.join("bad.toml")).expect("rm");
    let (code, _, stderr) = btfsm(&["analyze", &d]);
    assert_eq!(code, 0, "{stderr}");
    let scen = concat!(env!("CARGO_MANIFEST_DIR"), "/policies");
    let (code, _, stderr) = btfsm(&["validate", scen]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("ok (scenario `exp1-nominal`"), "{stderr}");
    assert!(stderr.contains("fig01-bt.toml: ok (bt"), "{stderr}");
    // A directory without policies is an error, not an empty report.
    let empty = scratch("dir-empty");
    let (code, _, stderr) = btfsm(&["analyze", &empty.display().to_string()]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("no policy file"), "{stderr}");
    std::fs::remove_dir_all(&dir).expect("cleanup");
    std::fs::remove_dir_all(&empty).expect("cleanup");
}

/// SCXML `<parallel>` (Apache Commons SCXML's parallel-01): counted with one
/// initial arc per region, drawn as dashed regions inside the parallel
/// state's box, written as `parallel = true` in TOML and `<parallel>` in
/// SCXML (both read back), `--` between regions in Mermaid; the simulator
/// refuses it with its reason, exit 2.
#[test]
fn parallel_regions_are_counted_drawn_converted_and_refused_by_the_simulator() {
    let f = format!("{CORPUS}/scxml/commons-scxml/parallel-01.scxml");
    let (code, stdout, stderr) = btfsm(&["analyze", "--format", "json", &f]);
    assert_eq!(code, 0, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("json");
    // para, para1, para11, para12, para2, para21, para22, end: 8 vertices;
    // 3 transitions + para -> para1, para2 + para1 -> para11, para2 -> para21.
    assert_eq!(
        (&v["policies"][0]["vertices"], &v["policies"][0]["edges"]),
        (&serde_json::json!(8), &serde_json::json!(7))
    );
    let (code, dot, _) = btfsm(&["dot", &f]);
    assert_eq!(code, 0);
    assert!(dot.contains("label=\"para ‖\""), "{dot}");
    assert_eq!(dot.matches("style=dashed").count(), 2, "{dot}");
    assert!(dot.contains("para -> para1 [lhead=cluster_para1]"), "{dot}");
    let (code, toml, stderr) = btfsm(&["convert", &f, "--to", "toml"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(toml.contains("[states.para]\nparallel = true\n"), "{toml}");
    let (code, mermaid, _) = btfsm(&["convert", &f, "--to", "mermaid"]);
    assert_eq!(code, 0);
    assert_eq!(mermaid.matches("\n        --\n").count(), 1, "{mermaid}");
    let (code, scxml, _) = btfsm(&["convert", &f, "--to", "scxml"]);
    assert_eq!(code, 0);
    assert!(scxml.contains("<parallel id=\"para\">"), "{scxml}");
    let dir = scratch("parallel-sim");
    std::fs::copy(&f, dir.join("p.scxml")).expect("copy");
    let scenario = dir.join("s.toml");
    std::fs::write(
        &scenario,
        "[world]\nobjects = { cube2 = { at = \"east-table\" } }\n[[policies]]\nfile = \"p.scxml\"\n",
    )
    .expect("write");
    let (code, _, stderr) = btfsm(&["sim", &scenario.display().to_string()]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains(
            "has parallel regions (SCXML `<parallel>`): the simulator runs one state at a time"
        ),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).expect("cleanup");
}

/// The W3C tests' `pass`/`fail` (a nested state's transition to a top-level
/// `<final>`) and a state holding only a `<final>` (test372) read, count and
/// round-trip; `validate` gives no warning.
#[test]
fn w3c_finals_of_enclosing_regions_and_final_only_states_read() {
    for t in ["test372", "test403a", "test412", "test579"] {
        let f = format!("{CORPUS}/scxml/w3c/{t}.scxml");
        let (code, _, stderr) = btfsm(&["validate", &f]);
        assert_eq!(code, 0, "{stderr}");
        assert!(stderr.contains(", 0 warnings)"), "{t}: {stderr}");
        // `pass` / `fail` are reached from nested states: lint agrees.
        let (_, stdout, stderr) = btfsm(&["lint", &f]);
        assert!(
            !format!("{stdout}{stderr}").contains("outcome-never-reached"),
            "{t}: {stdout}{stderr}"
        );
    }
    let f = format!("{CORPUS}/scxml/commons-scxml/scxml-initial-attr.scxml");
    let (code, stdout, stderr) = btfsm(&["analyze", "--format", "json", &f]);
    assert_eq!(code, 0, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("json");
    assert_eq!(v["policies"][0]["vertices"], 1, "the machine is one final");
    assert_eq!(v["policies"][0]["edges"], 0);
}

const PROJECTS: &str = "tests/fixtures/btcpp-projects";

/// Vertices per reported file of `analyze --format json`.
fn vertices_by_file(stdout: &str) -> Vec<(String, u64)> {
    let v: serde_json::Value = serde_json::from_str(stdout).expect("json");
    v["policies"]
        .as_array()
        .expect("policies")
        .iter()
        .map(|p| {
            let f = p["file"].as_str().expect("file");
            (
                f.rsplit('/').next().unwrap_or(f).to_string(),
                p["vertices"].as_u64().expect("vertices"),
            )
        })
        .collect()
}

#[test]
fn subtrees_resolve_across_files_given_together() {
    // pick.xml uses Approach (subtrees/approach.xml), which uses Localize
    // (subtrees/localize.xml); no file includes another.
    let dir = format!("{PROJECTS}/pick");
    let (code, out, err) = btfsm(&["analyze", &dir, "--format", "json"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        vertices_by_file(&out),
        [
            ("pick.xml".to_string(), 10),
            ("approach.xml".to_string(), 6),
            ("localize.xml".to_string(), 4)
        ]
    );
    // The same files named one by one.
    let files = [
        format!("{dir}/pick.xml"),
        format!("{dir}/subtrees/approach.xml"),
        format!("{dir}/subtrees/localize.xml"),
    ];
    let (code, named, err) = btfsm(&[
        "analyze", &files[0], &files[1], &files[2], "--format", "json",
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(vertices_by_file(&named), vertices_by_file(&out));
    // Alone, pick.xml cannot resolve Approach, and the hint says how.
    let (code, _, err) = btfsm(&["analyze", &files[0]]);
    assert_eq!(code, 2);
    assert!(
        err.contains("unknown tree `Approach` in `<SubTree>`"),
        "{err}"
    );
    assert!(err.contains("given together with this one"), "{err}");
}

#[test]
fn tree_flag_reads_the_file_that_defines_it_among_several() {
    let dir = format!("{PROJECTS}/pick");
    let (code, out, err) = btfsm(&["analyze", &dir, "--tree", "Approach", "--format", "json"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(vertices_by_file(&out), [("approach.xml".to_string(), 6)]);
    let (code, _, err) = btfsm(&["analyze", &dir, "--tree", "Aproach"]);
    assert_eq!(code, 2);
    assert!(
        err.contains("none of the 3 BehaviorTree.CPP files given defines it")
            && err.contains("did you mean `Approach`?"),
        "{err}"
    );
}

#[test]
fn a_subtree_defined_by_several_files_given_together_is_an_error() {
    let d = scratch("ambiguous-subtree");
    let tree = |id: &str, body: &str| {
        format!("<root BTCPP_format=\"4\"><BehaviorTree ID=\"{id}\">{body}</BehaviorTree></root>")
    };
    std::fs::write(d.join("main.xml"), tree("Main", "<SubTree ID=\"Dock\"/>")).expect("write");
    std::fs::write(d.join("a.xml"), tree("Dock", "<AlwaysSuccess/>")).expect("write");
    std::fs::write(d.join("b.xml"), tree("Dock", "<AlwaysFailure/>")).expect("write");
    let main = d.join("main.xml").display().to_string();
    let (code, _, err) = btfsm(&["analyze", d.to_str().expect("utf-8"), "--tree", "Main"]);
    assert_eq!(code, 2);
    assert!(
        err.contains("tree `Dock` in `<SubTree>` is defined by several files given together")
            && err.contains(&format!("{main}:1:")),
        "{err}"
    );
    // One companion: no ambiguity.
    let a = d.join("a.xml").display().to_string();
    let (code, out, err) = btfsm(&["analyze", &main, &a, "--tree", "Main", "--format", "json"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(vertices_by_file(&out), [("main.xml".to_string(), 1)]);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_groot2_project_file_reads_the_trees_it_includes() {
    // Husarion's LightsBT.btproj: a Groot2 project (includes and a nodes
    // model, no tree of its own), read as BehaviorTree.CPP registers it.
    let husarion = format!("{CORPUS}/bt-xml/husarion");
    let (code, proj, err) = btfsm(&[
        "analyze",
        &format!("{husarion}/LightsBT.btproj"),
        "--format",
        "json",
    ]);
    assert_eq!(code, 0, "{err}");
    let (code, tree, err) = btfsm(&[
        "analyze",
        &format!("{husarion}/lights.xml"),
        "--format",
        "json",
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(vertices_by_file(&proj)[0].1, 16);
    assert_eq!(vertices_by_file(&tree)[0].1, 16);
}
