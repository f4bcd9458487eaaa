//! Symbolic runs of the paper's policies in the MoMa domain.

use super::run::{self, Outcome};
use super::scenario::parse;
use crate::episodes::Budget;
use crate::scenario::expect::Status;
use btfsm_core::diagnostic::SourceFile;
use std::path::Path;

fn scenario(text: &str) -> super::SymScenario {
    let base = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../policies/domains"
    ));
    parse(&SourceFile::new("t.toml", text), base, &Default::default())
        .unwrap_or_else(|e| panic!("{e:?}"))
}

/// The problems of a scenario that must be refused.
fn refused(text: &str) -> Vec<btfsm_core::diagnostic::Diagnostic> {
    let base = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../policies/domains"
    ));
    parse(&SourceFile::new("t.toml", text), base, &Default::default())
        .err()
        .unwrap_or_else(|| panic!("accepted: {text}"))
}

const HEAD: &str = r#"name = "t"
domain = "moma.toml"
durations = { Move-To = 3, Pick = 2, Place = 2 }
"#;

fn policies(files: &[&str]) -> String {
    files
        .iter()
        .map(|f| format!("[[policies]]\nfile = \"../paper/{f}.toml\"\n"))
        .collect()
}

#[test]
fn fig_1_and_fig_4_deliver_and_fig_3_chatters() {
    let s = scenario(&format!(
        "{HEAD}{}",
        policies(&["fig01-bt", "fig04-fsm", "fig03-bt"])
    ));
    let runs = run::run_all(&s, None, None);
    let outcomes: Vec<Outcome> = runs.iter().map(|r| r.outcome).collect();
    assert_eq!(
        outcomes,
        [Outcome::Success, Outcome::Success, Outcome::Chattering]
    );
    let plan = [
        "Move-To(cube2)",
        "Pick(cube2)",
        "Move-To(delivery)",
        "Place(cube2, delivery)",
    ];
    assert_eq!(runs[0].effective(), plan);
    assert_eq!(run::first_difference(&runs[0], &runs[1]), None);
    // Fig. 3 goes to the delivery station, then to the cube, starts Pick
    // and is called back to the delivery station: the chattering the paper
    // describes (Pick is halted each time, never done).
    assert_eq!(
        runs[2].effective()[..3],
        ["Move-To(delivery)", "Move-To(cube2)", "Move-To(delivery)"]
    );
    assert!(!runs[2].actions.iter().any(|a| a.1.starts_with("Pick")));
}

#[test]
fn a_dropped_cube_is_recovered_by_the_reactive_policies_only() {
    let s = scenario(&format!(
        "{HEAD}{}[[disturbances]]\nat = 4\nunset = [\"In-Hand(cube2)\"]\n",
        policies(&["fig01-bt", "fig04-fsm", "fig02-fsm"])
    ));
    let runs = run::run_all(&s, None, None);
    let outcomes: Vec<Outcome> = runs.iter().map(|r| r.outcome).collect();
    assert_eq!(
        outcomes,
        [Outcome::Success, Outcome::Success, Outcome::Failure]
    );
    // Place fails for Fig. 2 (its precondition, the cube in hand, no longer
    // holds) and the sequential FSM has no way back.
    assert_eq!(
        runs[2].actions.last().map(|a| (a.1.as_str(), a.2)),
        Some(("Place(cube2, delivery)", false))
    );
}

fn budget(runs: u32, seed: u64, threads: usize) -> Budget {
    Budget {
        runs,
        seed,
        threads,
        deadline: None,
    }
}

const MC: &str = "[monte_carlo]\nrates = { Pick = 0.3 }\nunset = { probability = 0.5, facts = [\"In-Hand(cube2)\"], window = [1, 12] }\n";

#[test]
fn monte_carlo_is_reproducible_and_counts_every_episode() {
    let s = scenario(&format!(
        "{HEAD}{}{MC}",
        policies(&["fig01-bt", "fig02-fsm"])
    ));
    let a = run::monte_carlo(&s, &budget(200, 9, 1));
    let b = run::monte_carlo(&s, &budget(200, 9, 3));
    assert_eq!(format!("{a:?}"), format!("{b:?}"), "1 thread and 3 alike");
    assert_eq!(a.runs, 200);
    for p in &a.policies {
        assert_eq!(p.successes + p.failures + p.chattering + p.timeouts, 200);
    }
    assert_eq!(
        a.policies[0].success_rate, 1.0,
        "the BT retries and recovers"
    );
    assert!(
        a.policies[1].success_rate < 0.8,
        "the sequential FSM cannot: {a:?}"
    );
}

#[test]
fn the_seed_of_a_diverging_episode_replays_it() {
    let s = scenario(&format!(
        "{HEAD}{}{MC}",
        policies(&["fig01-bt", "fig02-fsm"])
    ));
    let mc = run::monte_carlo(&s, &budget(50, 9, 2));
    let (_, seed) = mc.pairs[0]
        .first_diverging
        .expect("the FSM fails somewhere");
    let runs = run::run_all(&s, Some(seed), None);
    assert!(
        run::first_difference(&runs[0], &runs[1]).is_some(),
        "episode seed {seed} replayed alike: {runs:?}"
    );
}

#[test]
fn a_deadline_stops_monte_carlo_at_the_episodes_completed() {
    let s = scenario(&format!(
        "{HEAD}{}{MC}",
        policies(&["fig01-bt", "fig02-fsm"])
    ));
    let past = Budget {
        deadline: Some(std::time::Instant::now()),
        ..budget(1_000_000, 9, 2)
    };
    let mc = run::monte_carlo(&s, &past);
    assert_eq!(mc.runs, 0);
    assert!(mc.policies.iter().all(|p| p.runs == 0 && p.successes == 0));
    // A run cut short by the deadline says so, as `timeout`.
    let cut = run::run_all(&s, None, Some(std::time::Instant::now()));
    assert!(
        cut.iter()
            .all(|r| r.cut_short && r.outcome == Outcome::Timeout && r.steps == 0)
    );
}

#[test]
fn scenario_errors_are_reported_together() {
    let text = format!(
        "name = \"t\"\ndomain = \"moma.toml\"\nfacts = [\"Robot-Art(cube2)\", \"Robot-At(20)\"]\ndurations = {{ Pik = 2 }}\n{}",
        policies(&["fig01-bt"])
    );
    let e = refused(&text);
    let msgs: Vec<&str> = e.iter().map(|d| d.message.as_str()).collect();
    assert!(
        msgs.iter()
            .any(|m| m.contains("unknown predicate `Robot-Art`")),
        "{msgs:?}"
    );
    assert!(
        msgs.iter().any(|m| m.contains("no action `Pik`")),
        "{msgs:?}"
    );
    assert!(e.iter().all(|d| d.span.is_some()));
}

#[test]
fn step_and_livelock_bounds_point_at_their_values() {
    let text = format!(
        "{HEAD}max_steps = 0\nlivelock_repeats = 1\n{}",
        policies(&["fig01-bt"])
    );
    let e = refused(&text);
    for (key, value) in [("max_steps", "0"), ("livelock_repeats", "1")] {
        let d = (e.iter())
            .find(|d| d.message.contains(key))
            .unwrap_or_else(|| panic!("no message about {key}: {e:?}"));
        let span = d.span.clone().expect("positioned");
        assert_eq!(&text[span], value, "{key}");
    }
}

#[test]
fn named_policies_and_expectations_are_checked_against_the_runs() {
    let text = format!(
        "{HEAD}[[policies]]\nfile = \"../paper/fig01-bt.toml\"\nname = \"bt\"\n[[policies]]\nfile = \"../paper/fig02-fsm.toml\"\nname = \"seq\"\n[[disturbances]]\nat = 4\nunset = [\"In-Hand(cube2)\"]\n[expect]\nreach_goal = [\"bt\", \"seq\"]\nmatch = [[\"bt\", \"seq\"]]\noutcome = {{ seq = \"failure\" }}\n"
    );
    let s = scenario(&text);
    let runs = run::run_all(&s, None, None);
    assert_eq!(runs[0].policy, "bt");
    let got: Vec<(String, Status)> = super::expect::check(&s.expect, &runs)
        .into_iter()
        .map(|e| (e.name, e.status))
        .collect();
    assert_eq!(
        got,
        [
            ("bt reaches the goal".to_string(), Status::Pass),
            ("seq reaches the goal".to_string(), Status::Fail),
            ("seq ends failure".to_string(), Status::Pass),
            ("bt matches seq".to_string(), Status::Fail),
        ]
    );
    // A name no policy has is a positioned error with a suggestion.
    let bad = text.replace("reach_goal = [\"bt\"", "reach_goal = [\"bq\"");
    let e = refused(&bad);
    let span = e[0].span.clone().expect("positioned");
    assert_eq!(&bad[span], "\"bq\"");
    assert!(e[0].to_string().contains("did you mean `bt`?"), "{}", e[0]);
}

/// A symbolic run's JSON has the planar run's verdict keys: `verdicts`,
/// `match`, `first_divergence` (with the actions where the runs part).
#[test]
fn symbolic_verdicts_use_the_planar_keys() {
    use btfsm_core::output::{Format, Report};
    let s = scenario(&format!(
        "{HEAD}{}",
        policies(&["fig01-bt", "fig04-fsm", "fig03-bt"])
    ));
    let runs = run::run_all(&s, None, None);
    let r = super::report::RunsReport::new(&s, &runs);
    let v: serde_json::Value = serde_json::from_str(&r.write(Format::Json)).unwrap();
    assert!(v.get("pairs").is_none());
    let verdicts = v["verdicts"].as_array().expect("verdicts");
    assert_eq!(verdicts[0]["match"], true, "{v}");
    assert!(verdicts[0]["first_divergence"].is_null());
    // Fig. 1 against Fig. 3: Fig. 3 first goes to the delivery station.
    let d = &verdicts[1]["first_divergence"];
    assert_eq!(d["index"], 0, "{d}");
    assert_eq!(
        (d["a"].as_str(), d["b"].as_str()),
        (Some("Move-To(cube2)"), Some("Move-To(delivery)"))
    );
    assert_eq!(d["kind"], "action");
}

/// Two entries of one file are told apart (`NAME#2`); a stated name given
/// twice is refused.
#[test]
fn duplicate_symbolic_policy_names_are_told_apart_or_refused() {
    let s = scenario(&format!("{HEAD}{}", policies(&["fig01-bt", "fig01-bt"])));
    let names: Vec<&str> = s.policies.iter().map(|(_, p)| p.name.as_str()).collect();
    assert_eq!(names, ["Fig. 1 BT baseline", "Fig. 1 BT baseline#2"]);
    let e = refused(&format!(
        "{HEAD}[[policies]]\nfile = \"../paper/fig01-bt.toml\"\nname = \"x\"\n[[policies]]\nfile = \"../paper/fig04-fsm.toml\"\nname = \"x\"\n"
    ));
    let all: String = e.iter().map(|d| d.to_string()).collect();
    assert!(all.contains("two policies are named `x`"), "{all}");
}
