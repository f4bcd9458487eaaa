#!/usr/bin/env python3
"""Writes the random policy pairs of docs/robustness.md "Budgets" into DIR:
random FSMs (n states, three outcome arcs each to a random state or to
SUCCESS) and random BTs (n nodes, 30% sequence/fallback, each node a child of
a random earlier control node). Deterministic (seeded xorshift), so the same
pairs are measured on every run.

usage: budgets_gen.py DIR
"""
import os
import sys


def rng(seed):
    x = seed or 1

    def nxt(m):
        nonlocal x
        x ^= (x << 13) & 0xFFFFFFFFFFFFFFFF
        x ^= x >> 7
        x ^= (x << 17) & 0xFFFFFFFFFFFFFFFF
        return x % m

    return nxt


def fsm(n, seed):
    r = rng(seed)
    out = ['kind = "fsm"', 'initial = "s0"', 'outcomes = ["SUCCESS"]']
    for i in range(n):
        arcs = []
        for o in ("SUCCESS", "FAILURE", "RUNNING"):
            t = r(n + 1)
            arcs.append('%s = "%s"' % (o, "SUCCESS" if t == n else "s%d" % t))
        out.append("[states.s%d]" % i)
        out.append('skill = "Move-To"')
        out.append('args = { target = "cube1" }')
        out.append("on = { %s }" % ", ".join(arcs))
    return "\n".join(out) + "\n"


def bt(n, seed):
    r = rng(seed)
    control = [True] + [r(10) < 3 for _ in range(1, n)]
    kind = ["sequence" if r(2) == 0 else "fallback" for _ in range(n)]
    children = [[] for _ in range(n)]
    controls = [0]
    for i in range(1, n):
        children[controls[r(len(controls))]].append(i)
        if control[i]:
            controls.append(i)
    out = ['kind = "bt"', 'root = "n0"', "[nodes]"]
    for i in range(n):
        if children[i]:
            names = ", ".join('"n%d"' % c for c in children[i])
            out.append("n%d = { %s = [%s] }" % (i, kind[i], names))
        else:
            out.append('n%d = { action = "Act %d!", skill = "Dock" }' % (i, i))
    return "\n".join(out) + "\n"


def main():
    d = sys.argv[1]
    os.makedirs(d, exist_ok=True)
    for name, make, n in [
        ("fsm500", fsm, 500),
        ("fsm2000", fsm, 2000),
        ("bt5000", bt, 5000),
        ("bt100000", bt, 100000),
    ]:
        for side, seed in (("a", 1), ("b", 2)):
            path = os.path.join(d, "%s-%s.toml" % (name, side))
            if not os.path.exists(path):
                with open(path, "w") as f:
                    f.write(make(n, seed * 7919 + n))


if __name__ == "__main__":
    main()
