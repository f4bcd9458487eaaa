#!/usr/bin/env python3
"""The wheel's Python module `btfsm` against the paper (docs/guide/python.md).

Installs the btfsm wheel and py_trees (tests/packaging/requirements-python.txt)
into a fresh venv, puts SMACH's real core (tests/fixtures/smach/) on
PYTHONPATH, and with that venv's `python -m btfsm export` and `btfsm`:

1. the paper reproduced from its own libraries: examples/py_trees_fig01.py,
   examples/smach_fig02.py and examples/smach_fig04.py exported and compared
   with policies/paper/ (`btfsm compare --mode named`: GED 0, exact), and
   `btfsm analyze` equal cell by cell (counts per type, V, E, cc,
   essential cc, M, M_fc, Table I estimates);
2. the mappings: a py_trees tree of every composite, Parallel policy and
   decorator loads in btfsm with the node types of a hand count; names full
   of TOML's special characters read back as themselves with Python's own
   TOML parser (tomllib, an independent reader); a nested SMACH machine with
   a Concurrence loads as an HFSM with the vertex and arc counts of a hand
   count (SPEC §2); what cannot be expressed is refused with the node named.

Usage: tests/packaging/python_export.py WHEEL_DIR   (exit 0: all pass)
"""

import glob
import json
import os
import subprocess
import sys
import tempfile
import textwrap

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
FAILS = []


def check(ok, what, detail=""):
    print(("ok   " if ok else "FAIL ") + what + ("" if ok or not detail else f": {detail}"))
    if not ok:
        FAILS.append(what)


def run(cmd, env, **kw):
    return subprocess.run(cmd, env=env, capture_output=True, text=True, **kw)


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: python_export.py WHEEL_DIR")
    wheels = glob.glob(os.path.join(sys.argv[1], "btfsm-*.whl"))
    if len(wheels) != 1:
        sys.exit(f"python_export.py: expected one btfsm wheel in {sys.argv[1]}, found {len(wheels)}")
    with tempfile.TemporaryDirectory() as tmp:
        venv = os.path.join(tmp, "venv")
        subprocess.run([sys.executable, "-m", "venv", venv], check=True)
        pip = [os.path.join(venv, "bin", "pip"), "install", "--quiet", "--disable-pip-version-check"]
        subprocess.run(pip + ["--no-index", "--no-deps", wheels[0]], check=True)
        subprocess.run(pip + ["-r", os.path.join(REPO, "tests", "packaging", "requirements-python.txt")], check=True)
        env = {
            "HOME": tmp,
            "PATH": os.path.join(venv, "bin") + ":/usr/local/bin:/usr/bin:/bin",
            "LANG": "C.UTF-8",
            "PYTHONPATH": os.path.join(REPO, "tests", "fixtures", "smach") + ":" + REPO,
            "PYTHONWARNINGS": "ignore::SyntaxWarning",
        }
        py = os.path.join(venv, "bin", "python")
        btfsm = os.path.join(venv, "bin", "btfsm")
        where = run([py, "-c", "import btfsm, os; print(os.path.dirname(btfsm.__file__))"], env, cwd=tmp)
        check(where.stdout.strip().startswith(venv), "`import btfsm` is the wheel's module", where.stdout + where.stderr)
        paper(py, btfsm, env, tmp)
        mappings(py, btfsm, env, tmp)
        renders(py, btfsm, env, tmp)
    print(f"python_export: {len(FAILS)} failure(s)")
    return 1 if FAILS else 0


def analyze(btfsm, env, path):
    out = run([btfsm, "analyze", path, "--format", "json"], env)
    if out.returncode != 0:
        return None, out.stderr
    row = json.loads(out.stdout)["policies"][0]
    for k in ("file", "name", "millis"):
        row.pop(k, None)
    return row, ""


def paper(py, btfsm, env, tmp):
    cases = [
        ("py_trees", "examples.py_trees_fig01:make", ["--ids", "examples.py_trees_fig01:IDS"], "fig01-bt.toml", 0),
        ("smach", "examples.smach_fig02:make", [], "fig02-fsm.toml", 0),
        # SMACH has outcomes, not guard predicates: the SELECTOR's five guards
        # keep their targets and labels but not their conditions (relabels).
        ("smach", "examples.smach_fig04:make", [], "fig04-fsm.toml", 5),
    ]
    for lib, factory, extra, bundled, relabels in cases:
        out = os.path.join(tmp, bundled)
        r = run([py, "-m", "btfsm", "export", lib, factory, "-o", out] + extra, env, cwd=REPO)
        check(r.returncode == 0, f"export {factory}", r.stderr[-2000:])
        if r.returncode != 0:
            continue
        ref = os.path.join(REPO, "policies", "paper", bundled)
        c = run([btfsm, "compare", out, ref, "--mode", "named", "--format", "json"], env)
        named = json.loads(c.stdout)["named"] if c.returncode in (0, 1) and c.stdout else {}
        check(
            named.get("ged") == 0 and named.get("exact") is True,
            f"{factory} vs policies/paper/{bundled}: named GED {named.get('ged')}",
            c.stderr[-1000:],
        )
        check(named.get("relabels") == relabels, f"{factory}: {named.get('relabels')} relabels, expected {relabels}")
        a, err = analyze(btfsm, env, out)
        b, _ = analyze(btfsm, env, ref)
        cells = flat(a or {})
        ref_cells = flat(b or {})
        diff = {k: (cells.get(k), v) for k, v in ref_cells.items() if cells.get(k) != v}
        check(a is not None and not diff and cells.keys() == ref_cells.keys(),
              f"{factory}: analyze equal to policies/paper/{bundled} in all {len(ref_cells)} cells", f"{diff} {err}")


def flat(d, prefix=""):
    out = {}
    for k, v in d.items():
        if isinstance(v, dict):
            out.update(flat(v, f"{prefix}{k}."))
        else:
            out[prefix + k] = v
    return out


PY_TREES_ALL = textwrap.dedent(
    '''
    import py_trees as pt
    from py_trees import composites as c, decorators as d, behaviours as b
    from py_trees.common import ParallelPolicy as P, Status

    class IsDocked(pt.behaviour.Behaviour):
        def update(self):
            return Status.SUCCESS

    def leaf(n):
        return b.Success(name=n)

    def make():
        x, y = leaf("x"), leaf("y")
        return c.Sequence("root", memory=False, children=[
            c.Sequence("seq*", memory=True, children=[leaf("a")]),
            c.Selector("sel", memory=False, children=[IsDocked(name="docked")]),
            c.Selector("sel*", memory=True, children=[leaf("Battery ok?")]),
            c.Parallel("all", policy=P.SuccessOnAll(), children=[leaf("p1"), leaf("p2")]),
            c.Parallel("one", policy=P.SuccessOnOne(), children=[leaf("p3"), leaf("p4"), leaf("p5")]),
            c.Parallel("sel-all", policy=P.SuccessOnSelected([x, y]), children=[x, y]),
            d.Inverter("inv", leaf("i")),
            d.FailureIsSuccess("fis", leaf("f")),
            d.SuccessIsFailure("sif", leaf("s")),
            d.Repeat("rep", leaf("r"), num_success=3),
            d.Repeat("rep-forever", leaf("rf"), num_success=-1),
            d.Retry("ret", leaf("t"), num_failures=2),
            d.Timeout("tmo", leaf("o"), duration=1.5),
            d.FailureIsRunning("fir", leaf("g")),
            d.EternalGuard("guard", leaf("e"), condition=lambda: True),
            d.Condition("cond", leaf("k"), status=Status.SUCCESS),
            b.CheckBlackboardVariableExists(name="has key", variable_name="k"),
            b.WaitForBlackboardVariable(name="wait key", variable_name="k"),
            leaf("a"),
        ])

    def partial():
        x = leaf("x")
        return c.Parallel("some", policy=P.SuccessOnSelected([x]), children=[x, leaf("y")])

    def hostile():
        names = ['q"uote', "back\\\\slash", "new\\nline\\ttab", "bell\\x07del\\x7f", "ünï ☃ 𝄞", "", "[nodes]", "a.b = 1"]
        return c.Sequence("root \\"x\\"", memory=False, children=[leaf(n) for n in names])

    def childless():
        return c.Sequence("root", memory=False, children=[c.Selector("empty", memory=False, children=[])])
    '''
)

SMACH_NESTED = textwrap.dedent(
    '''
    import smach

    class S(smach.State):
        def __init__(self, outcomes):
            super().__init__(outcomes=outcomes)
        def execute(self, ud):
            return self.get_registered_outcomes()[0]

    def make():
        top = smach.StateMachine(outcomes=["done", "failed"])
        with top:
            inner = smach.StateMachine(outcomes=["ok", "bad"])
            with inner:
                smach.StateMachine.add("grasp", S(["ok", "retry", "bad"]), transitions={"ok": "lift", "retry": "grasp"})
                smach.StateMachine.add("lift", S(["ok", "bad"]), transitions={"ok": "ok", "bad": None})
            smach.StateMachine.add("fetch", inner, transitions={"ok": "both", "bad": "failed"})
            both = smach.Concurrence(outcomes=["joined", "aborted"], default_outcome="aborted",
                                     outcome_map={"joined": {"arm": "ok", "base": "ok"}})
            with both:
                smach.Concurrence.add("arm", S(["ok", "bad"]))
                base = smach.StateMachine(outcomes=["ok"])
                with base:
                    smach.StateMachine.add("drive", S(["ok"]), transitions={"ok": "ok"})
                smach.Concurrence.add("base", base)
            smach.StateMachine.add("both", both, transitions={"joined": "done", "aborted": "failed"})
        return top

    def iterator():
        top = smach.StateMachine(outcomes=["done"])
        with top:
            it = smach.Iterator(outcomes=["done"], input_keys=[], output_keys=[], it=[1, 2], it_label="i", exhausted_outcome="done")
            with it:
                smach.Iterator.set_contained_state("body", S(["continue"]), loop_outcomes=["continue"])
            smach.StateMachine.add("loop", it, transitions={"done": "done"})
        return top
    '''
)


def mappings(py, btfsm, env, tmp):
    mods = os.path.join(tmp, "mods")
    os.makedirs(mods)
    for name, text in (("pt_all", PY_TREES_ALL), ("smach_nested", SMACH_NESTED)):
        with open(os.path.join(mods, name + ".py"), "w") as f:
            f.write(text)
    env = dict(env, PYTHONPATH=env["PYTHONPATH"] + ":" + mods)

    def export(lib, factory, *extra):
        out = os.path.join(tmp, factory.replace(":", "_") + ".toml")
        r = run([py, "-m", "btfsm", "export", lib, factory, "-o", out, *extra], env, cwd=tmp)
        return r, out

    r, out = export("py_trees", "pt_all:make")
    check(r.returncode == 0, "py_trees: every composite, Parallel policy and decorator exports", r.stderr[-1500:])
    if r.returncode == 0:
        a, err = analyze(btfsm, env, out)
        # Hand count of pt_all.make (analyze counts every decorator type as
        # `decorator`; the fragments below check each one's mapping): leaves
        # a, p1-p5, x, y, the ten decorated leaves, `wait key` and the second
        # `a` are actions (20); `docked` (class IsDocked), `Battery ok?` and
        # `has key` conditions (3).
        want = {
            "sequence": 1, "sequence_memory": 1, "fallback": 1, "fallback_memory": 1, "parallel": 3,
            "decorator": 10, "condition": 3, "action": 20,
        }
        got = (a or {}).get("counts")
        check(got == want, "py_trees: node types as the hand count", f"{got} {err}")
        check(a is not None and a["vertices"] == 40 and a["edges"] == 39, "py_trees: 40 vertices, 39 edges",
              f"{a and (a['vertices'], a['edges'])}")
        text = open(out, encoding="utf-8").read()
        for frag in ('parallel = ["p3", "p4", "p5"], success = 1, ports = { failure_count = "1" }', 'repeat = "r", times = 3', 'retry = "t", times = 2',
                     'timeout = "o", ms = 1500', 'type = "EternalGuard"', 'inv = { inverter = "i" }',
                     'fis = { force_success = "f" }', 'sif = { force_failure = "s" }', 'rep-forever = { repeat = "rf" }',
                     'type = "Condition", ports = { status = "SUCCESS" }', 'parallel = ["x", "y"], success = 2', '"a (2)" = { action = "a" }',
                     '"has key" = { condition', '"wait key" = { action'):
            check(frag in text, f"py_trees export holds `{frag}`")
    r, out = export("py_trees", "pt_all:make", "--leaf-kind", "docked=action", "--leaf-kind", "p1=condition",
                    "--leaf-kind", "p2=condition")
    a, err = analyze(btfsm, env, out) if r.returncode == 0 else (None, r.stderr)
    got = a and (a["counts"]["action"], a["counts"]["condition"])
    check(got == (19, 4), "py_trees --leaf-kind overrides the rule both ways (19 actions, 4 conditions)", f"{got} {err}")
    r, _ = export("py_trees", "no_such_module:make")
    check(r.returncode == 2 and "cannot import" in r.stderr, "export of a module that does not import: exit 2", r.stderr)
    r, _ = export("py_trees", "pt_all:make", "--strict")
    check(r.returncode == 2 and "`fir`" in r.stderr and "FailureIsRunning" in r.stderr,
          "py_trees --strict refuses FailureIsRunning naming the node", r.stderr)
    r, _ = export("py_trees", "pt_all:partial")
    check(r.returncode == 0, "py_trees: a partial SuccessOnSelected is kept as a generic control", r.stderr)
    r, _ = export("py_trees", "pt_all:partial", "--strict")
    check(r.returncode == 2 and "`some`" in r.stderr and "SuccessOnSelected" in r.stderr,
          "py_trees --strict refuses a partial SuccessOnSelected naming the node", r.stderr)
    r, _ = export("py_trees", "pt_all:childless")
    check(r.returncode == 2 and "`empty`" in r.stderr and "no children" in r.stderr,
          "py_trees: a composite without children is refused naming it", r.stderr)
    r, out = export("py_trees", "pt_all:hostile")
    check(r.returncode == 0, "py_trees: hostile names export", r.stderr)
    if r.returncode == 0:
        check_hostile(py, btfsm, env, out)

    r, out = export("smach", "smach_nested:make")
    check(r.returncode == 0, "smach: nested machine and Concurrence export", r.stderr[-1500:])
    if r.returncode == 0:
        a, err = analyze(btfsm, env, out)
        # Hand count (SPEC §2, HFSM): states fetch, grasp, lift, both, arm,
        # base, drive + top outcomes done, failed = 9 vertices. Arcs: grasp
        # ok, retry, bad (unmapped: SMACH falls through to the outcome
        # `bad`); lift ok, bad (mapped to None: falls through likewise);
        # fetch ok, bad; both joined, aborted; drive ok; and the initial arcs
        # fetch->grasp, both->arm, both->base, base->drive = 14.
        check(a is not None and a["kind"] == "hfsm" and a["vertices"] == 9 and a["edges"] == 14,
              "smach: HFSM of 9 vertices and 14 arcs as the hand count", f"{a and (a['kind'], a['vertices'], a['edges'])} {err}")
    r, _ = export("smach", "smach_nested:iterator")
    check(r.returncode == 2 and "`loop`" in r.stderr and "Iterator" in r.stderr,
          "smach: an Iterator is refused naming the state", r.stderr)


def renders(py, btfsm, env, tmp):
    """py_trees DOT renders read as BTs (docs/guide/py-trees-dot.md): the
    real py_trees draws each tree (`py_trees.display.dot_tree`), btfsm reads
    the render, and it is the tree `python -m btfsm export py_trees` writes
    of the same tree: named GED 0 where every name is unique and every
    leaf's kind is in its name (Fig. 1), structural GED 0 for the tree of
    every composite, Parallel policy and decorator (py_trees renders a
    repeated name `a` as `a*`, the export as `a (2)`; a decorator's class
    and a leaf's class are not in a render)."""
    env = dict(env, PYTHONPATH=env["PYTHONPATH"] + ":" + os.path.join(tmp, "mods"))
    draw = "import importlib, sys, py_trees; m, f = sys.argv[1].split(':'); " \
        "open(sys.argv[2], 'w').write(py_trees.display.dot_tree(getattr(importlib.import_module(m), f)()).to_string())"
    for factory, mode in (("examples.py_trees_fig01:make", "named"), ("pt_all:make", "structural")):
        base = os.path.join(tmp, "render_" + factory.replace(":", "_").replace(".", "_"))
        r = run([py, "-c", draw, factory, base + ".dot"], env, cwd=REPO)
        check(r.returncode == 0, f"py_trees renders {factory}", r.stderr[-1500:])
        e = run([py, "-m", "btfsm", "export", "py_trees", factory, "-o", base + ".toml"], env, cwd=REPO)
        check(e.returncode == 0, f"export {factory} (to compare with its render)", e.stderr[-1500:])
        if r.returncode != 0 or e.returncode != 0:
            continue
        c = run([btfsm, "compare", base + ".dot", base + ".toml", "--mode", mode, "--format", "json"], env)
        got = json.loads(c.stdout).get(mode, {}) if c.returncode in (0, 1) and c.stdout else {}
        check(got.get("ged") == 0 and got.get("exact") is True,
              f"{factory}: py_trees' render vs the export, {mode} GED {got.get('ged')}", c.stderr[-1500:])
        # GED does not count a node's type: compare the types too, node by
        # node in pre-order, from the render's TOML and the export, both
        # read with Python's tomllib.
        t = run([btfsm, "convert", base + ".dot", "--to", "toml", "-o", base + ".dot.toml"], env)
        check(t.returncode == 0, f"{factory}: the render converts to TOML", t.stderr[-1500:])
        if t.returncode == 0:
            got, want = node_types(base + ".dot.toml"), node_types(base + ".toml")
            # Not in a render: a decorator's class (every one is `decorator`),
            # and the class that makes `docked` (IsDocked) and `has key`
            # (CheckBlackboardVariableExists) conditions.
            want = [("decorator", None) if k in DECORATOR_KINDS else
                    ("action", None) if (k, n) in (("condition", "docked"), ("condition", "has key")) else (k, sc)
                    for (k, sc, n) in want]
            got = [(k, sc) for (k, sc, _) in got]
            check(got == want, f"{factory}: render and export have the same node types and Parallel successes in pre-order",
                  f"{got} != {want}")


DECORATOR_KINDS = ("inverter", "force_success", "force_failure", "repeat", "retry", "timeout", "decorator")
NODE_KINDS = ("sequence", "fallback", "sequence_memory", "fallback_memory", "parallel", "action", "condition") + DECORATOR_KINDS


def node_types(path):
    """(type, Parallel success, name) of each node of a TOML BT, in pre-order."""
    import tomllib
    with open(path, "rb") as f:
        doc = tomllib.load(f)
    nodes, out, stack = doc["nodes"], [], [doc["root"]]
    while stack:
        nid = stack.pop()
        n = nodes[nid]
        kind = next(k for k in NODE_KINDS if k in n)
        kids = n[kind] if isinstance(n[kind], list) else [n[kind]] if kind in DECORATOR_KINDS else []
        out.append((kind, n.get("success"), n.get(kind) if kind in ("action", "condition") else nid))
        stack.extend(reversed(kids))
    return out


def check_hostile(py, btfsm, env, out):
    # tomllib is Python's own TOML parser: an independent reader.
    code = (
        "import sys, tomllib, json; d = tomllib.load(open(sys.argv[1], 'rb')); "
        "print(json.dumps([d['root']] + [n.get('action') for n in d['nodes'].values() if 'action' in n]))"
    )
    r = run([py, "-c", code, out], env)
    want = ['root "x"', 'q"uote', "back\\slash", "new\nline\ttab", "bell\x07del\x7f", "ünï ☃ 𝄞", "", "[nodes]", "a.b = 1"]
    got = json.loads(r.stdout) if r.returncode == 0 else r.stderr
    check(got == want, "hostile names read back as themselves (tomllib)", repr(got))
    v = run([btfsm, "validate", out], env)
    check(v.returncode == 0, "hostile names: btfsm validate accepts the export", v.stdout[-800:] + v.stderr[-800:])


if __name__ == "__main__":
    sys.exit(main())
