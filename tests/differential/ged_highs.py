#!/usr/bin/env python3
"""Exact GED by HiGHS (PyPI `highspy`), an independent oracle for btfsm's GED.

The cost model is btfsm's (SPEC §3, src/metrics/ged/mod.rs): directed
multigraphs with self-loops and parallel arcs, unit costs; for a partial
injection f of G1's vertices into G2's, the cost is the vertices deleted and
inserted plus, over ordered pairs (u, w) of G1 vertices (u = w for a
self-loop), |A(u, w) - B(f u, f w)|, plus every arc at a deleted or inserted
vertex. With m1, m2 the arc counts this is

    n1 + n2 - 2 |f| + m1 + m2 - 2 * sum_{(u,w)} min(A(u, w), B(f u, f w)),

so minimising it maximises mapped vertices plus twice the preserved arcs.

Binary formulation: the "F2" formulation of Lerouge, Abu-Aisheh, Raveaux,
Héroux and Adam ("New binary linear programming formulation to compute the
graph edit distance", Pattern Recognition 72, 2017), specialised to unit
costs, with substitutions free, and with arc pairs weighted by the smaller
multiplicity (so parallel arcs and self-loops count as btfsm counts them):

    x[u,v] in {0,1}   u in V1, v in V2 (same label in labeled mode)
    y[k,l] in [0,1]   k = (u,w) a support pair of A, l = (v,z) one of B,
                      loops only onto loops (and labels compatible)
    sum_v x[u,v] <= 1 (each u),   sum_u x[u,v] <= 1 (each v)
    sum_z y[(u,w),(v,z)] <= x[u,v]   for each k = (u,w) and v
    sum_v y[(u,w),(v,z)] <= x[w,z]   for each k = (u,w) and z
    minimise n1 + n2 + m1 + m2 - 2 sum x - 2 sum min(A_k, B_l) y[k,l]

y may stay continuous: with x integral the two F2 rows leave y[k,l] = 1 only
at l = (f u, f w).

`strong=True` adds, for each arc l = (v,z) of B, the two rows

    sum_w y[(u,w),(v,z)] <= x[u,v]   for each u   (u's out-arcs onto l)
    sum_u y[(u,w),(v,z)] <= x[w,z]   for each w   (w's in-arcs onto l)

so that at each pair (u,v) the out-arcs (and the in-arcs) of u and v meet in
a matching: redundant for integral x, but a much tighter linear relaxation
(the relaxation btfsm's ascent bound optimises, src/metrics/ged/ascent.rs).

Run as a program it is the differential test of `make differential`: seeded
random pairs of trees (15-27 nodes, written as BehaviorTree TOML) and of
FSM-like graphs (written as FSM TOML), structural and labeled, each compared
with `btfsm compare --format json`: where btfsm says exact its value must be
HiGHS's optimum, and HiGHS's optimum must lie in btfsm's certified interval
whatever btfsm says.

Usage: ged_highs.py BTFSM [--pairs N] [--seed S] [--shapes KINDS] [--paper JSONL]
"""

import argparse
import json
import os
import random
import subprocess
import sys
import tempfile
import time

import numpy as np
import highspy


def solve(g1, g2, labeled, time_limit=10.0, strong=False):
    """Exact GED of two graphs {n, arcs: [(t, h)], labels: [str]} by HiGHS,
    on F2 (or F2 with the matching rows, `strong`).

    Returns (value or None if not proven, seconds of `run`)."""
    from collections import Counter

    n1, n2 = g1["n"], g2["n"]
    lab1 = g1["labels"] if labeled else ["v"] * n1
    lab2 = g2["labels"] if labeled else ["v"] * n2
    pa = sorted(Counter(map(tuple, g1["arcs"])).items())
    pb = sorted(Counter(map(tuple, g2["arcs"])).items())
    m1, m2 = len(g1["arcs"]), len(g2["arcs"])
    xid = {}
    costs, lower, upper, integ = [], [], [], []
    for u in range(n1):
        for v in range(n2):
            if lab1[u] == lab2[v]:
                xid[(u, v)] = len(costs)
                costs.append(-2.0)
                integ.append(True)
    yid = []
    for k, ((u, w), ma) in enumerate(pa):
        for l, ((v, z), mb) in enumerate(pb):
            if (u == w) != (v == z) or (u, v) not in xid or (w, z) not in xid:
                continue
            yid.append((k, l, len(costs)))
            costs.append(-2.0 * min(ma, mb))
            integ.append(False)
    ncols = len(costs)
    rows = []  # (indices, values, upper)
    for u in range(n1):
        idx = [xid[(u, v)] for v in range(n2) if (u, v) in xid]
        if idx:
            rows.append((idx, [1.0] * len(idx)))
    for v in range(n2):
        idx = [xid[(u, v)] for u in range(n1) if (u, v) in xid]
        if idx:
            rows.append((idx, [1.0] * len(idx)))
    # Each row: a group of y columns <= one x column. A group is keyed by
    # the x pair it is bounded by and what it sums over.
    groups = {}
    for k, l, c in yid:
        (u, w), _ = pa[k]
        (v, z), _ = pb[l]
        keys = [("F2 tail", k, (u, v)), ("F2 head", k, (w, z))]
        if strong:
            keys += [("tail", l, (u, v)), ("head", l, (w, z))]
        for key in keys:
            groups.setdefault(key, []).append(c)
    for (_, _, pair), cols in groups.items():
        rows.append((cols + [xid[pair]], [1.0] * len(cols) + [-1.0]))
    rows = [(i, v, 1.0 if all(x > 0 for x in v) else 0.0) for i, v in rows]

    h = highspy.Highs()
    h.setOptionValue("output_flag", False)
    h.setOptionValue("time_limit", float(time_limit))
    h.setOptionValue("threads", 1)
    h.setOptionValue("mip_rel_gap", 0.0)
    h.setOptionValue("mip_abs_gap", 0.0)
    inf = highspy.kHighsInf
    if ncols:
        h.addVars(ncols, np.zeros(ncols), np.ones(ncols))
        h.changeColsCost(ncols, np.arange(ncols, dtype=np.int32), np.array(costs))
        ints = np.array([i for i in range(ncols) if integ[i]], dtype=np.int32)
        if len(ints):
            h.changeColsIntegrality(len(ints), ints,
                                    np.array([highspy.HighsVarType.kInteger] * len(ints)))
    for idx, vals, ub in rows:
        h.addRow(-inf, ub, len(idx), np.array(idx, dtype=np.int32), np.array(vals))
    t0 = time.perf_counter()
    h.run()
    secs = time.perf_counter() - t0
    const = n1 + n2 + m1 + m2
    if ncols == 0:
        return const, secs
    if h.getModelStatus() != highspy.HighsModelStatus.kOptimal:
        return None, secs
    return int(round(const + h.getInfo().objective_function_value)), secs


# ---- seeded random instances, each both as a btfsm policy and as a graph ----

def random_tree(rng, n):
    """A random recursive tree as a BT TOML text and its graph (parent -> child)."""
    parent = [None] + [rng.randrange(i) for i in range(1, n)]
    inner = set(parent[1:])
    kinds = []
    for i in range(n):
        if i in inner:
            kinds.append(rng.choice(["sequence", "fallback"]))
        else:
            kinds.append("action" if rng.random() < 0.5 else "condition")
    return tree_text(parent, kinds)


def random_fsm(rng, n):
    """A random FSM of n states (plus outcomes SUCCESS and FAILURE): each
    action state has up to three transitions (SUCCESS, FAILURE, RUNNING),
    each condition state up to two, to random states or outcomes, self-loops
    and parallel arcs allowed. The graph is SPEC §2's: states, then outcomes."""
    outs = ["SUCCESS", "FAILURE"]
    lines = ['kind = "fsm"', 'name = "random fsm"', 'initial = "s0"',
             'outcomes = ["SUCCESS", "FAILURE"]', ""]
    labels, arcs = [], []
    for i in range(n):
        cond = rng.random() < 0.3
        labels.append("condition_state" if cond else "state")
        lines.append(f"[states.s{i}]")
        if cond:
            lines.append('skill = "In-Hand"')
            triggers = ["SUCCESS", "FAILURE"]
        else:
            lines.append('skill = "Pick"')
            triggers = ["SUCCESS", "FAILURE", "RUNNING"]
        lines.append('args = { object = "c" }')
        on = []
        for t in triggers:
            if rng.random() < 0.8:
                j = rng.randrange(n + 2)
                target = f"s{j}" if j < n else outs[j - n]
                on.append(f'{t} = "{target}"')
                arcs.append((i, j))
        if on:
            lines.append("on = { " + ", ".join(on) + " }")
        lines.append("")
    labels += ["outcome", "outcome"]
    return "\n".join(lines), {"n": n + 2, "arcs": arcs, "labels": labels}


# ---- more shapes (bench/ged_vs_highs.py --groups shapes) ----

LEAVES = ("action", "condition")


def tree_text(parent, kinds):
    """A BT TOML text and its graph from a parent list (parent[0] is None)
    and a kind per node: a node with children is a sequence or fallback
    (kinds naming a leaf become sequences), a leaf an action or condition
    (kinds naming a composite become actions)."""
    n = len(parent)
    kids = [[] for _ in range(n)]
    for i in range(1, n):
        kids[parent[i]].append(i)
    lines = ['kind = "bt"', 'name = "random tree"', 'root = "n0"', "", "[nodes]"]
    labels = []
    for i in range(n):
        if kids[i]:
            t = kinds[i] if kinds[i] in ("sequence", "fallback") else "sequence"
            names = ", ".join(f'"n{c}"' for c in kids[i])
            lines.append(f"n{i} = {{ {t} = [{names}] }}")
        elif kinds[i] == "condition":
            t = "condition"
            lines.append(f'n{i} = {{ condition = "c{i}", skill = "In-Hand", args = {{ object = "c" }} }}')
        else:
            t = "action"
            lines.append(f'n{i} = {{ action = "a{i}", skill = "Pick", args = {{ object = "c" }} }}')
        labels.append(t)
    arcs = [(parent[i], i) for i in range(1, n)]
    return "\n".join(lines) + "\n", {"n": n, "arcs": arcs, "labels": labels}


def tree_parents(rng, n, shape):
    """Parents of a random tree of n nodes: "recursive" (uniform earlier
    parent), "preferential" (by degree + 1), "deep" (one of the 3 latest),
    "wide" (one of the first 3), "binary" (heap order), "bt" (composites of
    at most 5 children)."""
    parent, deg = [None], [0] * n
    for i in range(1, n):
        if shape == "recursive":
            j = rng.randrange(i)
        elif shape == "preferential":
            j = rng.choices(range(i), weights=[d + 1 for d in deg[:i]])[0]
        elif shape == "deep":
            j = rng.randrange(max(0, i - 3), i)
        elif shape == "wide":
            j = rng.randrange(min(i, 3))
        elif shape == "binary":
            j = (i - 1) // 2
        else:
            j = rng.choice([k for k in range(i) if deg[k] < 5])
        parent.append(j)
        deg[j] += 1
    return parent


def random_kinds(rng, n):
    return [rng.choice(["sequence", "fallback", "action", "condition"]) for _ in range(n)]


def edited_tree(rng, parent, kinds, k):
    """k random edits of a tree: add a leaf, delete a leaf, move a subtree
    under another parent, or change a node's kind."""
    parent, kinds = list(parent), list(kinds)
    for _ in range(k):
        n = len(parent)
        op = rng.choice(["add", "delete", "move", "kind"])
        if op == "add":
            parent.append(rng.randrange(n))
            kinds.append(rng.choice(LEAVES))
        elif op == "delete" and n > 3:
            inner = set(parent[1:])
            v = rng.choice([i for i in range(1, n) if i not in inner])
            del parent[v], kinds[v]
            parent = [None] + [p if p < v else p - 1 for p in parent[1:]]
        elif op == "move" and n > 3:
            v = rng.randrange(1, n)
            below, grew = {v}, True
            while grew:
                grew = False
                for i in range(1, n):
                    if i not in below and parent[i] in below:
                        below.add(i)
                        grew = True
            parent[v] = rng.choice([i for i in range(n) if i not in below])
        else:
            kinds[rng.randrange(n)] = rng.choice(["sequence", "fallback", "action", "condition"])
    return parent, kinds


def fsm_states(rng, n):
    """n random FSM states as (is_condition, {outcome: target}), targets a
    state index or "SUCCESS" / "FAILURE", as `random_fsm` draws them."""
    out = []
    for _ in range(n):
        cond = rng.random() < 0.3
        on = {}
        for t in (("SUCCESS", "FAILURE") if cond else ("SUCCESS", "FAILURE", "RUNNING")):
            if rng.random() < 0.8:
                j = rng.randrange(n + 2)
                on[t] = j if j < n else ("SUCCESS", "FAILURE")[j - n]
        out.append((cond, on))
    return out


def fsm_text(states):
    """An FSM TOML text and its graph (SPEC §2: states, then the outcomes)."""
    n = len(states)
    lines = ['kind = "fsm"', 'name = "random fsm"', 'initial = "s0"',
             'outcomes = ["SUCCESS", "FAILURE"]', ""]
    labels, arcs = [], []
    for i, (cond, on) in enumerate(states):
        labels.append("condition_state" if cond else "state")
        lines += [f"[states.s{i}]", 'skill = "In-Hand"' if cond else 'skill = "Pick"',
                  'args = { object = "c" }']
        parts = []
        for t, j in on.items():
            parts.append(f'{t} = "{f"s{j}" if isinstance(j, int) else j}"')
            arcs.append((i, j if isinstance(j, int) else n + ("SUCCESS", "FAILURE").index(j)))
        if parts:
            lines.append("on = { " + ", ".join(parts) + " }")
        lines.append("")
    return "\n".join(lines), {"n": n + 2, "arcs": arcs, "labels": labels + ["outcome", "outcome"]}


def edited_fsm(rng, states, k):
    """k random edits of an FSM: retarget, add or drop a transition, add a
    state reached from an existing one, or turn an action state into a
    condition state or back."""
    states = [(c, dict(on)) for c, on in states]
    for _ in range(k):
        n = len(states)
        i = rng.randrange(n)
        cond, on = states[i]
        outs = ("SUCCESS", "FAILURE") if cond else ("SUCCESS", "FAILURE", "RUNNING")
        target = rng.randrange(n + 2)
        target = target if target < n else ("SUCCESS", "FAILURE")[target - n]
        op = rng.choice(["retarget", "add", "drop", "state", "flip"])
        if op in ("retarget", "add"):
            on[rng.choice(list(on) if op == "retarget" and on else outs)] = target
        elif op == "drop" and on:
            del on[rng.choice(list(on))]
        elif op == "state":
            states.append((rng.random() < 0.3, {"SUCCESS": rng.randrange(n)}))
            on[rng.choice(outs)] = n
        elif op == "flip":
            on.pop("RUNNING", None)
            states[i] = (not cond, on)
    return states


def random_scxml(rng, n, lo, hi):
    """An SCXML chart of n flat states, each with lo..hi transitions (own
    events) to random states or one of 1-3 final states, and its graph
    (states, then finals, in document order)."""
    finals = rng.randint(1, 3)
    lines = ['<?xml version="1.0"?>',
             '<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0" initial="s0">']
    arcs = []
    for i in range(n):
        lines.append(f'  <state id="s{i}">')
        for e in range(rng.randint(lo, hi)):
            j = rng.randrange(n + finals)
            lines.append(f'    <transition event="e{e}" target="{f"s{j}" if j < n else f"f{j - n}"}"/>')
            arcs.append((i, j))
        lines.append("  </state>")
    lines += [f'  <final id="f{f}"/>' for f in range(finals)] + ["</scxml>"]
    return "\n".join(lines) + "\n", {"n": n + finals, "arcs": arcs,
                                       "labels": ["state"] * n + ["final"] * finals}


def shapes(seed):
    """Named pairs of other shapes than `random_tree`/`random_fsm`'s: trees
    of six shapes (30-50 nodes), edited copies of trees (3-30 edits) and of
    FSMs (3-25 edits), FSMs of very different sizes, and SCXML charts of
    1-2, 2-4 and 3-6 transitions per state (10-28 states)."""
    rng = random.Random(seed)
    out = []
    for shape in ("recursive", "preferential", "deep", "wide", "binary", "bt"):
        for _ in range(3):
            na, nb = rng.randint(30, 50), rng.randint(30, 50)
            out.append((f"tree-{shape}", tree_text(tree_parents(rng, na, shape), random_kinds(rng, na)),
                        tree_text(tree_parents(rng, nb, shape), random_kinds(rng, nb))))
    for k in (3, 6, 10, 15, 20, 30):
        for _ in range(2):
            n = rng.randint(35, 50)
            parent = tree_parents(rng, n, rng.choice(["recursive", "bt", "preferential"]))
            kinds = random_kinds(rng, n)
            out.append((f"tree-edit{k}", tree_text(parent, kinds), tree_text(*edited_tree(rng, parent, kinds, k))))
    for k in (3, 8, 15, 25):
        for _ in range(3):
            st = fsm_states(rng, rng.randint(15, 26))
            out.append((f"fsm-edit{k}", fsm_text(st), fsm_text(edited_fsm(rng, st, k))))
    for _ in range(4):
        out.append(("fsm-sizes", fsm_text(fsm_states(rng, rng.randint(5, 9))),
                    fsm_text(fsm_states(rng, rng.randint(24, 28)))))
    for lo, hi in ((1, 2), (2, 4), (3, 6)):
        for _ in range(3):
            out.append((f"scxml-{lo}-{hi}", random_scxml(rng, rng.randint(10, 28), lo, hi),
                        random_scxml(rng, rng.randint(10, 28), lo, hi)))
    return out


def ft_fsm(k):
    """A fault-tolerant FSM of k action states in the shape of the paper's
    Fig. 8d / 16b, as a list of (name, label, [(trigger, target)]): each
    action state goes on to the next on SUCCESS (the last to the outcome
    SUCCESS), to SELECTOR on FAILURE, to itself on RUNNING, and has a
    battery guard to Recharge; Recharge returns to SELECTOR; SELECTOR (a
    decision state) guards to Recharge, to every action state and to the
    outcome SUCCESS. k + 4 vertices (with the outcomes SUCCESS and
    FAILURE), 5k + 5 arcs."""
    acts = [f"a{i}" for i in range(k)]
    states = []
    for i, a in enumerate(acts):
        nxt = acts[i + 1] if i + 1 < k else "SUCCESS"
        states.append((a, "state", [("SUCCESS", nxt), ("FAILURE", "SELECTOR"), ("RUNNING", a),
                                    ("guard", "Recharge")]))
    states.append(("Recharge", "state", [("SUCCESS", "SELECTOR"), ("RUNNING", "Recharge")]))
    states.append(("SELECTOR", "decision", [("guard", "Recharge")] + [("guard", a) for a in acts]
                   + [("guard", "SUCCESS"), ("RUNNING", "SELECTOR")]))
    return states


def rewire(rng, states, r):
    """r arcs of an FSM of `ft_fsm`'s form moved to random targets (states
    or outcomes)."""
    states = [(n, lab, list(arcs)) for n, lab, arcs in states]
    targets = [n for n, _, _ in states] + ["SUCCESS", "FAILURE"]
    for _ in range(r):
        _, _, arcs = rng.choice(states)
        j = rng.randrange(len(arcs))
        arcs[j] = (arcs[j][0], rng.choice(targets))
    return states


def ft_text(states):
    """The FSM TOML text of `ft_fsm`'s states and its graph (states in
    order, then the outcomes SUCCESS and FAILURE)."""
    names = [n for n, _, _ in states] + ["SUCCESS", "FAILURE"]
    index = {n: i for i, n in enumerate(names)}
    lines = ['kind = "fsm"', 'name = "fault-tolerant fsm"', f'initial = "{states[0][0]}"',
             'outcomes = ["SUCCESS", "FAILURE"]', ""]
    arcs, labels = [], []
    for i, (n, lab, trs) in enumerate(states):
        labels.append(lab)
        lines.append(f"[states.{n}]")
        if lab == "decision":
            lines.append("decision = true")
        else:
            lines += ['skill = "Pick"', 'args = { object = "c" }']
        guards = [t for g, t in trs if g == "guard"]
        if guards:
            lines.append("guards = [" + ", ".join(
                f'{{ unless = "Battery-Level", args = {{ min = 20 }}, to = "{t}" }}' for t in guards) + "]")
        on = [(g, t) for g, t in trs if g != "guard"]
        if on:
            lines.append("on = { " + ", ".join(f'{g} = "{t}"' for g, t in on) + " }")
        lines.append("")
        arcs += [(i, index[t]) for g, t in trs]
    return "\n".join(lines), {"n": len(names), "arcs": arcs, "labels": labels + ["outcome", "outcome"]}


def ft_rewired(seed):
    """Pairs of rewired fault-tolerant FSMs of 18-25 vertices (14-21 action
    states, up to 110 arcs): an FSM and a copy with 3-12 arcs moved, and
    two independently rewired FSMs of close sizes."""
    rng = random.Random(seed)
    out = []
    for r in (3, 6, 12):
        for _ in range(3):
            base = ft_fsm(rng.randint(14, 21))
            out.append((f"ft-copy{r}", ft_text(base), ft_text(rewire(rng, base, r))))
    for _ in range(4):
        k = rng.randint(14, 21)
        a = rewire(rng, ft_fsm(k), rng.randint(3, 12))
        b = rewire(rng, ft_fsm(max(14, min(21, k + rng.randint(-3, 3)))), rng.randint(3, 12))
        out.append(("ft-pair", ft_text(a), ft_text(b)))
    return out


def bt_toml_graph(text):
    """The graph of a BT TOML text (the vertices reachable from `root`,
    parent -> child arcs, each labelled by its kind key), for trees that
    btfsm converted (`convert --to toml`, SubTrees expanded)."""
    import tomllib
    t = tomllib.loads(text)
    nodes = t["nodes"]
    leaf_keys = ("action", "condition")
    order, index, arcs, labels = [], {}, [], []
    stack = [t["root"]]
    while stack:
        n = stack.pop()
        index[n] = len(order)
        order.append(n)
        spec = nodes[n]
        kind = next(k for k in spec if k not in ("name", "type", "ports", "skill", "args", "description"))
        labels.append(kind)
        kids = [] if kind in leaf_keys else spec[kind]
        kids = [kids] if isinstance(kids, str) else kids
        stack += list(reversed(kids))
    for n in order:
        spec = nodes[n]
        kind = labels[index[n]]
        kids = [] if kind in leaf_keys else spec[kind]
        kids = [kids] if isinstance(kids, str) else kids
        arcs += [(index[n], index[c]) for c in kids]
    return {"n": len(order), "arcs": arcs, "labels": labels}


def write_pair(d, ta, tb):
    """Writes a pair's two texts into directory d (.scxml or .toml, by
    content) and returns their paths."""
    ext = ".scxml" if ta.startswith("<?xml") else ".toml"
    paths = os.path.join(d, "a" + ext), os.path.join(d, "b" + ext)
    for path, text in zip(paths, (ta, tb)):
        with open(path, "w") as f:
            f.write(text)
    return paths


def run_btfsm(btfsm, fa, fb, mode, extra=()):
    out = subprocess.run([btfsm, "compare", fa, fb, "--mode", mode, "--format", "json", *extra],
                         capture_output=True, text=True, check=True).stdout
    return json.loads(out)[mode]


def pairs(seed, count):
    """`count` seeded pairs: trees of 15-27 nodes, then FSM-like graphs."""
    rng = random.Random(seed)
    for i in range(count):
        if i % 2 == 0:
            yield f"tree-{i}", random_tree(rng, rng.randint(15, 27)), random_tree(rng, rng.randint(15, 27))
        else:
            yield f"fsm-{i}", random_fsm(rng, rng.randint(4, 9)), random_fsm(rng, rng.randint(4, 9))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("btfsm")
    ap.add_argument("--pairs", type=int, default=16)
    ap.add_argument("--seed", type=int, default=15)
    ap.add_argument("--paper", metavar="JSONL",
                    help="graphs of policy files (the ignored test dump_policy_graphs writes "
                         "them); every pair of them is also checked, by file")
    ap.add_argument("--shapes", metavar="KINDS", default="",
                    help="also check the pairs of shapes(--seed) whose kind starts with one of "
                         "these comma-separated prefixes (e.g. tree-edit,fsm-edit3)")
    args = ap.parse_args()
    tally = {"checked": 0, "exact": 0, "bad": 0}

    def check(name, fa, fb, ga, gb, shown=""):
        """Both modes of one pair: btfsm's result must hold HiGHS's optimum."""
        for mode in ("structural", "labeled"):
            r = run_btfsm(args.btfsm, fa, fb, mode)
            truth, _ = solve(ga, gb, mode == "labeled", time_limit=60, strong=True)
            if truth is None:
                print(f"{name} {mode}: HiGHS did not finish, skipped")
                continue
            tally["checked"] += 1
            tally["exact"] += r["exact"]
            ok = r["lower_bound"] <= truth <= r["upper_bound"] and (not r["exact"] or r["ged"] == truth)
            if not ok:
                tally["bad"] += 1
                print(f"DISAGREE {name} {mode}: HiGHS {truth}, btfsm {r['ged']} "
                      f"[{r['lower_bound']}, {r['upper_bound']}] exact={r['exact']}{shown}")

    with tempfile.TemporaryDirectory() as d:
        for name, (ta, ga), (tb, gb) in pairs(args.seed, args.pairs):
            fa, fb = write_pair(d, ta, tb)
            check(name, fa, fb, ga, gb, f"\n{ta}\n{tb}")
        kinds = [k for k in args.shapes.split(",") if k]
        for i, (kind, (ta, ga), (tb, gb)) in enumerate(shapes(args.seed)):
            if not any(kind.startswith(k) for k in kinds):
                continue
            fa, fb = write_pair(d, ta, tb)
            check(f"{kind}-{i}", fa, fb, ga, gb, f"\n{ta}\n{tb}")
    if args.paper:
        with open(args.paper) as f:
            graphs = [json.loads(line) for line in f if line.strip()]
        for i, ga in enumerate(graphs):
            for gb in graphs[i + 1:]:
                name = f"{os.path.basename(ga['file'])} -> {os.path.basename(gb['file'])}"
                check(name, ga["file"], gb["file"], ga, gb)
    checked, exact, bad = tally["checked"], tally["exact"], tally["bad"]
    print(f"GED vs HiGHS: {checked} pair-modes, {exact} exact in btfsm, {bad} disagreements")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
