//! The dataflow rules on small BehaviorTree.CPP trees: silence without a
//! model, SubTree blackboards, scripts, literals given by SubTrees, the
//! tree's declared ports, built-ins, and linear work on large inputs.

use super::*;
use std::path::Path;

/// The codes `lint` reports on BehaviorTree.CPP XML `xml`, with the
/// message of each.
/// (`key-never-read`, off by default, on.)
fn run(xml: &str) -> Vec<(String, String)> {
    let mut cfg = config::Config::default();
    cfg.set("key-never-read", Level::Note).unwrap();
    run_with(xml, &cfg)
}

/// [`run`] at the levels of `cfg`.
fn run_with(xml: &str, cfg: &config::Config) -> Vec<(String, String)> {
    // Read as `lint` reads (a Sleep without `msec` loads: the rule says).
    let limits = btfsm_format::Limits {
        for_lint: true,
        ..Default::default()
    };
    let l = btfsm_format::btcpp_xml::parse_str("t.xml", xml, Path::new("."), &limits)
        .unwrap_or_else(|e| panic!("{e:?}"));
    let s = Subject {
        policy: &l.policy,
        dataflow: l.dataflow.as_deref(),
    };
    lint_subject(&s, None, "t.xml", cfg)
        .into_iter()
        .map(|f| (f.code.to_string(), f.message))
        .collect()
}

fn codes(xml: &str) -> Vec<String> {
    run(xml).into_iter().map(|(c, _)| c).collect()
}

const MODEL: &str = r#"<TreeNodesModel>
  <Action ID="Detect"><output_port name="pose" type="Pose"/></Action>
  <Action ID="Pick"><input_port name="pose" type="Pose"/></Action>
</TreeNodesModel>"#;

fn tree(body: &str, extra: &str) -> String {
    format!(
        r#"<root BTCPP_format="4" main_tree_to_execute="Main"><BehaviorTree ID="Main">{body}</BehaviorTree>{extra}</root>"#
    )
}

#[test]
fn dataflow_rules_are_silent_without_a_model() {
    // Nav2-style nodes with no model: directions unknown, nothing judged.
    let xml = tree(
        r#"<Sequence>
             <Action ID="ComputePathToPose" goal="{goal}" path="plan" junk="1"/>
             <Action ID="FollowPath" path="{path}"/>
             <Action ID="Report" error_code_id="{code}"/>
           </Sequence>"#,
        "",
    );
    assert_eq!(codes(&xml), Vec::<String>::new());
    // A `{key}` on an unmodelled node may write it: the modelled reader
    // before it is not reported, nor the modelled writer after it. (The
    // file's model declares the tree's other types: `Mystery` is an
    // `unknown-node-type`.)
    let xml = tree(
        r#"<Sequence><Pick pose="{p}"/><Action ID="Mystery" x="{p}"/><Detect pose="{q}"/></Sequence>"#,
        MODEL,
    );
    assert_eq!(
        codes(&xml),
        ["key-never-read", "unknown-node-type"],
        "{:?}",
        run(&xml)
    );
}

#[test]
fn subtrees_have_their_own_blackboard() {
    let sub = r#"<BehaviorTree ID="Find"><Detect pose="{pose}"/></BehaviorTree>"#;
    // The subtree writes its own `pose`; the parent's is another entry.
    let xml = tree(
        r#"<Sequence><SubTree ID="Find"/><Pick pose="{pose}"/></Sequence>"#,
        &format!("{sub}{MODEL}"),
    );
    let found = run(&xml);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].0, "key-never-read");
    assert!(
        found[0].1.contains("{pose} (of SubTree `Find`)"),
        "{found:?}"
    );
    // Remapped, or shared by name: one entry, written then read.
    for attrs in [r#"pose="{pose}""#, r#"pose="{=}""#, r#"_autoremap="true""#] {
        let xml = tree(
            &format!(r#"<Sequence><SubTree ID="Find" {attrs}/><Pick pose="{{pose}}"/></Sequence>"#),
            &format!("{sub}{MODEL}"),
        );
        assert_eq!(codes(&xml), Vec::<String>::new(), "{attrs}");
    }
    // Read inside a subtree, given by nothing: the subtree's own entry.
    let xml = tree(
        r#"<SubTree ID="Use"/>"#,
        &format!(r#"<BehaviorTree ID="Use"><Pick pose="{{pose}}"/></BehaviorTree>{MODEL}"#),
    );
    assert_eq!(codes(&xml), ["read-before-write"]);
    // A literal on the SubTree gives it.
    let xml = tree(
        r#"<SubTree ID="Use" pose="1;2;3"/>"#,
        &format!(r#"<BehaviorTree ID="Use"><Pick pose="{{pose}}"/></BehaviorTree>{MODEL}"#),
    );
    assert_eq!(codes(&xml), Vec::<String>::new());
    // `{@key}` is the root's entry.
    let xml = tree(
        r#"<Sequence><Detect pose="{pose}"/><SubTree ID="Use"/></Sequence>"#,
        &format!(r#"<BehaviorTree ID="Use"><Pick pose="{{@pose}}"/></BehaviorTree>{MODEL}"#),
    );
    assert_eq!(codes(&xml), Vec::<String>::new());
}

#[test]
fn scripts_and_set_blackboard_write_entries() {
    let ok = tree(
        r#"<Sequence><Script code="n := 3"/><SetBlackboard value="{n}" output_key="m"/><Sleep msec="{m}"/></Sequence>"#,
        "",
    );
    assert_eq!(codes(&ok), Vec::<String>::new());
    let late = tree(
        r#"<Sequence><Sleep msec="{n}"/><Script code="n := 3"/></Sequence>"#,
        "",
    );
    assert_eq!(codes(&late), ["read-before-write"]);
    // A SubTree element's scripts use the enclosing tree's entries.
    let sub = tree(
        r#"<Sequence><Script code="done := false"/><SubTree ID="S" _skipIf="done"/></Sequence>"#,
        r#"<BehaviorTree ID="S"><AlwaysSuccess/></BehaviorTree>"#,
    );
    assert_eq!(codes(&sub), Vec::<String>::new());
    // Names a script only reads may be enums: never "read before write".
    let enums = tree(
        r#"<Sequence><Script code="mode == IDLE"/><AlwaysSuccess _onSuccess="mode = BUSY"/></Sequence>"#,
        "",
    );
    assert_eq!(codes(&enums), Vec::<String>::new());
}

#[test]
fn declared_tree_ports_are_the_applications() {
    let model = r#"<TreeNodesModel>
      <SubTree ID="Main"><input_port name="goal"/><output_port name="done"/></SubTree>
      <Action ID="Go"><input_port name="goal"/><output_port name="done"/></Action>
    </TreeNodesModel>"#;
    let xml = tree(r#"<Go goal="{goal}" done="{done}"/>"#, model);
    assert_eq!(codes(&xml), Vec::<String>::new());
    // A key the interface does not give is read before anything writes it.
    let xml = tree(r#"<Go goal="{target}" done="{done}"/>"#, model);
    assert_eq!(codes(&xml), ["read-before-write"]);
}

#[test]
fn built_in_ports_are_btcpp_4s() {
    let xml = tree(r#"<Sleep msec="10" duration="1"/>"#, "");
    let found = run(&xml);
    assert_eq!(found[0].0, "undeclared-port");
    assert!(
        found[0]
            .1
            .contains("the built-in `Sleep` declares no port `duration`")
    );
    assert_eq!(codes(&tree("<Sleep/>", "")), ["missing-required-port"]);
    let v3 = r#"<root BTCPP_format="3" main_tree_to_execute="Main"><BehaviorTree ID="Main"><Sleep msec="10" duration="1"/></BehaviorTree></root>"#;
    assert_eq!(codes(v3), Vec::<String>::new());
    // LoopInt writes `value` (an int); `_` attributes are not ports.
    let xml = tree(
        r#"<LoopInt queue="1;2" value="{v}" _description="x"><Repeat num_cycles="{v}"><AlwaysSuccess/></Repeat></LoopInt>"#,
        "",
    );
    assert_eq!(codes(&xml), Vec::<String>::new());
    // Sleep's `msec` is an unsigned int: BehaviorTree.CPP 4 refuses the
    // tree ("initially created with type [int] and, later type [unsigned
    // int]").
    let xml = tree(
        r#"<LoopInt queue="1;2" value="{v}"><Sleep msec="{v}"/></LoopInt>"#,
        "",
    );
    assert_eq!(codes(&xml), ["port-type-mismatch"]);
}

#[test]
fn dataflow_rules_are_linear_in_nodes_and_ports() {
    // 2,000 declared ports and 5,000 nodes each giving none of them, and
    // each writing and reading its own keys: 10 million pairs if compared
    // pairwise.
    let ports: String = (0..2000)
        .map(|i| format!(r#"<input_port name="p{i}"/>"#))
        .collect();
    let nodes: String = (0..5000)
        .map(|i| format!(r#"<Detect pose="{{k{i}}}"/><Pick pose="{{k{i}}}" x="1"/>"#))
        .collect();
    let xml = tree(
        &format!("<Sequence>{nodes}</Sequence>"),
        &format!(
            r#"<TreeNodesModel><Action ID="Detect"><output_port name="pose"/></Action><Action ID="Pick"><input_port name="pose"/>{ports}</Action></TreeNodesModel>"#
        ),
    );
    let t = std::time::Instant::now();
    let mut cfg = config::Config::default();
    cfg.set("missing-model-port", Level::Warning).unwrap();
    let found = run_with(&xml, &cfg);
    assert_eq!(
        found.iter().filter(|f| f.0 == "missing-model-port").count(),
        5000
    );
    assert_eq!(
        found.iter().filter(|f| f.0 == "undeclared-port").count(),
        5000
    );
    assert!(t.elapsed().as_secs() < 20, "{:?}", t.elapsed());
}

/// A tree with every dataflow feature: models with ports, SubTrees with
/// remaps, literals and `_autoremap`, scripts, `{@key}`, built-ins.
const SEED: &str = r#"<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence _skipIf="stop == true">
      <Script code="n := 1; m += n"/>
      <Detect pose="{pose}"/>
      <SubTree ID="Sub" target="{pose}" count="3" out="{res}"/>
      <SubTree ID="Sub" _autoremap="true"/>
      <LoopInt queue="1;2" value="{v}"><Sleep msec="{v}"/></LoopInt>
      <SetBlackboard value="{res}" output_key="copy"/>
      <Pick pose="{@pose}" extra="1"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Sub">
    <Fallback>
      <Pick pose="{target}"/>
      <Detect pose="{out}"/>
      <Precondition if="count > 1"><Repeat num_cycles="{count}"><AlwaysSuccess/></Repeat></Precondition>
    </Fallback>
  </BehaviorTree>
  <TreeNodesModel>
    <SubTree ID="Main"><input_port name="stop"/></SubTree>
    <Action ID="Detect"><output_port name="pose" type="Pose"/></Action>
    <Condition ID="Pick"><input_port name="pose" type="Pose" default="{x}"/><inout_port name="io"/></Condition>
  </TreeNodesModel>
</root>"#;

#[test]
fn the_seed_tree_reads_and_lints() {
    let found = codes(SEED);
    assert!(found.contains(&"undeclared-port".to_string()), "{found:?}");
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 300, ..Default::default() })]

    /// Mutated dataflow trees never panic the rules.
    #[test]
    fn mutated_dataflow_trees_never_panic(
        cuts in proptest::collection::vec((0usize..2000, 0usize..8, "[<>/={}@:;\" a-zA-Z_]{0,3}"), 1..4)
    ) {
        let text = btfsm_format::xml::mutate(SEED, &cuts);
        if let Ok(l) = btfsm_format::btcpp_xml::parse_str("t.xml", &text, Path::new("."), &Default::default()) {
            let s = Subject { policy: &l.policy, dataflow: l.dataflow.as_deref() };
            let _ = lint_subject(&s, None, "t.xml", &config::Config::default());
        }
    }
}

#[test]
fn a_read_in_a_fallback_branch_before_the_writer_is_the_check_else_compute_idiom() {
    // Nav2's navigate_w_replanning_only_if_path_becomes_invalid.xml: the
    // first branch checks {path} (failing while it is unset), the second
    // computes it. Not reported; the same order under a Sequence is.
    let model = r#"<TreeNodesModel>
      <Action ID="ValidatePath"><input_port name="path"/></Action>
      <Action ID="ComputePath"><output_port name="path"/></Action>
      <Action ID="Follow"><input_port name="path"/></Action>
    </TreeNodesModel>"#;
    let fallback = tree(
        r#"<Sequence><Fallback><ValidatePath path="{path}"/><ComputePath path="{path}"/></Fallback><Follow path="{path}"/></Sequence>"#,
        model,
    );
    assert_eq!(codes(&fallback), Vec::<String>::new());
    let sequence = tree(
        r#"<Sequence><ValidatePath path="{path}"/><ComputePath path="{path}"/><Follow path="{path}"/></Sequence>"#,
        model,
    );
    assert_eq!(codes(&sequence), ["read-before-write"]);
    // Deep in the first branch of a Fallback inside a Sequence: the
    // lowest common ancestor decides (a Fallback: not reported).
    let deep = tree(
        r#"<Sequence><Fallback><Inverter><Sequence><AlwaysSuccess/><ValidatePath path="{path}"/></Sequence></Inverter><Sequence><AlwaysSuccess/><ComputePath path="{path}"/></Sequence></Fallback><Follow path="{path}"/></Sequence>"#,
        model,
    );
    assert_eq!(codes(&deep), Vec::<String>::new());
}

#[test]
fn the_trees_own_entries_written_and_never_read_are_the_applications() {
    // Nav2's error codes: written by the tree for the navigator. Not
    // reported, unless the tree declares its ports or the entry is close
    // to one that is read (a misspelling).
    let model = r#"<TreeNodesModel>
      <Action ID="Plan"><input_port name="goal"/><output_port name="error_code_id"/></Action>
    </TreeNodesModel>"#;
    let app = tree(
        r#"<Plan goal="{goal}" error_code_id="{plan_error_code}"/>"#,
        model,
    );
    assert_eq!(codes(&app), Vec::<String>::new());
    let typo = tree(
        r#"<Sequence><Plan goal="{goal}" error_code_id="{gaol}"/><Plan goal="{gaol_x}"/></Sequence>"#,
        model,
    );
    let found = run(&typo);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(found[0].1.contains("writes {gaol}"), "{found:?}");
    let declared = tree(
        r#"<Plan goal="{goal}" error_code_id="{plan_error_code}"/>"#,
        &model.replace(
            "<TreeNodesModel>",
            r#"<TreeNodesModel><SubTree ID="Main"><input_port name="goal"/></SubTree>"#,
        ),
    );
    assert_eq!(codes(&declared), ["key-never-read"]);
}

#[test]
fn a_subtree_remapping_no_node_reads_is_not_reported() {
    // MoveIt Studio objectives pass `{parameters}` down SubTrees that do
    // not use it: a dead remapping, harmless.
    let xml = r#"<root BTCPP_format="4" main_tree_to_execute="Main">
      <BehaviorTree ID="Main"><Sequence><SubTree ID="Sub" parameters="{parameters}"/><SubTree ID="Read" p="{parameters}"/></Sequence></BehaviorTree>
      <BehaviorTree ID="Sub"><AlwaysSuccess/></BehaviorTree>
      <BehaviorTree ID="Read"><Pick pose="{p}"/></BehaviorTree>
      <TreeNodesModel><SubTree ID="Main"/><Action ID="Pick"><input_port name="pose"/></Action></TreeNodesModel>
    </root>"#;
    let found = run(xml);
    // Only the remapping some node reads ({p} of Read, by Pick).
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].0, "subtree-remap-unprovided");
    assert!(found[0].1.contains("SubTree `Read`"), "{found:?}");
}
