//! `btfsm sim --sensitivity` through the binary (issue 31, docs/guide/sim.md
//! "Sensitivity"): each verdict with the policy-independent settings whose
//! flip reverses it, in a single run and under `--runs`; a failed
//! expectation names them without the flag.

use super::*;

/// The verdicts of a sensitivity report as `name -> [setting = to]`.
fn reversals(v: &serde_json::Value) -> std::collections::BTreeMap<String, Vec<String>> {
    (v["sensitivity"]["verdicts"]
        .as_array()
        .expect("verdicts")
        .iter())
    .map(|x| {
        let by = (x["reversed_by"].as_array().unwrap().iter())
            .map(|r| {
                format!(
                    "{} = {}",
                    r["setting"].as_str().unwrap(),
                    r["to"].as_str().unwrap()
                )
            })
            .collect();
        (x["verdict"].as_str().unwrap().to_string(), by)
    })
    .collect()
}

/// A cube moved during the task defeats the sequential FSM only because
/// Move-To keeps the pose it started with (`follow_belief = false`, the
/// default): the report says so. The BT's and the fault-tolerant FSM's
/// success no flip reverses.
#[test]
fn sensitivity_names_the_setting_that_decides_a_verdict() {
    let (code, out, err) = btfsm(&[
        "sim",
        "policies/scenarios/exp1-cube-moved-during.toml",
        "--sensitivity",
        "--format",
        "json",
    ]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["sensitivity"]["flips"].as_array().unwrap().len(), 14);
    let r = reversals(&v);
    assert_eq!(
        r["outcome of Fig. 2 FSM sequential"],
        ["world.follow_belief = true"]
    );
    assert!(r["outcome of Fig. 1 BT baseline"].is_empty(), "{r:?}");
    assert!(
        r["outcome of Fig. 4 FSM fault tolerant"].is_empty(),
        "{r:?}"
    );
    let (_, text, _) = btfsm(&[
        "sim",
        "policies/scenarios/exp1-cube-moved-during.toml",
        "--sensitivity",
    ]);
    assert!(
        text.contains("outcome of Fig. 2 FSM sequential: failure, goal not met — reversed by world.follow_belief = true (success, goal met)"),
        "{text}"
    );
}

/// Fig. 9 with a latched shut-down: the FSM's expectation fails, and the
/// report names the flip under which it would hold, without the flag
/// (and without the whole sensitivity section).
#[test]
fn a_failed_expectation_names_the_settings_that_would_make_it_hold() {
    let (code, out, err) = btfsm(&[
        "sim",
        "tests/fixtures/sim/fig09-latched.toml",
        "--format",
        "json",
    ]);
    assert_eq!(code, 1, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(
        v["expectations"][0]["reversed_by"],
        serde_json::json!(["world.shut_down_latches = false"])
    );
    assert!(v.get("sensitivity").is_none());
    let (_, text, _) = btfsm(&["sim", "tests/fixtures/sim/fig09-latched.toml"]);
    assert!(
        text.contains(
            "(outcome failure, goal not met); would hold with world.shut_down_latches = false"
        ),
        "{text}"
    );
}

/// Under `--runs`, every flip runs the same episodes; the verdicts are
/// which policy succeeds more often and the rate expectations, and the
/// report is the same for every thread count.
#[test]
fn monte_carlo_sensitivity_is_the_same_for_every_thread_count() {
    let run = |threads: &str| {
        let (code, out, err) = btfsm(&[
            "sim",
            "tests/fixtures/sim/rates-expect.toml",
            "--runs",
            "30",
            "--threads",
            threads,
            "--sensitivity",
            "--format",
            "json",
        ]);
        assert!(code <= 1, "{err}");
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        v["sensitivity"].clone()
    };
    let one = run("1");
    assert_eq!(one, run("2"));
    let names: Vec<&str> = (one["verdicts"].as_array().unwrap().iter())
        .map(|x| x["verdict"].as_str().unwrap())
        .collect();
    assert!(
        names.contains(&"success of Fig. 1 BT baseline vs Fig. 2 FSM sequential"),
        "{names:?}"
    );
}

/// A symbolic scenario has none of the planar world's settings: asked for
/// their sensitivity, `sim` says so (exit 2) rather than printing nothing.
#[test]
fn a_symbolic_scenario_has_no_settings_to_flip() {
    let (code, _, err) = btfsm(&["sim", "policies/domains/moma-sim.toml", "--sensitivity"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("a symbolic scenario has none"), "{err}");
}

/// `--runs` names per policy the first episode it did not succeed in; its
/// seed replays that episode, and the policy does not succeed in it.
#[test]
fn the_first_unsuccessful_episode_of_a_policy_replays() {
    let (_, out, err) = btfsm(&[
        "sim",
        "tests/fixtures/sim/rates-expect.toml",
        "--runs",
        "30",
        "--format",
        "json",
    ]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap_or_else(|_| panic!("{err}"));
    let fsm2 = (v["policies"].as_array().unwrap().iter())
        .find(|p| p["policy"] == "Fig. 2 FSM sequential")
        .unwrap();
    assert!(fsm2["successes"].as_u64().unwrap() < 30, "{fsm2}");
    let seed = fsm2["first_unsuccessful"]["seed"]
        .as_u64()
        .expect("a failure");
    let (_, one, err) = btfsm(&[
        "sim",
        "tests/fixtures/sim/rates-expect.toml",
        "--seed",
        &seed.to_string(),
        "--format",
        "json",
    ]);
    let one: serde_json::Value = serde_json::from_str(&one).unwrap_or_else(|_| panic!("{err}"));
    let run = (one["policies"].as_array().unwrap().iter())
        .find(|p| p["policy"] == "Fig. 2 FSM sequential")
        .unwrap();
    assert!(
        run["outcome"] != "success" || run["goal_met"] == false,
        "{run}"
    );
}
