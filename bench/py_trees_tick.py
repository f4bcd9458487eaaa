"""Ticks the 80-node five-cube BT of Fig. 16a (Iovino et al.) with py_trees,
leaves answering like the frozen world of benches/sim.rs (cubes 1-2 delivered,
cube3 in hand, robot away from the delivery station; actions RUNNING), and
prints ticks per second."""
import sys
import time

import py_trees
from py_trees.common import Status

TRUE = {"Battery > 20%?", "Cubes found?", "Cube1 in delivery?", "Cube2 in delivery?",
        "Cube3 in Hand?"}


class Cond(py_trees.behaviour.Behaviour):
    def update(self):
        return Status.SUCCESS if self.name in TRUE else Status.FAILURE


class Act(py_trees.behaviour.Behaviour):
    def update(self):
        return Status.RUNNING


def fb(*c):
    return py_trees.composites.Selector("Fallback", memory=False, children=list(c))


def seq(*c):
    return py_trees.composites.Sequence("Sequence", memory=False, children=list(c))


def moma(i):
    return fb(Cond(f"Cube{i} in delivery?"),
              seq(fb(Cond(f"Cube{i} in Hand?"),
                     seq(fb(Cond(f"Robot-At cube{i}?"), Act(f"Move-To cube{i}!")),
                         Act(f"Pick cube{i}!"))),
                  fb(Cond("Robot-At delivery?"), Act("Move-To delivery!")),
                  Act(f"Place cube{i}!")))


root = seq(fb(Cond("Battery > 20%?"), Act("Recharge!")),
           fb(Cond("Cubes found?"), Act("Search cubes!")),
           *[moma(i) for i in range(1, 6)],
           fb(Cond("Robot-At inspection?"), Act("Dock!")))
tree = py_trees.trees.BehaviourTree(root)
count = sum(1 for _ in root.iterate())
assert count == 80, count
n = int(sys.argv[1]) if len(sys.argv) > 1 else 20000
dt = float("inf")
for _ in range(5):  # best of 5 rounds, as benches/sim.rs does
    t0 = time.perf_counter()
    for _ in range(n):
        tree.tick()
    dt = min(dt, time.perf_counter() - t0)
assert root.status == Status.RUNNING
print(f"py_trees_ticks_per_s {n / dt:.0f}")
