//! The complexity gate of `analyze` (`--max`, `--baseline`, `--max-increase`):
//! exit 0 within limits, 1 naming each metric over its limit, 2 for a bad
//! limit or baseline.

use super::*;
use common::scratch;

#[test]
fn gate_ceilings_exit_1_naming_the_policy_and_metric() {
    let (code, stdout, stderr) = btfsm(&[
        "analyze",
        "policies/paper/fig01-bt.toml",
        "policies/paper/fig04-fsm.toml",
        "--max",
        "cc=10",
        "--max",
        "vertices=100",
    ]);
    assert_eq!(code, 1, "{stderr}");
    // The report is printed all the same.
    assert!(
        stdout.contains("policies/paper/fig01-bt.toml   bt"),
        "{stdout}"
    );
    assert_eq!(
        stderr,
        "error: complexity gate: `Fig. 4 FSM fault tolerant` (policies/paper/fig04-fsm.toml): cc is 14, above the limit 10 (--max cc=10)\n\
         error: complexity gate: 1 limit exceeded in 2 policies (--max cc=10; --max vertices=100)\n"
    );
    let (code, _, stderr) = btfsm(&["analyze", "policies/paper/fig04-fsm.toml", "--max", "cc=14"]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(
        stderr,
        "complexity gate: 1 policy within limits (--max cc=14)\n"
    );
}

#[test]
fn gate_fails_when_complexity_grows_over_the_baseline() {
    let dir = scratch("gate");
    let policy = dir.join("policy.toml");
    let base = dir.join("base.json");
    let p = policy.to_str().expect("utf-8");
    // The base revision: Fig. 4's FSM; the change: Fig. 8d's (recharging).
    std::fs::copy("policies/paper/fig04-fsm.toml", &policy).expect("copy");
    let (code, json, _) = btfsm(&["analyze", p, "--format", "json"]);
    assert_eq!(code, 0);
    std::fs::write(&base, json).expect("write");
    let b = base.to_str().expect("utf-8");
    let (code, _, stderr) = btfsm(&["analyze", p, "--baseline", b]);
    assert_eq!(code, 0, "{stderr}");
    std::fs::copy("policies/paper/fig08d-fsm.toml", &policy).expect("copy");
    let (code, _, stderr) = btfsm(&["analyze", p, "--baseline", b]);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr
            .contains("cc grew from 14 to 20 (+6), more than the allowed +0 (--max-increase cc=0)"),
        "{stderr}"
    );
    // Allowing the growth passes; vertices are gated only when asked.
    let (code, _, stderr) = btfsm(&["analyze", p, "--baseline", b, "--max-increase", "cc=6"]);
    assert_eq!(code, 0, "{stderr}");
    let (code, _, stderr) = btfsm(&[
        "analyze",
        p,
        "--baseline",
        b,
        "--max-increase",
        "cc=6",
        "--max-increase",
        "vertices=0",
    ]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("vertices grew from"), "{stderr}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn gate_rejects_bad_limits_and_baselines_with_exit_2() {
    let (code, stdout, stderr) =
        btfsm(&["analyze", "policies/paper/fig01-bt.toml", "--max", "cx=3"]);
    assert_eq!(code, 2);
    assert!(stdout.is_empty());
    assert!(
        stderr.contains("unknown metric `cx`: did you mean `cc`?"),
        "{stderr}"
    );
    let dir = scratch("gate-bad");
    let bad = dir.join("bad.json");
    std::fs::write(&bad, "{\"policies\": [\n  {\"cc\": }\n]}\n").expect("write");
    let (code, stdout, stderr) = btfsm(&[
        "analyze",
        "policies/paper/fig01-bt.toml",
        "--baseline",
        bad.to_str().expect("utf-8"),
    ]);
    assert_eq!(code, 2);
    assert!(stdout.is_empty(), "no report when the gate cannot run");
    assert!(stderr.contains("bad.json:2:"), "{stderr}");
    std::fs::remove_dir_all(&dir).ok();
}
