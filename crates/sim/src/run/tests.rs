//! Runs, Monte Carlo episodes, timelines, `after_success`, replays.

use super::*;
use crate::livelock::{LIVELOCK_STATES, Livelock};
use crate::monte_carlo::{monte_carlo, monte_carlo_within};
use crate::test_support::{deliver, scenario};
use btfsm_core::diagnostic::SourceFile;
use btfsm_format::Limits;
use std::path::Path;

/// Fig. 1's BT and Fig. 4's FSM fetching cube2 to the delivery station,
/// with `rest` (disturbances, more policies) after them.
fn fig1_fig4(rest: &str) -> String {
    deliver(&format!(
        "{}{rest}",
        r#"[[policies]]
file = "../paper/fig01-bt.toml"
[[policies]]
file = "../paper/fig04-fsm.toml"
"#
    ))
}

const FLAKY: &str = r#"
seed = 11
goal = [{ if = "Object-At", args = { object = "cube2", at = "delivery" } }]
[world]
objects = { cube2 = { at = "east-table" } }
[rates]
Pick = 0.5
[[policies]]
file = "../paper/fig01-bt.toml"
[[policies]]
file = "../paper/fig04-fsm.toml"
[monte_carlo]
battery_drop = { probability = 1.0, level = [10, 15], window = [1.0, 5.0] }
"#;

/// Equivalent policies produce equal timelines: with grasps failing at
/// random, the BT of Fig. 1, its HFSM and the fault-tolerant FSM of
/// Fig. 4 start every skill in the same step (no step lost after a
/// failure), so their verdict is a match for every seed.
#[test]
fn equivalent_bt_and_fsm_produce_equal_timelines() {
    let mut s = scenario(&FLAKY.replace(
        "[[policies]]\nfile = \"../paper/fig04-fsm.toml\"",
        "[[policies]]\nfile = \"../paper/fig04-fsm.toml\"\n[[policies]]\nfile = \"../paper/fig01-bt.toml\"\nconvert = \"hfsm\"",
    ));
    let mut failed = 0;
    for seed in 0..20 {
        s.seed = seed;
        let runs = run_scenario(&s, false);
        failed += (runs[0].skills.iter())
            .filter(|r| r.outcome == "failure")
            .count();
        for v in crate::trace::verdicts(&runs, 300) {
            assert!(v.matches, "seed {seed}: {v:?}");
            assert_eq!(v.trajectory_distance_m, 0.0);
        }
        let starts = |r: &Run| r.skills.iter().map(|k| k.start).collect::<Vec<_>>();
        assert_eq!(starts(&runs[0]), starts(&runs[1]), "seed {seed}");
        assert_eq!(starts(&runs[0]), starts(&runs[2]), "seed {seed}");
    }
    assert!(failed >= 10, "the grasps failed {failed} times");
}

/// Retrying an action that failed is not a livelock (that is what
/// `max_failures` bounds): five failed grasps in a row, then success.
#[test]
fn retries_of_a_failing_action_are_not_a_livelock() {
    let s = scenario(&fig1_fig4(
        r#"[[disturbances]]
at = 0.0
fail = "Pick"
times = 5
"#,
    ));
    for r in run_scenario(&s, false) {
        assert_eq!(
            (r.outcome, r.goal_met),
            (Outcome::Success, Some(true)),
            "{}",
            r.policy
        );
    }
}

/// What happens after SUCCESS is written per policy: a BT told to stop
/// ignores the cube moved after completion, the BT that keeps ticking
/// fetches it again. An FSM told to keep ticking is re-entered at its
/// initial state: Fig. 4's is `Move-To cube2`, so it starts its task
/// over at once — it picks the delivered cube up again — and so also
/// ends with the cube delivered, by other skills than the BT's.
#[test]
fn after_success_is_a_property_of_the_run() {
    let s = scenario(&deliver(
        r#"[[policies]]
file = "../paper/fig01-bt.toml"
name = "BT stop"
after_success = "stop"
[[policies]]
file = "../paper/fig04-fsm.toml"
name = "FSM keep-ticking"
after_success = "keep-ticking"
[[policies]]
file = "../paper/fig01-bt.toml"
[[disturbances]]
after_done = 2.0
move = "cube2"
to = [0.0, 1.3]
"#,
    ));
    let runs = run_scenario(&s, false);
    assert_eq!(runs[0].goal_met, Some(false));
    assert_eq!(runs[1].goal_met, Some(true));
    assert_eq!(runs[2].goal_met, Some(true));
    assert_eq!(runs[0].skills.len(), 4);
    assert_eq!(
        (runs[1].skills[4].skill.as_str(), runs[1].skills[4].start),
        ("Move-To", 16.5)
    );
    assert_eq!(
        (runs[1].skills[5].skill.as_str(), runs[1].skills[5].start),
        ("Pick", 16.6)
    );
    let v = crate::trace::verdicts(&runs, 300);
    assert!(v.iter().all(|v| !v.matches), "{v:?}");
}

/// What happens after FAILURE is written per policy too: the sequential
/// FSM of Fig. 2 told to keep ticking is re-entered at its initial state
/// after its failed grasp (the paper's "task reset") and reaches the goal;
/// the BT told to stop ends at its root's first FAILURE; the defaults
/// (FSM stops, BT and its HFSM keep ticking) are as before.
#[test]
fn after_failure_is_a_property_of_the_run() {
    let s = scenario(&deliver(
        r#"[[policies]]
file = "../paper/fig02-fsm.toml"
name = "FSM reset"
after_failure = "keep-ticking"
[[policies]]
file = "../paper/fig02-fsm.toml"
after_failure = "stop"
[[policies]]
file = "../paper/fig01-bt.toml"
name = "BT stop"
after_failure = "stop"
[[policies]]
file = "../paper/fig01-bt.toml"
convert = "hfsm"
[[disturbances]]
at = 0.0
fail = "Pick"
"#,
    ));
    let runs = run_scenario(&s, false);
    let got: Vec<(Outcome, Option<bool>, &str)> = (runs.iter())
        .map(|r| (r.outcome, r.goal_met, r.after_failure))
        .collect();
    assert_eq!(
        got,
        vec![
            (Outcome::Success, Some(true), "keep-ticking"),
            (Outcome::Failure, Some(false), "stop"),
            (Outcome::Failure, Some(false), "stop"),
            (Outcome::Success, Some(true), "keep-ticking"),
        ]
    );
    assert_eq!(
        runs[2].reason,
        "the root returned FAILURE (after_failure = \"stop\")"
    );
    // The reset starts the task over at once: Move-To cube2 (already there).
    let r = &runs[0].skills;
    assert_eq!(
        (r[1].skill.as_str(), r[1].outcome.as_str()),
        ("Pick", "failure")
    );
    assert_eq!(
        (r[2].skill.as_str(), r[2].start),
        ("Move-To", r[1].end.unwrap())
    );
}

/// `sim --seed S` runs episode S of `--runs`: for every episode, the
/// single run with its seed gives the pair verdicts Monte Carlo counted,
/// and the first diverging episode is the first whose replay differs.
#[test]
fn the_seed_of_an_episode_replays_it() {
    let s = crate::scenario::load(
        Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../tests/fixtures/sim/monte-carlo-pick.toml"
        )),
        &Limits::default(),
    )
    .expect("valid");
    let n = 30;
    let mc = monte_carlo(&s, n, 7, 2);
    let mut first = vec![None; mc.pairs.len()];
    let mut diverged = 0;
    for i in 0..n {
        let seed = crate::monte_carlo::episode_seed(7, i);
        let (ds, rates) = crate::monte_carlo::episode(&s, seed);
        let mut one = s.clone();
        (one.seed, one.disturbances, one.rates) = (seed, ds, rates);
        let runs = run_scenario(&one, false);
        for (k, v) in crate::trace::verdicts(&runs, 300).iter().enumerate() {
            if !v.matches && first[k].is_none() {
                first[k] = Some((i, seed));
                diverged += 1;
            }
        }
    }
    assert!(diverged >= 2, "{mc:?}");
    for (p, f) in mc.pairs.iter().zip(first) {
        let got = p.first_divergence.as_ref().map(|d| (d.episode, d.seed));
        assert_eq!(got, f, "{} vs {}", p.a, p.b);
    }
}

#[test]
fn wilson_intervals_are_the_textbook_ones() {
    use crate::monte_carlo::wilson;
    assert_eq!(wilson(0, 10), [0.0, 0.2775]);
    assert_eq!(wilson(10, 10), [0.7225, 1.0]);
    assert_eq!(wilson(5, 10), [0.2366, 0.7634]);
    assert_eq!(wilson(10_000, 10_000), [0.9996, 1.0]);
    assert_eq!(wilson(0, 0), [0.0, 1.0]);
}

/// The livelock detector remembers at most LIVELOCK_STATES states: a
/// run through ever new states never fires and never grows past it.
#[test]
fn livelock_memory_is_bounded() {
    let mut l = Livelock::new(2);
    for x in 0..3 * LIVELOCK_STATES as u64 {
        assert_eq!(l.step(x, true, 0, false), None);
        assert!(l.seen.len() <= LIVELOCK_STATES);
    }
    // A state entered twice without progress fires; progress resets it.
    assert_eq!(l.step(7, true, 0, false), None);
    assert_eq!(l.step(7, true, 1, false), None);
    assert_eq!(l.step(7, true, 1, false), Some(2));
}

#[test]
fn runs_are_deterministic_given_the_seed() {
    let s = scenario(FLAKY);
    let a = run_scenario(&s, false);
    let b = run_scenario(&s, false);
    assert_eq!(a[0].skills, b[0].skills);
    assert_eq!(a[0].trajectory, b[0].trajectory);
    // With a 50% grasp failure rate some seed makes a Pick fail.
    let failed = (0..10u64).any(|seed| {
        let mut s = s.clone();
        s.seed = seed;
        run_scenario(&s, false)[0]
            .skills
            .iter()
            .any(|r| r.skill == "Pick" && r.outcome == "failure")
    });
    assert!(failed);
}

#[test]
fn monte_carlo_does_not_depend_on_the_number_of_threads() {
    let s = scenario(FLAKY);
    let one = monte_carlo(&s, 6, 3, 1);
    let two = monte_carlo(&s, 6, 3, 2);
    assert_eq!(one, two);
    assert_eq!(one.pairs.len(), 1);
    let one = one.policies;
    assert_eq!(one.len(), 2);
    assert_eq!(one[0].runs, 6);
    // Every episode drops the battery, so every policy recharges.
    assert!(
        one.iter()
            .all(|p| p.recharges == 0 || p.mean_recharge_latency_s.is_some())
    );
    assert!(one.iter().all(|p| p.success_rate > 0.0));
}

#[test]
fn a_spent_wall_clock_budget_stops_every_run_at_once() {
    let s = scenario(FLAKY);
    // No deadline: the same figures as without the budget.
    let mc = monte_carlo_within(&s, 6, 3, 2, None);
    assert_eq!(mc.runs, 6);
    assert_eq!(mc, monte_carlo(&s, 6, 3, 2));
    // A deadline already past: no episode completes, no figure is made up.
    let mc = monte_carlo_within(&s, 6, 3, 2, Some(Instant::now()));
    assert_eq!(mc.runs, 0);
    assert!(mc.policies.iter().all(|p| p.runs == 0 && p.successes == 0));
    assert!(
        mc.pairs
            .iter()
            .all(|p| p.runs == 0 && p.first_divergence.is_none())
    );
    let (runs, cut) = run_scenario_within(&s, false, Some(Instant::now()));
    assert!(cut);
    for r in &runs {
        assert_eq!(r.outcome, Outcome::Timeout);
        assert_eq!(
            (r.steps, r.reason.as_str()),
            (0, "wall-clock budget exhausted at step 0")
        );
    }
    let (free, cut) = run_scenario_within(&s, false, None);
    assert!(!cut);
    let plain = run_scenario(&s, false);
    let key = |r: &Run| (r.outcome, r.steps, r.reason.clone());
    assert_eq!(
        free.iter().map(key).collect::<Vec<_>>(),
        plain.iter().map(key).collect::<Vec<_>>()
    );
}

/// A BT that picks and places the cube every other step (both instantaneous)
/// recorded two skills and four events a step, 3.3 GB over 10^6 steps:
/// a run now ends once its records are full, and that is not taken for
/// the wall-clock budget.
#[test]
fn a_run_ends_when_its_records_are_full() {
    let dir = std::env::temp_dir().join(format!("btfsm-records-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("pp.toml"),
        "kind = \"bt\"\nroot = \"root\"\n[nodes]\nroot = { sequence_memory = [\"pick\", \"place\"] }\npick = { action = \"Pick\", skill = \"Pick\", args = { object = \"cube2\" } }\nplace = { action = \"Place\", skill = \"Place\", args = { object = \"cube2\", at = \"east-table\" } }\n",
    )
    .unwrap();
    let text = "max_steps = 1000000\nlivelock_repeats = 1000000\n[world]\nrobot = \"east-table\"\nparams = { manipulation_s = 0 }\nobjects = { cube2 = { at = \"east-table\" } }\n[[policies]]\nfile = \"pp.toml\"\n[[disturbances]]\nat = 1000000000.0\nbattery = 100.0\n";
    let f = SourceFile::new("pp-scenario.toml", text);
    let s = super::super::scenario::parse(&f, &dir, &Limits::default()).expect("valid");
    let (runs, cut) = run_scenario_within(&s, false, None);
    assert!(!cut);
    let r = &runs[0];
    assert_eq!(r.outcome, Outcome::Timeout);
    assert!(
        r.reason.starts_with("record budget exhausted at step"),
        "{}",
        r.reason
    );
    assert_eq!(r.skills.len(), MAX_SKILL_RECORDS);
    assert!(r.events.len() <= MAX_EVENTS);
    // Every action takes at least one step: two steps a record.
    assert!(r.steps < 2100, "{}", r.steps);
    // Monte Carlo: a timeout of the episode, not a budget cut.
    let mc = monte_carlo_within(&s, 2, 1, 1, None);
    assert_eq!((mc.runs, mc.policies[0].timeouts), (2, 2));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_sequential_policy_without_a_failure_arc_fails() {
    let s = scenario(
        r#"
[world]
objects = { cube2 = { at = "east-table" } }
[[policies]]
file = "../paper/fig02-fsm.toml"
after_failure = "stop"
[[disturbances]]
at = 0.0
fail = "Move-To"
"#,
    );
    let r = &run_scenario(&s, true)[0];
    assert_eq!(r.outcome, Outcome::Failure);
    assert_eq!(r.skills.len(), 1);
    assert!(!r.trace.is_empty());
    assert!(
        r.trace[0]
            .statuses
            .iter()
            .any(|(k, st)| k == "Move-To cube2" && st == "RUNNING")
    );
}

#[test]
fn a_dropped_cube_is_picked_again_and_a_blocked_goal_gives_up() {
    let s = scenario(&fig1_fig4(
        r#"[[disturbances]]
when = [{ if = "In-Hand", args = { object = "cube2" } }]
drop = "cube2"
"#,
    ));
    let runs = run_scenario(&s, false);
    for r in &runs {
        assert_eq!(r.goal_met, Some(true), "{}", r.policy);
        let picks = r
            .skills
            .iter()
            .filter(|x| x.skill == "Pick" && x.outcome == "success");
        assert_eq!(picks.count(), 2, "{}", r.policy);
    }
    // The BT notices the drop at once; the FSM only when Place fails.
    assert!(
        !runs[0]
            .skills
            .iter()
            .any(|x| x.skill == "Place" && x.outcome == "failure")
    );
    assert!(
        runs[1]
            .skills
            .iter()
            .any(|x| x.skill == "Place" && x.outcome == "failure")
    );

    let s = scenario(
        r#"
[world]
objects = { cube2 = { at = "east-table" } }
[[policies]]
file = "../paper/fig01-bt.toml"
[[policies]]
file = "../paper/fig04-fsm.toml"
[[disturbances]]
at = 0.0
block = { name = "fence", rect = [-0.5, 1.4, 1.5, 1.5] }
[[disturbances]]
at = 0.0
block = { name = "fence2", rect = [-0.5, 1.4, -0.4, 2.99] }
[[disturbances]]
at = 0.0
block = { name = "fence3", rect = [1.4, 1.4, 1.5, 2.99] }
"#,
    );
    for r in run_scenario(&s, false) {
        assert_eq!(r.outcome, Outcome::Failure, "{}", r.policy);
        assert!(r.reason.starts_with("gave up"), "{}", r.reason);
    }
}

/// The same skills at the same times do not make a match when the robots
/// were apart: the verdict compares motion too, within the scenario's
/// `pose_tolerance_m` (default 0.2 m), and names it (`same_motion`).
#[test]
fn runs_apart_by_more_than_the_pose_tolerance_differ() {
    let s = scenario(&fig1_fig4(""));
    let mut runs = run_scenario(&s, false);
    let v = &crate::trace::verdicts(&runs, 300)[0];
    assert!(v.matches && v.same_motion, "{v:?}");
    assert_eq!(v.pose_tolerance_m, 0.2);
    // The FSM's robot 0.5 m off its path for one step in the middle.
    let k = runs[1].track.len() / 2;
    runs[1].track[k].1.0 += 0.5;
    let v = &crate::trace::verdicts(&runs, 300)[0];
    assert!(v.same_skills && !v.same_motion && !v.matches, "{v:?}");
    // (0.5 m at that step; a step's shift of the clock brings it closer.)
    assert!(v.trajectory_distance_m >= 0.4, "{v:?}");
    // The worlds diverged at that step (within the step's shift of the
    // clocks), not at the first differing call: there is none.
    let t = runs[1].track[k].0 as f64 * runs[1].dt;
    let at = v.worlds_diverge_s.expect("diverged");
    assert!((at - t).abs() <= runs[1].dt + 1e-9, "{at} vs {t}");
    // A scenario that allows 1 m calls it the same motion.
    let loose = scenario(&format!("pose_tolerance_m = 1.0\n{}", fig1_fig4("")));
    let mut runs2 = run_scenario(&loose, false);
    runs2[1].track[k].1.0 += 0.5;
    assert!(crate::trace::verdicts(&runs2, 300)[0].matches);
}

/// What a policy does after FAILURE is one setting for every
/// representation: by default a BT and a machine alike are ticked (or
/// started) again; the scenario's own `after_failure` applies to all its
/// policies, and an entry may still state its own.
#[test]
fn after_failure_is_one_setting_for_every_representation() {
    let body = r#"[[policies]]
file = "../paper/fig02-fsm.toml"
[[policies]]
file = "../paper/fig01-bt.toml"
[[disturbances]]
at = 0.0
fail = "Pick"
"#;
    // `top` goes before the tables.
    let outcomes = |top: &str, text: &str| -> Vec<(Outcome, &'static str)> {
        let s = scenario(&format!("{top}{}", deliver(text)));
        (run_scenario(&s, false).iter())
            .map(|r| (r.outcome, r.after_failure))
            .collect()
    };
    assert_eq!(
        outcomes("", body),
        [
            (Outcome::Success, "keep-ticking"),
            (Outcome::Success, "keep-ticking")
        ]
    );
    // The scenario's setting: both stop at their first FAILURE.
    assert_eq!(
        outcomes("after_failure = \"stop\"\n", body),
        [(Outcome::Failure, "stop"), (Outcome::Failure, "stop")]
    );
    // An entry's own setting wins over the scenario's.
    let own = body.replace(
        "fig01-bt.toml\"\n",
        "fig01-bt.toml\"\nafter_failure = \"keep-ticking\"\n",
    );
    assert_eq!(
        outcomes("after_failure = \"stop\"\n", &own),
        [
            (Outcome::Failure, "stop"),
            (Outcome::Success, "keep-ticking")
        ]
    );
}

/// The same motion some steps later is the same motion when the scenario's
/// `time_shift_s` allows that shift, and differs when it does not: the
/// verdict reports the shift it used.
#[test]
fn a_run_steps_later_moves_alike_within_the_time_shift() {
    let late = |text: &str| {
        let s = scenario(&format!("{text}{}", fig1_fig4("")));
        let mut runs = run_scenario(&s, false);
        // The FSM's robot does everything 6 steps (0.6 s) later.
        for p in runs[1].track.iter_mut().skip(1) {
            p.0 += 6;
        }
        crate::trace::verdicts(&runs, 300).remove(0)
    };
    let strict = late("time_shift_s = 0.0\n");
    assert!(!strict.same_motion, "{strict:?}");
    assert_eq!(strict.time_shift_s, 0.0);
    assert!(strict.worlds_diverge_s.is_some(), "{strict:?}");
    let allowed = late("time_shift_s = 0.6\n");
    assert!(allowed.same_motion && allowed.matches, "{allowed:?}");
    assert_eq!((allowed.time_shift_s, allowed.max_time_shift_s), (0.6, 0.6));
    assert_eq!(allowed.trajectory_distance_m, 0.0);
    assert_eq!(allowed.worlds_diverge_s, None);
    // By default the shift is one step (`start_tolerance_s`).
    assert_eq!(late("").max_time_shift_s, 0.1);
}

/// The trace says where the base is going and what the robot believes, so
/// that a detour can be explained: cube2 moved 0.8 m at 4 s while the robot
/// drives to it; the first Move-To goes where the cube was believed at its
/// start, the camera then sees it elsewhere (a `belief` event), and a later
/// Move-To goes to the new belief.
#[test]
fn the_trace_records_navigation_goals_and_beliefs() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../policies/scenarios/exp1-cube-moved-during.toml"
    ))
    .unwrap();
    let s = crate::scenario::parse(
        &btfsm_core::diagnostic::SourceFile::new("exp1.toml", &text),
        std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../policies/scenarios"
        )),
        &btfsm_format::Limits::default(),
    )
    .unwrap();
    let bt = &run_scenario(&s, true)[0];
    let seen: Vec<&crate::trace::Event> = bt.events.iter().filter(|e| e.kind == "belief").collect();
    assert!(
        seen.iter()
            .any(|e| e.t > 4.0 && e.text.starts_with("camera: cube2 believed at")),
        "{:?}",
        bt.events
    );
    let goals: Vec<[f64; 2]> = bt.trace.iter().filter_map(|st| st.goal).collect();
    assert!(!goals.is_empty());
    let mut distinct = goals.clone();
    distinct.dedup();
    // Out to the cube's first believed place, to its new one, to delivery.
    assert!(distinct.len() >= 3, "{distinct:?}");
    assert!(
        bt.trace
            .iter()
            .all(|st| st.goal.is_none() || !st.running.is_empty()),
        "a goal only while something drives"
    );
}

/// The recharge latency is measured, not 0 by construction: Fig. 8d with
/// no battery guard on `Move-To cube2` (its arrival goes to SELECTOR, which
/// has one) drives on to the cube after the battery falls at 4 s and starts
/// Recharge only once it arrives, while the BT of Fig. 7d (its battery
/// check ticked every step) starts it in the step the battery falls.
#[test]
fn recharge_latency_is_the_time_a_policy_takes_to_react() {
    let dir = std::env::temp_dir().join(format!("btfsm-latency-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let paper = concat!(env!("CARGO_MANIFEST_DIR"), "/../../policies/paper/");
    let fsm = std::fs::read_to_string(format!("{paper}fig08d-fsm.toml")).unwrap();
    let guard = "guards = [{ unless = \"Battery-Level\", args = { min = 20 }, to = \"Recharge\", label = \"battery < 20%\" }]\non = { SUCCESS = \"Pick cube2\",";
    assert!(fsm.contains(guard));
    let late = fsm
        .replace(guard, "on = { SUCCESS = \"SELECTOR\",")
        .replace("name = \"Fig. 8d FSM recharge\"", "name = \"late\"");
    std::fs::write(dir.join("late.toml"), late).unwrap();
    std::fs::copy(format!("{paper}fig07d-bt.toml"), dir.join("bt.toml")).unwrap();
    let text = r#"goal = [{ if = "Object-At", args = { object = "cube2", at = "delivery" } }]
[world]
robot = "start"
objects = { cube2 = { at = "east-table" } }
[[policies]]
file = "bt.toml"
[[policies]]
file = "late.toml"
[[disturbances]]
at = 4.0
battery = 15
"#;
    let f = btfsm_core::diagnostic::SourceFile::new("s.toml", text);
    let s = crate::scenario::parse(&f, &dir, &btfsm_format::Limits::default()).unwrap();
    let runs = run_scenario(&s, false);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(runs[0].recharge_latency_s, [0.0], "the BT reacts at once");
    let arrived = (runs[1].skills.iter())
        .find(|k| k.skill == "Move-To")
        .and_then(|k| k.end)
        .expect("the first Move-To ends");
    assert!(arrived > 4.5, "{arrived}");
    let lat = runs[1].recharge_latency_s[0];
    assert!(
        (lat - (arrived - 4.0)).abs() <= s.dt + 1e-9,
        "{lat} vs arrival {arrived}"
    );
    assert!(runs.iter().all(|r| r.goal_met == Some(true)));
}
