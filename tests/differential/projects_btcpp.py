#!/usr/bin/env python3
"""Project oracle: SubTrees resolved across BehaviorTree.CPP files given
together, compared with the real BehaviorTree.CPP 4 factory (behaviortreepy).

For every project folder tests/fixtures/btcpp-projects/*/ (its *.xml files,
which do not include each other):

1. BehaviorTree.CPP: a factory registers every leaf type of the folder as a
   dummy (a condition where a <TreeNodesModel> says so), registers every file
   of the folder (registerBehaviorTreeFromText, as a program registering a
   project does), then creates every tree it registered; the instantiated
   tree's size (nodes in pre-order, SubTree nodes replaced by their subtree's
   root, from the FileLogger2 header) or the error.
2. btfsm: `btfsm analyze FOLDER --tree ID --format json` for the same ID:
   the vertices of the one policy it reports, or the error (exit 2).

Both must agree on every tree: both load it with the same node count, or
both reject it. Exit 0 when they do, 1 on a mismatch, 2 when the oracle
cannot run.

Usage: projects_btcpp.py --btfsm PATH
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from accept_btcpp import instantiated_shape  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
PROJECTS = REPO / "tests" / "fixtures" / "btcpp-projects"
BUILTIN_LEAVES = {"AlwaysSuccess", "AlwaysFailure", "Script", "ScriptCondition", "SetBlackboard",
                  "Sleep", "SubTree", "WasEntryUpdated", "UnsetBlackboard", "SkipUnlessUpdated"}
STRUCTURE = {"root", "BehaviorTree", "TreeNodesModel", "include", "input_port", "output_port",
             "inout_port", "MetadataFields", "Metadata"}


def leaf_types(files):
    """Leaf types the folder uses, with `condition` where a model says so."""
    kinds, used = {}, set()
    for f in files:
        root = ET.parse(f).getroot()
        for m in root.iter("TreeNodesModel"):
            for el in m:
                if el.get("ID"):
                    kinds[el.get("ID")] = el.tag.lower()
        for t in root.iter("BehaviorTree"):
            for el in t.iter():
                if el is t or len(el):
                    continue
                name = el.get("ID") if el.tag in ("Action", "Condition") else el.tag
                if el.tag == "Condition":
                    kinds.setdefault(name, "condition")
                if name not in BUILTIN_LEAVES and name not in STRUCTURE:
                    used.add(name)
    return {n: kinds.get(n, "action") for n in sorted(used)}


def btcpp(folder, files):
    import behaviortreepy as bt  # noqa: PLC0415

    def ok(*_a):
        return bt.NodeStatus.SUCCESS

    f = bt.BehaviorTreeFactory()
    for name, kind in leaf_types(files).items():
        (f.register_simple_condition if kind == "condition" else f.register_simple_action)(name, ok)
    os.chdir(folder)
    for p in files:
        f.register_behavior_tree_from_text(p.read_text("utf-8"))
    out = {}
    for tid in f.registered_behavior_trees():
        try:
            tree = f.create_tree(tid)
            log = tempfile.NamedTemporaryFile(suffix=".btlog", delete=False)
            log.close()
            try:
                logger = bt.FileLogger(tree, log.name)
                del logger
                data = Path(log.name).read_bytes()
            finally:
                os.unlink(log.name)
            xml = data[data.index(b"<root"): data.index(b"</root>") + 7].decode("utf-8", "replace")
            out[tid] = len(instantiated_shape(xml))
        except Exception as e:  # noqa: BLE001 - the engine's verdict
            out[tid] = f"error: {' '.join(str(e).split())[:120]}"
    return out


def btfsm(exe, folder, tid):
    r = subprocess.run([exe, "analyze", str(folder), "--tree", tid, "--format", "json"],
                       capture_output=True, text=True, timeout=60)
    if r.returncode == 0:
        pols = json.loads(r.stdout)["policies"]
        if len(pols) != 1:
            return f"error: {len(pols)} policies reported"
        return pols[0]["vertices"]
    if r.returncode == 2:
        return f"error: {' '.join(r.stderr.split())[:120]}"
    return f"crash: exit {r.returncode}: {r.stderr[:200]}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--btfsm", required=True)
    a = ap.parse_args()
    try:
        import behaviortreepy  # noqa: F401, PLC0415
    except ImportError:
        print("projects_btcpp: needs behaviortreepy", file=sys.stderr)
        return 2
    exe = str(Path(a.btfsm).resolve())
    folders = sorted(p for p in PROJECTS.iterdir() if p.is_dir())
    if not folders:
        print("projects_btcpp: no project folder", file=sys.stderr)
        return 2
    bad = checked = 0
    cwd = os.getcwd()
    for folder in folders:
        files = sorted(folder.rglob("*.xml"))
        want = btcpp(folder, files)
        os.chdir(cwd)
        for tid, w in sorted(want.items()):
            got = btfsm(exe, folder, tid)
            checked += 1
            same = (got == w) or (isinstance(got, str) and got.startswith("error")
                                  and isinstance(w, str))
            print(f"{'ok ' if same else 'MISMATCH'} {folder.name} tree {tid}: "
                  f"BehaviorTree.CPP {w}, btfsm {got}")
            bad += not same
    print(f"projects_btcpp: {checked} trees in {len(folders)} projects, {bad} mismatches")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
