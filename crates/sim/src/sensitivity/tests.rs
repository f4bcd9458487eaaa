//! Tests of [`super`]: which flips a scenario has, that a policy's own
//! `after_*` is never flipped, and that a verdict decided by a setting is
//! named with that setting (and one the policies decide is not).

use super::*;
use crate::test_support::{deliver, scenario};

const FIG1_FIG2: &str = r#"[[policies]]
file = "../paper/fig01-bt.toml"
[[policies]]
file = "../paper/fig02-fsm.toml"
"#;

/// Every world rule, both after-settings where they change something, the
/// tolerances both ways and the budgets: 14 flips for Fig. 1 and Fig. 2
/// (after SUCCESS differs by representation, so both ways; after FAILURE
/// is keep-ticking for both, so only `stop`).
#[test]
fn flips_are_the_policy_independent_settings() {
    let s = scenario(&deliver(FIG1_FIG2));
    let names: Vec<String> = flips(&s).iter().map(|(f, _)| f.text()).collect();
    assert_eq!(
        names,
        [
            "world.drop_sensed = false",
            "world.follow_belief = true",
            "world.shut_down_latches = true",
            "after_success = stop",
            "after_success = keep-ticking",
            "after_failure = stop",
            "pose_tolerance_m = 0.1",
            "time_shift_s = 0.05",
            "start_tolerance_s = 0.05",
            "pose_tolerance_m = 0.4",
            "time_shift_s = 0.2",
            "start_tolerance_s = 0.2",
            "max_failures = 100",
            "livelock_repeats = 6",
        ]
    );
    let (f, t) = &flips(&s)[3];
    assert_eq!(f.from, "per representation (the default)");
    assert!(
        t.policies
            .iter()
            .all(|p| p.after_success == Afterwards::Stop)
    );
}

/// A policy stating its own `after_failure` keeps it in every flip: it
/// is the policy's structure, not a modelling choice.
#[test]
fn a_policys_own_setting_is_never_flipped() {
    let s = scenario(&deliver(
        r#"[[policies]]
file = "../paper/fig01-bt.toml"
after_failure = "keep-ticking"
[[policies]]
file = "../paper/fig02-fsm.toml"
"#,
    ));
    for (f, t) in flips(&s) {
        assert_eq!(
            t.policies[0].after_failure,
            Afterwards::KeepTicking,
            "{}",
            f.text()
        );
    }
    let stop = flips(&s)
        .into_iter()
        .find(|(f, _)| f.text() == "after_failure = stop")
        .expect("the FSM's after_failure is the default");
    assert_eq!(stop.1.policies[1].after_failure, Afterwards::Stop);
}

/// One failed grasp: Fig. 1's BT and Fig. 2's FSM, both started again
/// after FAILURE (the default for every representation), both deliver;
/// with `after_failure = stop` both fail. Their outcomes are named with
/// that flip and with no other (the world rules, tolerances and budgets
/// change nothing here).
#[test]
fn a_verdict_a_setting_decides_names_it() {
    let s = scenario(&deliver(&format!(
        "{FIG1_FIG2}[[disturbances]]\nat = 0.0\nfail = \"Pick\"\ntimes = 1\n"
    )));
    let base = single_verdicts(&s, None).expect("no deadline");
    let x = of_single_run(&s, &base, None);
    let by = |name: &str| -> Vec<String> {
        let v = x
            .verdicts
            .iter()
            .find(|v| v.verdict == name)
            .unwrap_or_else(|| panic!("no verdict {name}: {x:?}"));
        (v.reversed_by.iter())
            .map(|r| format!("{} = {} ({})", r.setting, r.to, r.value))
            .collect()
    };
    for p in ["Fig. 1 BT baseline", "Fig. 2 FSM sequential"] {
        let name = format!("outcome of {p}");
        assert_eq!(
            base.iter().find(|(n, _)| *n == name).unwrap().1,
            "success, goal met"
        );
        assert_eq!(by(&name), ["after_failure = stop (failure, goal not met)"]);
    }
    assert_eq!(x.flips.len(), 14);
    assert!(x.not_tried.is_empty());
}
