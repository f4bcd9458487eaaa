#!/usr/bin/env python3
"""btfsm's ordered tree edit distance vs the `apted` package (Pawlik &
Augsten's APTED, Python port; pinned in tests/differential/requirements.txt)
on the same seeded random trees, measured in one run (docs/performance.md).

Pairs: for each size, a tree and a copy with 5 random edits (the pull-request
case) and two unrelated trees, labels from an 8-letter alphabet. btfsm runs
them all in one `btfsm ted-pairs` process (the release build), which reports
each distance's time without process start-up; apted is timed in this
process. Both distances must agree. Prints each pair and the median ratio.

Usage: bench/ted_vs_apted.py BTFSM [--sizes 100,200,400,600] [--seed S]
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "differential"))
import ted as gen  # noqa: E402  (the differential test's tree generator)
import random  # noqa: E402

from apted import APTED  # noqa: E402
from apted.helpers import Tree  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("btfsm")
    ap.add_argument("--sizes", default="100,200,400,600")
    ap.add_argument("--seed", type=int, default=15)
    a = ap.parse_args()
    sys.setrecursionlimit(100000)
    rng = random.Random(a.seed)
    alphabet = "abcdefgh"
    pairs = []
    for n in [int(s) for s in a.sizes.split(",")]:
        t = gen.random_tree(rng, n, alphabet)
        pairs.append(("%d nodes, copy with 5 edits" % n, t, gen.mutate(rng, t[0], t[1], alphabet, 5)))
        pairs.append(("%d nodes, unrelated" % n, t, gen.random_tree(rng, n, alphabet)))
    with tempfile.TemporaryDirectory(prefix="btfsm-ted-bench-") as d:
        path = os.path.join(d, "pairs.txt")
        with open(path, "w") as f:
            for _, x, y in pairs:
                f.write(gen.bracket(*x) + "\t" + gen.bracket(*y) + "\n")
        p = subprocess.run([a.btfsm, "ted-pairs", path, "--allow-outside-root"],
                           capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("btfsm ted-pairs failed: " + p.stderr)
    mine = [json.loads(l) for l in p.stdout.splitlines() if l.strip()]
    print("%-30s %6s %6s %6s %12s %12s %9s" % ("pair", "nodes", "nodes", "TED", "btfsm", "apted", "ratio"))
    ratios = []
    for (name, x, y), m in zip(pairs, mine):
        start = time.perf_counter()
        want = APTED(Tree.from_text(gen.bracket(*x)), Tree.from_text(gen.bracket(*y))).compute_edit_distance()
        apted_s = time.perf_counter() - start
        if want != m["ted"] or not m["exact"]:
            sys.exit("%s: apted %d, btfsm %s" % (name, want, m))
        ours = max(m["micros"], 1) / 1e6
        ratios.append(apted_s / ours)
        print("%-30s %6d %6d %6d %9.2f ms %9.1f ms %8.0fx" % (
            name, len(x[1]), len(y[1]), want, ours * 1e3, apted_s * 1e3, apted_s / ours))
    print("median: btfsm is %.0fx faster than apted (Python) on these %d pairs" % (statistics.median(ratios), len(pairs)))


if __name__ == "__main__":
    main()
