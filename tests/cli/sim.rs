//! `btfsm sim` through the binary: the behavior-match verdicts of SPEC §6,
//! determinism, bad scenarios, and `dot --trace`.

use super::*;

fn sim_json(scenario: &str) -> serde_json::Value {
    let (code, stdout, stderr) = btfsm(&["sim", scenario, "--format", "json"]);
    assert_eq!(code, 0, "{stderr}");
    serde_json::from_str(&stdout).expect("sim prints JSON")
}

fn sim_policy<'a>(v: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    v["policies"]
        .as_array()
        .expect("policies")
        .iter()
        .find(|p| p["policy"] == name)
        .unwrap_or_else(|| panic!("no policy `{name}` in {v}"))
}

fn sim_verdict(v: &serde_json::Value, a: &str, b: &str) -> bool {
    let x = v["verdicts"]
        .as_array()
        .expect("verdicts")
        .iter()
        .find(|x| (x["a"] == a && x["b"] == b) || (x["a"] == b && x["b"] == a))
        .unwrap_or_else(|| panic!("no verdict {a} / {b}"));
    x["match"].as_bool().expect("bool")
}

const BT1: &str = "Fig. 1 BT baseline";
const HFSM1: &str = "Fig. 1 BT baseline (HFSM)";
const FSM4: &str = "Fig. 4 FSM fault tolerant";
const FSM2: &str = "Fig. 2 FSM sequential";

#[test]
fn sim_exp1_bt_fsm_and_hfsm_match_and_the_sequential_fsm_fails_on_a_failed_pick() {
    let v = sim_json("policies/scenarios/exp1-nominal.toml");
    for (a, b) in [(BT1, HFSM1), (BT1, FSM4), (BT1, FSM2)] {
        assert!(sim_verdict(&v, a, b), "{a} vs {b} in exp1-nominal");
    }
    let v = sim_json("policies/scenarios/exp1-pick-fails.toml");
    assert!(sim_verdict(&v, BT1, HFSM1));
    assert!(sim_verdict(&v, BT1, FSM4));
    assert!(!sim_verdict(&v, BT1, FSM2));
    for p in [BT1, HFSM1, FSM4] {
        assert_eq!(sim_policy(&v, p)["outcome"], "success", "{p}");
        let skills = sim_policy(&v, p)["skills"].as_array().unwrap();
        assert_eq!(skills[1]["skill"], "Pick");
        assert_eq!(skills[1]["outcome"], "failure");
        assert_eq!(skills[2]["outcome"], "success");
    }
    let fsm2 = sim_policy(&v, FSM2);
    assert_eq!(fsm2["outcome"], "failure");
    assert_eq!(fsm2["goal_met"], false);
    assert!(fsm2["reason"].as_str().unwrap().contains("Pick cube2"));
}

#[test]
fn sim_only_the_bt_fetches_the_cube_again_after_the_task_is_done() {
    let v = sim_json("policies/scenarios/exp1-cube-moved-after-done.toml");
    let picks = |p: &str| {
        sim_policy(&v, p)["skills"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|s| s["skill"] == "Pick" && s["outcome"] == "success")
            .count()
    };
    assert_eq!(picks(BT1), 2);
    assert_eq!(picks(FSM4), 1);
    assert_eq!(picks(HFSM1), 1);
    assert_eq!(
        sim_policy(&v, BT1)["final_world"]["objects"]["cube2"]["at"],
        "delivery"
    );
    // Left where it was moved, in view of the delivery station.
    let cube = &sim_policy(&v, FSM4)["final_world"]["objects"]["cube2"];
    assert_eq!(
        (cube["x"].as_f64(), cube["y"].as_f64()),
        (Some(0.0), Some(1.3))
    );
    assert_eq!(cube["at"], serde_json::Value::Null);
    assert!(!sim_verdict(&v, BT1, FSM4));
    assert!(sim_verdict(&v, HFSM1, FSM4));
}

/// The cube moved while the robot drives to it: Move-To goes to where the
/// cube was believed to be when it started, so the grasp there fails; the
/// reactive policies go to where the camera has since seen it, the
/// sequential FSM stops. The BT halts its Pick as soon as Robot-At fails
/// (cancelled) where the FSM waits for the Pick to fail: the same timeline.
#[test]
fn sim_a_cube_moved_during_the_task_defeats_only_the_sequential_fsm() {
    let v = sim_json("policies/scenarios/exp1-cube-moved-during.toml");
    for p in [BT1, HFSM1, FSM4] {
        let r = sim_policy(&v, p);
        assert_eq!(r["outcome"], "success", "{p}");
        assert_eq!(r["goal_met"], true, "{p}");
        let skills = r["skills"].as_array().unwrap();
        assert_eq!(skills[1]["skill"], "Pick", "{p}");
        assert_ne!(skills[1]["outcome"], "success", "{p}");
        assert_eq!(skills[2]["skill"], "Move-To", "{p}");
    }
    let fsm2 = sim_policy(&v, FSM2);
    assert_eq!(fsm2["outcome"], "failure");
    assert_eq!(fsm2["goal_met"], false);
    assert_eq!(fsm2["final_world"]["objects"]["cube2"]["y"], -0.8);
    // The same motion: a Pick cancelled and a Pick failed are the same
    // behavior (issue 31), so the BT and the fault-tolerant FSM match.
    assert!(sim_verdict(&v, BT1, FSM4));
    assert!(sim_verdict(&v, HFSM1, FSM4));
}

/// An injected navigation fault stops the base short of its goal: the
/// sequential FSM is left part-way, the reactive policies drive on from
/// there with a new Move-To.
#[test]
fn sim_a_navigation_fault_stops_the_robot_short_of_its_goal() {
    let v = sim_json("tests/fixtures/sim/navigation-fault.toml");
    let fsm2 = sim_policy(&v, FSM2);
    assert_eq!(fsm2["outcome"], "failure");
    assert_eq!(fsm2["final_world"]["robot_at"], serde_json::Value::Null);
    let [x, y] = [0, 1].map(|i| fsm2["final_world"]["robot"][i].as_f64().unwrap());
    // Part-way from the start (-2.0, -2.2) to the east table (1.7, 0.0).
    assert!(x > -1.9 && x < 1.6, "{x}");
    assert!(y > -2.2 && y < -0.05, "{y}");
    for p in [BT1, FSM4] {
        let r = sim_policy(&v, p);
        assert_eq!(r["goal_met"], true, "{p}");
        let s = r["skills"].as_array().unwrap();
        assert_eq!(
            (s[0]["skill"].as_str(), s[0]["outcome"].as_str()),
            (Some("Move-To"), Some("failure"))
        );
        assert_eq!(s[1]["skill"], "Move-To", "{p}");
        // Within a step of the failure (whether a representation restarts
        // in the failing step is the executors' business, not the world's).
        let gap = s[1]["start"].as_f64().unwrap() - s[0]["end"].as_f64().unwrap();
        assert!((-1e-9..=0.1 + 1e-9).contains(&gap), "{p}: {gap}");
    }
}

/// A cube moved out of the camera's view is seen by no policy: the BT
/// tries where it believes the cube is and gives up.
#[test]
fn sim_no_policy_fetches_a_cube_it_cannot_see() {
    let v = sim_json("tests/fixtures/sim/cube-moved-out-of-sight.toml");
    let bt = sim_policy(&v, BT1);
    assert_eq!(bt["outcome"], "failure");
    assert!(
        bt["reason"].as_str().unwrap().starts_with("gave up"),
        "{bt}"
    );
    assert_eq!(bt["goal_met"], false);
    assert_eq!(sim_policy(&v, FSM4)["goal_met"], false);
}

#[test]
fn sim_recharge_docking_arena_and_five_cubes_match() {
    let cases = [
        (
            "exp2-recharge",
            "Fig. 7d BT recharge",
            "Fig. 8d FSM recharge",
        ),
        ("exp3-docking", "Fig. 15 BT docking", "Fig. 15 FSM docking"),
        ("exp5-arena", "Fig. 15 BT docking", "Fig. 15 FSM docking"),
        (
            "exp4-five-cubes",
            "Fig. 16a BT five cubes",
            "Fig. 16b FSM five cubes",
        ),
    ];
    for (scn, bt, fsm) in cases {
        let v = sim_json(&format!("policies/scenarios/{scn}.toml"));
        assert!(sim_verdict(&v, bt, fsm), "{scn}");
        for p in [bt, fsm] {
            let r = sim_policy(&v, p);
            assert_eq!(r["outcome"], "success", "{scn} {p}");
            assert_eq!(r["goal_met"], true, "{scn} {p}");
            // Every one of these scenarios makes the robot recharge.
            assert!(
                r["skills"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .any(|s| s["skill"] == "Recharge" && s["outcome"] == "success"),
                "{scn} {p}"
            );
        }
    }
}

/// The Fig. 1 BT written for BehaviorTree.CPP, its MoMa subtree
/// parameterised by a SubTree port remapping (`cube="cube2"` over
/// `object="{cube}"`), behaves as the TOML tree when a grasp fails.
#[test]
fn sim_a_btcpp_tree_with_a_parameterised_subtree_matches_the_toml_bt() {
    let v = sim_json("tests/fixtures/sim/btcpp-subtree-pick-fails.toml");
    assert!(sim_verdict(&v, BT1, "Main"), "{v}");
    let skills = sim_policy(&v, "Main")["skills"]
        .as_array()
        .expect("skills")
        .len();
    assert_eq!(skills, 5, "{v}");
}

#[test]
fn sim_reports_the_fig03_bt_as_chattering() {
    let v = sim_json("policies/scenarios/fig03-chattering.toml");
    let r = sim_policy(&v, "Fig. 3 BT chattering");
    assert_eq!(r["outcome"], "chattering");
    assert!(r["steps"].as_u64().unwrap() < 200, "{r}");
    assert_eq!(sim_policy(&v, BT1)["outcome"], "success");
}

/// Every bundled scenario states the paper's claim as `[expect]`, and every
/// expectation holds: `sim` exits 0 and says so in the table and the JSON.
#[test]
fn sim_bundled_scenarios_hold_the_papers_claims() {
    for f in fixtures_in("policies/scenarios") {
        let (code, stdout, stderr) = btfsm(&["sim", &f, "--format", "json"]);
        assert_eq!(code, 0, "{f}: {stderr}");
        let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
        let e = v["expectations"].as_array().expect("expectations");
        assert!(e.len() >= 3, "{f} states the paper's claim");
        assert!(e.iter().all(|x| x["status"] == "pass"), "{f}: {e:?}");
        assert_eq!(v["expectations_failed"], 0);
    }
}

fn fixtures_in(dir: &str) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path().display().to_string())
        .filter(|p| p.ends_with(".toml"))
        .collect();
    v.sort();
    v
}

/// A failed expectation: exit 1, named in the table, in JSON and on stderr;
/// the ones that hold are listed as such.
#[test]
fn sim_exits_1_naming_the_expectations_that_fail() {
    let f = "tests/fixtures/sim/expect-fails.toml";
    let (code, stdout, stderr) = btfsm(&["sim", f]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stdout.contains("expectations: 1 of 3 hold"), "{stdout}");
    assert!(
        stdout.contains(
            "  FAIL Fig. 2 FSM sequential reaches the goal (outcome failure, goal not met)"
        ),
        "{stdout}"
    );
    assert!(stdout.contains("  FAIL Fig. 1 BT baseline matches Fig. 2 FSM sequential (they differ: at 9.4 s, skill 3"), "{stdout}");
    assert!(stderr.contains("2 of 3 expectations of the scenario failed: Fig. 2 FSM sequential reaches the goal; Fig. 1 BT baseline matches Fig. 2 FSM sequential"), "{stderr}");
    let (code, stdout, _) = btfsm(&["sim", f, "--format", "json"]);
    assert_eq!(code, 1);
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(v["expectations_failed"], 2);
    assert_eq!(
        v["expectations"][1]["name"],
        "Fig. 2 FSM sequential reaches the goal"
    );
    assert_eq!(v["expectations"][1]["status"], "fail");
    assert_eq!(v["expectations"][0]["status"], "pass");
    // A budget spent before the runs: nothing can be decided, which fails too.
    let (code, stdout, _) = btfsm(&[
        "sim",
        "policies/scenarios/exp1-nominal.toml",
        "--timeout-ms",
        "0",
        "--format",
        "json",
    ]);
    assert_eq!(code, 1);
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert!(
        v["expectations"]
            .as_array()
            .unwrap()
            .iter()
            .all(|e| e["status"] == "undecided"),
        "{v}"
    );
}

/// Livelock is a recurring abstract state without progress, not a count of
/// action starts: a 14-leg patrol (14 starts, no world change) completes; a
/// loop through Tuck-Arm (which changes the arm each time) is chattering.
#[test]
fn sim_a_14_leg_patrol_is_not_chattering_and_a_tuck_arm_loop_is() {
    let v = sim_json("tests/fixtures/sim/patrol-14.toml");
    let r = sim_policy(&v, "Patrol 14 legs");
    assert_eq!(r["outcome"], "success", "{r}");
    assert_eq!(r["skills"].as_array().unwrap().len(), 14);
    let v = sim_json("tests/fixtures/sim/tuck-arm-livelock.toml");
    let r = sim_policy(&v, "Tuck-Arm loop");
    assert_eq!(r["outcome"], "chattering", "{r}");
    assert!(r["steps"].as_u64().unwrap() < 200, "{r}");
    let skills = r["skills"].as_array().unwrap();
    assert!(
        skills.iter().filter(|s| s["skill"] == "Tuck-Arm").count() >= 2,
        "{r}"
    );
}

/// After completion, a converted HFSM with `after_success = "keep-ticking"`
/// fetches the moved cube exactly as the BT (same skills, same times); the
/// same HFSM left to stop does not.
#[test]
fn sim_a_converted_hfsm_that_keeps_ticking_reacts_like_the_bt() {
    let v = sim_json("tests/fixtures/sim/hfsm-keep-ticking.toml");
    assert!(sim_verdict(&v, BT1, "HFSM keep-ticking"));
    assert!(!sim_verdict(&v, BT1, "HFSM stop"));
    assert_eq!(
        sim_policy(&v, "HFSM keep-ticking")["after_success"],
        "keep-ticking"
    );
    assert_eq!(sim_policy(&v, "HFSM stop")["after_success"], "stop");
    assert_eq!(sim_policy(&v, BT1)["after_success"], "keep-ticking");
    assert_eq!(
        sim_policy(&v, BT1)["skills"],
        sim_policy(&v, "HFSM keep-ticking")["skills"]
    );
}

/// An HFSM file converted from a BT with a memory node is run with a
/// warning positioned at its entry in the scenario.
#[test]
fn sim_warns_about_an_hfsm_converted_from_a_memory_bt() {
    let (code, _, stderr) = btfsm(&["sim", "tests/fixtures/sim/memory-hfsm.toml"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.starts_with("warning: `policies-fig12-hfsm.toml` looks converted from a BT with memory: its container `moma` (Sequence*)"), "{stderr}");
    assert!(
        stderr.contains("--> tests/fixtures/sim/memory-hfsm.toml:13:8"),
        "{stderr}"
    );
}

/// Equivalent policies produce equal timelines: after the failed grasp the
/// BT, the HFSM and the fault-tolerant FSM start the retry in the same step,
/// and every skill at the same time.
#[test]
fn sim_equivalent_bt_and_fsm_produce_equal_timelines() {
    let v = sim_json("policies/scenarios/exp1-pick-fails.toml");
    let starts = |p: &str| -> Vec<f64> {
        (sim_policy(&v, p)["skills"].as_array().unwrap().iter())
            .map(|s| s["start"].as_f64().unwrap())
            .collect()
    };
    assert_eq!(starts(BT1), starts(FSM4));
    assert_eq!(starts(BT1), starts(HFSM1));
    assert_eq!(
        sim_policy(&v, BT1)["completion_s"],
        sim_policy(&v, FSM4)["completion_s"]
    );
    let verdict = (v["verdicts"].as_array().unwrap().iter())
        .find(|x| x["a"] == BT1 && x["b"] == FSM4)
        .unwrap();
    assert_eq!(verdict["trajectory_distance_m"], 0.0);
    assert_eq!(verdict["tolerance_s"], 0.1);
}

/// Monte Carlo answers questions: success rates with Wilson intervals,
/// completion quantiles, per-pair match rates and the seed of the first
/// diverging episode, which `sim --seed` replays (the pair differs there).
#[test]
fn sim_monte_carlo_names_the_first_diverging_episode_and_its_seed_replays_it() {
    let f = "tests/fixtures/sim/monte-carlo-pick.toml";
    let (code, stdout, stderr) = btfsm(&[
        "sim",
        f,
        "--runs",
        "40",
        "--format",
        "json",
        "--threads",
        "2",
    ]);
    assert_eq!(code, 0, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let bt = &v["policies"][0];
    let ci = bt["success_ci95"].as_array().unwrap();
    assert!(ci[0].as_f64().unwrap() <= bt["success_rate"].as_f64().unwrap());
    assert!(bt["completion_quantiles_s"].as_array().unwrap().len() == 3);
    let seq = &v["policies"][2];
    assert!(seq["success_rate"].as_f64().unwrap() < 1.0, "{v}");
    let pair = (v["pairs"].as_array().unwrap().iter())
        .find(|p| p["a"] == BT1 && p["b"] == FSM2)
        .expect("pair");
    assert!(pair["match_rate"].as_f64().unwrap() < 1.0, "{v}");
    let seed = pair["first_divergence"]["seed"]
        .as_u64()
        .expect("a diverging episode")
        .to_string();
    let (code, stdout, stderr) = btfsm(&["sim", f, "--seed", &seed, "--format", "json"]);
    assert_eq!(code, 0, "{stderr}");
    let r: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert!(!sim_verdict(&r, BT1, FSM2), "the replay diverges too");
    let (code, md, _) = btfsm(&["sim", f, "--runs", "40", "--format", "markdown"]);
    assert_eq!(code, 0);
    assert!(md.contains("| policy | success rate | 95% CI |"), "{md}");
    assert!(
        md.contains(
            "| pair | behavior match rate | 95% CI | moved alike | first diverging episode (seed) |"
        ),
        "{md}"
    );
    // One run prints a table, JSON or CSV: markdown is refused.
    let (code, out, err) = btfsm(&["sim", f, "--format", "markdown"]);
    assert_eq!((code, out.as_str()), (2, ""), "{err}");
    assert!(err.starts_with("error: `sim`"), "{err}");
}

/// Recording a trace makes the executors note every node's status: every
/// bundled scenario must report the same either way.
#[test]
fn sim_reports_the_same_with_and_without_a_trace() {
    let dir = common::scratch("trace-same");
    let trace = dir.join("t.json");
    let trace = trace.to_str().expect("utf-8");
    let mut scenarios: Vec<_> = std::fs::read_dir("policies/scenarios")
        .expect("scenarios")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    scenarios.sort();
    assert!(scenarios.len() >= 8);
    for s in scenarios {
        let s = s.to_str().expect("utf-8");
        let plain = btfsm(&["sim", s, "--format", "json"]);
        let traced = btfsm(&["sim", s, "--format", "json", "--trace", trace]);
        assert_eq!(plain.0, 0, "{s}: {}", plain.2);
        assert_eq!(plain, traced, "{s}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn sim_is_deterministic() {
    let a = btfsm(&[
        "sim",
        "policies/scenarios/exp3-docking.toml",
        "--format",
        "json",
    ]);
    let b = btfsm(&[
        "sim",
        "policies/scenarios/exp3-docking.toml",
        "--format",
        "json",
    ]);
    assert_eq!(a, b);
}

/// A scenario naming an unknown object, station or skill, or a pose inside a
/// wall or table, exits 2 with the recorded positioned messages.
#[test]
fn sim_rejects_bad_scenarios_with_positioned_messages() {
    let bless = std::env::var_os("BLESS").is_some();
    let mut failures = Vec::new();
    let files = fixtures("sim-invalid");
    assert!(files.len() >= 5);
    for f in files {
        let (code, stdout, stderr) = btfsm(&["sim", &rel(&f)]);
        let expected_path = f.with_extension("stderr");
        if bless {
            std::fs::write(&expected_path, &stderr).expect("write expected");
        }
        let expected = std::fs::read_to_string(&expected_path).unwrap_or_default();
        let positioned = stderr
            .lines()
            .any(|l| l.trim_start().starts_with("--> ") && l.matches(':').count() >= 2);
        if code != 2 || !stdout.is_empty() || stderr != expected || !positioned {
            failures.push(format!(
                "{}: exit {code}\n--- stderr\n{stderr}--- expected\n{expected}",
                rel(&f)
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn dot_colours_nodes_by_their_status_at_a_trace_step() {
    let dir = std::env::temp_dir().join(format!("btfsm-dot-trace-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let trace = dir.join("exp2.json");
    let plot = dir.join("exp2.svg");
    let (code, _, stderr) = btfsm(&[
        "sim",
        "policies/scenarios/exp2-recharge.toml",
        "--trace",
        trace.to_str().unwrap(),
        "--plot",
        plot.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert!(
        svg.starts_with("<svg")
            && svg.contains("central table")
            && svg.contains("Fig. 8d FSM recharge")
    );
    // Step 45 (t = 4.5 s): the battery is low and the robot drives to the charger.
    let (code, dot, stderr) = btfsm(&[
        "dot",
        "policies/paper/fig07d-bt.toml",
        "--trace",
        trace.to_str().unwrap(),
        "--step",
        "45",
    ]);
    assert_eq!(code, 0, "{stderr}");
    let line = |id: &str| {
        dot.lines()
            .find(|l| l.trim_start().starts_with(id))
            .unwrap_or("")
            .to_string()
    };
    assert!(line("recharge[").contains("fillcolor=gold"), "{dot}");
    assert!(
        line("\"battery-ok\"[").contains("fillcolor=tomato"),
        "{dot}"
    );
    assert!(line("root[").contains("fillcolor=gold"), "{dot}");
    assert!(!line("pick[").contains("gold"), "{dot}");
    let (code, dot, _) = btfsm(&[
        "dot",
        "policies/paper/fig08d-fsm.toml",
        "--trace",
        trace.to_str().unwrap(),
        "--step",
        "45",
    ]);
    assert_eq!(code, 0);
    assert!(
        line_of(&dot, "Recharge[").contains("fillcolor=gold"),
        "{dot}"
    );
    let (code, _, stderr) = btfsm(&[
        "dot",
        "policies/paper/fig07d-bt.toml",
        "--trace",
        trace.to_str().unwrap(),
        "--step",
        "999999",
    ]);
    assert_eq!(code, 2);
    assert!(stderr.contains("past the end of the trace"), "{stderr}");
    std::fs::remove_dir_all(&dir).unwrap();
}

fn line_of(dot: &str, id: &str) -> String {
    dot.lines()
        .find(|l| l.trim_start().starts_with(id))
        .unwrap_or("")
        .to_string()
}

/// exp1-nominal with a step budget of 10^6 and a disturbance that never
/// fires (so no run ends before its step budget): far more work than the
/// wall-clock budgets below allow.
fn endless_scenario(dir: &std::path::Path) -> String {
    // The policies beside the scenario: files it names stay inside its root.
    let paper = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("policies/paper");
    for f in ["fig01-bt.toml", "fig04-fsm.toml", "fig02-fsm.toml"] {
        std::fs::copy(paper.join(f), dir.join(f)).expect("copy policy");
    }
    let text = std::fs::read_to_string("policies/scenarios/exp1-nominal.toml")
        .expect("exp1-nominal")
        // Without its expectations: a spent budget leaves them undecided.
        .split("[expect]")
        .next()
        .unwrap_or_default()
        .replace("file = \"../paper/", "file = \"")
        .replacen("seed = ", "max_steps = 1000000\nseed = ", 1)
        + "\n[[disturbances]]\nat = 1000000000.0\nbattery = 100.0\n";
    let path = dir.join("endless.toml");
    std::fs::write(&path, text).expect("write scenario");
    path.display().to_string()
}

#[test]
fn sim_timeout_stops_runs_cleanly_and_says_so() {
    let dir = std::env::temp_dir().join(format!("btfsm-sim-budget-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scenario = endless_scenario(&dir);
    // Monte Carlo: the episodes completed, out of those asked for.
    let t = std::time::Instant::now();
    let (code, stdout, stderr) = btfsm(&[
        "sim",
        &scenario,
        "--runs",
        "1000",
        "--timeout-ms",
        "200",
        "--format",
        "json",
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(t.elapsed().as_secs() < 10, "took {:?}", t.elapsed());
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("json");
    assert_eq!(v["budget"]["timeout_ms"], 200, "{v}");
    assert_eq!(v["budget"]["exhausted"], true, "{v}");
    assert_eq!(v["budget"]["requested_runs"], 1000, "{v}");
    let done = v["runs"].as_u64().expect("runs");
    assert!(done < 1000, "{v}");
    for p in v["policies"].as_array().expect("policies") {
        assert_eq!(p["runs"].as_u64(), Some(done), "{p}");
    }
    let (code, table, _) = btfsm(&["sim", &scenario, "--runs", "1000", "--timeout-ms", "50"]);
    assert_eq!(code, 0);
    assert!(
        table.contains("note: the wall-clock budget of 50 ms ran out")
            && table.contains("of 1000 episodes completed"),
        "{table}"
    );
    // One run per policy: the first stops at the step reached, with outcome
    // `timeout`; the trace is written whole.
    let trace = dir.join("trace.json");
    let (code, stdout, stderr) = btfsm(&[
        "sim",
        &scenario,
        "--timeout-ms",
        "50",
        "--format",
        "json",
        "--trace",
        trace.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("json");
    assert_eq!(v["budget"]["exhausted"], true, "{v}");
    let first = &v["policies"][0];
    assert_eq!(first["outcome"], "timeout", "{first}");
    let steps = first["steps"].as_u64().expect("steps");
    assert!(steps < 1_000_000, "{first}");
    assert_eq!(
        first["reason"],
        format!("wall-clock budget exhausted at step {steps}"),
        "{first}"
    );
    let t: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&trace).expect("trace")).expect("whole");
    assert_eq!(t["policies"][0]["steps"], steps);
    // A budget that is not exhausted is said so too.
    let (code, stdout, _) = btfsm(&[
        "sim",
        "policies/scenarios/exp1-nominal.toml",
        "--timeout-ms",
        "600000",
        "--format",
        "json",
    ]);
    assert_eq!(code, 0);
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("json");
    assert_eq!(v["budget"]["exhausted"], false, "{v}");
    assert!(v["budget"].get("requested_runs").is_none(), "{v}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `validate` reads a scenario as `sim` does (its policies included), without
/// running it; `analyze` on a scenario points at `sim`.
#[test]
fn validate_checks_scenarios_without_running_them() {
    let (code, out, err) = btfsm(&[
        "validate",
        "policies/scenarios/exp1-nominal.toml",
        "policies/paper/fig01-bt.toml",
    ]);
    assert_eq!((code, out.as_str()), (0, ""), "{err}");
    assert_eq!(
        err,
        "policies/scenarios/exp1-nominal.toml: ok (scenario `exp1-nominal`, 4 policies)\n\
         policies/paper/fig01-bt.toml: ok (bt `Fig. 1 BT baseline`, 0 warnings)\n"
    );
    let (code, _, err) = btfsm(&["validate", "tests/fixtures/sim-invalid/unknown-skill.toml"]);
    assert_eq!(code, 2);
    assert!(err.contains("unknown-skill.toml:10:8"), "{err}");
    let (code, _, err) = btfsm(&["analyze", "policies/scenarios/exp1-nominal.toml"]);
    assert_eq!(code, 2);
    assert!(err.contains("run it with `btfsm sim FILE`"), "{err}");
}

/// Issue 12, simulator side: hostile scenarios answered in bounded time and
/// memory. Inputs are generated here, in milliseconds.
mod hostile {
    use super::*;
    use std::time::Duration;

    use crate::common::btfsm_capped as btfsm_within;

    /// A hang guard, not a speed target (machines are shared and noisy;
    /// speed lives in benches/): the refusals below take milliseconds.
    const HANG_GUARD: Duration = Duration::from_secs(60);

    /// A scratch folder holding the Fig. 1 BT: a scenario's policies stay
    /// inside its root.
    fn scratch(tag: &str) -> std::path::PathBuf {
        let dir = common::scratch(tag);
        let paper = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("policies/paper");
        std::fs::copy(paper.join("fig01-bt.toml"), dir.join("fig01-bt.toml")).expect("copy");
        dir
    }

    fn policies(n: usize) -> String {
        "[[policies]]\nfile = \"fig01-bt.toml\"\n".repeat(n)
    }

    const CUBE: &str = "[world]\nobjects = { cube2 = { at = \"east-table\" } }\n";

    /// 200,000 stations took minutes (each looked up by a scan of the
    /// others); now over the fixed limit of 1024 before any is read.
    #[test]
    fn sim_hostile_many_stations_are_refused_at_once() {
        let dir = scratch("many-stations");
        let mut text = format!("{CUBE}[world.stations]\n");
        for i in 0..200_000 {
            text.push_str(&format!("s{i} = [-2.0, -2.2]\n"));
        }
        text.push_str(&policies(1));
        let f = dir.join("stations.toml");
        std::fs::write(&f, text).unwrap();
        let (code, _, err, took) = btfsm_within(1024, &["sim", f.to_str().unwrap()]);
        assert_eq!(code, 2, "{err}");
        assert!(
            err.contains("200007 stations, more than the limit of 1024")
                && err.contains("stations.toml:3:1"),
            "{err}"
        );
        assert!(took < HANG_GUARD, "{took:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// 3000 policies ran for minutes past `--timeout-ms 500` (their 4.5
    /// million pairwise verdicts were not budgeted): now at most 64
    /// policies, and the verdicts stop at the deadline, the pairs left
    /// listed.
    #[test]
    fn sim_hostile_policies_are_capped_and_verdicts_stop_at_the_deadline() {
        let dir = scratch("many-policies");
        let f = dir.join("p65.toml");
        std::fs::write(&f, format!("{CUBE}{}", policies(65))).unwrap();
        let (code, _, err, _) = btfsm_within(1024, &["sim", f.to_str().unwrap()]);
        assert_eq!(code, 2, "{err}");
        assert!(
            err.contains("65 policies, more than the limit of 64") && err.contains("p65.toml:3:1"),
            "{err}"
        );
        let f = dir.join("p64.toml");
        std::fs::write(&f, format!("{CUBE}{}", policies(64))).unwrap();
        let (code, out, err, took) = btfsm_within(
            1024,
            &[
                "sim",
                f.to_str().unwrap(),
                "--timeout-ms",
                "100",
                "--format",
                "json",
            ],
        );
        assert_eq!(code, 0, "{err}");
        assert!(took < HANG_GUARD, "{took:?}");
        let v: serde_json::Value = serde_json::from_str(&out).expect("json");
        let done = v["verdicts"].as_array().unwrap().len();
        let skipped = v["skipped_verdicts"]
            .as_array()
            .expect("skipped pairs")
            .len();
        assert_eq!(done + skipped, 64 * 63 / 2);
        assert!(skipped > 0, "{done} verdicts in 100 ms");
        assert_eq!(v["budget"]["exhausted"], true);
        assert!(
            v["budget"]["millis"].as_u64().unwrap() < 1000,
            "{}",
            v["budget"]
        );
        let (code, table, _, _) =
            btfsm_within(1024, &["sim", f.to_str().unwrap(), "--timeout-ms", "100"]);
        assert_eq!(code, 0);
        assert!(
            table.contains("verdicts skipped, the wall-clock budget ran out first: "),
            "{table}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A scratch folder holding `long.toml`, a scenario of one policy that
    /// runs its 200,000 steps (a disturbance far past them keeps it
    /// going), and the path of a trace to write there.
    fn long_run(name: &str) -> (std::path::PathBuf, std::path::PathBuf, std::path::PathBuf) {
        let dir = scratch(name);
        let f = dir.join("long.toml");
        std::fs::write(
            &f,
            format!(
                "max_steps = 200000\n{CUBE}{}[[disturbances]]\nat = 1000000000.0\nbattery = 100.0\n",
                policies(1)
            ),
        )
        .unwrap();
        let trace = dir.join("trace.json");
        (dir, f, trace)
    }

    /// `sim --trace` kept every step of every run in memory (a run of
    /// 200,000 steps: over 80 MiB; 10^6 steps of two policies: 1 GB): it is
    /// now written as the runs go, in a temporary file renamed when whole.
    #[test]
    fn sim_hostile_long_trace_is_streamed_in_bounded_memory() {
        let (dir, f, trace) = long_run("long-trace");
        let (code, out, err, took) = btfsm_within(
            80,
            &[
                "sim",
                f.to_str().unwrap(),
                "--trace",
                trace.to_str().unwrap(),
                "--format",
                "json",
            ],
        );
        assert_eq!(code, 0, "{err}");
        assert!(took < HANG_GUARD, "{took:?}");
        let v: serde_json::Value = serde_json::from_str(&out).expect("json");
        assert_eq!(v["policies"][0]["steps"], 200_000);
        let bytes = std::fs::read(&trace).expect("trace written");
        assert!(bytes.len() > 20_000_000, "{}", bytes.len());
        assert!(bytes.starts_with(b"{\"scenario\":\"long\",") && bytes.ends_with(b"}\n"));
        assert!(
            String::from_utf8_lossy(&bytes[bytes.len() - 4096..]).contains("\"verdicts\":[]"),
            "ends with the verdicts"
        );
        let names: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names.len(), 3, "no temporary left: {names:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A trace is at most `--max-file-bytes`, what btfsm reads back
    /// (issue 33: a 1 KB scenario wrote a 4.2 GB trace): past it the run
    /// exits 2 and leaves no file.
    #[test]
    fn sim_hostile_trace_is_bounded_by_max_file_bytes() {
        let (dir, f, trace) = long_run("capped-trace");
        let (code, _, err, took) = btfsm_within(
            80,
            &[
                "sim",
                f.to_str().unwrap(),
                "--trace",
                trace.to_str().unwrap(),
                "--max-file-bytes",
                "5000000",
            ],
        );
        assert_eq!(code, 2, "{err}");
        assert!(took < HANG_GUARD, "{took:?}");
        assert!(err.contains("larger than 5000000 bytes"), "{err}");
        let mut names: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(
            names,
            ["fig01-bt.toml", "long.toml"],
            "a trace or a temporary left"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// 64 policies picking and placing a cube every step for 10^6 steps
    /// (a 400-byte scenario) recorded 2 million skills each: 3.3 GB per
    /// policy. A run now records at most 1024 skills and 4096 events (every
    /// action takes at least one step: the tree picks or places every step).
    #[test]
    fn sim_hostile_endless_skills_fill_a_bounded_record() {
        let dir = scratch("endless-skills");
        std::fs::write(
            dir.join("pp.toml"),
            "kind = \"bt\"\nroot = \"root\"\n[nodes]\nroot = { sequence_memory = [\"pick\", \"place\"] }\npick = { action = \"Pick\", skill = \"Pick\", args = { object = \"cube2\" } }\nplace = { action = \"Place\", skill = \"Place\", args = { object = \"cube2\", at = \"east-table\" } }\n",
        )
        .unwrap();
        let f = dir.join("pp-scenario.toml");
        std::fs::write(
            &f,
            format!(
                "max_steps = 1000000\nlivelock_repeats = 1000000\n[world]\nrobot = \"east-table\"\nparams = {{ manipulation_s = 0 }}\nobjects = {{ cube2 = {{ at = \"east-table\" }} }}\n{}[[disturbances]]\nat = 1000000000.0\nbattery = 100.0\n",
                "[[policies]]\nfile = \"pp.toml\"\n".repeat(64)
            ),
        )
        .unwrap();
        let (code, out, err, took) =
            btfsm_within(512, &["sim", f.to_str().unwrap(), "--format", "json"]);
        assert_eq!(code, 0, "{err}");
        // About 2,100 steps per policy (every action takes a step).
        assert!(took < HANG_GUARD, "{took:?}");
        assert!(out.len() < 64 << 20, "{} bytes of JSON", out.len());
        let v: serde_json::Value = serde_json::from_str(&out).expect("json");
        for p in v["policies"].as_array().unwrap() {
            assert_eq!(p["outcome"], "timeout");
            assert!(
                p["reason"]
                    .as_str()
                    .unwrap()
                    .starts_with("record budget exhausted at step"),
                "{}",
                p["reason"]
            );
            assert_eq!(p["skills"].as_array().unwrap().len(), 1024);
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// `dot --trace /dev/zero` read until memory ran out.
    #[test]
    fn dot_hostile_trace_is_read_within_the_file_limit() {
        let (code, _, err, took) = btfsm_within(
            512,
            &[
                "dot",
                "policies/paper/fig01-bt.toml",
                "--trace",
                "/dev/zero",
                "--step",
                "0",
                "--max-file-bytes",
                "1000000",
            ],
        );
        assert_eq!(code, 2, "{err}");
        assert!(
            err.contains("`/dev/zero` is larger than the limit of 1000000 bytes")
                && err.contains("--max-file-bytes"),
            "{err}"
        );
        assert!(took < HANG_GUARD, "{took:?}");
    }

    /// `--threads 100000` aborted (threads the system refused to create);
    /// `--threads 0` is refused; a budget past the clock's range is none
    /// (`ms * 950` overflowed).
    #[test]
    fn sim_hostile_threads_and_timeouts_are_bounded() {
        let (code, out, err, _) = btfsm_within(
            4096,
            &[
                "sim",
                "policies/scenarios/exp1-nominal.toml",
                "--runs",
                "100000",
                "--threads",
                "100000",
                "--timeout-ms",
                "300",
                "--format",
                "json",
            ],
        );
        assert_eq!(code, 0, "{err}");
        let v: serde_json::Value = serde_json::from_str(&out).expect("json");
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get()) as u64;
        let threads = v["threads"].as_u64().unwrap();
        assert!((1..=4 * cores).contains(&threads), "{threads}");
        let (code, _, err) = btfsm(&[
            "sim",
            "policies/scenarios/exp1-nominal.toml",
            "--runs",
            "2",
            "--threads",
            "0",
        ]);
        assert_eq!(code, 2);
        assert!(err.contains("--threads must be at least 1"), "{err}");
        // u64::MAX / 950 + 1 ms: the runs' 95% wrapped to about 1.5 ms.
        for ms in ["19417625340746898", "18446744073709551615"] {
            let (code, out, err) = btfsm(&[
                "sim",
                "policies/scenarios/exp1-nominal.toml",
                "--timeout-ms",
                ms,
                "--format",
                "json",
            ]);
            assert_eq!(code, 0, "{err}");
            let v: serde_json::Value = serde_json::from_str(&out).expect("json");
            assert_eq!(v["budget"]["exhausted"], false, "{ms}");
            assert!(
                v["policies"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .all(|p| p["outcome"] != "timeout"),
                "{ms}"
            );
        }
    }

    /// NaN positions passed the wall check; `max_steps = 1.5` was read as 1;
    /// a `Battery-Level` minimum took any number.
    #[test]
    fn sim_hostile_numbers_are_refused_with_positions() {
        let dir = scratch("nan-scenario");
        let f = dir.join("nan.toml");
        std::fs::write(
            &f,
            format!(
                "max_steps = 1.5\n[world]\nrobot = [nan, 0.0]\nobjects = {{ cube2 = {{ at = [0.5, inf] }} }}\n{}[monte_carlo]\nbattery_drop = {{ level = [nan, 19], window = [5.0, inf] }}\n",
                policies(1)
            ),
        )
        .unwrap();
        let (code, _, err) = btfsm(&["validate", f.to_str().unwrap()]);
        assert_eq!(code, 2, "{err}");
        for want in [
            "`max_steps` must be an integer, found 1.5",
            "nan.toml:1:13",
            "the robot's start must be a position `[x, y]` in metres (finite numbers)",
            "nan.toml:3:9",
            "nan.toml:4:28",
            "`level` must be a range",
            "nan.toml:8:26",
            "`window` must be a range",
        ] {
            assert!(err.contains(want), "{want}:\n{err}");
        }
        std::fs::write(
            &f,
            format!(
                "goal = [{{ if = \"Battery-Level\", args = {{ min = 1e300 }} }}]\n{CUBE}{}",
                policies(1)
            ),
        )
        .unwrap();
        let (code, _, err) = btfsm(&["validate", f.to_str().unwrap()]);
        assert_eq!(code, 2, "{err}");
        assert!(
            err.contains(
                "`min` of `Battery-Level` must be a percentage from 0 to 100, found 1e300"
            ) && err.contains("nan.toml:1:9"),
            "{err}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[test]
fn sim_csv_has_the_figures_of_the_json_report() {
    // SPEC §7: --format csv wherever figures are printed. The CSV's rows
    // carry the JSON report's figures, policy by policy.
    let s = "policies/scenarios/exp1-cube-moved-during.toml";
    let (code, csv, err) = btfsm(&["sim", s, "--format", "csv"]);
    assert_eq!(code, 0, "{err}");
    let (_, json, _) = btfsm(&["sim", s, "--format", "json"]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let mut lines = csv.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| head.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let pols = v["policies"].as_array().unwrap();
    assert_eq!(rows.len(), pols.len());
    for (r, p) in rows.iter().zip(pols) {
        assert_eq!(r.len(), head.len(), "{r:?}");
        assert_eq!(r[col("policy")], p["policy"].as_str().unwrap());
        assert_eq!(r[col("outcome")], p["outcome"].as_str().unwrap());
        let num = |c: &str| r[col(c)].parse::<f64>().unwrap();
        assert_eq!(num("duration_s"), p["duration_s"].as_f64().unwrap());
        assert_eq!(num("distance_m"), p["distance_m"].as_f64().unwrap());
        assert_eq!(
            num("skills") as usize,
            p["skills"].as_array().unwrap().len()
        );
        assert_eq!(num("steps") as u64, p["steps"].as_u64().unwrap());
    }
    // The sequential FSM fails here, the others succeed.
    assert!(csv.contains(",failure,") && csv.contains(",success,"));
    // --runs: one row per policy with the Monte Carlo figures.
    let (code, csv, err) = btfsm(&["sim", s, "--format", "csv", "--runs", "8"]);
    assert_eq!(code, 0, "{err}");
    let (_, json, _) = btfsm(&["sim", s, "--format", "json", "--runs", "8"]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let mut lines = csv.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let sr = head.iter().position(|h| *h == "success_rate").unwrap();
    for (l, p) in lines.zip(v["policies"].as_array().unwrap()) {
        let r: Vec<&str> = l.split(',').collect();
        assert_eq!(
            r[sr].parse::<f64>().unwrap(),
            p["success_rate"].as_f64().unwrap()
        );
    }
}

/// `--runs` is at most 10,000,000 (issue 33: `--runs 4294967295` allocated
/// 4 GiB of per-episode flags); the most allowed, with a budget, stays
/// small: 10 MB of flags.
#[test]
fn sim_hostile_runs_are_capped() {
    let s = "policies/scenarios/exp1-nominal.toml";
    let (code, _, err, _) = common::btfsm_capped(512, &["sim", s, "--runs", "4294967295"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("0..=10000000"), "{err}");
    let (code, out, err, _) = common::btfsm_capped(
        512,
        &[
            "sim",
            s,
            "--runs",
            "10000000",
            "--timeout-ms",
            "300",
            "--format",
            "json",
        ],
    );
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("\"requested_runs\": 10000000"), "{out}");
}

/// The symbolic simulator keeps the one simulation contract of the planar
/// one (`btfsm_sim::episodes`): `--timeout-ms` stops a million episodes at
/// the deadline in bounded memory, and `--threads` changes no figure.
#[test]
fn symbolic_monte_carlo_honours_timeout_and_threads_in_bounded_memory() {
    let domain = "policies/domains/moma-sim.toml";
    let (code, stdout, stderr, _) = crate::common::btfsm_capped(
        256,
        &[
            "sim",
            domain,
            "--runs",
            "1000000",
            "--timeout-ms",
            "300",
            "--format",
            "json",
        ],
    );
    assert_eq!(code, 0, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("json");
    assert_eq!(v["budget"]["exhausted"], true, "{v}");
    assert_eq!(v["budget"]["requested_runs"], 1_000_000, "{v}");
    let done = v["runs"].as_u64().expect("runs");
    assert!(done < 1_000_000, "{v}");
    for p in v["policies"].as_array().expect("policies") {
        assert_eq!(p["runs"].as_u64(), Some(done), "{p}");
        let sum: u64 = ["successes", "failures", "chattering", "timeouts"]
            .iter()
            .map(|k| p[k].as_u64().expect("count"))
            .sum();
        assert_eq!(sum, done, "{p}");
    }
    let json = |threads: &str| {
        let (code, out, err) = btfsm(&[
            "sim",
            domain,
            "--runs",
            "120",
            "--threads",
            threads,
            "--format",
            "json",
        ]);
        assert_eq!(code, 0, "{err}");
        out
    };
    assert_eq!(json("1"), json("3"));
}

/// `[expect]` on Monte Carlo rates is checked under `--runs` by the 95 %
/// interval: inside the range passes, outside fails, across a bound is
/// undecided (exit 1, more episodes decide it); the expectations about
/// single runs are named as not checked, not skipped silently.
#[test]
fn sim_runs_checks_expected_rates_by_their_intervals() {
    let f = "tests/fixtures/sim/rates-expect.toml";
    let (code, out, err) = btfsm(&["sim", f, "--runs", "40", "--format", "json"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(
            "note: the scenario's 1 expectation about single runs is checked without --runs"
        ),
        "{err}"
    );
    let v: serde_json::Value = serde_json::from_str(&out).expect("json");
    let status: Vec<&str> = (v["expectations"].as_array().expect("expectations").iter())
        .map(|e| e["status"].as_str().expect("status"))
        .collect();
    assert_eq!(status, ["pass", "fail", "undecided"], "{v}");
    assert_eq!(v["expectations_failed"], 2);
    // One run per policy: the rates are not expectations of a single run.
    let (code, out, err) = btfsm(&["sim", f, "--format", "json"]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).expect("json");
    assert_eq!(v["expectations"].as_array().map(Vec::len), Some(1), "{v}");
    // A rate out of [0, 1] is a positioned error.
    let d = crate::common::scratch("rates-bad");
    let text = std::fs::read_to_string(f)
        .expect("fixture")
        .replace("[0.75, 1.0]", "[0.75, 1.5]")
        .replace(
            "../../../policies/",
            &format!("{}/policies/", env!("CARGO_MANIFEST_DIR")),
        );
    let bad = d.join("bad.toml");
    std::fs::write(&bad, text).expect("write");
    let bad = bad.to_str().expect("utf-8");
    let (code, _, err) = btfsm(&["sim", bad, "--runs", "2", "--allow-outside-root"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("a success rate must be a range"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}
