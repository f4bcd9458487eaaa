#!/usr/bin/env python3
"""btfsm vs HiGHS on exact graph edit distance, measured in one run.

Generates seeded random pairs (tests/differential/ged_highs.py): independent
random trees of 15-27 nodes (as BehaviorTree TOML) and of 40-50 nodes, and
FSM-like graphs of 10-28 states (as FSM TOML), and with `--groups shapes`
pairs of other shapes (`ged_highs.shapes`: trees of six shapes, edited
copies of trees and FSMs, FSMs of very different sizes, SCXML charts), with
`--groups ft-rewired` fault-tolerant FSMs of 18-25 vertices with arcs moved,
and with `--groups nav2` Nav2's trees across releases (bench/nav2-releases,
structural only); times
`btfsm compare --mode structural|labeled --format json` at its default budget
(the engine's own `micros`, no process start-up; at least 1 µs) and HiGHS (PyPI `highspy`, one thread) on the binary formulations
documented in ged_highs.py: F2 (Lerouge et al. 2017, unit costs) and F2 with
the matching rows ("strong": the relaxation btfsm's ascent bound works on,
so the fairer rival on graphs that are not forests); prints per pair the
values, the times and the ratios, then per group and formulation how many
pairs btfsm settled exactly and the median ratio on the pairs both settled
(HiGHS within --highs-timeout).

Usage: python3 bench/ged_vs_highs.py BTFSM [--seed S] [--highs-timeout S]
       [--groups trees,big-trees,fsm,fsm-set,shapes,ft-rewired,nav2] [--fsm-count N] [--fsm-sizes LO,HI]
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

from ged_highs import (bt_toml_graph, ft_rewired, random_fsm, random_tree, run_btfsm,  # noqa: E402
                       shapes, solve, write_pair)

NAV2 = os.path.join(ROOT, "bench", "nav2-releases")


def nav2_pairs(btfsm):
    """Nav2's trees across releases (bench/nav2-releases): each version
    against the next, and the first against the last, of each lineage;
    both as btfsm reads them (`convert --to toml` with Nav2's node model:
    SubTrees expanded) so that HiGHS gets the same graphs."""
    import subprocess
    lines = {}
    for f in sorted(os.listdir(NAV2)):
        if f.endswith(".xml") and f != "nav2_tree_nodes.xml":
            line, tag = f[:-4].rsplit("-", 1)
            lines.setdefault(line, []).append((tag, f))

    def order(tag):
        return (1, ()) if tag == "main" else (0, tuple(int(x) for x in tag.split(".")))

    def read(f):
        text = subprocess.run([btfsm, "convert", os.path.join(NAV2, f), "--to", "toml",
                               "--nodes-model", os.path.join(NAV2, "nav2_tree_nodes.xml"),
                               "--assume-leaf", "action"], capture_output=True, text=True, check=True).stdout
        return text, bt_toml_graph(text)

    out = []
    for line, versions in sorted(lines.items()):
        versions.sort(key=lambda v: order(v[0]))
        steps = list(zip(versions, versions[1:]))
        if len(versions) > 2:
            steps.append((versions[0], versions[-1]))
        for (ta, fa), (tb, fb) in steps:
            out.append((f"nav2-{line}-{ta}-{tb}", read(fa), read(fb)))
    return out


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
    # Fault-tolerant FSMs (the paper's Fig. 8d / 16b shape) with arcs moved.
    yield "ft-rewired", ft_rewired(seed)


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
        all_groups = list(groups(args.seed, args.fsm_count, sizes))
        if "nav2" in wanted:
            all_groups.append(("nav2", nav2_pairs(args.btfsm)))
        for group, plist in all_groups:
            if group not in wanted:
                continue
            for i, pair in enumerate(plist):
                kind, (ta, ga), (tb, gb) = pair if len(pair) == 3 else (group, *pair)
                if kinds and kind != group and not any(kind.startswith(k) for k in kinds):
                    continue
                fa, fb = write_pair(d, ta, tb)
                for mode in args.modes.split(","):
                    if group == "nav2" and mode == "labeled":
                        continue  # Nav2's own node types: structural only
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
    # Issue 34: every pair at least 10x faster than HiGHS, or named here.
    slow = []
    for r in rows:
        solved = [r[f"ratio_{f}"] for f in forms if r.get(f"highs_{f}") is not None]
        if solved and r["exact"] and min(solved) < 10.0:
            slow.append((r, min(solved)))
    print(f"\npair-modes HiGHS solved and btfsm settled at less than 10x the fastest HiGHS: {len(slow)}")
    for r, ratio in slow:
        print(f"  {r['kind']}-{r['pair']} {r['mode']}: {ratio:.1f}x (btfsm {r['btfsm_ms']:.1f} ms)")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
