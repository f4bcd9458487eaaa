#!/usr/bin/env python3
"""FlexBE oracle: each FlexBE behavior of tests/fixtures/flexbe that btfsm
loads is also *run* by Python 3 (its `create()` is called), with stand-ins
for flexbe_core and for every other import, and the state machine Python
builds is compared with btfsm's TOML export of the same file
(`btfsm convert FILE --to toml`, read with Python's own `tomllib`).

The stand-ins do what flexbe_core's constructors do and nothing more
(flexbe_core/core/state_machine.py, operatable_state_machine.py,
concurrency_container.py at FlexBE/flexbe_behavior_engine b1422c2):
`with sm:` opens a container, `OperatableStateMachine.add(label, state,
transitions, autonomy, remapping)` adds a state to the opened one, the
first state added is the initial one, `ConcurrencyContainer` takes
`conditions`. Every other import is a module whose every attribute is a
class accepting any arguments, so that the states' own classes need not
exist. Python, not btfsm's parser, evaluates the file: it decides which
states are added where, with which transitions and autonomy levels.

Compared, per container (the machine and each nested one): its outcomes,
whether it runs its states at once (`parallel`), its initial state, its
states in the order added, each state's transitions (`on`), and the
autonomy levels kept in each state's label (`Name [done:Off]`).

Usage: tests/differential/flexbe_exec.py --btfsm PATH   (exit 0: all agree)
"""

import argparse
import glob
import importlib.abc
import importlib.machinery
import os
import subprocess
import sys
import tempfile
import tomllib
import types

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))

# Fixtures that Python itself cannot build, and why: any other file that
# fails to build is a failure of this oracle.
CANNOT_BUILD = {
    # FlexBE's own test data: its manual import section raises on purpose
    # (the engine's test replaces the code before running it).
    "complex_behavior_test_sm.py": "ValueError",
    # Reads `stand_up_front_100`, a name the file never defines (FlexBE's
    # own run of it would fail the same way).
    "stand_up_behavior_sm.py": "NameError",
}


class AnyMeta(type):
    """Class attributes a behavior reads from a stand-in class (an enum
    value, `initialize_ros`) are stand-ins too."""

    def __getattr__(cls, name):
        if name.startswith("__"):
            raise AttributeError(name)
        return Anything


class Anything(metaclass=AnyMeta):
    """A stand-in for any class or value a behavior uses."""

    def __init__(self, *args, **kwargs):
        pass

    def __call__(self, *args, **kwargs):
        return Anything()

    def __getattr__(self, name):
        return Anything()

    def __setattr__(self, name, value):
        object.__setattr__(self, name, value)


class Container(metaclass=AnyMeta):
    """flexbe_core's StateMachine as far as construction goes."""

    opened = None

    def __init__(self, outcomes=None, input_keys=None, output_keys=None, conditions=None, **kwargs):
        self.outcomes = list(outcomes or [])
        self.states = []  # (label, state, transitions, autonomy)
        self.parallel = False
        self.userdata = Anything()

    def __enter__(self):
        self._outer = Container.opened
        Container.opened = self
        return self

    def __exit__(self, *exc):
        Container.opened = self._outer
        return False

    @staticmethod
    def add(label, state, transitions, autonomy=None, remapping=None):
        Container.opened.states.append((label, state, dict(transitions), dict(autonomy or {})))


class Concurrency(Container):
    def __init__(self, conditions=None, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.parallel = True


class Autonomy:
    Off, Low, High, Full, Inherit = "Off", "Low", "High", "Full", "Inherit"


class Behavior(metaclass=AnyMeta):
    def __init__(self, *args, **kwargs):
        self.name = type(self).__name__

    def add_parameter(self, name, value):
        setattr(self, name, value)

    def add_behavior(self, *args, **kwargs):
        pass

    def use_behavior(self, *args, **kwargs):
        return Anything()

    def __getattr__(self, name):
        return Anything()


def flexbe_core():
    m = types.ModuleType("flexbe_core")
    m.Behavior, m.Autonomy, m.Logger = Behavior, Autonomy, Anything()
    m.OperatableStateMachine = m.PriorityContainer = Container
    m.LockableStateMachine = m.PreemptableStateMachine = Container
    m.ConcurrencyContainer = Concurrency
    m.EventState = Anything
    return m


class StandIns(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Every import that is not the standard library: a stand-in module."""

    def find_spec(self, name, path, target=None):
        top = name.split(".")[0]
        if top in sys.stdlib_module_names:
            return None
        return importlib.machinery.ModuleSpec(name, self, is_package=True)

    def create_module(self, spec):
        if spec.name == "flexbe_core":
            return flexbe_core()
        m = types.ModuleType(spec.name)
        m.__path__ = []
        m.__getattr__ = lambda attr: Anything
        return m

    def exec_module(self, module):
        pass


def run_behavior(path):
    """The container tree Python builds, or the exception it raised."""
    source = open(path, encoding="utf-8").read()
    module = types.ModuleType("behavior")
    try:
        exec(compile(source, path, "exec"), module.__dict__)
        cls = next(
            v for v in module.__dict__.values()
            if isinstance(v, type) and issubclass(v, Behavior) and v is not Behavior
        )
        b = cls.__new__(cls)
        try:
            cls.__init__(b)
        except TypeError:
            cls.__init__(b, Anything())  # ROS 2 behaviors take the node
        return b.create()
    except Exception as e:  # noqa: BLE001 - the oracle reports any failure
        return e


def compare(sm, table, where):
    """Differences between container `sm` (Python's) and TOML table `table`."""
    diffs = []
    if sm.outcomes != table.get("outcomes", []):
        diffs.append(f"{where}: outcomes {sm.outcomes} vs {table.get('outcomes')}")
    if sm.parallel != table.get("parallel", False):
        diffs.append(f"{where}: parallel {sm.parallel} vs {table.get('parallel', False)}")
    states = table.get("states", {})
    names = [s[0] for s in sm.states]
    if names != list(states):
        return diffs + [f"{where}: states {names} vs {list(states)}"]
    if where == "machine" and table.get("initial") != names[0]:
        diffs.append(f"{where}: initial {names[0]} vs {table.get('initial')}")
    for label, state, transitions, autonomy in sm.states:
        t = states[label]
        if transitions != t.get("on", {}):
            diffs.append(f"{where}/{label}: transitions {transitions} vs {t.get('on')}")
        want = label + (" [" + " ".join(f"{o}:{l}" for o, l in autonomy.items()) + "]" if autonomy else "")
        if want != t.get("label", label):
            diffs.append(f"{where}/{label}: label {want!r} vs {t.get('label')!r}")
        if isinstance(state, Container):
            diffs += compare(state, t, f"{where}/{label}")
    return diffs


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--btfsm", required=True)
    args = ap.parse_args()
    sys.meta_path.insert(0, StandIns())
    files = sorted(glob.glob(os.path.join(REPO, "tests/fixtures/flexbe/*/*_sm.py")))
    agreed, not_loaded, not_built, fails = 0, 0, [], []
    with tempfile.TemporaryDirectory() as tmp:
        for f in files:
            rel = os.path.relpath(f, REPO)
            out = os.path.join(tmp, os.path.basename(f) + ".toml")
            r = subprocess.run([args.btfsm, "convert", f, "--to", "toml", "-o", out], capture_output=True, text=True)
            if r.returncode != 0:
                not_loaded += 1
                continue
            sm = run_behavior(f)
            if isinstance(sm, BaseException):
                not_built.append(f"{rel}: {type(sm).__name__}: {sm}")
                if CANNOT_BUILD.get(os.path.basename(f)) != type(sm).__name__:
                    fails.append((rel, [f"Python could not build it: {type(sm).__name__}: {sm}"]))
                    print(f"FAIL {rel}: Python could not build it: {type(sm).__name__}: {sm}")
                continue
            with open(out, "rb") as fh:
                table = tomllib.load(fh)
            diffs = compare(sm, table, "machine")
            if diffs:
                fails.append((rel, diffs))
                print(f"FAIL {rel}")
                for d in diffs[:10]:
                    print(f"     {d}")
            else:
                agreed += 1
                print(f"ok   {rel}")
    for n in not_built:
        print(f"note: Python could not build {n}")
    print(f"{agreed} FlexBE behaviors agree with Python's run of create(); "
          f"{len(fails)} differ; {not_loaded} not loaded by btfsm; {len(not_built)} not built by Python")
    sys.exit(1 if fails or agreed == 0 else 0)


if __name__ == "__main__":
    main()
