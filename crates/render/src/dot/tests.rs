//! Unit tests of the DOT drawings.

use super::graphviz::*;
use super::*;
use btfsm_format::toml::parse_str;
use btfsm_model::{Target, Trigger};
use graphviz_rust::dot_structures::Graph as DotGraph;
use graphviz_rust::dot_structures::Id;
use std::path::Path;
use std::time::{Duration, Instant};

fn policy(text: &str) -> Policy {
    match parse_str("inline.toml", text, Path::new("."), &Default::default()) {
        Ok(l) => l.policy,
        Err(d) => panic!("test policy does not parse: {d:?}"),
    }
}

const BT: &str = r#"
kind = "bt"
name = "Fetch cube2"
root = "fetch"

[nodes]
fetch        = { sequence = ["reached-cube", "pick", "finish"] }
reached-cube = { fallback = ["at-cube", "move-to-cube"] }
at-cube      = { condition = "Robot-At cube2?", skill = "Robot-At", args = { target = "cube2" } }
move-to-cube = { retry = "move", times = 3 }
move         = { action = "Move-To cube2!", skill = "Move-To", args = { target = "cube2" } }
pick         = { timeout = "pick-it", ms = 5000 }
pick-it      = { action = "Pick cube2!", skill = "Pick", args = { object = "cube2" } }
finish       = { sequence_memory = ["both", "not-tucked"], name = "Finish" }
both         = { parallel = ["dock", "tuck"], success = 1 }
dock         = { action = "Dock!", skill = "Dock" }
tuck         = { action = "Tuck arm!", skill = "Tuck-Arm" }
not-tucked   = { inverter = "tucked" }
tucked       = { condition = "Arm tucked?", skill = "Arm-Tucked" }
"#;

const FSM: &str = r#"
kind = "fsm"
name = "Fault-tolerant fetch"
initial = "Move-To cube2"
outcomes = ["SUCCESS"]

[states."Move-To cube2"]
skill = "Move-To"
args = { target = "cube2" }
on = { SUCCESS = "Pick cube2", FAILURE = "SELECTOR", RUNNING = "Move-To cube2" }

[states."Pick cube2"]
skill = "Pick"
args = { object = "cube2" }
on = { SUCCESS = "SUCCESS", FAILURE = "SELECTOR", RUNNING = "Pick cube2" }

[states.SELECTOR]
decision = true
guards = [
  { if = "In-Hand", args = { object = "cube2" }, to = "SUCCESS", label = "cube2 in hand" },
  { if = "Robot-At", args = { target = "cube2" }, to = "Pick cube2", label = "cube2 reached" },
  { unless = "Robot-At", args = { target = "cube2" }, to = "Move-To cube2", label = "restart" },
]
on = { RUNNING = "SELECTOR" }
"#;

const HFSM: &str = r#"
kind = "hfsm"
name = "Fig. 6"
initial = "fetch"
outcomes = ["SUCCESS", "FAILURE", "RUNNING"]

[states.fetch]
label = "Sequence"
initial = "at-cube"
outcomes = ["SUCCESS", "FAILURE", "RUNNING"]
on = { SUCCESS = "SUCCESS", FAILURE = "FAILURE", RUNNING = "RUNNING" }

[states.fetch.states.at-cube]
label = "Fallback"
initial = "is-at"
outcomes = ["SUCCESS", "FAILURE", "RUNNING"]
on = { SUCCESS = "pick", FAILURE = "FAILURE", RUNNING = "RUNNING" }

[states.fetch.states.at-cube.states.is-at]
label = "Robot-At cube2?"
skill = "Robot-At"
args = { target = "cube2" }
on = { SUCCESS = "SUCCESS", FAILURE = "move" }

[states.fetch.states.at-cube.states.move]
label = "Move-To cube2!"
skill = "Move-To"
args = { target = "cube2" }
on = { SUCCESS = "SUCCESS", FAILURE = "FAILURE", RUNNING = "RUNNING" }

[states.fetch.states.pick]
label = "Pick cube2!"
skill = "Pick"
args = { object = "cube2" }
on = { SUCCESS = "SUCCESS", FAILURE = "FAILURE", RUNNING = "RUNNING" }
"#;

/// Distinct node ids declared anywhere, and the number of edges, of a DOT
/// text, read back with graphviz-rust's parser (which also checks syntax).
fn census(dot: &str) -> (Vec<String>, usize) {
    let g = graphviz_rust::parse(dot).unwrap_or_else(|e| panic!("bad DOT: {e}\n{dot}"));
    let DotGraph::DiGraph { stmts, .. } = g else {
        panic!("not a digraph")
    };
    let mut ids = Vec::new();
    let mut edges = 0;
    let mut todo = vec![stmts];
    while let Some(stmts) = todo.pop() {
        for s in stmts {
            match s {
                Stmt::Node(n) => {
                    let id = match n.id.0 {
                        Id::Plain(s) | Id::Escaped(s) | Id::Html(s) => s,
                        Id::Anonymous(_) => continue,
                    };
                    // The start dot of a machine is no vertex.
                    if id == START {
                        continue;
                    }
                    if !ids.contains(&id) {
                        ids.push(id);
                    }
                }
                // Nor is its arrow an arc.
                Stmt::Edge(e) if is_start(&e.attributes) => {}
                Stmt::Edge(_) => edges += 1,
                Stmt::Subgraph(sg) => todo.push(sg.stmts),
                _ => {}
            }
        }
    }
    (ids, edges)
}

/// Is this the edge from a machine's start dot (`class=start`)?
fn is_start(attrs: &[graphviz_rust::dot_structures::Attribute]) -> bool {
    attrs
        .iter()
        .any(|a| a.0 == Id::Plain("class".into()) && a.1 == Id::Plain("start".into()))
}

/// The drawing has the graph's vertices (plus `extra` outcome boxes) and
/// exactly its arcs.
fn assert_matches_graph(p: &Policy, dot: &str, extra: usize) {
    let g = btfsm_model::graph::policy_graph(p);
    let (ids, edges) = census(dot);
    assert_eq!(ids.len(), g.vertex_count() + extra, "nodes of\n{dot}");
    assert_eq!(edges, g.arc_count(), "edges of\n{dot}");
    for v in g.g.node_weights() {
        assert!(
            ids.contains(&quote(&v.key)) || ids.contains(&v.key),
            "vertex {} not drawn",
            v.key
        );
    }
}

#[test]
fn bt_golden() {
    let p = policy(BT);
    let dot = policy_dot(&p, &DotOptions::default());
    assert_matches_graph(&p, &dot, 0);
    insta::assert_snapshot!("bt", dot);
}

#[test]
fn fsm_golden() {
    let p = policy(FSM);
    let dot = policy_dot(&p, &DotOptions::default());
    assert_matches_graph(&p, &dot, 0);
    insta::assert_snapshot!("fsm", dot);
}

/// A parallel state (TOML `parallel = true`): its regions are dashed
/// clusters inside its box, one initial arc to each; `/done` is the
/// machine's outcome, taken from inside a region.
const PARALLEL: &str = include_str!("../../../../tests/fixtures/valid/parallel-regions.toml");

#[test]
fn parallel_golden() {
    let p = policy(PARALLEL);
    let dot = policy_dot(&p, &DotOptions::default());
    // Two regions with one outcome box each.
    assert_matches_graph(&p, &dot, 2);
    assert!(dot.contains("label=\"both ‖\""), "{dot}");
    assert_eq!(dot.matches("style=dashed").count(), 2, "{dot}");
    assert!(dot.contains("move -> done [label=FAILURE"), "{dot}");
    insta::assert_snapshot!("parallel", dot);
}

#[test]
fn hfsm_golden() {
    let p = policy(HFSM);
    let dot = policy_dot(&p, &DotOptions::default());
    // Two containers with three outcome boxes each.
    assert_matches_graph(&p, &dot, 6);
    assert!(dot.contains("subgraph cluster_fetch {"), "{dot}");
    assert!(dot.contains("subgraph \"cluster_at-cube\" {"), "{dot}");
    insta::assert_snapshot!("hfsm", dot);
}

#[test]
fn output_is_deterministic() {
    for text in [BT, FSM, HFSM] {
        let p = policy(text);
        let a = policy_dot(&p, &DotOptions::default());
        let b = policy_dot(&p.clone(), &DotOptions::default());
        assert_eq!(a, b);
    }
}

#[test]
fn ids_with_quotes_spaces_slashes_and_unicode_are_quoted() {
    let p = policy(
        r#"
kind = "bt"
name = "say \"hi\""
root = 'go "home" now'

[nodes]
'go "home" now' = { sequence = ["a/b", "ü→x", "back\\slash"] }
"a/b"   = { action = "Say \"hi\"!", skill = "Dock" }
"ü→x"   = { condition = "Ünïcode?", skill = "Found" }
"back\\slash" = { action = "C:\\dir\\", skill = "Dock" }
"#,
    );
    let dot = policy_dot(&p, &DotOptions::default());
    assert!(dot.starts_with("digraph \"say \\\"hi\\\"\" {"), "{dot}");
    assert!(dot.contains(r#""go \"home\" now" -> "a/b""#), "{dot}");
    assert!(dot.contains(r#""go \"home\" now" -> "ü→x""#), "{dot}");
    assert!(dot.contains(r#"label="Say \"hi\"!""#), "{dot}");
    assert!(dot.contains(r#"label="C:\\dir\\""#), "{dot}");
    let (ids, edges) = census(&dot);
    assert_eq!(ids.len(), 4);
    assert_eq!(edges, 3);
    // Graphviz itself accepts it, where installed.
    match render(&dot, RenderFormat::Svg, T) {
        Ok(svg) => {
            let svg = String::from_utf8(svg).unwrap();
            assert!(svg.contains("Say &quot;hi&quot;!"), "{svg}");
            assert!(svg.contains("Ünïcode?"), "{svg}");
            assert!(svg.contains(r"C:\dir\"), "{svg}");
        }
        Err(RenderError::NotInstalled { .. }) => {}
        Err(e) => panic!("{e}"),
    }
}

#[test]
fn plain_ids_stay_bare_and_keywords_are_quoted() {
    assert_eq!(dot_id("SELECTOR"), Id::Plain("SELECTOR".into()));
    assert_eq!(dot_id("0.5"), Id::Plain("0.5".into()));
    assert_eq!(dot_id("node"), Id::Escaped("\"node\"".into()));
    assert_eq!(dot_id("Node"), Id::Escaped("\"Node\"".into()));
    assert_eq!(dot_id(""), Id::Escaped("\"\"".into()));
    assert_eq!(dot_id("1.2.3"), Id::Escaped("\"1.2.3\"".into()));
    assert_eq!(quote("a\nb\tc\r"), "\"a\\nb c\"");
}

#[test]
fn missing_dot_is_a_clear_error() {
    let err = render_with(
        "btfsm-test-no-such-graphviz",
        "digraph { a }",
        RenderFormat::Svg,
        T,
    )
    .unwrap_err();
    assert!(matches!(err, RenderError::NotInstalled { .. }), "{err:?}");
    let msg = err.to_string();
    assert!(msg.contains("is not installed"), "{msg}");
    assert!(msg.contains("apt-get install graphviz"), "{msg}");
}

#[test]
fn graphviz_errors_are_reported() {
    match render("digraph { a -> }", RenderFormat::Svg, T) {
        Err(RenderError::Failed { stderr, .. }) => assert!(!stderr.is_empty()),
        Err(RenderError::NotInstalled { .. }) => {}
        other => panic!("expected a syntax error, got {other:?}"),
    }
}

/// The budget of the tests that run Graphviz.
const T: Duration = Duration::from_secs(60);

/// A fake Graphviz: a shell script in a scratch directory.
fn fake_graphviz(tag: &str, script: &str) -> std::path::PathBuf {
    use std::os::unix::fs::PermissionsExt;
    let dir = std::env::temp_dir().join(format!("btfsm-gv-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("dot");
    std::fs::write(&p, format!("#!/bin/sh\n{script}\n")).unwrap();
    std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
    p
}

/// Runs a fake Graphviz, retrying while the script is "busy" (another
/// test thread forked while it was open for writing).
fn run_fake(
    program: &std::path::Path,
    dot: &str,
    budget: Budget,
) -> (Result<(Vec<u8>, String), RenderError>, Duration) {
    for _ in 0..100 {
        let t0 = Instant::now();
        match run_graphviz(program.to_str().unwrap(), dot, RenderFormat::Svg, budget) {
            Err(RenderError::Io { source, .. }) if source.raw_os_error() == Some(26) => {
                std::thread::sleep(Duration::from_millis(20));
            }
            r => return (r, t0.elapsed()),
        }
    }
    panic!("{} stayed busy", program.display());
}

#[test]
fn graphviz_runs_under_a_deadline_and_an_output_cap() {
    let short = Budget::new(Duration::from_millis(300));
    // Answers: the output is what it wrote (here, its input).
    let cat = fake_graphviz("cat", "exec cat");
    let (r, _) = run_fake(&cat, "digraph { a }", short);
    assert_eq!(r.unwrap().0, b"digraph { a }");
    // Never answers; its `sleep` child holds the pipes: killed at the
    // deadline without waiting for them.
    let sleeper = fake_graphviz("sleep", "sleep 30");
    let (r, took) = run_fake(&sleeper, "digraph { a }", short);
    assert!(
        matches!(r, Err(RenderError::Timeout { ms: 300, .. })),
        "{r:?}"
    );
    assert!(took < Duration::from_secs(5), "{took:?}");
    let msg = r.unwrap_err().to_string();
    assert!(msg.contains("did not finish within 300 ms") && msg.contains("--timeout-ms"));
    // Does not read 8 MiB of input: no dead-lock either.
    let big = "x".repeat(8 << 20);
    let (r, took) = run_fake(&sleeper, &big, short);
    assert!(matches!(r, Err(RenderError::Timeout { .. })), "{r:?}");
    assert!(took < Duration::from_secs(5), "{took:?}");
    // Writes without end: stopped past the output cap.
    let flood = fake_graphviz("flood", "exec cat /dev/zero");
    let capped = Budget {
        max_output: 1 << 20,
        ..Budget::new(T)
    };
    let (r, took) = run_fake(&flood, "digraph { a }", capped);
    assert!(
        matches!(r, Err(RenderError::TooLarge { limit: 1048576, .. })),
        "{r:?}"
    );
    assert!(took < Duration::from_secs(10), "{took:?}");
    // Floods its stderr and fails: the message keeps the first bytes.
    let noisy = fake_graphviz("noisy", "yes e | head -c 4000000 >&2; exit 3");
    let (r, _) = run_fake(&noisy, "digraph { a }", Budget::new(T));
    match r {
        Err(RenderError::Failed { stderr, .. }) => {
            // 64 KiB of `e\n`, trimmed.
            assert_eq!(stderr.len() as u64, MAX_RENDER_STDERR_BYTES - 1);
        }
        r => panic!("{r:?}"),
    }
    for p in [cat, sleeper, flood, noisy] {
        let _ = std::fs::remove_dir_all(p.parent().unwrap());
    }
}

/// Added and changed elements are drawn in colours that no transition
/// label, guard, status fill or ghost uses (issue 15, point 5).
#[test]
fn diff_colours_are_used_by_no_transition_label() {
    let statuses = [Status::Running, Status::Success, Status::Failure];
    let mut taken: Vec<&str> = statuses.iter().map(|s| s.line_color()).collect();
    taken.extend(statuses.iter().map(|s| s.fill_color()));
    taken.extend([GUARD, REMOVED, "black"]);
    for c in [ADDED, CHANGED] {
        assert!(!taken.contains(&c), "{c}");
    }
    assert_ne!(ADDED, CHANGED);
}

#[test]
fn highlights_and_ghosts() {
    let p = policy(FSM);
    let mut opts = DotOptions::default();
    opts.highlight.insert("Pick cube2".into(), Highlight::Added);
    opts.highlight
        .insert("SELECTOR".into(), Highlight::Status(Status::Running));
    opts.highlight.insert("SUCCESS".into(), Highlight::Removed);
    opts.arc_highlight.insert(
        ("Move-To cube2".into(), "Pick cube2".into()),
        Highlight::Added,
    );
    opts.ghost_vertices
        .push(("Tuck arm".into(), "Tuck arm".into()));
    opts.ghost_arcs
        .push(("Pick cube2".into(), "Tuck arm".into(), "SUCCESS".into()));
    opts.ghost_arcs
        .push(("Tuck arm".into(), "gone".into(), String::new()));
    let dot = policy_dot(&p, &opts);
    let line = |id: &str| {
        dot.lines()
            .find(|l| l.trim_start().starts_with(id))
            .unwrap_or_else(|| panic!("no line for {id} in\n{dot}"))
            .to_string()
    };
    assert!(line("\"Pick cube2\"[").contains("color=magenta"), "{dot}");
    assert!(line("SELECTOR[").contains("fillcolor=gold"), "{dot}");
    assert!(line("SUCCESS[").contains("style=dashed"), "{dot}");
    assert!(line("\"Tuck arm\"[").contains("style=dashed"), "{dot}");
    assert!(line("gone[").contains("color=grey55"), "{dot}");
    assert!(
        line("\"Move-To cube2\" -> \"Pick cube2\"").contains("color=magenta"),
        "{dot}"
    );
    assert!(
        line("\"Pick cube2\" -> \"Tuck arm\"").contains("style=dashed"),
        "{dot}"
    );
    // Ghosts add to the drawing, never to the policy's own elements; a
    // status fill adds the status legend's three samples.
    let (ids, edges) = census(&dot);
    assert_eq!((ids.len(), edges), (4 + 2 + 3, 10 + 2));
}

#[test]
fn hfsm_ghost_goes_into_its_cluster_and_arcs_target_outcome_boxes() {
    let p = policy(HFSM);
    let mut opts = DotOptions::default();
    opts.ghost_vertices
        .push(("at-cube/old".into(), "Old!".into()));
    opts.arc_highlight
        .insert(("pick".into(), "fetch".into()), Highlight::Removed);
    opts.arc_label_highlight.insert(
        ("pick".into(), "fetch".into(), "SUCCESS".into()),
        Highlight::Status(Status::Success),
    );
    let dot = policy_dot(&p, &opts);
    let cluster = dot
        .find("subgraph \"cluster_at-cube\"")
        .expect("inner cluster");
    let ghost = dot.find("\"at-cube/old\"[").expect("ghost");
    assert!(ghost > cluster, "{dot}");
    // pick's SUCCESS goes to fetch's SUCCESS box, highlighted.
    let arc = dot
        .lines()
        .find(|l| l.contains("pick -> \"fetch/SUCCESS\""))
        .expect("arc to the outcome box");
    assert!(arc.contains("penwidth=3"), "{arc}");
    // Its parallel arcs get the (from, to) highlight.
    let other = dot
        .lines()
        .find(|l| l.contains("pick -> \"fetch/FAILURE\""))
        .expect("parallel arc");
    assert!(other.contains("style=dashed"), "{other}");
    // fetch's own SUCCESS transition leaves from that box.
    assert!(dot.contains("\"fetch/SUCCESS\" -> SUCCESS"), "{dot}");
}

#[test]
fn deep_hfsm_nesting_is_capped() {
    use btfsm_model::{Region, State, StateMachine, Transition};
    const DEPTH: usize = 3 * MAX_CLUSTER_NESTING;
    let ok = || vec!["SUCCESS".to_string()];
    let to_success = || Transition {
        trigger: Trigger::Outcome("SUCCESS".into()),
        target: Target::Outcome("SUCCESS".into()),
        span: None,
    };
    // Containers 0..DEPTH, each holding the next; a task at the bottom.
    let mut states: Vec<State> = (0..DEPTH)
        .map(|k| State {
            name: format!("c{k}"),
            label: format!("C{k}"),
            parent: k.checked_sub(1),
            body: StateBody::Container(Region::at(k + 1, ok(), vec![k + 1])),
            transitions: vec![to_success()],
            pseudo: None,
            span: None,
        })
        .collect();
    states.push(State {
        name: "work".into(),
        label: "Work!".into(),
        parent: Some(DEPTH - 1),
        body: StateBody::Task(None),
        transitions: vec![to_success()],
        pseudo: None,
        span: None,
    });
    let p = Policy {
        name: "deep".into(),
        description: None,
        body: PolicyBody::Machine(StateMachine {
            hierarchical: true,
            top: Region::at(0, ok(), vec![0]),
            states,
        }),
    };
    let dot = policy_dot(&p, &DotOptions::default());
    assert_matches_graph(&p, &dot, DEPTH);
    assert_eq!(
        dot.matches("subgraph \"cluster_").count() + dot.matches("subgraph cluster_").count(),
        DEPTH
    );
    let mut depth = 0usize;
    let mut max = 0;
    for c in dot.chars() {
        match c {
            '{' => {
                depth += 1;
                max = max.max(depth);
            }
            '}' => depth -= 1,
            _ => {}
        }
    }
    // digraph + clusters + the innermost rank group.
    assert!(max <= MAX_CLUSTER_NESTING + 2, "nesting {max}");
}

/// Every bundled policy draws as its graph and, where Graphviz is
/// installed, renders without warnings. With `BTFSM_RENDER_DIR` set, the
/// PNGs are written there for a look.
#[test]
fn bundled_policies_draw_and_render() {
    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("policies/paper");
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return;
    };
    let mut files: Vec<_> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    let out = std::env::var_os("BTFSM_RENDER_DIR").map(std::path::PathBuf::from);
    for f in files {
        // Files being edited by others may not load; they are not ours to test.
        let Ok(loaded) = btfsm_format::load(&f, &Default::default()) else {
            continue;
        };
        let p = loaded.policy;
        let dot = policy_dot(&p, &DotOptions::default());
        let extra = match &p.body {
            PolicyBody::Machine(m) => m
                .states
                .iter()
                .map(|s| match &s.body {
                    StateBody::Container(r) => r.outcomes.len(),
                    _ => 0,
                })
                .sum(),
            PolicyBody::Bt(_) => 0,
        };
        assert_matches_graph(&p, &dot, extra);
        let format = if out.is_some() {
            RenderFormat::Png
        } else {
            RenderFormat::Svg
        };
        match run_graphviz("dot", &dot, format, Budget::new(T)) {
            Ok((bytes, warnings)) => {
                assert!(warnings.is_empty(), "{}: {warnings}", f.display());
                if let Some(out) = &out {
                    let name = f.file_stem().unwrap().to_string_lossy().to_string();
                    std::fs::write(out.join(format!("{name}.png")), bytes).unwrap();
                    std::fs::write(out.join(format!("{name}.dot")), &dot).unwrap();
                }
            }
            Err(RenderError::NotInstalled { .. }) => return,
            Err(e) => panic!("{}: {e}", f.display()),
        }
    }
}
