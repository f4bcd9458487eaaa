#!/usr/bin/env python3
"""Dataflow oracle: the port mistakes BehaviorTree.CPP 4 itself refuses when
it creates a tree are the ones `btfsm lint` reports at error level.

Seeded random BehaviorTree.CPP 4 trees of built-in nodes (whose ports
BehaviorTree.CPP declares) and of Python leaves registered through
behaviortreepy (`register_simple_action`, which registers a node type with
no ports: behaviortreepy 0.1.4 cannot declare ports for a Python node) and
declared, with no ports, in the file's <TreeNodesModel>. Mutations plant,
at random: an attribute the node type does not declare, a port removed
(`Script`'s `code`, `Sleep`'s `msec`, a Loop's `queue`, ...), and entries
shared between ports of different types (`LoopInt`'s int `value` read as
`Sleep`'s unsigned `msec`).

For each file, BehaviorTree.CPP (behaviortreepy) creates the tree (no tick)
and btfsm lints it (`btfsm lint FILE --format json`). Checked:

1. btfsm reports an error-level finding only when BehaviorTree.CPP refuses
   to create the tree or throws at its first tick, or for
   `output-port-literal` (an output lost at run time, which BehaviorTree.CPP
   does not check); btfsm's load errors on trees BehaviorTree.CPP creates
   (rules it checks at a node's first tick, such as `RetryUntilSuccessful`
   without `num_attempts` in a branch the first tick skips) are
   accept_btcpp.py's matter;
2. every file BehaviorTree.CPP refuses to create for an undeclared or a
   missing port ("a port with name [x] is found in the XML ... but not in
   the providedPorts()", "Missing port [code]") btfsm fails (an error-level
   finding, or a load error, exit 2);
3. every file BehaviorTree.CPP refuses for a port type clash ("initially
   created with type [int] and, later type [unsigned int]") btfsm fails or
   reports `port-type-mismatch`, and btfsm reports `port-type-mismatch`
   only on files BehaviorTree.CPP refuses.

Exit 0 when all hold, 1 otherwise (the first counterexamples printed), 2
when the oracle cannot run.

Usage: dataflow_btcpp.py --btfsm PATH [--trees N] [--seed S]
"""
import argparse
import json
import random
import subprocess
import sys
import tempfile
from pathlib import Path

LEAVES = [
    ("AlwaysSuccess", {}),
    ("Sleep", {"msec": "1"}),
    ("Script", {"code": "k := 1"}),
    ("SetBlackboard", {"value": "1", "output_key": "k"}),
    ("ActA", {}),
    ("ActB", {}),
    ("CondC", {}),
]
DECORATORS = [
    ("Inverter", {}),
    ("Repeat", {"num_cycles": "1"}),
    ("Timeout", {"msec": "100"}),
    ("Delay", {"delay_msec": "1"}),
    ("RetryUntilSuccessful", {"num_attempts": "1"}),
    ("RunOnce", {}),
    ("Precondition", {"if": "true"}),
    ("LoopInt", {"queue": "1;2", "value": "{v}"}),
    ("LoopDouble", {"queue": "1.5", "value": "{w}"}),
]
CONTROLS = ["Sequence", "Fallback", "ReactiveSequence", "ReactiveFallback"]
# Near misses of real ports, and real ports of other types.
EXTRA = ["foo", "msecs", "num_cycle", "speed", "value", "code", "queue", "if", "delay"]
# Ports that read an entry, with the entry's key.
TYPED_READS = [("Sleep", "msec"), ("Repeat", "num_cycles"), ("Timeout", "msec")]
MODEL = ('<TreeNodesModel><Action ID="ActA"/><Action ID="ActB"/>'
         '<Condition ID="CondC"/></TreeNodesModel>')


def node(rng, depth):
    """A random subtree: (tag, attrs, children)."""
    r = rng.random()
    if depth >= 3 or r < 0.4:
        tag, attrs = rng.choice(LEAVES)
        return [tag, dict(attrs), []]
    if r < 0.7:
        tag, attrs = rng.choice(DECORATORS)
        return [tag, dict(attrs), [node(rng, depth + 1)]]
    return [rng.choice(CONTROLS), {}, [node(rng, depth + 1) for _ in range(rng.randint(1, 3))]]


def walk(t):
    yield t
    for c in t[2]:
        yield from walk(c)


def mutate(rng, t):
    nodes = list(walk(t))
    if rng.random() < 0.3:
        n = rng.choice(nodes)
        n[1][rng.choice(EXTRA)] = "1"
    if rng.random() < 0.2:
        with_ports = [n for n in nodes if n[1]]
        if with_ports:
            n = rng.choice(with_ports)
            del n[1][rng.choice(sorted(n[1]))]
    if rng.random() < 0.3:
        tag, port = rng.choice(TYPED_READS)
        for n in nodes:
            if n[0] == tag and port in n[1]:
                n[1][port] = rng.choice(["{v}", "{w}"])
                break


def xml(t):
    tag, attrs, kids = t
    a = "".join(f' {k}="{v}"' for k, v in attrs.items())
    if not kids:
        return f"<{tag}{a}/>"
    return f"<{tag}{a}>" + "".join(xml(k) for k in kids) + f"</{tag}>"


def document(t):
    return (f'<root BTCPP_format="4" main_tree_to_execute="Main">'
            f'<BehaviorTree ID="Main">{xml(t)}</BehaviorTree>{MODEL}</root>')


def engine(bt, text):
    """None when BehaviorTree.CPP creates the tree and ticks it once, else
    why it refuses (`tick: ...` when the first tick throws)."""
    f = bt.BehaviorTreeFactory()
    ok = lambda _node: bt.NodeStatus.SUCCESS  # noqa: E731
    f.register_simple_action("ActA", ok)
    f.register_simple_action("ActB", ok)
    f.register_simple_condition("CondC", ok)
    try:
        f.register_behavior_tree_from_text(text)
        tree = f.create_tree("Main")
    except Exception as e:  # noqa: BLE001 (any refusal)
        m = str(e)
        if "is found in the XML" in m:
            return "undeclared"
        if "Missing port" in m or "Missing parameter" in m or "not found" in m:
            return "missing"
        if "initially created with type" in m:
            return "type"
        return "other: " + m[:120]
    try:
        tree.tick_once()
        tree.halt_tree()
    except Exception as e:  # noqa: BLE001
        return "tick: " + str(e)[:120]
    return None


def btfsm(exe, path):
    p = subprocess.run([exe, "lint", str(path), "--format", "json"],
                       capture_output=True, text=True, timeout=60)
    if p.returncode == 2:
        return True, set(), set()
    found = json.loads(p.stdout)
    return False, {f["code"] for f in found if f["level"] == "error"}, {f["code"] for f in found}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--btfsm", required=True)
    ap.add_argument("--trees", type=int, default=400)
    ap.add_argument("--seed", type=int, default=17)
    a = ap.parse_args()
    try:
        import behaviortreepy as bt  # noqa: PLC0415
    except ImportError:
        print("dataflow_btcpp: needs behaviortreepy", file=sys.stderr)
        return 2
    rng = random.Random(a.seed)
    tmp = Path(tempfile.mkdtemp(prefix="dataflow-"))
    bad, counts = [], {}
    for i in range(a.trees):
        t = node(rng, 0)
        if rng.random() < 0.3:
            # A Loop around the tree writes the entry typed reads may share.
            loop, key = rng.choice([("LoopInt", "{v}"), ("LoopDouble", "{w}")])
            t = [loop, {"queue": "1", "value": key}, [t]]
        mutate(rng, t)
        text = document(t)
        path = tmp / f"t{i}.xml"
        path.write_text(text, "utf-8")
        why = engine(bt, text)
        load_error, errors, codes = btfsm(a.btfsm, path)
        fails = load_error or bool(errors)
        key = (why or "accepted").split(":")[0]
        counts[key] = counts.get(key, 0) + 1
        problems = []
        # An output given a literal is lost at run time, which
        # BehaviorTree.CPP does not check (docs/lint.md): an error of btfsm's
        # on a tree the engine runs.
        if errors - {"output-port-literal"} and why is None:
            problems.append("an error-level finding on a tree BehaviorTree.CPP creates and ticks")
        if why in ("undeclared", "missing") and not fails:
            problems.append(f"BehaviorTree.CPP refuses ({why}), btfsm passes")
        if why == "type" and not (fails or "port-type-mismatch" in codes):
            problems.append("BehaviorTree.CPP refuses a type clash, btfsm says nothing")
        if "port-type-mismatch" in codes and why is None:
            problems.append("port-type-mismatch on a tree BehaviorTree.CPP creates")
        if why is not None and why.startswith("other"):
            problems.append(f"unexpected refusal: {why}")
        if problems:
            bad.append((text, why, sorted(codes), problems))
    print(f"dataflow_btcpp: {a.trees} trees, BehaviorTree.CPP verdicts {dict(sorted(counts.items()))}")
    for text, why, codes, problems in bad[:5]:
        print(f"MISMATCH {problems}\n  engine: {why}\n  btfsm: {codes}\n  {text}")
    if bad:
        print(f"dataflow_btcpp: {len(bad)} mismatches")
        return 1
    print("dataflow_btcpp: BehaviorTree.CPP and btfsm agree on every tree")
    return 0


if __name__ == "__main__":
    sys.exit(main())
