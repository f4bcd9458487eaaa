//! Tests of the simulator's physics through the robot the executors drive
//! (src/sim/robot.rs): one base and one arm, motion once per step, halts
//! before anything moves, faults part-way, the empty battery, Shut-Down,
//! and, over whole scenarios, the speed and turn-rate limits and the
//! difference gradual charging makes (docs/simulator-model.md names each).

use super::exec::Leaves;
use super::robot::{Faults, Robot, apply};
use super::run::run_scenario;
use super::scenario::{self, Disturbance, Effect, Scenario, When};
use super::skills::{Call, Status, Target};
use super::world::{Object, Place, World, dist};
use btfsm_core::diagnostic::SourceFile;
use btfsm_format::Limits;
use std::collections::BTreeMap;
use std::path::Path;

fn world() -> World {
    let cube = Object::new("cube2", Place::At((1.7, 0.0)), (1.7, 0.0), true);
    crate::world::paper_room_with(vec![cube])
}

fn robot(w: World, leaves: usize) -> Robot {
    Robot::new(w, 0.1, leaves, Faults::new(1, BTreeMap::new()), true)
}

fn station(r: &Robot, name: &str) -> Target {
    Target::Station(r.world.layout.station_index(name).expect("station"))
}

fn to(r: &Robot, name: &str) -> Call {
    Call::MoveTo {
        target: station(r, name),
        safe: false,
    }
}

/// Ends a step as the run loop does.
fn end(r: &mut Robot) {
    r.end_step();
    r.world.advance(r.dt);
}

fn outcome(r: &Robot, i: usize) -> &str {
    r.records[i].outcome.as_str()
}

#[test]
fn a_new_navigation_goal_aborts_the_running_one() {
    let mut r = robot(world(), 2);
    let (a, b) = (to(&r, "delivery"), to(&r, "charging"));
    assert_eq!(r.action(0, &a), Status::Running);
    end(&mut r);
    assert_eq!(r.action(0, &a), Status::Running);
    // Both ticked in one step: the second goal aborts the first at once.
    assert_eq!(r.action(1, &b), Status::Running);
    assert_eq!(outcome(&r, 0), "aborted");
    let before = r.world.robot;
    end(&mut r);
    // The base moved once, toward the new goal only.
    assert!(dist(before, r.world.robot) <= 0.05 + 1e-9);
    let goal = r.world.layout.station("charging").unwrap();
    assert!(dist(r.world.robot, goal) < dist(before, goal));
    // The aborted leaf learns it at its next tick, with no new record.
    assert_eq!(r.action(0, &a), Status::Failure);
    assert_eq!(r.action(1, &b), Status::Running);
    assert_eq!(r.records.len(), 2);
    // The same for the arm.
    let mut w = world();
    w.robot = (1.7, 0.0);
    let mut r = robot(w, 2);
    let pick = Call::Pick { object: 0 };
    assert_eq!(r.action(0, &pick), Status::Running);
    assert_eq!(r.action(1, &Call::TuckArm), Status::Running);
    assert_eq!(outcome(&r, 0), "aborted");
}

#[test]
fn a_halted_action_stops_before_anything_moves() {
    let mut r = robot(world(), 1);
    let a = to(&r, "delivery");
    for _ in 0..5 {
        assert_eq!(r.action(0, &a), Status::Running);
        end(&mut r);
    }
    let here = r.world.robot;
    r.halt(0);
    assert_eq!(outcome(&r, 0), "cancelled");
    end(&mut r);
    assert_eq!(r.world.robot, here);
    // Not ticked in a step: cancelled at the end of it, before the motion.
    assert_eq!(r.action(0, &a), Status::Running);
    end(&mut r);
    let here = r.world.robot;
    end(&mut r);
    assert_eq!(r.world.robot, here);
    assert_eq!(outcome(&r, 1), "cancelled");
}

/// Every action's first tick is RUNNING, failing or not, even with zero
/// durations and the robot already at its goal; so an FSM makes at most one
/// attempt per step.
#[test]
fn every_action_takes_at_least_one_step() {
    let mut w = world();
    w.params.manipulation_s = 0.0;
    w.params.arm_s = 0.0;
    w.robot = w.layout.station("charging").unwrap();
    let mut r = robot(w, 1);
    let long = [
        Call::MoveTo {
            target: Target::Object(0),
            safe: true,
        },
        Call::Dock,
        Call::Search,
    ];
    // Done, or failing, at once: still RUNNING first, the outcome next.
    let short = [
        to(&r, "charging"),
        Call::Pick { object: 0 },
        Call::Place { object: 0, at: 0 },
        Call::Recharge,
        Call::TuckArm,
        Call::ShutDown,
    ];
    for c in long.into_iter().chain(short) {
        assert_eq!(r.action(0, &c), Status::Running, "{}", c.name());
        end(&mut r);
        if short.contains(&c) {
            assert_ne!(r.action(0, &c), Status::Running, "{}", c.name());
        }
        r.halt(0);
        r.world.shut_down = false;
    }
}

/// An injected fault aborts a navigation part-way: it stops short of its
/// goal, at a point drawn from the seed (different seeds, different points).
#[test]
fn an_injected_fault_stops_navigation_short_of_its_goal() {
    let mut stops = Vec::new();
    for seed in 0..4 {
        let mut r = robot(world(), 1);
        r.faults = Faults::new(seed, BTreeMap::new());
        r.faults.next.insert("Move-To".into(), 1);
        let a = to(&r, "charging");
        let goal = r.world.layout.station("charging").unwrap();
        let full = dist(r.world.robot, goal);
        let mut n = 0;
        while r.action(0, &a) == Status::Running {
            end(&mut r);
            n += 1;
            assert!(n < 1000);
        }
        assert_eq!(outcome(&r, 0), "failure");
        let left = dist(r.world.robot, goal);
        assert!(
            left > 0.05 * full - 1e-9 && left < 0.95 * full + 1e-9,
            "{left}"
        );
        stops.push((left * 1000.0).round() as i64);
    }
    stops.sort();
    stops.dedup();
    assert!(stops.len() > 1, "{stops:?}");
}

#[test]
fn an_empty_battery_stops_the_base_and_the_navigation_aborts_when_stalled() {
    let mut w = world();
    w.battery = 0.0;
    let mut r = robot(w, 1);
    let here = r.world.robot;
    let a = to(&r, "delivery");
    let mut n = 0;
    while r.action(0, &a) == Status::Running {
        end(&mut r);
        n += 1;
    }
    assert_eq!(r.world.robot, here);
    assert_eq!(outcome(&r, 0), "failure");
    // Nav2's progress checker: stall_s (10 s) without moving.
    assert!((100..=102).contains(&n), "{n}");
}

#[test]
fn shut_down_stops_every_moving_skill_until_the_emergency_clears() {
    let mut w = world();
    w.robot = (1.7, 0.0);
    let mut r = robot(w, 1);
    let run = |r: &mut Robot, c: Call| {
        let mut n = 0;
        loop {
            let s = r.action(0, &c);
            if s != Status::Running {
                return s;
            }
            end(r);
            n += 1;
            assert!(n < 10_000);
        }
    };
    apply(
        &Disturbance {
            when: When::At(0.0),
            effect: Effect::Emergency(true),
            text: "emergency".into(),
        },
        &mut r,
    );
    assert_eq!(run(&mut r, Call::ShutDown), Status::Success);
    assert!(r.world.shut_down);
    let here = r.world.robot;
    for c in [
        to(&r, "delivery"),
        Call::Pick { object: 0 },
        Call::TuckArm,
        Call::Recharge,
        Call::Dock,
        Call::Search,
    ] {
        assert_eq!(run(&mut r, c), Status::Failure, "{}", c.name());
    }
    assert_eq!(r.world.robot, here);
    assert_eq!(r.world.objects[0].place, Place::At((1.7, 0.0)));
    apply(
        &Disturbance {
            when: When::At(0.0),
            effect: Effect::Emergency(false),
            text: "emergency over".into(),
        },
        &mut r,
    );
    assert!(!r.world.shut_down);
    assert_eq!(run(&mut r, Call::Pick { object: 0 }), Status::Success);
}

#[test]
fn pick_needs_the_object_within_reach() {
    let mut w = world();
    w.robot = (1.7, 0.15);
    let mut r = robot(w, 1);
    let pick = Call::Pick { object: 0 };
    assert_eq!(r.action(0, &pick), Status::Running);
    end(&mut r);
    assert_eq!(r.action(0, &pick), Status::Failure);
    r.world.robot = (1.7, 0.09);
    let mut s = Status::Running;
    while s == Status::Running {
        s = r.action(0, &pick);
        end(&mut r);
    }
    assert_eq!(s, Status::Success);
    assert!(r.world.arm_tucked);
}

fn scenario_in(dir: &Path, text: &str) -> Scenario {
    let f = SourceFile::new("t.toml", text);
    scenario::parse(&f, dir, &Limits::default()).expect("valid scenario")
}

/// Over every bundled scenario and a BT running two Move-Tos under a
/// Parallel, no step moves the base further than `max_speed * dt`, turns it
/// faster than `max_turn_rate`, or puts it inside an obstacle.
#[test]
fn the_base_never_exceeds_its_limits_nor_enters_an_obstacle() {
    let dir = std::env::temp_dir().join(format!("btfsm-limits-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("par.toml"),
        "kind = \"bt\"\nroot = \"root\"\n[nodes]\nroot = { parallel = [\"a\", \"b\"], success = 2 }\na = { action = \"A\", skill = \"Move-To\", args = { target = \"delivery\" } }\nb = { action = \"B\", skill = \"Move-To\", args = { target = \"east-table\" } }\n",
    )
    .unwrap();
    let mut scenarios = vec![scenario_in(
        &dir,
        "max_steps = 400\n[[policies]]\nfile = \"par.toml\"\n",
    )];
    let mut files: Vec<_> = std::fs::read_dir(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../policies/scenarios"
    ))
    .unwrap()
    .map(|e| e.unwrap().path())
    .collect();
    files.sort();
    for f in files {
        scenarios.push(scenario::load(&f, &Limits::default()).expect("bundled"));
    }
    for s in &scenarios {
        let p = &s.world.params;
        for run in run_scenario(s, true) {
            let mut prev = (s.world.robot, s.world.yaw);
            for st in &run.trace {
                let d = dist(prev.0, (st.x, st.y));
                assert!(
                    d <= p.max_speed * s.dt + 1e-9,
                    "{} {}: {d} m at {}",
                    s.name,
                    run.policy,
                    st.t
                );
                let mut dy = (st.yaw - prev.1).abs();
                if dy > std::f64::consts::PI {
                    dy = std::f64::consts::TAU - dy;
                }
                assert!(
                    dy <= p.max_turn_rate * s.dt + 1e-9,
                    "{} {}: turned {dy}",
                    s.name,
                    run.policy
                );
                let layout = &s.world.layout;
                assert!(
                    layout
                        .check_free((st.x, st.y), p.robot_radius - 1e-6)
                        .is_ok(),
                    "{} {}: ({}, {}) in an obstacle",
                    s.name,
                    run.policy,
                    st.x,
                    st.y
                );
                prev = ((st.x, st.y), st.yaw);
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// With gradual charging the BT of Fig. 7d leaves the charger as soon as
/// `Battery-Level(20)` holds (its Recharge is halted, or aborted by the next
/// Move-To goal), drains below 20 % on its first metre and goes back: it
/// hovers at the threshold and never delivers. The FSM of Fig. 8d runs its
/// Recharge state to a full battery and delivers. The paper (sec. V-C)
/// assumes instantaneous charging and notes that gradual charging needs a
/// different recharge subtree; with the default (instantaneous) they match.
#[test]
fn gradual_charging_separates_the_bt_from_the_fsm() {
    let text = |rate: &str| {
        format!(
            "goal = [{{ if = \"Object-At\", args = {{ object = \"cube2\", at = \"delivery\" }} }}]\n[world]\nobjects = {{ cube2 = {{ at = \"east-table\" }} }}\n{rate}\n[[policies]]\nfile = \"../paper/fig07d-bt.toml\"\n[[policies]]\nfile = \"../paper/fig08d-fsm.toml\"\n[[disturbances]]\nat = 4.0\nbattery = 15\n"
        )
    };
    let base = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../policies/scenarios"
    ));
    let s = scenario_in(base, &text("params = { charge_per_s = 2.0 }"));
    let runs = run_scenario(&s, false);
    let recharges = |i: usize| {
        (runs[i].skills.iter())
            .filter(|k| k.skill == "Recharge")
            .map(|k| k.outcome.as_str())
            .collect::<Vec<_>>()
    };
    let bt = recharges(0);
    assert!(bt.len() > 2, "{bt:?}");
    assert!(!bt.contains(&"success"), "{bt:?}");
    assert_eq!(runs[0].goal_met, Some(false));
    assert!(runs[0].final_world.battery < 25.0);
    assert_eq!(recharges(1), ["success"]);
    assert_eq!(runs[1].goal_met, Some(true));
    let s = scenario_in(base, &text(""));
    let runs = run_scenario(&s, false);
    // The same behavior (the BT's preempted Move-To is `aborted` by the
    // Recharge goal, the FSM's `cancelled` by its guard: the same outcome
    // for the verdict).
    let v = crate::trace::verdicts(&runs, 300);
    assert!(v[0].matches, "{:?}", v[0]);
    assert_eq!(runs[0].goal_met, Some(true));
}

/// A cube dropped short of the station lies on the floor and is never
/// delivered; Place puts it on the table.
#[test]
fn a_dropped_cube_is_not_delivered() {
    let s = scenario_in(
        Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../policies/scenarios"
        )),
        "goal = [{ if = \"Object-At\", args = { object = \"cube2\", at = \"delivery\" } }]\n[world]\nrobot = [0.5, 1.83]\nobjects = { cube2 = { at = \"east-table\" } }\n[[policies]]\nfile = \"../paper/fig02-fsm.toml\"\nafter_failure = \"stop\"\n[[disturbances]]\nwhen = [{ if = \"Robot-At\", args = { target = \"delivery\" } }, { if = \"In-Hand\", args = { object = \"cube2\" } }]\ndrop = \"cube2\"\n",
    );
    let r = &run_scenario(&s, false)[0];
    assert_eq!(r.goal_met, Some(false));
    let c = &r.final_world.objects["cube2"];
    assert_eq!(c.at, None);
    assert!(!c.held);
}

/// A `block` that would land on the robot during a run is refused, with an
/// event saying so (the scenario check refuses one over the start).
#[test]
fn a_block_over_the_robot_is_refused() {
    let mut r = robot(world(), 1);
    let n = r.world.layout.obstacles.len();
    let here = r.world.robot;
    apply(
        &Disturbance {
            when: When::At(0.0),
            effect: Effect::Block(super::world::Rect::new(
                "box",
                here.0 - 0.1,
                here.1 - 0.1,
                here.0 + 0.1,
                here.1 + 0.1,
            )),
            text: "path blocked by box".into(),
        },
        &mut r,
    );
    assert_eq!(r.world.layout.obstacles.len(), n);
    assert_eq!(r.world.map_version, 0);
    let e = r.events.last().expect("an event");
    assert!(e.text.contains("refused"), "{}", e.text);
}

/// Whether a Move-To toward an object follows the robot's belief while it
/// runs is a modelling choice (`follow_belief`, default off) and it changes
/// the verdict: with it, the sequential FSM of Fig. 2 fetches the cube moved
/// during the task, as the issue found it did when navigation was
/// omniscient; without it, its grasp at the old place fails.
#[test]
fn following_the_belief_is_a_setting_that_changes_the_verdict() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../policies/scenarios/exp1-cube-moved-during.toml"
    ))
    .unwrap();
    let base = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../policies/scenarios"
    ));
    let fsm2 = |text: &str| {
        let s = scenario_in(base, text);
        let runs = run_scenario(&s, false);
        let r = runs
            .iter()
            .find(|r| r.policy == "Fig. 2 FSM sequential")
            .unwrap();
        r.goal_met
    };
    assert_eq!(fsm2(&text), Some(false));
    let follow = text.replace(
        "robot = \"start\"",
        "robot = \"start\"\nparams = { follow_belief = true }",
    );
    assert_ne!(follow, text);
    assert_eq!(fsm2(&follow), Some(true));
}

/// A cube dropped while carried: the robot that held it knows where it fell
/// (`drop_sensed`, default true), so the BT, which reacts in the step of
/// the drop, before the camera looks, drives to where the cube lies, and
/// never finishes later than the fault-tolerant FSM, which drives on to the
/// delivery station first. With `drop_sensed = false` (the belief stays
/// where the cube was picked until the camera sees it) the BT drives back
/// to the stale pickup spot and finishes later at some drop times: a
/// modelling choice that favoured the policy reacting later.
#[test]
fn a_dropped_cube_is_believed_where_it_fell() {
    let base = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../policies/scenarios"
    ));
    let later = |sensed: bool| {
        (0..24)
            .filter(|k| {
                let t = 10.0 + f64::from(*k) * 0.25;
                let text = format!(
                    "goal = [{{ if = \"Object-At\", args = {{ object = \"cube2\", at = \"delivery\" }} }}]\n[world]\nrobot = \"start\"\nobjects = {{ cube2 = {{ at = \"east-table\" }} }}\nparams = {{ drop_sensed = {sensed} }}\n[[policies]]\nfile = \"../paper/fig01-bt.toml\"\n[[policies]]\nfile = \"../paper/fig04-fsm.toml\"\n[[disturbances]]\nat = {t:?}\ndrop = \"cube2\"\n"
                );
                let runs = run_scenario(&scenario_in(base, &text), false);
                let (bt, fsm) = (runs[0].completion_s, runs[1].completion_s);
                assert!(bt.is_some() && fsm.is_some(), "{t}: {bt:?} {fsm:?}");
                bt > fsm
            })
            .count()
    };
    assert_eq!(later(true), 0);
    assert!(
        later(false) > 0,
        "the stale belief is a setting that changes results"
    );
}

/// A Shut-Down completed with no emergency in force: with
/// `shut_down_latches` the robot stays down and nothing moves again; by
/// default the shut-down lasts only as long as an emergency, so the robot
/// moves again.
#[test]
fn a_shut_down_without_an_emergency_latches_only_when_set() {
    for latches in [true, false] {
        let mut w = world();
        w.params.shut_down_latches = latches;
        let mut r = robot(w, 1);
        let mut s = Status::Running;
        while s == Status::Running {
            s = r.action(0, &Call::ShutDown);
            end(&mut r);
        }
        assert_eq!(s, Status::Success);
        let here = r.world.robot;
        let a = to(&r, "delivery");
        for _ in 0..200 {
            let _ = r.action(0, &a);
            end(&mut r);
        }
        assert_eq!(r.world.shut_down, latches);
        assert_eq!(r.world.robot == here, latches);
    }
}

/// The paper's Fig. 9 emergency, cleared at any of 10 times: the BT of
/// Fig. 9a and the FSM of Fig. 9b both deliver, each resuming as its own
/// structure says (a latched shut-down failed the FSM at every time, whose
/// Shut Down state outlasts the all-clear), and no run is cut as a
/// livelock while the all-clear is still to come.
#[test]
fn fig_9_bt_and_fsm_both_resume_after_the_all_clear() {
    let base = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../policies/scenarios"
    ));
    for k in 0..10 {
        let clear = 5.5 + f64::from(k) * 0.7;
        let text = format!(
            "goal = [{{ if = \"Object-At\", args = {{ object = \"cube2\", at = \"delivery\" }} }}]\n[world]\nrobot = \"start\"\nobjects = {{ cube2 = {{ at = \"east-table\" }} }}\n[[policies]]\nfile = \"../paper/fig09a-bt.toml\"\n[[policies]]\nfile = \"../paper/fig09b-fsm.toml\"\n[[disturbances]]\nat = 5.0\nemergency = true\n[[disturbances]]\nat = {clear:?}\nemergency = false\n"
        );
        let runs = run_scenario(&scenario_in(base, &text), false);
        for r in &runs {
            assert_eq!(
                r.goal_met,
                Some(true),
                "all-clear at {clear}: {} {}",
                r.policy,
                r.reason
            );
        }
    }
}

/// No panic, and the limits hold, on random worlds: extreme parameters,
/// objects on tables and floors, blocks, drops, moves, faults, emergencies
/// and battery drops at random times, for the paper's BTs and FSMs.
#[test]
fn random_worlds_and_disturbances_never_panic() {
    let mut rng = super::rng::SimRng::named(13, "random-worlds");
    let base = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../policies/scenarios"
    ));
    let mut ran = 0;
    for k in 0..80 {
        let mut text = random_world(&mut rng, k);
        text.push_str(&random_policies(&mut rng));
        text.push_str(&random_disturbances(&mut rng));
        let f = SourceFile::new("random.toml", &text);
        // A random block may cover a station or the start: refused, fine.
        let s = match scenario::parse(&f, base, &Limits::default()) {
            Ok(s) => s,
            Err(d) => {
                assert!(
                    d.iter()
                        .all(|d| d.message.contains("covers") || d.message.contains("reported as")),
                    "{k}: {d:?}\n{text}"
                );
                continue;
            }
        };
        ran += 1;
        assert_speed_and_battery_bounds(&s, k, &text);
    }
    assert!(ran >= 40, "{ran}");
}

/// A number from `lo` to `hi`, one of the bounds themselves three times in
/// ten.
fn extreme_or_uniform(rng: &mut super::rng::SimRng, lo: f64, hi: f64) -> f64 {
    if rng.chance(0.3) {
        if rng.chance(0.5) { lo } else { hi }
    } else {
        rng.range(lo, hi)
    }
}

/// The top of a random scenario (seed `k`): its `[world]` with random
/// parameters and battery, and five cubes on tables or floors.
fn random_world(rng: &mut super::rng::SimRng, k: u32) -> String {
    let mut params = Vec::new();
    for &(name, lo, hi) in scenario::PARAMS {
        if rng.chance(0.5) {
            params.push(format!("{name} = {}", extreme_or_uniform(rng, lo, hi)));
        }
    }
    if rng.chance(0.3) {
        params.push("follow_belief = true".into());
    }
    let mut text = format!(
        "seed = {k}\nmax_steps = 1500\n[world]\nbattery = {}\nparams = {{ {} }}\n[world.objects]\n",
        extreme_or_uniform(rng, 0.0, 100.0),
        params.join(", ")
    );
    for c in 1..=5 {
        let at = [
            "east-table",
            "west-table",
            "central-table",
            "[1.2, 1.4]",
            "[-1.0, -2.0]",
            "[1.7, -0.8]",
        ][(rng.next_u64() % 6) as usize];
        let at = if at.starts_with('[') {
            at.to_string()
        } else {
            format!("\"{at}\"")
        };
        text.push_str(&format!(
            "cube{c} = {{ at = {at}, found = {} }}\n",
            rng.chance(0.5)
        ));
    }
    text
}

/// Three `[[policies]]` drawn from the paper's BTs and FSMs.
fn random_policies(rng: &mut super::rng::SimRng) -> String {
    let policies = [
        "fig01-bt",
        "fig02-fsm",
        "fig04-fsm",
        "fig09a-bt",
        "fig09b-fsm",
        "fig15-bt",
        "fig15-fsm",
        "fig16a-bt",
        "fig16b-fsm",
    ];
    let mut text = String::new();
    for _ in 0..3 {
        let f = policies[(rng.next_u64() % policies.len() as u64) as usize];
        text.push_str(&format!("[[policies]]\nfile = \"../paper/{f}.toml\"\n"));
    }
    text
}

/// Up to seven `[[disturbances]]` at random times, each of a random kind.
fn random_disturbances(rng: &mut super::rng::SimRng) -> String {
    let mut text = String::new();
    for _ in 0..(rng.next_u64() % 8) {
        let t = rng.range(0.0, 50.0);
        let effect = match rng.next_u64() % 7 {
            0 => format!("battery = {}", extreme_or_uniform(rng, 0.0, 100.0)),
            1 => format!("drop = \"cube{}\"", 1 + rng.next_u64() % 5),
            2 => format!("move = \"cube{}\"\nto = [1.2, 1.4]", 1 + rng.next_u64() % 5),
            3 => format!(
                "fail = \"{}\"\ntimes = {}",
                ["Move-To", "Pick", "Place", "Recharge", "Dock", "Search"]
                    [(rng.next_u64() % 6) as usize],
                1 + rng.next_u64() % 3
            ),
            4 => {
                let (x, y) = (rng.range(-1.0, 2.0), rng.range(-1.5, 0.0));
                format!(
                    "block = {{ name = \"b\", rect = [{x}, {y}, {}, {}] }}",
                    x + 0.05,
                    y + 0.5
                )
            }
            5 => "emergency = true".into(),
            _ => "emergency = false".into(),
        };
        text.push_str(&format!("[[disturbances]]\nat = {t}\n{effect}\n"));
    }
    text
}

/// Runs every policy of `s` (scenario `k`, written `text`): no step moves
/// farther than the top speed allows, and the battery stays in 0..=100.
fn assert_speed_and_battery_bounds(s: &Scenario, k: u32, text: &str) {
    let p = s.world.params.clone();
    for run in run_scenario(s, true) {
        let mut prev = s.world.robot;
        for st in &run.trace {
            let d = dist(prev, (st.x, st.y));
            assert!(d <= p.max_speed * s.dt + 1e-9, "{k}: {d}\n{text}");
            assert!((0.0..=100.0).contains(&st.battery), "{k}");
            prev = (st.x, st.y);
        }
    }
}

/// The built-in action domain (`policies/domains/moma.toml`) describes the
/// planar simulator: along a run of the domain's actions in the paper's
/// room, each action's preconditions hold (as the room's conditions say)
/// before it starts, it succeeds, and afterwards the facts it adds hold,
/// the facts it deletes and the ones its additions exclude do not.
#[test]
fn the_built_in_domain_describes_the_planar_skills() {
    use btfsm_plan::Domain;
    use btfsm_plan::fact::Fact;
    let d = btfsm_plan::domain::builtin();
    let mut r = robot(world(), 1);
    let holds = |r: &Robot, f: &Fact| -> bool {
        let pred = d.predicate(&f.pred).expect("domain predicate");
        let call = Domain::skill_call(
            pred.skill.as_deref().expect("library skill"),
            &pred.params,
            &f.args,
        );
        let c = super::skills::resolve(&call, &r.world)
            .unwrap_or_else(|e| panic!("{f}: {}", e.message));
        super::skills::condition(&c, &r.world)
    };
    let plan: [(&str, &[&str]); 9] = [
        ("Move-To", &["cube2"]),
        ("Pick", &["cube2"]),
        ("Move-To", &["delivery"]),
        ("Place", &["cube2", "delivery"]),
        ("Tuck-Arm", &[]),
        ("Safe-Move-To", &["charging"]),
        ("Search", &[]),
        ("Recharge", &[]),
        ("Dock", &[]),
    ];
    for (name, objs) in plan {
        let a = d.actions.iter().find(|a| a.name == name).expect("action");
        let bind = a
            .params
            .iter()
            .map(|p| p.name.clone())
            .zip(objs.iter().map(|o| o.to_string()))
            .collect();
        let step = btfsm_plan::backchain::Step { action: a, bind };
        for f in step.pre() {
            assert!(
                holds(&r, &f),
                "{name}: precondition {f} does not hold in the room"
            );
        }
        let call = Domain::skill_call(
            a.skill.as_deref().expect("library skill"),
            &a.params,
            &objs.iter().map(|o| o.to_string()).collect::<Vec<_>>(),
        );
        let c = super::skills::resolve(&call, &r.world)
            .unwrap_or_else(|e| panic!("{name}: {}", e.message));
        let mut s = Status::Running;
        let mut steps = 0;
        while s == Status::Running && steps < 5000 {
            s = r.action(0, &c);
            end(&mut r);
            steps += 1;
        }
        assert_eq!(s, Status::Success, "{name} {objs:?} in the room");
        for f in step.adds() {
            assert!(holds(&r, &f), "{name}: {f} does not hold after it");
        }
        for f in step.deletes() {
            assert!(!holds(&r, &f), "{name}: {f} still holds after it");
        }
        for f in step.adds() {
            if let Some(k) = d.predicate(&f.pred).and_then(|p| p.exclusive) {
                for other in d.objects_of(&d.predicate(&f.pred).unwrap().params[k].ty) {
                    let mut g = f.clone();
                    g.args[k] = other.to_string();
                    if g != f && r.world.layout.station_index(other).is_some() {
                        assert!(!holds(&r, &g), "{name}: {g} holds beside {f}");
                    }
                }
            }
        }
    }
}

/// The bundled Fig. 9 scenario under Monte Carlo: both policies always
/// deliver, no episode ends as a livelock, and in every episode the two
/// robots move and end alike, though their skill calls differ (the BT
/// restarts Move-To between Shut-Downs). Before the scenario's timed
/// disturbances kept their order, 17 in 1000 episodes had the all-clear
/// before the emergency and ended "chattering" with the emergency in force.
#[test]
fn fig_9_monte_carlo_has_no_livelock_and_the_robots_move_alike() {
    let f = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../policies/scenarios/fig09-emergency.toml"
    ));
    let s = scenario::load(f, &Limits::default()).expect("bundled");
    let mc = crate::monte_carlo::monte_carlo(&s, 300, s.seed, 2);
    for p in &mc.policies {
        assert_eq!((p.successes, p.chattering), (300, 0), "{p:?}");
        assert_eq!(p.first_unsuccessful, None);
    }
    let pair = &mc.pairs[0];
    assert_eq!((pair.matches, pair.moved_alike), (0, 300), "{pair:?}");
}
