#!/usr/bin/env python3
"""Differential test of btfsm's ordered tree edit distance (`compare --mode
tree`, src/metrics/ted/) against the PyPI packages `apted` (Pawlik &
Augsten's APTED, Python port) and `zss` (Zhang & Shasha), both pinned in
tests/differential/requirements.txt.

Generates seeded random ordered labelled trees — varied sizes and shapes
(paths, combs, bushes), small label alphabets so that matches and renames
both happen — in three kinds of pairs: independent trees, a tree and a
mutated copy (renames, deletions, insertions, subtree moves, sibling swaps:
the banded computation's narrow case), and a tree with itself. Sends them
all to the hidden `btfsm ted-pairs` in a few processes, and requires for
every pair: the distance equal to apted's (and to zss's on the smaller
pairs), exact, and an edit script whose cost is the distance. A last batch
runs under a tiny work budget and requires an interval that holds apted's
distance, with a script costing its upper bound.

Usage: ted.py BTFSM [--pairs N] [--seed S]
"""

import argparse
import json
import os
import random
import subprocess
import sys
import tempfile

import zss
from apted import APTED
from apted.helpers import Tree


def random_tree(rng, n, alphabet):
    """(children lists, labels) of a random tree of n nodes."""
    style = rng.random()
    kids = [[] for _ in range(n)]
    for v in range(1, n):
        if style < 0.15:
            p = v - 1  # path-like
        elif style < 0.3:
            p = rng.randrange(max(1, v // 4))  # bushy near the root
        else:
            p = v - 1 if rng.random() < 0.3 else rng.randrange(v)
        kids[p].append(v)
    labels = [rng.choice(alphabet) for _ in range(n)]
    return kids, labels


def subtree(kids, labels, v):
    """Copy of the subtree at v as (kids, labels), node 0 its root."""
    order, stack = [], [v]
    while stack:
        x = stack.pop()
        order.append(x)
        stack.extend(reversed(kids[x]))
    index = {x: i for i, x in enumerate(order)}
    return [[index[c] for c in kids[x]] for x in order], [labels[x] for x in order]


def mutate(rng, kids, labels, alphabet, edits):
    """A copy with `edits` random edits: rename, delete (children move up),
    insert (over a run of siblings), move a subtree, swap two siblings."""
    kids = [list(k) for k in kids]
    labels = list(labels)
    alive = set(range(len(kids)))
    for _ in range(edits):
        op = rng.choice(["rename", "delete", "insert", "move", "swap"])
        nodes = sorted(alive)
        v = rng.choice(nodes)
        parent = {c: p for p in alive for c in kids[p]}
        if op == "rename":
            labels[v] = rng.choice(alphabet)
        elif op == "delete" and v in parent:
            p = parent[v]
            i = kids[p].index(v)
            kids[p][i:i + 1] = kids[v]
            alive.discard(v)
        elif op == "insert":
            w = len(kids)
            i = rng.randrange(len(kids[v]) + 1)
            j = rng.randrange(i, len(kids[v]) + 1)
            kids.append(kids[v][i:j])
            labels.append(rng.choice(alphabet))
            kids[v][i:j] = [w]
            alive.add(w)
        elif op == "move" and v in parent:
            inside, stack = set(), [v]
            while stack:
                x = stack.pop()
                inside.add(x)
                stack.extend(kids[x])
            targets = [x for x in nodes if x not in inside]
            kids[parent[v]].remove(v)
            t = rng.choice(targets)
            kids[t].insert(rng.randrange(len(kids[t]) + 1), v)
        elif op == "swap" and len(kids[v]) >= 2:
            i, j = rng.sample(range(len(kids[v])), 2)
            kids[v][i], kids[v][j] = kids[v][j], kids[v][i]
    return subtree(kids, labels, 0)


def bracket(kids, labels):
    out, stack = [], [(0, False)]
    while stack:
        v, closing = stack.pop()
        if closing:
            out.append("}")
            continue
        out.append("{" + labels[v])
        stack.append((v, True))
        stack.extend((c, False) for c in reversed(kids[v]))
    return "".join(out)


def zss_tree(kids, labels):
    nodes = [zss.Node(l) for l in labels]
    for v, ks in enumerate(kids):
        for c in ks:
            nodes[v].addkid(nodes[c])
    return nodes[0]


def make_pairs(rng, count):
    pairs = []
    for i in range(count):
        alphabet = "abcd"[: 1 + rng.randrange(4)]
        big = rng.random() < 0.1
        n = rng.randint(1, 120 if big else 40)
        a = random_tree(rng, n, alphabet)
        kind = i % 10
        if kind < 5:
            b = random_tree(rng, rng.randint(1, 120 if big else 40), alphabet)
        elif kind < 9:
            b = mutate(rng, a[0], a[1], alphabet, rng.randint(1, 6))
        else:
            b = a
        pairs.append((a, b))
    return pairs


def run_btfsm(btfsm, d, name, pairs, extra):
    path = os.path.join(d, name)
    with open(path, "w") as f:
        for a, b in pairs:
            f.write(bracket(*a) + "\t" + bracket(*b) + "\n")
    p = subprocess.run([btfsm, "ted-pairs", path, "--allow-outside-root"] + extra,
                       capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("btfsm ted-pairs failed (exit %d):\n%s" % (p.returncode, p.stderr))
    out = [json.loads(line) for line in p.stdout.splitlines() if line.strip()]
    if len(out) != len(pairs):
        sys.exit("btfsm ted-pairs gave %d results for %d pairs" % (len(out), len(pairs)))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("btfsm")
    ap.add_argument("--pairs", type=int, default=3000)
    ap.add_argument("--seed", type=int, default=15)
    a = ap.parse_args()
    rng = random.Random(a.seed)
    pairs = make_pairs(rng, a.pairs)
    tight = make_pairs(rng, 200)
    failures = []
    zss_checked = 0
    with tempfile.TemporaryDirectory(prefix="btfsm-ted-") as d:
        got = run_btfsm(a.btfsm, d, "pairs.txt", pairs, [])
        got_tight = run_btfsm(a.btfsm, d, "tight.txt", tight, ["--max-work", "300"])
    for (ta, tb), g in zip(pairs, got):
        want = APTED(Tree.from_text(bracket(*ta)), Tree.from_text(bracket(*tb))).compute_edit_distance()
        problems = []
        if g["ted"] != want or not g["exact"]:
            problems.append("apted %d, btfsm %s" % (want, g))
        if g["script_cost"] != g["ted"]:
            problems.append("script costs %d, distance %d" % (g["script_cost"], g["ted"]))
        if len(ta[1]) <= 25 and len(tb[1]) <= 25:
            z = zss.simple_distance(zss_tree(*ta), zss_tree(*tb))
            zss_checked += 1
            if z != want:
                problems.append("zss %d, apted %d" % (z, want))
        if problems:
            failures.append((len(ta[1]) + len(tb[1]), bracket(*ta), bracket(*tb), problems))
    inexact = 0
    for (ta, tb), g in zip(tight, got_tight):
        want = APTED(Tree.from_text(bracket(*ta)), Tree.from_text(bracket(*tb))).compute_edit_distance()
        inexact += not g["exact"]
        if not (g["lower_bound"] <= want <= g["ted"]) or g["script_cost"] != g["ted"]:
            failures.append((len(ta[1]) + len(tb[1]), bracket(*ta), bracket(*tb),
                             ["under --max-work 300: apted %d, btfsm %s" % (want, g)]))
    if failures:
        failures.sort(key=lambda f: f[0])
        size, ta, tb, problems = failures[0]
        print("%d of %d pairs disagree; the smallest (%d nodes):" % (len(failures), len(pairs) + len(tight), size))
        print("  a: " + ta)
        print("  b: " + tb)
        for p in problems:
            print("  " + p)
        return 1
    print("ted differential: %d pairs (%d also against zss): btfsm's tree edit distance equals apted's, "
          "each with an edit script of that cost; %d pairs under a tiny work budget (%d inexact) hold "
          "apted's distance in their interval" % (len(pairs), zss_checked, len(tight), inexact))
    return 0


if __name__ == "__main__":
    sys.exit(main())
