//! Unit tests of the relabels and reorders (`changes.rs`) and of how the
//! table, markdown, JSON and diff drawing show them (issue 15, points 1
//! and 5).

use super::*;
use btfsm_format::toml::parse_str;
use std::path::Path;

fn policy(src: &str) -> Policy {
    parse_str("test.toml", src, Path::new(""), &Default::default())
        .expect("valid")
        .policy
}

fn paper(name: &str) -> String {
    std::fs::read_to_string(format!(
        "{}/../../policies/paper/{name}",
        env!("CARGO_MANIFEST_DIR")
    ))
    .expect("paper policy")
}

fn all_modes(a: &Policy, b: &Policy) -> CompareReport {
    let side = |policy| Side {
        file: "test.toml",
        policy,
    };
    let pair = Pair::new(side(a), side(b));
    let modes = modes_of(None)
        .into_iter()
        .map(|m| pair.run(m, &GedOptions::default()))
        .collect();
    pair.report(modes)
}

fn texts(r: &CompareReport) -> [String; 3] {
    [render_table(r), render_markdown(r), render_json(r)]
}

#[test]
fn fig01_to_fig03_reports_the_new_priority_of_deliver_in_every_mode_and_format() {
    let (a, b) = (
        policy(&paper("fig01-bt.toml")),
        policy(&paper("fig03-bt.toml")),
    );
    let r = all_modes(&a, &b);
    for m in &r.modes {
        // The paper's distance is unchanged: the graphs are isomorphic.
        assert_eq!((m.ged, m.reorders, m.relabels), (0, 1, 0), "{:?}", m.mode);
        let o = &m.edit_script.reordered[0];
        assert_eq!((o.of, o.key.as_str()), ("children", "deliver"));
        let names = |l: &[Text]| l.iter().map(|t| t.to_string()).collect::<Vec<_>>();
        assert_eq!(names(&o.before), ["held", "reached-delivery", "place"]);
        assert_eq!(names(&o.after), ["reached-delivery", "held", "place"]);
    }
    let [table, md, json] = texts(&r);
    assert!(table.contains(
        "~ order of `deliver`: held, reached-delivery → reached-delivery, held (the priority of its children changed)"
    ), "{table}");
    assert!(!table.contains("identical"), "{table}");
    // Markdown: the change is the first thing after the title.
    let first = md.lines().find(|l| l.starts_with("- ")).expect("a change");
    assert!(
        first.contains("order of `deliver`") && first.contains("priority"),
        "{md}"
    );
    assert!(md.find("order of `deliver`") < md.find("| mode |"), "{md}");
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    for m in ["structural", "labeled", "named"] {
        assert_eq!(v[m]["reorders"], 1);
        assert_eq!(v[m]["ged"], 0);
        assert_eq!(v[m]["edit_script"]["reordered"][0]["key"], "deliver");
    }
}

#[test]
fn fig01_root_fallback_turned_sequence_is_a_type_relabel() {
    let src = paper("fig01-bt.toml");
    let changed = src.replace(
        "moma             = { fallback =",
        "moma             = { sequence =",
    );
    assert_ne!(src, changed);
    let r = all_modes(&policy(&src), &policy(&changed));
    let named = r.mode(GedMode::Named).unwrap();
    assert_eq!((named.ged, named.relabels, named.reorders), (0, 1, 0));
    let l = &named.edit_script.relabelled[0];
    assert_eq!((l.what, l.key.as_str()), ("type", "moma"));
    assert_eq!(
        (l.before.as_str(), l.after.as_str()),
        ("fallback", "sequence")
    );
    // `labeled` matches only equal types: moma is replaced there, at cost.
    let labeled = r.mode(GedMode::Labeled).unwrap();
    assert!(labeled.ged > 0);
    for t in texts(&r) {
        assert!(t.contains("fallback") && t.contains("sequence"), "{t}");
    }
    assert!(render_table(&r).contains("~ type of `moma`: fallback → sequence"));
}

const FSM: &str = r#"
kind = "fsm"
initial = "Go"
outcomes = ["SUCCESS"]
[states.Go]
skill = "Move-To"
args = { target = "cube2" }
guards = [
  { unless = "No-Emergency", to = "Stop", label = "emergency" },
  { unless = "Battery-Level", args = { min = 20 }, to = "Stop", label = "battery low" },
]
on = { SUCCESS = "Pick", FAILURE = "Go", RUNNING = "Go" }
[states.Pick]
skill = "Pick"
args = { object = "cube2" }
on = { SUCCESS = "SUCCESS", FAILURE = "Go", RUNNING = "Pick" }
[states.Stop]
skill = "Dock"
on = { SUCCESS = "Go", FAILURE = "Stop", RUNNING = "Stop" }
"#;

#[test]
fn a_state_bound_to_another_skill_is_a_skill_and_arguments_relabel() {
    let b = FSM.replace(
        "skill = \"Pick\"\nargs = { object = \"cube2\" }",
        "skill = \"Place\"\nargs = { object = \"cube2\", at = \"delivery\" }",
    );
    let r = all_modes(&policy(FSM), &policy(&b));
    let named = r.mode(GedMode::Named).unwrap();
    assert_eq!(named.ged, 0);
    let got: Vec<(&str, &str, &str, &str)> = named
        .edit_script
        .relabelled
        .iter()
        .map(|l| (l.what, l.key.as_str(), l.before.as_str(), l.after.as_str()))
        .collect();
    assert_eq!(
        got,
        [
            ("skill", "Pick", "Pick", "Place"),
            (
                "arguments",
                "Pick",
                "object=cube2",
                "at=delivery, object=cube2"
            ),
        ]
    );
    assert_eq!(named.relabels, 2);
    let table = render_table(&r);
    assert!(table.contains("~ skill of `Pick`: Pick → Place"), "{table}");
}

#[test]
fn a_changed_guard_is_reported_with_its_terms() {
    let b = FSM.replace("args = { min = 20 }", "args = { min = 35 }");
    let r = all_modes(&policy(FSM), &policy(&b));
    let named = r.mode(GedMode::Named).unwrap();
    assert_eq!((named.ged, named.relabels), (0, 1));
    let l = &named.edit_script.relabelled[0];
    assert_eq!((l.what, l.key.as_str()), ("guard", "Go"));
    assert_eq!(l.to.as_deref(), Some("Stop"));
    assert!(
        l.before.contains("min=20") && l.after.contains("min=35"),
        "{l:?}"
    );
    for t in texts(&r) {
        assert!(t.contains("min=35"), "{t}");
    }
}

#[test]
fn guards_checked_in_another_order_are_a_reorder() {
    let b = FSM.replace(
        "  { unless = \"No-Emergency\", to = \"Stop\", label = \"emergency\" },\n  { unless = \"Battery-Level\", args = { min = 20 }, to = \"Stop\", label = \"battery low\" },",
        "  { unless = \"Battery-Level\", args = { min = 20 }, to = \"Stop\", label = \"battery low\" },\n  { unless = \"No-Emergency\", to = \"Stop\", label = \"emergency\" },",
    );
    assert_ne!(b, FSM);
    let r = all_modes(&policy(FSM), &policy(&b));
    let named = r.mode(GedMode::Named).unwrap();
    assert_eq!((named.ged, named.reorders, named.relabels), (0, 1, 0));
    let o = &named.edit_script.reordered[0];
    assert_eq!((o.of, o.key.as_str()), ("guards", "Go"));
    assert_eq!(o.before[0].as_str(), "emergency");
    assert_eq!(o.after[0].as_str(), "battery low");
}

#[test]
fn a_changed_initial_state_is_a_relabel_at_every_level() {
    let src = paper("fig06-hfsm.toml");
    let b = src.replacen("initial = \"at-cube\"", "initial = \"move-to-cube\"", 1);
    assert_ne!(src, b);
    let r = all_modes(&policy(&src), &policy(&b));
    let named = r.mode(GedMode::Named).unwrap();
    // The container's arc to its initial state moves (2 arc edits) and is
    // told as what it is.
    assert_eq!(named.ged, 2);
    let l = &named.edit_script.relabelled[0];
    assert_eq!((l.what, l.key.as_str()), ("initial", "reached-cube"));
    assert_eq!(
        (l.before.as_str(), l.after.as_str()),
        ("at-cube", "move-to-cube")
    );
    // The top-level initial state is not a vertex: GED 0, still reported.
    let top = FSM.replace("initial = \"Go\"", "initial = \"Pick\"");
    let r = all_modes(&policy(FSM), &policy(&top));
    let named = r.mode(GedMode::Named).unwrap();
    assert_eq!((named.ged, named.relabels), (0, 1));
    assert!(render_table(&r).contains("~ initial state: Go → Pick"));
}

#[test]
fn unchanged_policies_have_no_relabel_nor_reorder() {
    for f in [
        "fig01-bt.toml",
        "fig04-fsm.toml",
        "fig06-hfsm.toml",
        "fig09b-fsm.toml",
    ] {
        let p = policy(&paper(f));
        let r = all_modes(&p, &p);
        for m in &r.modes {
            assert!(m.edit_script.is_unchanged(), "{f} {:?}", m.mode);
        }
        assert!(render_table(&r).contains("identical"));
        assert!(render_markdown(&r).contains("**What changed** (named mapping): nothing"));
    }
}

/// A BT whose root Sequence has `n` condition leaves, in order or reversed.
fn wide_bt(n: usize, reversed: bool) -> String {
    let mut ids: Vec<String> = (0..n).map(|i| format!("c{i}")).collect();
    if reversed {
        ids.reverse();
    }
    let list: Vec<String> = ids.iter().map(|i| format!("\"{i}\"")).collect();
    let mut s = format!(
        "kind = \"bt\"\nroot = \"r\"\n[nodes]\nr = {{ sequence = [{}] }}\n",
        list.join(", ")
    );
    for i in 0..n {
        s.push_str(&format!(
            "c{i} = {{ condition = \"C{i}\", skill = \"Found\" }}\n"
        ));
    }
    s
}

#[test]
fn a_long_reorder_is_cut_in_every_line_and_a_large_diff_is_not_drawn() {
    let (a, b) = (policy(&wide_bt(200, false)), policy(&wide_bt(200, true)));
    let side = |policy| Side {
        file: "test.toml",
        policy,
    };
    let pair = Pair::new(side(&a), side(&b));
    let r = pair.report(vec![pair.run(GedMode::Named, &GedOptions::default())]);
    let m = r.mode(GedMode::Named).unwrap();
    assert_eq!((m.ged, m.reorders), (0, 1));
    assert_eq!(m.edit_script.reordered[0].before.len(), 200);
    let table = render_table(&r);
    let line = table.lines().find(|l| l.contains("order of `r`")).unwrap();
    assert!(line.contains("(192 more)") && line.len() < 200, "{line}");
    let md = render_markdown(&r);
    assert!(
        md.contains("The diff diagram is left out: 201 nodes"),
        "{md}"
    );
    assert!(!md.contains("```mermaid"));
    let note = &pair.dot_options(&m.edit_script).changed["r"];
    assert!(note.len() < 200, "{note}");
    // Small enough: drawn, with the note.
    let (a, b) = (policy(&wide_bt(5, false)), policy(&wide_bt(5, true)));
    let r = all_modes(&a, &b);
    assert!(render_markdown(&r).contains("```mermaid\n"));
}

#[test]
fn a_bt_leaf_with_other_arguments_is_an_arguments_relabel() {
    let src = paper("fig01-bt.toml");
    let b = src.replace(
        "skill = \"Move-To\", args = { target = \"delivery\" }",
        "skill = \"Move-To\", args = { target = \"home\" }",
    );
    assert_ne!(src, b);
    let r = all_modes(&policy(&src), &policy(&b));
    let named = r.mode(GedMode::Named).unwrap();
    let got: Vec<(&str, &str, &str, &str)> = named
        .edit_script
        .relabelled
        .iter()
        .map(|l| (l.what, l.key.as_str(), l.before.as_str(), l.after.as_str()))
        .collect();
    assert_eq!(
        got,
        [(
            "arguments",
            "move-to-delivery",
            "target=delivery",
            "target=home"
        )]
    );
}

#[test]
fn a_relabelled_transition_is_drawn_with_its_old_label() {
    let b = FSM.replace("label = \"battery low\"", "label = \"battery critical\"");
    let (pa, pb) = (policy(FSM), policy(&b));
    let side = |policy| Side {
        file: "test.toml",
        policy,
    };
    let pair = Pair::new(side(&pa), side(&pb));
    let m = pair.run(GedMode::Named, &GedOptions::default());
    assert_eq!((m.ged, m.relabels), (0, 1));
    let opts = pair.dot_options(&m.edit_script);
    let dot = btfsm_render::dot::policy_dot(&pb, &opts);
    let arc = dot
        .lines()
        .find(|l| l.contains("battery critical"))
        .expect("the arc");
    assert!(
        arc.contains("battery critical\\n(was battery low)") && arc.contains("darkorange3"),
        "{arc}"
    );
    let mermaid = pair.diff_mermaid(&opts).expect("small");
    assert!(
        mermaid.contains("|\"battery critical (was battery low)\"|"),
        "{mermaid}"
    );
}

#[test]
fn the_drawings_title_names_both_files_escaped() {
    let p = policy(FSM);
    let pair = Pair::new(
        Side {
            file: "evil\u{1b}[31m\n.toml",
            policy: &p,
        },
        Side {
            file: "b.toml",
            policy: &p,
        },
    );
    let m = pair.run(GedMode::Named, &GedOptions::default());
    let opts = pair.dot_options(&m.edit_script);
    let title = opts.title.clone().unwrap();
    assert_eq!(title, "evil\\u{1b}[31m\\n.toml → b.toml");
    let dot = btfsm_render::dot::policy_dot(&p, &opts);
    assert!(!btfsm_core::sanitize::has_raw_control(&dot), "{dot}");
    let mermaid = pair.diff_mermaid(&opts).unwrap();
    assert!(
        !btfsm_core::sanitize::has_raw_control(&mermaid),
        "{mermaid}"
    );
    assert!(
        mermaid.contains("title: 'evil\\u{1b}[31m\\n.toml → b.toml'"),
        "{mermaid}"
    );
}
