"""Ticks the 80-node five-cube BT of Fig. 16a (Iovino et al.) with
BehaviorTree.CPP 4 (behaviortreepy, its Python bindings, pinned in
tests/differential/requirements.txt): `Tree.tick_exactly_once` on the tree
built from XML with built-in leaves answering like the frozen world of
benches/sim.rs and bench/py_trees_tick.py (cubes 1-2 delivered, cube3 in
hand, robot away from the delivery station): a condition is AlwaysSuccess or
AlwaysFailure, an action a Sleep that never ends (RUNNING). Prints ticks per
second (best of 5 rounds, as the other two benchmarks)."""
import sys
import time

import behaviortreepy as bt

TRUE = {"Battery > 20%?", "Cubes found?", "Cube1 in delivery?", "Cube2 in delivery?",
        "Cube3 in Hand?"}


def cond(name):
    return '<%s name="%s"/>' % ("AlwaysSuccess" if name in TRUE else "AlwaysFailure", name)


def act(name):
    return '<Sleep name="%s" msec="1000000000"/>' % name


def fb(*c):
    return "<ReactiveFallback>%s</ReactiveFallback>" % "".join(c)


def seq(*c):
    return "<ReactiveSequence>%s</ReactiveSequence>" % "".join(c)


def moma(i):
    return fb(cond(f"Cube{i} in delivery?"),
              seq(fb(cond(f"Cube{i} in Hand?"),
                     seq(fb(cond(f"Robot-At cube{i}?"), act(f"Move-To cube{i}!")),
                         act(f"Pick cube{i}!"))),
                  fb(cond("Robot-At delivery?"), act("Move-To delivery!")),
                  act(f"Place cube{i}!")))


root = seq(fb(cond("Battery > 20%?"), act("Recharge!")),
           fb(cond("Cubes found?"), act("Search cubes!")),
           *[moma(i) for i in range(1, 6)],
           fb(cond("Robot-At inspection?"), act("Dock!")))
assert root.count("<") - root.count("</") == 80
xml = '<root BTCPP_format="4"><BehaviorTree ID="Main">%s</BehaviorTree></root>' % root
tree = bt.BehaviorTreeFactory().create_tree_from_text(xml)
n = int(sys.argv[1]) if len(sys.argv) > 1 else 200000
dt = float("inf")
for _ in range(5):
    t0 = time.perf_counter()
    for _ in range(n):
        s = tree.tick_exactly_once()
    dt = min(dt, time.perf_counter() - t0)
assert s == bt.NodeStatus.RUNNING
print(f"btcpp_ticks_per_s {n / dt:.0f}")
