#!/usr/bin/env python3
"""Runs to compare: BehaviorTree.CPP 4 itself (behaviortreepy) runs the
paper's Fig. 1 tree against a small scripted world, with a FileLogger, once
nominally and once with the first Pick failing; the Python leaves record
every execution BehaviorTree.CPP asks of them (skill, outcome). Those
records are the oracle of `btfsm log compare`: its first divergence must be
the first index where the two recorded sequences differ, its counts their
lengths; and the simulator's run of `exp1-pick-fails` (the same tree, the
same failure) must match the failing run's log action for action.

Usage: btlog_compare.py --btfsm PATH [--keep DIR]
  --keep DIR writes the logs and the oracle (`compare-oracle.json`) there
  (tests/fixtures/logs/ holds the committed ones, which tests/cli/log.rs
  reads).
"""
import argparse
import json
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
TICK_S = 0.002


def fig01_xml(exe, tmp):
    x = tmp / "fig01.xml"
    subprocess.run([exe, "convert", "policies/paper/fig01-bt.toml", "--to", "btcpp-xml", "-o", str(x)],
                   cwd=REPO, check=True, capture_output=True)
    text = re.sub(r"<\?xml[^>]*\?>", "", x.read_text())
    text = re.sub(r'\sbtfsm:[\w-]+="[^"]*"', "", text)
    # Python leaves have no ports: keep name/ID and the reserved attributes.
    return re.sub(r'\s(?!name=|ID=|_|BTCPP_format=|main_tree_to_execute=)[A-Za-z_][\w.-]*="[^"]*"', "", text)


def run(xml_text, path, pick_failures):
    """Ticks Fig. 1 until it succeeds (re-ticking after a failure, as the
    simulator does); returns the executions the leaves saw."""
    import behaviortreepy as bt  # noqa: PLC0415
    S, F, R = bt.NodeStatus.SUCCESS, bt.NodeStatus.FAILURE, bt.NodeStatus.RUNNING
    world = {"robot": "start", "cube": "east-table", "held": False}
    seen = []
    left = {}
    fails = {"Pick": pick_failures}
    durations = {"Move-To": 4, "Pick": 2, "Place": 2}

    def target(node):
        return "cube2" if "cube2" in node.name() else "delivery"

    def effect(skill, node):
        if skill == "Move-To":
            world["robot"] = target(node)
        elif skill == "Pick":
            world["held"], world["cube"] = True, None
        elif skill == "Place":
            world["held"], world["cube"] = False, "delivery"

    def action(skill):
        def start(node):
            left[node.name()] = durations[skill]
            return R

        def running(node):
            left[node.name()] -= 1
            if left[node.name()] > 0:
                return R
            if fails.get(skill, 0) > 0:
                fails[skill] -= 1
                seen.append(f"{skill} -> failure")
                return F
            effect(skill, node)
            seen.append(f"{skill} -> success")
            return S

        def halted(node):
            seen.append(f"{skill} -> cancelled")
        return start, running, halted

    f = bt.BehaviorTreeFactory()
    for skill in durations:
        f.register_simple_stateful_action(skill, *action(skill))
    f.register_simple_condition("Object-At", lambda *_: S if world["cube"] == "delivery" else F)
    f.register_simple_condition("In-Hand", lambda *_: S if world["held"] else F)
    f.register_simple_condition(
        "Robot-At", lambda node, *_: S if world["robot"] == target(node) else F)
    tree = f.create_tree_from_text(xml_text)
    logger = bt.FileLogger(tree, str(path))
    for _ in range(200):
        status = tree.tick_once()
        time.sleep(TICK_S)
        if status == S:
            break
    time.sleep(0.05)
    logger.flush()
    del logger
    time.sleep(0.05)
    return seen


def first_difference(a, b):
    for i in range(max(len(a), len(b))):
        if i >= len(a) or i >= len(b) or a[i] != b[i]:
            return i
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--btfsm", required=True)
    ap.add_argument("--keep", type=Path)
    a = ap.parse_args()
    try:
        import behaviortreepy  # noqa: F401, PLC0415
    except ImportError:
        print("btlog_compare: needs behaviortreepy", file=sys.stderr)
        return 2
    exe = str(Path(a.btfsm).resolve())
    tmp = Path(tempfile.mkdtemp(prefix="btlog-compare-"))
    bad = 0
    try:
        xml = fig01_xml(exe, tmp)
        runs = {"compare-nominal.btlog": 0, "compare-pick-fails.btlog": 1}
        oracle = {name: run(xml, tmp / name, k) for name, k in runs.items()}
        nom, fail = (str(tmp / n) for n in runs)
        r = subprocess.run([exe, "log", "compare", nom, fail, "--format", "json"],
                           capture_output=True, text=True, timeout=60)
        v = json.loads(r.stdout)
        want = first_difference(*oracle.values())
        got = v["first_divergence"]["index"] if v["first_divergence"] else None
        ok = (r.returncode == (0 if want is None else 1) and got == want
              and v["a"]["actions"] == len(oracle["compare-nominal.btlog"])
              and v["b"]["actions"] == len(oracle["compare-pick-fails.btlog"]))
        if want is not None and ok:
            d = v["first_divergence"]
            ok = (d["a"] == oracle["compare-nominal.btlog"][want].replace(" ->", "() ->")
                  and d["b"] == oracle["compare-pick-fails.btlog"][want].replace(" ->", "() ->"))
        print(f"nominal vs pick-fails: divergence {got} (leaves saw {want}) {'ok' if ok else 'WRONG'}")
        bad += not ok
        # The same run, compared with itself: the same.
        r = subprocess.run([exe, "log", "compare", fail, fail], capture_output=True, text=True, timeout=60)
        print(f"a run with itself: exit {r.returncode}")
        bad += r.returncode != 0
        # Sim vs robot: the simulator's Fig. 1 run of exp1-pick-fails.
        sim = tmp / "sim.json"
        with open(sim, "w") as out:
            subprocess.run([exe, "sim", "policies/scenarios/exp1-pick-fails.toml", "--format", "json"],
                           cwd=REPO, stdout=out, check=True)
        for log, code in [(fail, 0), (nom, 1)]:
            r = subprocess.run([exe, "log", "compare", str(sim), log, "--policy", "Fig. 1 BT baseline",
                                "--ignore-args"], capture_output=True, text=True, timeout=60)
            print(f"sim vs {Path(log).name}: exit {r.returncode} (want {code})")
            bad += r.returncode != code
        if a.keep:
            a.keep.mkdir(parents=True, exist_ok=True)
            for n in runs:
                shutil.copy(tmp / n, a.keep / n)
            (a.keep / "compare-oracle.json").write_text(json.dumps(oracle, indent=1) + "\n")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print(f"btlog_compare: {'ok' if not bad else f'{bad} wrong'}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
