//! The dataflow rules on small BehaviorTree.CPP trees: silence without a
//! model, SubTree blackboards, scripts, literals given by SubTrees, the
//! tree's declared ports, built-ins, and linear work on large inputs.

use super::*;
use std::path::Path;

/// The codes `lint` reports on BehaviorTree.CPP XML `xml`, with the
/// message of each.
fn run(xml: &str) -> Vec<(String, String)> {
    let l = btfsm_format::btcpp_xml::parse_str("t.xml", xml, Path::new("."), &Default::default())
        .unwrap_or_else(|e| panic!("{e:?}"));
    let s = Subject {
        policy: &l.policy,
        dataflow: l.dataflow.as_deref(),
    };
    lint_subject(&s, None, "t.xml", &config::Config::default())
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
    // before it is not reported, nor the modelled writer after it.
    let xml = tree(
        r#"<Sequence><Pick pose="{p}"/><Action ID="Mystery" x="{p}"/><Detect pose="{q}"/></Sequence>"#,
        MODEL,
    );
    assert_eq!(codes(&xml), ["key-never-read"], "{:?}", run(&xml));
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
    let found = run(&xml);
    assert_eq!(
        found
            .iter()
            .filter(|f| f.0 == "missing-required-port")
            .count(),
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
