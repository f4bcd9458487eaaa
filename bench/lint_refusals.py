#!/usr/bin/env python3
"""Does `btfsm lint` miss a tree BehaviorTree.CPP refuses? (docs/lint.md,
"Precision on real repositories").

For every BehaviorTree.CPP XML file below REPO (a checkout, e.g. one made by
bench/lint_precision.sh), BehaviorTree.CPP 4 (behaviortreepy) creates the
file's tree alone, as a program that loads that one file does, and ticks it
once (the machinery of tests/differential/accept_btcpp.py: dummies for the
node types the program registers, with the attributes their model declares
as ports dropped, so that an attribute the model does not declare is refused
as the real node would refuse it). Which types the program registers: with
--model, the model's types only (a model given lists them all); without,
every leaf type BehaviorTree.CPP does not build in (accept_btcpp.py's
rule). `btfsm lint FILE [--nodes-model MODEL]` then lints the file alone.

Printed: the files BehaviorTree.CPP refuses and lint passes (no error-level
finding) — there should be none — and the files lint fails that
BehaviorTree.CPP creates, with the findings' codes.

Usage: lint_refusals.py --btfsm PATH REPO [--model FILE]... [--glob PATTERN]
"""
import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests" / "differential"))
import accept_btcpp as ac  # noqa: E402

BASE = Path(".").resolve()


def verdict(path, models, given, work):
    """BehaviorTree.CPP's verdict on one file, created alone."""
    ac.project_models = lambda _p: [Path(m) for m in models]
    files, roots, regs, controls, tree_ids = ac.plan(path)
    if not files:
        return {"ok": False, "error": "file not found"}
    # The program's registrations: a model given says them all (a model in
    # the file does not change what the C++ registers); else every model.
    ports = {}
    for r in list(roots.values()) * (not given) + [ac.parse(m) for m in models]:
        ports.update(model_ports(r))
    if given:
        regs = {t: k for t, k in regs.items() if t in ports}
        controls = {t for t in controls if t in ports}
    else:
        # No model: the program registers its custom decorators and controls
        # too (dummies: a decorator, a control read as a Sequence).
        uses, trees = {}, set()
        for r in roots.values():
            for t in (r.iter() if r is not None else []):
                if ac.local(t.tag) == "BehaviorTree" and t.get("ID"):
                    trees.add(t.get("ID"))
            for typ, n in ac.node_uses(r).items():
                uses[typ] = max(uses.get(typ, 0), n)
        custom = {t for t, n in uses.items() if n > 0 and t not in trees
                  and t not in regs and t not in controls}
        for t in custom - ac.btcpp_knows(custom):
            if uses[t] == 1:
                regs[t] = "decorator"
            else:
                controls.add(t)
    target = files[0]
    if roots.get(files[0]) is not None:
        # A dummy has no ports: the attributes the model declares are
        # dropped (the real node takes them), the others kept (refused).
        keep = {}
        for r in roots.values():
            for el in (r.iter() if r is not None else []):
                tag = ac.local(el.tag)
                typ = el.get("ID") if tag in ac.EXPLICIT else tag
                if typ in ports and typ in regs:
                    keep[id(el)] = {a: v for a, v in el.attrib.items()
                                    if a not in ports[typ] and not a.startswith("_")
                                    and a not in ac.RESERVED}
        target = ac.rewrite(files, roots, regs, controls, work, BASE)[0]
        if keep:
            restore(target, files[0], roots, keep)
    job = {"file": str(target), "regs": regs, "tree_ids": tree_ids, "statuses": {}}
    res = subprocess.run([sys.executable, str(Path(ac.__file__)), "--worker"],
                         input=json.dumps(job), capture_output=True, text=True,
                         timeout=ac.WORKER_TIMEOUT, check=False)
    try:
        # BehaviorTree.CPP prints its warnings on stdout first.
        out = json.loads(res.stdout.strip().splitlines()[-1])
    except (json.JSONDecodeError, IndexError):
        return {"ok": False, "error": f"BehaviorTree.CPP crashed: {res.stderr[-200:]}"}
    out["tick"] = "; ".join(out.get("tick_errors", {}).values())
    return out


def model_ports(root):
    """{type: {port names}} declared by the <TreeNodesModel>s of a document."""
    out = {}
    if root is None:
        return out
    for m in root.iter():
        if ac.local(m.tag) != "TreeNodesModel":
            continue
        for d in m:
            if ac.local(d.tag) in ac.EXPLICIT and d.get("ID"):
                out[d.get("ID")] = {p.get("name") for p in d if p.get("name")}
    return out


def restore(target, source, roots, keep):
    """Puts back, in the rewritten main file, the attributes a model does
    not declare (elements matched in document order)."""
    import xml.etree.ElementTree as ET  # noqa: PLC0415
    tree = ET.parse(target)
    originals = list(roots[source].iter())
    for orig, el in zip(originals, tree.getroot().iter()):
        for a, v in keep.get(id(orig), {}).items():
            el.set(a, v)
    tree.write(target, encoding="unicode")


def lint(exe, path, models):
    args = [exe, "lint", str(path), "--format", "json", "--no-config"]
    for m in models:
        args += ["--nodes-model", str(m)]
    r = subprocess.run(args, capture_output=True, text=True, timeout=120, check=False)
    try:
        found = json.loads(r.stdout)
    except json.JSONDecodeError:
        found = []
    return r.returncode, sorted({f["code"] for f in found if f["level"] == "error"})


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--btfsm", required=True)
    ap.add_argument("repo")
    ap.add_argument("--model", action="append", default=[])
    ap.add_argument("--glob", default="**/*.xml")
    a = ap.parse_args()
    global BASE
    BASE = Path(a.repo).resolve()
    files = [p for p in sorted(Path(a.repo).glob(a.glob))
             if p.is_file() and "<BehaviorTree" in p.read_text("utf-8", "replace")]
    missed, ticks, extra, refused, tick_fail = [], [], [], 0, 0
    with tempfile.TemporaryDirectory() as tmp:
        for i, f in enumerate(files):
            work = Path(tmp) / str(i)
            work.mkdir()
            b = verdict(f, a.model, bool(a.model), work)
            code, errors = lint(a.btfsm, f, a.model)
            passes = not errors and code == 0
            refused += not b.get("ok")
            tick_fail += bool(b.get("ok") and b.get("tick"))
            if not b.get("ok") and passes:
                missed.append((f, b.get("error", "")[:160]))
            elif b.get("ok") and b.get("tick") and passes:
                ticks.append((f, b["tick"][:160]))
            elif b.get("ok") and not b.get("tick") and errors:
                extra.append((f, errors))
    print(f"{len(files)} files: BehaviorTree.CPP refuses to create {refused}, lint passes "
          f"{len(missed)} of them; {tick_fail} created fail at their first tick (dummies "
          f"returning SUCCESS), lint passes {len(ticks)} of them; lint errors on "
          f"{len(extra)} files BehaviorTree.CPP creates and ticks")
    for f, why in missed:
        print(f"MISSED {f}: {why}")
    for f, why in ticks:
        print(f"TICK {f}: {why}")
    for f, codes in extra:
        print(f"LINT-ONLY {f}: {' '.join(codes)}")
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
