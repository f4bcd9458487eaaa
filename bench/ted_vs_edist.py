#!/usr/bin/env python3
"""btfsm's ordered tree edit distance vs the `edist` package (Paaßen's
compiled Zhang–Shasha, Cython; pinned in tests/differential/requirements.txt)
on unrelated seeded random trees of 1,000, 5,000 and 10,000 nodes, measured
in one run (docs/performance.md, "Tree edit distance").

Trees come from the differential test's generator (tests/differential/ted.py
`random_tree`, labels from an 8-letter alphabet, each tree's shape drawn at
random). btfsm runs all pairs in one `btfsm ted-pairs` process (the release
build; the distance's time, without process start-up or the edit script);
edist's `standard_ted` is timed in this process. Both distances must agree
and btfsm's must be exact under its default budgets. Prints each pair, both
times, the ratio, and the load average before and after.

Usage: bench/ted_vs_edist.py BTFSM [--sizes 1000,5000,10000] [--seed S]
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "differential"))
import ted as gen  # noqa: E402  (the differential test's tree generator)
import random  # noqa: E402

from edist.ted import standard_ted  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("btfsm")
    ap.add_argument("--sizes", default="1000,5000,10000")
    ap.add_argument("--seed", type=int, default=15)
    a = ap.parse_args()
    rng = random.Random(a.seed)
    alphabet = "abcdefgh"
    pairs = []
    for n in [int(s) for s in a.sizes.split(",")]:
        # Preorder copies: edist wants every subtree's nodes contiguous.
        x = gen.subtree(*gen.random_tree(rng, n, alphabet), 0)
        y = gen.subtree(*gen.random_tree(rng, n, alphabet), 0)
        pairs.append(("%d nodes, unrelated" % n, x, y))
    print("load average before: %.2f %.2f %.2f" % os.getloadavg())
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
    print("%-24s %6s %12s %12s %12s %8s" % ("pair", "TED", "cells", "btfsm", "edist", "ratio"))
    for (name, x, y), m in zip(pairs, mine):
        start = time.perf_counter()
        want = standard_ted(x[1], x[0], y[1], y[0])
        edist_s = time.perf_counter() - start
        if want != m["ted"] or not m["exact"]:
            sys.exit("%s: edist %d, btfsm %s" % (name, want, m))
        ours = max(m["micros"], 1) / 1e6
        print("%-24s %6d %12d %10.2f s %10.2f s %7.1fx" % (name, want, m["work"], ours, edist_s, edist_s / ours))
    print("load average after: %.2f %.2f %.2f" % os.getloadavg())


if __name__ == "__main__":
    main()
