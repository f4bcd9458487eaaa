#!/usr/bin/env python3
"""When does BehaviorTree.CPP 4 refuse a tree: when it creates it, or only
when it ticks the node? `btfsm lint` follows the engine (docs/lint.md): a
problem met at creation makes the file not load (lint reports it and runs
no other rule on it: SARIF's invocation says a file was not linted); a
problem met only at the first tick is a finding on a file that loads, beside
the other rules' findings. (An unknown node type is met at creation, but
lint reads it as its shape says and checks the rest of the tree too.)

For every case below, behaviortreepy (BehaviorTree.CPP 4) creates the tree
(with `A`, a registered action returning SUCCESS) and ticks it once, and
`btfsm lint --format sarif` lints the same file. Checked: the engine fails
where the case says (create or tick), and lint reports the case's rule,
with the file linted (tick) or not (create).

Exit 0 when every case agrees, 1 otherwise, 2 when the check cannot run.
Usage: btcpp_when.py --btfsm PATH
"""
import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

# name: (body of <BehaviorTree>, where BehaviorTree.CPP fails, lint rule)
CASES = {
    "parallel_success": ('<Parallel success_count="3" failure_count="1"><A/><A/></Parallel>',
                         "tick", "parallel-threshold"),
    "parallel_failure": ('<Parallel success_count="1" failure_count="3"><A/><A/></Parallel>',
                         "tick", "parallel-threshold"),
    "ifthenelse_1": ("<IfThenElse><A/></IfThenElse>", "tick", "wrong-child-count"),
    "ifthenelse_4": ("<IfThenElse><A/><A/><A/><A/></IfThenElse>", "tick", "wrong-child-count"),
    "whiledoelse_1": ("<WhileDoElse><A/></WhileDoElse>", "tick", "wrong-child-count"),
    "switch2_2": ('<Switch2 variable="{v}" case_1="1" case_2="2"><A/><A/></Switch2>',
                  "tick", "wrong-child-count"),
    "retry_no_attempts": ("<RetryUntilSuccessful><A/></RetryUntilSuccessful>",
                          "tick", "missing-required-port"),
    "sleep_no_msec": ("<Sleep/>", "tick", "missing-required-port"),
    "repeat_no_cycles": ("<Repeat><A/></Repeat>", "tick", "missing-required-port"),
    "timeout_no_msec": ("<Timeout><A/></Timeout>", "tick", "missing-required-port"),
    "delay_no_msec": ("<Delay><A/></Delay>", "tick", "missing-required-port"),
    "empty_sequence": ("<Sequence/>", "create", "empty-composite"),
    "inverter_2": ("<Inverter><A/><A/></Inverter>", "create", "wrong-child-count"),
    "script_no_code": ("<Script/>", "create", "load-error"),
    "precondition_no_if": ('<Precondition else="FAILURE"><A/></Precondition>', "create", "load-error"),
    "loop_no_queue": ("<LoopInt><A/></LoopInt>", "create", "load-error"),
    "entry_no_entry": ("<WasEntryUpdated/>", "create", "load-error"),
    "id_on_compact": ('<Sequence ID="x"><A/></Sequence>', "create", "load-error"),
}

# Refused at creation, but lint reads the file on (the rule's finding is an
# error beside the other rules'): a node type BehaviorTree.CPP does not know.
READ_ON = {
    "inverter_lowercase": ("<inverter><A/></inverter>", "create", "unknown-node-type"),
    "v3_name_in_v4": ("<SequenceStar><A/></SequenceStar>", "create", "unknown-node-type"),
    "unknown_with_model": ("<B/>", "create", "unknown-node-type"),
}
CASES.update(READ_ON)

MODEL = '<TreeNodesModel><Action ID="A"/></TreeNodesModel>'


def engine(xml):
    """Where BehaviorTree.CPP fails: 'create', 'tick' or 'none'."""
    import behaviortreepy as bt  # noqa: PLC0415
    f = bt.BehaviorTreeFactory()
    f.register_simple_action("A", lambda *_: bt.NodeStatus.SUCCESS)
    try:
        tree = f.create_tree_from_text(xml)
    except Exception:  # noqa: BLE001 - the engine's verdict, any type
        return "create"
    try:
        tree.tick_once()
    except Exception:  # noqa: BLE001
        return "tick"
    return "none"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--btfsm", required=True)
    a = ap.parse_args()
    try:
        import behaviortreepy  # noqa: F401, PLC0415
    except ImportError:
        print("btcpp_when: needs behaviortreepy (pip install behaviortreepy==0.1.4)")
        return 2
    bad = 0
    with tempfile.TemporaryDirectory() as tmp:
        for name, (body, when, rule) in CASES.items():
            xml = (f'<root BTCPP_format="4" main_tree_to_execute="M">'
                   f'<BehaviorTree ID="M">{body}</BehaviorTree>{MODEL}</root>')
            path = Path(tmp) / f"{name}.xml"
            path.write_text(xml)
            got = engine(xml.replace(MODEL, ""))
            r = subprocess.run([a.btfsm, "lint", str(path), "--format", "sarif", "--no-config"],
                               capture_output=True, text=True, timeout=60, check=False)
            try:
                run = json.loads(r.stdout)["runs"][0]
            except (json.JSONDecodeError, KeyError, IndexError):
                print(f"FAIL {name}: lint wrote no SARIF (exit {r.returncode}): {r.stderr[:200]}")
                bad += 1
                continue
            rules = {x["ruleId"] for x in run["results"]}
            linted = run["invocations"][0]["executionSuccessful"]
            problems = []
            if got != when:
                problems.append(f"BehaviorTree.CPP fails at {got}, the case says {when}")
            if rule not in rules:
                problems.append(f"lint reports {sorted(rules)}, not {rule}")
            if linted != (when == "tick" or name in READ_ON):
                problems.append("lint " + ("did not lint" if not linted else "linted") + " the file")
            if problems:
                bad += 1
                print(f"FAIL {name}: " + "; ".join(problems))
    print(f"btcpp_when: {len(CASES)} cases, {bad} disagreements")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
