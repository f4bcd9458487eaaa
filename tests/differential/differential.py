#!/usr/bin/env python3
"""Differential test of `btfsm tick` against BehaviorTree.CPP 4 (docs/bt-semantics.md).

Generates seeded random Behavior Trees over every node type `btfsm tick`
runs, with random leaf scripts; ticks each tree with BehaviorTree.CPP
(`behaviortreepy`, its Python bindings: `Tree.tick_exactly_once`,
`halt_tree`, stateful actions recording onStart/onRunning/onHalted,
conditions) and with `btfsm tick --format json`, and requires the same
leaf ticks (with their statuses), the same halts, in the same order, and
the same root status, tick by tick, and the same halts from `halt_tree`.
On a disagreement prints the smallest disagreeing tree (XML and script)
and both traces, and exits 1.

Usage: differential.py BTFSM [--trees N] [--seed S] [--ticks T]
"""

import argparse
import json
import os
import random
import subprocess
import sys
import tempfile

import behaviortreepy as bt

STATUS = {
    "success": bt.NodeStatus.SUCCESS,
    "failure": bt.NodeStatus.FAILURE,
    "running": bt.NodeStatus.RUNNING,
}

CONTROLS = [
    "Sequence", "ReactiveSequence", "SequenceWithMemory", "Fallback",
    "ReactiveFallback", "Parallel", "ParallelAll", "IfThenElse",
    "WhileDoElse", "AsyncSequence", "AsyncFallback",
]
DECORATORS = [
    "Inverter", "ForceSuccess", "ForceFailure", "RetryUntilSuccessful",
    "Repeat", "KeepRunningUntilFailure",
]


class Gen:
    """A random tree: XML text, its leaves (name, is_action), node count."""

    def __init__(self, rng, max_depth, max_kids):
        self.rng = rng
        self.max_depth = max_depth
        self.max_kids = max_kids
        self.leaves = []
        self.count = 0

    def leaf(self, pad):
        i = len(self.leaves)
        action = self.rng.random() < 0.6
        name = ("a%d" if action else "c%d") % i
        self.leaves.append((name, action))
        self.count += 1
        return '%s<%s name="%s"/>\n' % (pad, "A" if action else "C", name)

    def node(self, depth, parent=None):
        pad = "  " * (depth + 2)
        r = self.rng
        if depth >= self.max_depth or (depth > 0 and r.random() < 0.35):
            return self.leaf(pad)
        self.count += 1
        if r.random() < 0.65:
            ty = r.choice(CONTROLS)
            # BehaviorTree.CPP refuses a ReactiveSequence with two
            # AsyncSequence children (so does btfsm): one at most.
            if ty == "AsyncSequence" and parent is not None:
                if parent.get("async"):
                    ty = "Sequence"
                parent["async"] = True
            if ty in ("IfThenElse", "WhileDoElse"):
                k = r.choice([2, 3])
            else:
                k = r.randint(1, self.max_kids)
            attrs = ""
            if ty == "Parallel":
                # Either threshold may be left to its default (-1, 1).
                s = r.choice([r.randint(1, k), -1, None])
                f = r.choice([r.randint(1, k), -1, None])
                if s is not None:
                    attrs += ' success_count="%d"' % s
                if f is not None:
                    attrs += ' failure_count="%d"' % f
            elif ty == "ParallelAll" and r.random() < 0.8:
                attrs = ' max_failures="%d"' % r.randint(1, k)
            me = {} if ty == "ReactiveSequence" else None
            kids = "".join(self.node(depth + 1, me) for _ in range(k))
            return "%s<%s%s>\n%s%s</%s>\n" % (pad, ty, attrs, kids, pad, ty)
        ty = r.choice(DECORATORS)
        attrs = ""
        if ty == "RetryUntilSuccessful":
            attrs = ' num_attempts="%d"' % r.randint(0, 3)
        elif ty == "Repeat":
            attrs = ' num_cycles="%d"' % r.choice([0, 1, 2, 3, -1])
        kid = self.node(depth + 1)
        return "%s<%s%s>\n%s%s</%s>\n" % (pad, ty, attrs, kid, pad, ty)


def make_case(rng, ticks):
    g = Gen(rng, max_depth=rng.randint(1, 5), max_kids=4)
    body = g.node(0)
    xml = (
        '<root BTCPP_format="4" main_tree_to_execute="Main">\n'
        '  <BehaviorTree ID="Main">\n%s  </BehaviorTree>\n'
        '  <TreeNodesModel>\n    <Action ID="A"/>\n    <Condition ID="C"/>\n'
        '  </TreeNodesModel>\n</root>\n' % body
    )
    statuses = ["success", "failure", "running"]
    script = {
        "ticks": ticks,
        "default": rng.choice(statuses),
        "condition_default": rng.choice(statuses[:2]),
        "halt": rng.random() < 0.5,
        "leaves": {},
    }
    for name, action in g.leaves:
        if rng.random() < 0.2:
            continue
        pool = statuses if action else statuses[:2]
        lst = [rng.choice(pool) for _ in range(rng.randint(0, 5))]
        script["leaves"][name] = (lst, rng.choice(["default", "last", "cycle"]))
    return xml, script, g.count


def script_toml(s):
    lines = [
        "ticks = %d" % s["ticks"],
        'default = "%s"' % s["default"],
        'condition_default = "%s"' % s["condition_default"],
        "halt = %s" % ("true" if s["halt"] else "false"),
        "[leaves]",
    ]
    for name, (lst, then) in s["leaves"].items():
        lines.append(
            '%s = { statuses = [%s], then = "%s" }'
            % (name, ", ".join('"%s"' % x for x in lst), then)
        )
    return "\n".join(lines) + "\n"


class Engine:
    """BehaviorTree.CPP with scripted leaves `A` (stateful action) and `C`
    (condition); the k-th call of a leaf (onStart, onRunning or the
    condition's tick) gets its k-th scripted status."""

    def __init__(self):
        self.factory = bt.BehaviorTreeFactory()
        self.script = None
        self.count = {}
        self.log = []
        self.actions = set()
        self.factory.register_simple_stateful_action(
            "A", self.on_tick, self.on_tick, self.on_halted)
        self.factory.register_simple_condition("C", self.on_tick)

    def answer(self, name):
        k = self.count.get(name, 0)
        self.count[name] = k + 1
        action = name in self.actions
        s = self.script
        default = s["default"] if action else s["condition_default"]
        if name not in s["leaves"]:
            return default
        lst, then = s["leaves"][name]
        if k < len(lst):
            return lst[k]
        if lst and then == "last":
            return lst[-1]
        if lst and then == "cycle":
            return lst[k % len(lst)]
        return default

    def on_tick(self, node):
        name = node.name()
        st = self.answer(name)
        self.log.append({"leaf": name, "status": st.upper()})
        return STATUS[st]

    def on_halted(self, node):
        self.log.append({"halt": node.name()})

    def run(self, xml, script, leaves):
        self.script = script
        self.count = {}
        self.actions = {n for n, a in leaves if a}
        tree = self.factory.create_tree_from_text(xml)
        ticks = []
        for i in range(script["ticks"]):
            self.log = []
            root = tree.tick_exactly_once()
            ticks.append({"tick": i + 1, "root": root.name, "events": self.log})
        halt = None
        if script["halt"]:
            self.log = []
            tree.halt_tree()
            halt = [e["halt"] for e in self.log if "halt" in e]
        # The tree halts itself when destroyed: not part of the run.
        self.log = []
        del tree
        return {"ticks": ticks, "halt": halt}


def leaves_of(xml):
    import re
    return [(m.group(2), m.group(1) == "A")
            for m in re.finditer(r'<(A|C) name="([ac]\d+)"/>', xml)]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("btfsm")
    ap.add_argument("--trees", type=int, default=3000)
    ap.add_argument("--seed", type=int, default=13)
    ap.add_argument("--ticks", type=int, default=10)
    ap.add_argument("--batch", type=int, default=500)
    a = ap.parse_args()
    rng = random.Random(a.seed)
    cases = [make_case(rng, a.ticks) for _ in range(a.trees)]
    engine = Engine()
    failures = []
    calls = 0
    with tempfile.TemporaryDirectory(prefix="btfsm-diff-") as d:
        for b0 in range(0, len(cases), a.batch):
            batch = cases[b0:b0 + a.batch]
            args = [a.btfsm, "tick", "--format", "json", "--allow-outside-root"]
            for i, (xml, script, _) in enumerate(batch):
                t = os.path.join(d, "t%d.xml" % (b0 + i))
                s = os.path.join(d, "s%d.toml" % (b0 + i))
                with open(t, "w") as f:
                    f.write(xml)
                with open(s, "w") as f:
                    f.write(script_toml(script))
                args += [t, "--script", s]
            p = subprocess.run(args, capture_output=True, text=True)
            if p.returncode != 0:
                print("btfsm tick failed (exit %d):\n%s" % (p.returncode, p.stderr))
                return 1
            outs = [json.loads(line) for line in p.stdout.splitlines() if line.strip()]
            if len(outs) != len(batch):
                print("btfsm tick gave %d results for %d trees" % (len(outs), len(batch)))
                return 1
            for (xml, script, size), got in zip(batch, outs):
                want = engine.run(xml, script, leaves_of(xml))
                calls += sum(len(t["events"]) for t in want["ticks"])
                mine = {"ticks": got["ticks"], "halt": got["halt"]}
                if mine != want:
                    failures.append((size, xml, script, want, mine))
    if failures:
        failures.sort(key=lambda f: f[0])
        size, xml, script, want, mine = failures[0]
        print("%d of %d trees disagree; the smallest (%d nodes):\n" % (len(failures), len(cases), size))
        print(xml)
        print(script_toml(script))
        for i, (w, m) in enumerate(zip(want["ticks"], mine["ticks"])):
            mark = "  " if w == m else "!!"
            print("%s tick %d BehaviorTree.CPP: %s %s" % (mark, i + 1, w["root"], w["events"]))
            print("%s tick %d btfsm:            %s %s" % (mark, i + 1, m["root"], m["events"]))
        if want["halt"] != mine["halt"]:
            print("!! halt_tree: BehaviorTree.CPP %s, btfsm %s" % (want["halt"], mine["halt"]))
        return 1
    print("differential: %d trees, %d ticks each, %d leaf events: btfsm tick agrees with BehaviorTree.CPP %s"
          % (len(cases), a.ticks, calls, getattr(bt, "__version__", "?")))
    return 0


if __name__ == "__main__":
    sys.exit(main())
