#!/usr/bin/env python3
"""btfsm vs HiGHS on exact graph edit distance, measured in one run.

Generates seeded random pairs (tests/differential/ged_highs.py): independent
random trees of 15-27 nodes (as BehaviorTree TOML) and of 40-50 nodes, and
FSM-like graphs of 10-28 states (as FSM TOML); times
`btfsm compare --mode structural|labeled --format json` at its default budget
(the engine's own `millis`, no process start-up, counted as 1 ms when
below) and HiGHS (PyPI `highspy`,
one thread) on the binary formulation documented in ged_highs.py (Lerouge
et al. 2017, F2, unit costs), and prints per pair both values, both times and
the ratio, then per group how many pairs btfsm settled exactly and the
median ratio on the pairs HiGHS solved within --highs-timeout.

Usage: python3 bench/ged_vs_highs.py BTFSM [--seed S] [--highs-timeout S]
       [--groups trees,big-trees,fsm] [--json OUT]
"""
import argparse
import json
import os
import random
import statistics
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "differential"))

from ged_highs import random_fsm, random_tree, run_btfsm, solve  # noqa: E402


def groups(seed):
    rng = random.Random(seed)
    yield "trees", [(random_tree(rng, rng.randint(15, 27)), random_tree(rng, rng.randint(15, 27)))
                    for _ in range(10)]
    yield "big-trees", [(random_tree(rng, rng.randint(40, 50)), random_tree(rng, rng.randint(40, 50)))
                        for _ in range(6)]
    yield "fsm", [(random_fsm(rng, rng.randint(10, 28)), random_fsm(rng, rng.randint(10, 28)))
                  for _ in range(10)]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("btfsm")
    ap.add_argument("--seed", type=int, default=2017)
    ap.add_argument("--highs-timeout", type=float, default=10.0)
    ap.add_argument("--groups", default="trees,big-trees,fsm")
    ap.add_argument("--modes", default="structural,labeled")
    ap.add_argument("--json")
    args = ap.parse_args()
    wanted = args.groups.split(",")
    import highspy
    print(f"HiGHS {highspy.Highs().version()}, Python {sys.version.split()[0]}")
    print(f"{'pair':22} {'mode':10} {'btfsm':>9} {'HiGHS':>6} {'btfsm ms':>9} {'HiGHS ms':>9} {'ratio':>7}  note")
    rows = []
    with tempfile.TemporaryDirectory() as d:
        fa, fb = os.path.join(d, "a.toml"), os.path.join(d, "b.toml")
        for group, plist in groups(args.seed):
            if group not in wanted:
                continue
            for i, ((ta, ga), (tb, gb)) in enumerate(plist):
                with open(fa, "w") as f:
                    f.write(ta)
                with open(fb, "w") as f:
                    f.write(tb)
                for mode in args.modes.split(","):
                    r = run_btfsm(args.btfsm, fa, fb, mode)
                    value, hs = solve(ga, gb, mode == "labeled", args.highs_timeout)
                    # `millis` has a 1 ms resolution: a pair under 1 ms
                    # counts as 1 ms (so the ratio is, if anything, low).
                    ms = max(r["millis"], 1)
                    ours = str(r["ged"]) if r["exact"] else f"[{r['lower_bound']},{r['upper_bound']}]"
                    note = []
                    if value is None:
                        note.append("HiGHS timeout")
                    elif not (r["lower_bound"] <= value <= r["upper_bound"]) or (r["exact"] and r["ged"] != value):
                        note.append("DIFFERS")
                    if not r["exact"]:
                        note.append(f"inexact ({r.get('stopped_by', '?')})")
                    ratio = hs * 1e3 / ms
                    rows.append({"group": group, "pair": i, "mode": mode, "n": [ga["n"], gb["n"]],
                                 "btfsm": r["ged"], "exact": r["exact"], "lower": r["lower_bound"],
                                 "upper": r["upper_bound"], "btfsm_ms": r["millis"], "highs": value,
                                 "highs_ms": hs * 1e3, "ratio": ratio})
                    name = f"{group}-{i} ({ga['n']},{gb['n']})"
                    print(f"{name:22} {mode:10} {ours:>9} {str(value):>6} {r['millis']:>9} {hs*1e3:>9.1f} "
                          f"{ratio:>6.1f}x  {', '.join(note)}", flush=True)
    print()
    for group in wanted:
        for mode in args.modes.split(","):
            g = [r for r in rows if r["group"] == group and r["mode"] == mode]
            if not g:
                continue
            solved = [r for r in g if r["highs"] is not None]
            ex = sum(r["exact"] for r in g)
            line = (f"{group} {mode}: {len(g)} pairs, btfsm exact {ex}, median btfsm "
                    f"{statistics.median(r['btfsm_ms'] for r in g):.0f} ms; HiGHS solved {len(solved)}")
            if solved:
                line += (f", median HiGHS {statistics.median(r['highs_ms'] for r in solved):.0f} ms, "
                         f"median ratio HiGHS/btfsm {statistics.median(r['ratio'] for r in solved):.1f}x, "
                         f"btfsm exact on those {sum(r['exact'] for r in solved)}")
            print(line)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
