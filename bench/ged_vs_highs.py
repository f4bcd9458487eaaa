#!/usr/bin/env python3
"""btfsm vs HiGHS on exact graph edit distance, measured in one run.

Generates seeded random pairs (tests/differential/ged_highs.py): independent
random trees of 15-27 nodes (as BehaviorTree TOML) and of 40-50 nodes, and
FSM-like graphs of 10-28 states (as FSM TOML), and with `--groups shapes`
pairs of other shapes (`ged_highs.shapes`: trees of six shapes, edited
copies of trees and FSMs, FSMs of very different sizes, SCXML charts); times
`btfsm compare --mode structural|labeled --format json` at its default budget
(the engine's own `micros`, no process start-up; at least 1 µs) and HiGHS (PyPI `highspy`, one thread) on the binary formulations
documented in ged_highs.py: F2 (Lerouge et al. 2017, unit costs) and F2 with
the matching rows ("strong": the relaxation btfsm's ascent bound works on,
so the fairer rival on graphs that are not forests); prints per pair the
values, the times and the ratios, then per group and formulation how many
pairs btfsm settled exactly and the median ratio on the pairs both settled
(HiGHS within --highs-timeout).

Usage: python3 bench/ged_vs_highs.py BTFSM [--seed S] [--highs-timeout S]
       [--groups trees,big-trees,fsm,fsm-set,shapes] [--fsm-count N] [--fsm-sizes LO,HI]
       [--formulations f2,strong] [--kinds PREFIXES]
       [--work UNITS] [--json OUT]
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

from ged_highs import random_fsm, random_tree, run_btfsm, shapes, solve, write_pair  # noqa: E402


def groups(seed, fsm_count=30, fsm_sizes=(10, 28)):
    # "fsm-set": its own generator, so that a set of other seeds and sizes
    # (docs/performance.md, "More pairs") does not depend on the groups above.
    lo, hi = fsm_sizes
    own = random.Random(seed)
    yield "fsm-set", [(random_fsm(own, own.randint(lo, hi)), random_fsm(own, own.randint(lo, hi)))
                      for _ in range(fsm_count)]
    rng = random.Random(seed)
    yield "trees", [(random_tree(rng, rng.randint(15, 27)), random_tree(rng, rng.randint(15, 27)))
                    for _ in range(10)]
    yield "big-trees", [(random_tree(rng, rng.randint(40, 50)), random_tree(rng, rng.randint(40, 50)))
                        for _ in range(6)]
    yield "fsm", [(random_fsm(rng, rng.randint(10, 28)), random_fsm(rng, rng.randint(10, 28)))
                  for _ in range(10)]
    # Other shapes, from their own generator (ged_highs.shapes): the
    # groups above do not depend on it.
    yield "shapes", shapes(seed)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("btfsm")
    ap.add_argument("--seed", type=int, default=2017)
    ap.add_argument("--highs-timeout", type=float, default=10.0)
    ap.add_argument("--groups", default="trees,big-trees,fsm",
                    help="of trees, big-trees, fsm, fsm-set (--fsm-count pairs of --fsm-sizes states), "
                         "shapes (tree shapes, edited copies, FSMs of very different sizes, SCXML)")
    ap.add_argument("--fsm-count", type=int, default=30)
    ap.add_argument("--fsm-sizes", default="10,28", help="LO,HI states of fsm-set")
    ap.add_argument("--modes", default="structural,labeled")
    ap.add_argument("--formulations", default="f2,strong")
    ap.add_argument("--work", help="btfsm's --work (default: btfsm's default)")
    ap.add_argument("--kinds", default="",
                    help="only the shapes pairs whose kind starts with one of these "
                         "comma-separated prefixes (e.g. fsm-edit)")
    ap.add_argument("--json")
    args = ap.parse_args()
    forms = args.formulations.split(",")
    extra = ["--work", args.work] if args.work else []
    wanted = args.groups.split(",")
    kinds = [k for k in args.kinds.split(",") if k]
    import highspy
    print(f"HiGHS {highspy.Highs().version()}, Python {sys.version.split()[0]}")
    print(f"{'pair':28} {'mode':10} {'btfsm':>9} {'HiGHS':>6} {'btfsm ms':>9} "
          + " ".join(f"{f + ' ms':>9} {'ratio':>7}" for f in forms) + "  note")
    rows = []
    with tempfile.TemporaryDirectory() as d:
        sizes = tuple(int(x) for x in args.fsm_sizes.split(","))
        for group, plist in groups(args.seed, args.fsm_count, sizes):
            if group not in wanted:
                continue
            for i, pair in enumerate(plist):
                kind, (ta, ga), (tb, gb) = pair if len(pair) == 3 else (group, *pair)
                if kinds and kind != group and not any(kind.startswith(k) for k in kinds):
                    continue
                fa, fb = write_pair(d, ta, tb)
                for mode in args.modes.split(","):
                    r = run_btfsm(args.btfsm, fa, fb, mode, extra)
                    # The engine's own time in microseconds (`micros`), at
                    # least 1 µs; older builds report whole milliseconds
                    # only, where a pair under 1 ms counts as 1 ms.
                    ms = r["micros"] / 1e3 if "micros" in r else max(r["millis"], 1)
                    ms = max(ms, 1e-3)
                    ours = str(r["ged"]) if r["exact"] else f"[{r['lower_bound']},{r['upper_bound']}]"
                    row = {"group": group, "kind": kind, "pair": i, "mode": mode, "n": [ga["n"], gb["n"]],
                           "btfsm": r["ged"], "exact": r["exact"], "lower": r["lower_bound"],
                           "upper": r["upper_bound"], "btfsm_ms": ms}
                    note, cells, value = [], [], None
                    for form in forms:
                        v, hs = solve(ga, gb, mode == "labeled", args.highs_timeout, strong=form == "strong")
                        value = value if v is None else v
                        if v is None:
                            note.append(f"HiGHS {form} timeout")
                        elif not (r["lower_bound"] <= v <= r["upper_bound"]) or (r["exact"] and r["ged"] != v):
                            note.append("DIFFERS")
                        row[f"highs_{form}"] = v
                        row[f"highs_{form}_ms"] = hs * 1e3
                        row[f"ratio_{form}"] = hs * 1e3 / ms
                        cells.append(f"{hs*1e3:>9.1f} {hs*1e3/ms:>6.1f}x")
                    if not r["exact"]:
                        note.append(f"inexact ({r.get('stopped_by', '?')})")
                    rows.append(row)
                    name = f"{group}-{i} ({ga['n']},{gb['n']})" if kind == group else f"{kind}-{i} ({ga['n']},{gb['n']})"
                    print(f"{name:28} {mode:10} {ours:>9} {str(value):>6} {ms:>9.1f} "
                          + " ".join(cells) + f"  {', '.join(note)}", flush=True)
    print()
    for group in wanted:
        for mode in args.modes.split(","):
            g = [r for r in rows if r["group"] == group and r["mode"] == mode]
            if not g:
                continue
            ex = sum(r["exact"] for r in g)
            line = (f"{group} {mode}: {len(g)} pairs, btfsm exact {ex}, median btfsm "
                    f"{statistics.median(r['btfsm_ms'] for r in g):.1f} ms")
            for form in forms:
                solved = [r for r in g if r[f"highs_{form}"] is not None]
                line += f"; HiGHS {form} solved {len(solved)}"
                both = [r for r in solved if r["exact"]]
                if solved:
                    line += (f" (median {statistics.median(r[f'highs_{form}_ms'] for r in solved):.0f} ms), "
                             f"btfsm exact on {len(both)} of those")
                if both:
                    # Only where both settled the value: an inexact btfsm
                    # result is quick because it gave up, not a win.
                    line += (f", median ratio HiGHS/btfsm on those "
                             f"{statistics.median(r[f'ratio_{form}'] for r in both):.1f}x")
            either = [r for r in g if any(r.get(f"highs_{f}") is not None for f in forms)]
            line += (f"; HiGHS solved {len(either)} in some formulation, btfsm exact on "
                     f"{sum(r['exact'] for r in either)} of those")
            print(line)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
