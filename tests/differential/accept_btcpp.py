#!/usr/bin/env python3
"""Acceptance oracle: btfsm's accept/reject decision on BehaviorTree.CPP XML
compared with the real BehaviorTree.CPP 4 engine (Python bindings
`behaviortreepy`, see README "Differential tests" below).

For every BT XML fixture (tests/fixtures/corpus*/bt-xml/**/*.xml,
tests/fixtures/field/bt-xml/**/*.xml, tests/fixtures/valid/**/*.xml, tests/fixtures/invalid/**/*.xml,
tests/fixtures/lint/**/*.xml; a file that
only holds a <TreeNodesModel> is skipped):

1. BehaviorTree.CPP decides. Every leaf type the file (with its <include>s)
   uses that BehaviorTree.CPP does not know is registered as a dummy action
   (a condition if a <TreeNodesModel> says so). A type with children that
   BehaviorTree.CPP does not know is registered only if a <TreeNodesModel>
   (in the file, its includes, or the project's *tree_nodes*.xml beside it,
   e.g. Nav2's nav2_tree_nodes.xml) declares it: a Decorator as a dummy
   decorator, a Control as a `Sequence` (the Python bindings cannot register
   controls; any control takes 1..n children). Dummies have no ports, so their
   attributes other than `name`, `ID` and the reserved `_...` ones are
   dropped before loading. The file is loaded with createTreeFromFile (the
   tree is `main_tree_to_execute` or the only tree); when that fails only
   because there are several trees and no main tree, the file is registered
   and EVERY tree of the file is created (accept = all of them load).
2. btfsm decides: `btfsm validate --assume-leaf action [--nodes-model the
   project's model] FILE` (exit 0 = accept, 2 = reject, anything else = a
   crash, always a mismatch).
3. Every file btfsm accepts is exported with `btfsm convert FILE --to
   btcpp-xml` and loaded in BehaviorTree.CPP as written, with the same
   registrations (nothing of the export is stripped but the ports of dummy
   nodes, as for every file: the bindings cannot declare ports; a
   `btfsm:` attribute, which BehaviorTree.CPP rejects as an undeclared
   port, would make the export fail): it must load, and when the original
   loaded too, the instantiated trees must have the same nodes (types and
   names), child counts and ports (with BehaviorTree.CPP's defaults filled
   in from the instantiated tree's own <TreeNodesModel>, so that a Parallel
   written with `failure_count="1"` equals one that leaves it to the
   default; values compared for the nodes of the main tree, names only
   inside SubTrees, whose ports the export resolves through the remapping)
   in pre-order, SubTree nodes replaced by their subtree's root
   (BehaviorTree.CPP's FileLogger2 header gives the instantiated tree).
   Every bundled TOML BT is exported and loaded too.

Output: a table of mismatches with the reason from each side. Exit status:
0 when every mismatch is listed in accept_btcpp_known.txt and every listed
mismatch still happens; 1 otherwise (a new mismatch, or a stale entry); 2 when
the oracle cannot run (behaviortreepy or the btfsm binary missing).

Known-mismatch file format (one per line, `#` comments):
    <path relative to the repository> <check: accept|export> <wrong side: btfsm|btcpp|design>: <reason>

Usage:
    python3 tests/differential/accept_btcpp.py [--btfsm PATH] [--json OUT]
        [--print-known] [FILES...]
Requirements: Python >= 3.9, `pip install behaviortreepy==0.1.4` (Python
bindings of BehaviorTree.CPP 4), a built btfsm (cargo build --release; found
through $BTFSM, $CARGO_TARGET_DIR/release, target/release or target/debug).
"""

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
FIXTURES = REPO / "tests" / "fixtures"
KNOWN = HERE / "accept_btcpp_known.txt"
WORKER_TIMEOUT = 120
EXPLICIT = {"Action", "Condition", "Control", "Decorator"}
RESERVED = {"name", "ID"}
BTFSM_NS = "btfsm"


# --------------------------------------------------------------------------
# BehaviorTree.CPP side (runs in a child process: a crash there must not kill
# the oracle)
# --------------------------------------------------------------------------


def worker_main():
    """Reads a job (JSON) on stdin, prints the result (JSON) on stdout."""
    job = json.load(sys.stdin)
    import behaviortreepy as bt  # noqa: PLC0415

    def ok_tick(*_args):
        return bt.NodeStatus.SUCCESS

    statuses = job.get("statuses", {})

    def leaf_tick(name):
        status = getattr(bt.NodeStatus, statuses.get(name, "SUCCESS"))
        return lambda *_args: status

    def factory():
        f = bt.BehaviorTreeFactory()
        for name, kind in job["regs"].items():
            if name in statuses:
                f.register_simple_action(name, leaf_tick(name))
                continue
            if kind == "condition":
                f.register_simple_condition(name, ok_tick)
            elif kind == "decorator":
                f.register_simple_decorator(name, ok_tick)
            else:
                f.register_simple_action(name, ok_tick)
        return f

    def shape(tree):
        log = tempfile.NamedTemporaryFile(suffix=".btlog", delete=False)
        log.close()
        try:
            logger = bt.FileLogger(tree, log.name)
            del logger
            data = Path(log.name).read_bytes()
        finally:
            os.unlink(log.name)
        start = data.index(b"<root")
        end = data.index(b"</root>") + len(b"</root>")
        return instantiated_shape(data[start:end].decode("utf-8", "replace"))

    def tick(tree, name):
        # One tick with every dummy returning SUCCESS: BehaviorTree.CPP checks
        # some child-count rules (IfThenElse, WhileDoElse, Parallel
        # thresholds) only when a node runs.
        try:
            out["status"].setdefault(name, str(tree.tick_once()).split(".")[-1])
        except Exception as e:  # noqa: BLE001
            out["tick_errors"][name] = str(e)

    out = {"ok": False, "mode": "main", "error": "", "shapes": {}, "tick_errors": {}, "status": {}}
    path = job["file"]
    try:
        tree = factory().create_tree_from_file(path)
        out["ok"] = True
        out["shapes"]["<main>"] = shape(tree)
        # Ticked on a fresh copy: no logger attached to it.
        tick(factory().create_tree_from_file(path), "<main>")
    except Exception as e:  # noqa: BLE001 - the engine's verdict, any type
        msg = str(e)
        out["error"] = msg
        if "main_tree_to_execute" in msg and job["tree_ids"]:
            # Several trees and no main tree: create each tree of the file.
            out["mode"] = "each-tree"
            errors = []
            for tid in job["tree_ids"]:
                try:
                    # The bindings' register_behavior_tree_from_file lacks its
                    # path type; from text, <include> paths are relative to
                    # the working directory (when the parser is made): the file's.
                    os.chdir(Path(path).parent)
                    f = factory()
                    f.register_behavior_tree_from_text(Path(path).read_text("utf-8"))
                    out["shapes"][tid] = shape(f.create_tree(tid))
                    tick(f.create_tree(tid), tid)
                except Exception as e2:  # noqa: BLE001
                    errors.append(f"{tid}: {e2}")
            out["ok"] = not errors
            out["error"] = "; ".join(errors) if errors else ""
    print(json.dumps(out))


def instantiated_shape(xml_text):
    """[(type, children, name, ports)] in pre-order of the instantiated tree,
    subtrees expanded: a SubTree node is replaced by its subtree's root.
    `ports` maps each port to its value as written, BehaviorTree.CPP's
    default (from the <TreeNodesModel> of the same header) where the node
    does not set it; inside a SubTree only the port names are kept (the
    value None)."""
    root = ET.fromstring(xml_text)
    trees = {}
    for t in root.findall("BehaviorTree"):
        trees[t.get("_fullpath", "")] = t
    defaults = {}
    for m in root.findall("TreeNodesModel"):
        for d in m:
            defaults[d.get("ID")] = {p.get("name"): p.get("default") for p in d
                                     if p.get("default") is not None}
    out = []

    def visit(el, inside):
        if el.tag == "SubTree":
            sub = trees.get(el.get("_fullpath", ""))
            if sub is not None and len(sub):
                visit(sub[0], True)
                return
        kids = list(el)
        ports = dict(defaults.get(el.tag, {}))
        ports.update({k: v for k, v in el.attrib.items()
                      if k not in ("name", "_uid", "_fullpath")})
        if el.tag == "Parallel":
            # A negative count is counted from the number of children
            # (-1: all of them), as ParallelNode reads it.
            for k in ("success_count", "failure_count"):
                try:
                    v = int(ports.get(k, ""))
                except ValueError:
                    continue
                if v < 0:
                    ports[k] = str(len(kids) + v + 1)
        if inside:
            ports = {k: None for k in ports}
        out.append([el.tag, len(kids), el.get("name", ""), ports])
        for k in kids:
            visit(k, inside)

    main = trees.get("")
    if main is not None and len(main):
        visit(main[0], False)
    return out


# --------------------------------------------------------------------------
# Reading the XML (our own scan, for registrations only)
# --------------------------------------------------------------------------


def local(tag):
    return tag.split("}", 1)[1] if tag.startswith("{") else tag


def parse(path):
    try:
        return ET.parse(path).getroot()
    except (ET.ParseError, OSError, UnicodeDecodeError):
        return None


def closure(path):
    """The file and the files it <include>s (recursively), in order."""
    seen, order, stack = set(), [], [Path(path).resolve()]
    while stack:
        p = stack.pop()
        if p in seen or not p.is_file():
            continue
        seen.add(p)
        order.append(p)
        root = parse(p)
        if root is None:
            continue
        for inc in root.iter():
            if local(inc.tag) == "include" and inc.get("path"):
                stack.append((p.parent / inc.get("path")).resolve())
    return order


def models_in(root):
    """{type: kind} declared by <TreeNodesModel> sections of one document."""
    out = {}
    if root is None:
        return out
    for m in root.iter():
        if local(m.tag) != "TreeNodesModel":
            continue
        for d in m:
            kind = local(d.tag)
            if kind in EXPLICIT and d.get("ID"):
                out[d.get("ID")] = kind.lower()
    return out


def project_models(path):
    """The project's *tree_nodes*.xml (bt-xml/<project>/ in any corpus folder)."""
    rel = Path(path).resolve()
    parts = rel.parts
    if "bt-xml" not in parts:
        return []
    i = parts.index("bt-xml")
    if i + 1 >= len(parts) - 1:
        return []
    project = parts[i + 1]
    found = []
    for corpus in sorted(FIXTURES.glob("corpus*")):
        d = corpus / "bt-xml" / project
        if d.is_dir():
            found += sorted(d.glob("*tree_nodes*.xml"))
    return found


def is_nodes_model_only(root):
    if root is None:
        return False
    tags = {local(e.tag) for e in root}
    return "TreeNodesModel" in tags and "BehaviorTree" not in tags


def node_uses(root):
    """{type: max children} for the nodes under <BehaviorTree> elements."""
    uses = {}

    def visit(el):
        tag = local(el.tag)
        typ = el.get("ID") if tag in EXPLICIT else tag
        if tag != "SubTree" and typ:
            uses[typ] = max(uses.get(typ, 0), len(el))
        for c in el:
            visit(c)

    if root is None:
        return uses
    for t in root.iter():
        if local(t.tag) == "BehaviorTree":
            for c in t:
                visit(c)
    return uses


_KNOWN_CACHE = {}


def btcpp_knows(types):
    """Which of these type names BehaviorTree.CPP itself knows (one probe run)."""
    todo = sorted(t for t in types if t not in _KNOWN_CACHE)
    if todo:
        code = (
            "import json,sys,behaviortreepy as bt\n"
            "out={}\n"
            "for t in json.load(sys.stdin):\n"
            "  f=bt.BehaviorTreeFactory()\n"
            "  try:\n"
            "    f.create_tree_from_text('<root BTCPP_format=\"4\"><BehaviorTree ID=\"P\"><%s/></BehaviorTree></root>'%t)\n"
            "    out[t]=True\n"
            "  except Exception as e:\n"
            "    out[t]='Node not recognized' not in str(e)\n"
            "print(json.dumps(out))\n"
        )
        safe = [t for t in todo if re.fullmatch(r"[A-Za-z_][\w.-]*", t)]
        res = subprocess.run(
            [sys.executable, "-c", code], input=json.dumps(safe), capture_output=True,
            text=True, timeout=WORKER_TIMEOUT, check=False)
        known = json.loads(res.stdout) if res.returncode == 0 else {}
        for t in todo:
            _KNOWN_CACHE[t] = bool(known.get(t, False))
    return {t for t in types if _KNOWN_CACHE.get(t)}


def plan(path):
    """Registrations and rewrites BehaviorTree.CPP needs for this file."""
    files = closure(path)
    roots = {p: parse(p) for p in files}
    models = {}
    for m in project_models(path):
        models.update(models_in(parse(m)))
    for r in roots.values():
        models.update(models_in(r))
    tree_ids = set()
    uses = {}
    for r in roots.values():
        if r is None:
            continue
        for t in r.iter():
            if local(t.tag) == "BehaviorTree" and t.get("ID"):
                tree_ids.add(t.get("ID"))
        for typ, n in node_uses(r).items():
            uses[typ] = max(uses.get(typ, 0), n)
    if files and roots.get(files[0]) is None:
        # Our parser refuses the text (tinyxml2 may not): registrations from a
        # tag scan, every unknown tag a leaf.
        text = Path(files[0]).read_text("utf-8", "replace")
        for tag in re.findall(r"<([A-Za-z_][\w.-]*)", text):
            uses.setdefault(tag, 0)
        for tag, idv in re.findall(r"<(Action|Condition)\s[^>]*ID\s*=\s*\"([^\"]+)\"", text):
            uses.setdefault(idv, 0)
    structural = {"root", "BehaviorTree", "TreeNodesModel", "include", "SubTree",
                  "input_port", "output_port", "inout_port", "description",
                  "MetadataFields", "Metadata"}
    candidates = {t for t in uses if t not in structural and t not in tree_ids}
    known = btcpp_knows(candidates)
    regs, controls = {}, set()
    for t in sorted(candidates - known):
        kind = models.get(t)
        if uses[t] == 0:
            regs[t] = "condition" if kind == "condition" else "action"
        elif kind == "decorator":
            regs[t] = "decorator"
        elif kind == "control":
            controls.add(t)
        # else: a type with children no model declares: BehaviorTree.CPP
        # decides alone (it rejects it), as btfsm does.
    main_root = roots.get(files[0]) if files else None
    ids_in_main = []
    if main_root is not None:
        ids_in_main = [t.get("ID") for t in main_root if local(t.tag) == "BehaviorTree" and t.get("ID")]
    return files, roots, regs, controls, ids_in_main


def rewrite(files, roots, regs, controls, outdir, base):
    """Copies the file closure to outdir (paths relative to base), dropping
    dummy nodes' ports and turning declared custom controls into Sequence."""
    written = []
    for p in files:
        try:
            rel = p.relative_to(base)
        except ValueError:
            rel = Path("_outside") / p.name
        dst = outdir / rel
        dst.parent.mkdir(parents=True, exist_ok=True)
        root = roots.get(p)
        if root is None:
            shutil.copyfile(p, dst)
        else:
            for el in root.iter():
                tag = local(el.tag)
                typ = el.get("ID") if tag in EXPLICIT else tag
                if typ in regs or typ in controls:
                    for a in list(el.attrib):
                        if a not in RESERVED and not a.startswith("_"):
                            del el.attrib[a]
                if typ in controls and not _in_model(el, root):
                    el.tag = "Sequence"
                    el.attrib.pop("ID", None)
            ET.ElementTree(root).write(dst, encoding="unicode", xml_declaration=False)
        written.append(dst)
    return written


def _in_model(el, root):
    for m in root.iter():
        if local(m.tag) == "TreeNodesModel" and any(c is el for c in m.iter()):
            return True
    return False


def btcpp(path, outdir, base=None, statuses=None):
    """BehaviorTree.CPP's verdict on one file: dict(ok, mode, error, shapes)."""
    files, roots, regs, controls, tree_ids = plan(path)
    if not files:
        return {"ok": False, "mode": "main", "error": "file not found", "shapes": {}}
    # Rewrite only when needed (dummy ports, custom controls): otherwise
    # tinyxml2 reads the file exactly as written. An export is loaded as
    # written too: nothing BehaviorTree.CPP would reject is stripped.
    need_rewrite = roots.get(files[0]) is not None and bool(regs or controls)
    target = files[0]
    if need_rewrite:
        written = rewrite(files, {p: roots[p] for p in files}, regs, controls, outdir,
                          base or FIXTURES)
        target = written[0]
    job = {"file": str(target), "regs": regs, "tree_ids": tree_ids, "statuses": statuses or {}}
    try:
        res = subprocess.run(
            [sys.executable, str(Path(__file__).resolve()), "--worker"],
            input=json.dumps(job), capture_output=True, text=True,
            timeout=WORKER_TIMEOUT, check=False)
    except subprocess.TimeoutExpired:
        return {"ok": False, "mode": "main", "error": "BehaviorTree.CPP timed out", "shapes": {}}
    if res.returncode != 0 or not res.stdout.strip():
        return {"ok": False, "mode": "main", "shapes": {},
                "error": f"BehaviorTree.CPP crashed (exit {res.returncode}): {res.stderr.strip()[-300:]}"}
    out = json.loads(res.stdout.strip().splitlines()[-1])
    out["regs"] = regs
    out["controls"] = sorted(controls)
    return out


# --------------------------------------------------------------------------
# btfsm side
# --------------------------------------------------------------------------


def btfsm_args(path):
    args = ["--assume-leaf", "action"]
    for m in project_models(path):
        args += ["--nodes-model", str(m)]
    return args


def unnamed_trees(path):
    """The tree IDs of a file with several <BehaviorTree>s and no
    main_tree_to_execute (a program names one in code: `--tree ID`)."""
    root = parse(path)
    if root is None or root.get("main_tree_to_execute"):
        return []
    ids = [el.get("ID") for el in root if local(el.tag) == "BehaviorTree" and el.get("ID")]
    return ids if len(ids) > 1 else []


def btfsm_validate(exe, path):
    # Several trees and no main tree: BehaviorTree.CPP registers them all and
    # a program creates one; btfsm must accept each with `--tree ID`.
    for tid in unnamed_trees(path):
        code, why = btfsm_validate_one(exe, path, ["--tree", tid])
        if code != 0:
            return code, f"--tree {tid}: {why}"
    return btfsm_validate_one(exe, path, [] if not unnamed_trees(path) else ["--tree", unnamed_trees(path)[0]])


def btfsm_validate_one(exe, path, extra):
    res = subprocess.run([exe, "validate", *btfsm_args(path), *extra, str(path)],
                         capture_output=True, text=True, timeout=WORKER_TIMEOUT, check=False)
    lines = res.stderr.splitlines()
    first = next((ln for ln in lines if ln.startswith("error")), "")
    if not first:
        first = next((ln for ln in lines if ln.startswith("warning")), "")
    if not first and lines:
        first = lines[-1].replace(str(path) + ": ", "")
    return res.returncode, first


def btfsm_export(exe, path, out):
    ids = unnamed_trees(path)
    extra = ["--tree", ids[0]] if ids else []
    res = subprocess.run([exe, "convert", *btfsm_args(path), *extra, str(path), "--to", "btcpp-xml",
                          "-o", str(out)], capture_output=True, text=True,
                         timeout=WORKER_TIMEOUT, check=False)
    return res.returncode, res.stderr.strip()


def same_node(o, e):
    """An instantiated node of the original and of the export are the same:
    type, child count, name and port names; and port values where the
    original's is known (outside SubTrees: `instantiated_shape`)."""
    if o[:3] != e[:3] or set(o[3]) != set(e[3]):
        return False
    return all(v is None or e[3][k] is None or v == e[3][k] for k, v in o[3].items())


def check_export(exe, f, rel, work, b, r, mismatches):
    """btfsm's BehaviorTree.CPP export of an accepted file must load (and tick
    once) in BehaviorTree.CPP, with the original's shape when the original
    loaded. b: BehaviorTree.CPP's verdict on the original (None: not XML)."""
    exp = work / "export.xml"
    ecode, eerr = btfsm_export(exe, f, exp)
    r["export_exit"] = ecode
    if ecode != 0:
        if b is None and "behavior trees only" in eerr:
            r["export_exit"] = "not a BT"
            return
        mismatches.append((rel, "export", "-", f"convert exit {ecode}", "", short(eerr)))
        return
    e = btcpp(exp, work / "exp", base=work)
    r["export_btcpp_ok"] = e["ok"]
    r["export_btcpp_error"] = e["error"]
    r["export_tick_errors"] = e.get("tick_errors", {})
    if not e["ok"]:
        mismatches.append((rel, "export", "export rejected", "exported",
                           short(e["error"]), "btfsm wrote it"))
        return
    tick0 = (b or {}).get("tick_errors", {})
    tick1 = e.get("tick_errors", {})
    if tick1 and not tick0:
        mismatches.append((rel, "export", "export fails its first tick", "exported",
                           short(next(iter(tick1.values()))), "btfsm wrote it"))
    if b is not None and b["ok"]:
        s0 = next(iter(b["shapes"].values()), [])
        s1 = e["shapes"].get("<main>", [])
        same = len(s0) == len(s1) and all(same_node(x, y) for x, y in zip(s0, s1))
        r["shape_equal"] = same
        if not same:
            diff = next((k for k in range(min(len(s0), len(s1))) if not same_node(s0[k], s1[k])),
                        min(len(s0), len(s1)))
            a0 = s0[diff] if diff < len(s0) else "end"
            a1 = s1[diff] if diff < len(s1) else "end"
            what = ("shape differs" if [x[:2] for x in s0] != [x[:2] for x in s1]
                    else "names or ports differ")
            mismatches.append((rel, "export", what, what,
                               f"original node #{diff}: {a0} ({len(s0)} nodes)",
                               f"export node #{diff}: {a1} ({len(s1)} nodes)"))


# Semantic probes: a TOML tree whose meaning the README states, exported and
# ticked once in BehaviorTree.CPP with the leaves returning fixed statuses.
# (name, TOML text, leaf statuses, the status the TOML tree gives)
PARALLEL = """kind = "bt"
name = "probe"
[nodes]
root = { parallel = ["a", "b", "c"]%s }
a = { action = "A" }
b = { action = "B" }
c = { action = "C" }
"""
PROBES = [
    ("parallel-2-of-3-one-fails", PARALLEL % ", success = 2",
     {"A": "SUCCESS", "B": "FAILURE", "C": "SUCCESS"}, "SUCCESS"),
    ("parallel-2-of-3-two-fail", PARALLEL % ", success = 2",
     {"A": "FAILURE", "B": "FAILURE", "C": "SUCCESS"}, "FAILURE"),
    ("parallel-all-one-fails", PARALLEL % "",
     {"A": "SUCCESS", "B": "FAILURE", "C": "SUCCESS"}, "FAILURE"),
    ("parallel-all-succeed", PARALLEL % "",
     {"A": "SUCCESS", "B": "SUCCESS", "C": "SUCCESS"}, "SUCCESS"),
]


def check_probes(exe, tmp, mismatches, results):
    for name, text, statuses, want in PROBES:
        work = tmp / f"probe-{name}"
        work.mkdir()
        src = work / f"{name}.toml"
        src.write_text(text)
        exp = work / "export.xml"
        rel = f"probe:{name}"
        ecode, eerr = btfsm_export(exe, src, exp)
        if ecode != 0:
            mismatches.append((rel, "export", "-", f"convert exit {ecode}", "", short(eerr)))
            continue
        e = btcpp(exp, work / "exp", base=work, statuses=statuses)
        got = e.get("status", {}).get("<main>") or short(e["error"] or str(e.get("tick_errors")))
        results.append({"file": rel, "probe": True, "want": want, "got": got})
        print(f"[probe] {name}: TOML semantics {want}, BehaviorTree.CPP {got}", file=sys.stderr)
        if got != want:
            leaves = " ".join(f"{k}={v}" for k, v in statuses.items())
            mismatches.append((rel, "export", f"first tick: {got}", f"TOML semantics: {want}",
                               f"leaves {leaves}", short(exp.read_text().split("<BehaviorTree", 1)[1]
                                                        .split("</BehaviorTree>")[0], 120)))


# Child-count and threshold rules, as one-tree files (BehaviorTree.CPP checks
# some of them only at the first tick).
XML_PROBES = [
    ("ifthenelse-1-child", "<IfThenElse><AlwaysSuccess/></IfThenElse>"),
    ("ifthenelse-2-children", "<IfThenElse><AlwaysSuccess/><AlwaysSuccess/></IfThenElse>"),
    ("ifthenelse-3-children", "<IfThenElse><AlwaysSuccess/><AlwaysSuccess/><AlwaysFailure/></IfThenElse>"),
    ("ifthenelse-4-children",
     "<IfThenElse><AlwaysSuccess/><AlwaysSuccess/><AlwaysFailure/><AlwaysFailure/></IfThenElse>"),
    ("whiledoelse-1-child", "<WhileDoElse><AlwaysSuccess/></WhileDoElse>"),
    ("whiledoelse-2-children", "<WhileDoElse><AlwaysSuccess/><AlwaysSuccess/></WhileDoElse>"),
    ("whiledoelse-4-children",
     "<WhileDoElse><AlwaysSuccess/><AlwaysSuccess/><AlwaysFailure/><AlwaysFailure/></WhileDoElse>"),
    ("trycatch-2-children", "<TryCatch><AlwaysSuccess/><AlwaysSuccess/></TryCatch>"),
    ("parallel-success-count-above-children",
     '<Parallel success_count="4"><AlwaysSuccess/><AlwaysSuccess/><AlwaysSuccess/></Parallel>'),
    ("parallel-success-count-minus-1",
     '<Parallel success_count="-1"><AlwaysSuccess/><AlwaysSuccess/></Parallel>'),
    ("parallel-failure-count-2",
     '<Parallel success_count="2" failure_count="2"><AlwaysSuccess/><AlwaysFailure/><AlwaysSuccess/></Parallel>'),
    ("switch2-3-children",
     '<Switch2 variable="a" case_1="a" case_2="b"><AlwaysSuccess/><AlwaysSuccess/><AlwaysFailure/></Switch2>'),
    ("switch2-2-children",
     '<Switch2 variable="a" case_1="a" case_2="b"><AlwaysSuccess/><AlwaysSuccess/></Switch2>'),
    ("retry-without-num-attempts", "<RetryUntilSuccessful><AlwaysSuccess/></RetryUntilSuccessful>"),
    ("timeout-msec", '<Timeout msec="100"><AlwaysSuccess/></Timeout>'),
    ("sequence-no-children", "<Sequence/>"),
    ("inverter-2-children", "<Inverter><AlwaysSuccess/><AlwaysSuccess/></Inverter>"),
    ("leaf-with-child", "<AlwaysSuccess><AlwaysFailure/></AlwaysSuccess>"),
    # What tinyxml2 (BehaviorTree.CPP's parser) tolerates and XML 1.0 does not.
    ("xml-duplicate-attribute", '<AlwaysSuccess name="a" name="b"/>'),
    ("xml-bare-ampersand", '<AlwaysSuccess name="fish & chips"/>'),
    ("xml-text-between-nodes", "<Sequence>some text<AlwaysSuccess/></Sequence>"),
    ("xml-undeclared-prefix", '<AlwaysSuccess name="a" x:y="1"/>'),
]


def toml_files():
    """Bundled TOML policies: btfsm's own BTs, checked on export only."""
    out = sorted((REPO / "policies").rglob("*.toml")) + sorted((FIXTURES / "valid").rglob("*.toml"))
    return [p for p in out if not {"scenarios", "lib", "tables", "domains"} & set(p.parts)]


# --------------------------------------------------------------------------
# Driver
# --------------------------------------------------------------------------


def fixture_files():
    out = []
    for corpus in sorted(FIXTURES.glob("corpus*")):
        out += sorted((corpus / "bt-xml").rglob("*.xml")) if (corpus / "bt-xml").is_dir() else []
    out += sorted((FIXTURES / "field" / "bt-xml").rglob("*.xml"))
    out += sorted((FIXTURES / "valid").rglob("*.xml"))
    out += sorted((FIXTURES / "invalid").rglob("*.xml"))
    out += sorted((FIXTURES / "lint").rglob("*.xml"))
    return [p for p in out if not is_nodes_model_only(parse(p))]


def find_btfsm(given):
    if given:
        return given
    cands = []
    if os.environ.get("BTFSM"):
        cands.append(os.environ["BTFSM"])
    if os.environ.get("CARGO_TARGET_DIR"):
        cands.append(str(Path(os.environ["CARGO_TARGET_DIR"]) / "release" / "btfsm"))
    cands += [str(REPO / "target" / "release" / "btfsm"), str(REPO / "target" / "debug" / "btfsm")]
    for c in cands:
        if Path(c).is_file() and os.access(c, os.X_OK):
            return c
    return None


def read_known(path):
    known = {}
    if not path.is_file():
        return known
    for n, line in enumerate(path.read_text().splitlines(), 1):
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        parts = line.split(None, 2)
        if len(parts) < 3 or parts[1] not in ("accept", "export"):
            raise SystemExit(f"{path}:{n}: expected `<path> <accept|export> <side>: <reason>`")
        known[(parts[0], parts[1])] = parts[2]
    return known


def short(s, n=150):
    s = " ".join(s.split())
    return s if len(s) <= n else s[: n - 1] + "…"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--btfsm", help="btfsm binary")
    ap.add_argument("--json", help="write every result as JSON here")
    ap.add_argument("--known", type=Path, default=KNOWN,
                    help="known-mismatch file (default: accept_btcpp_known.txt beside this script)")
    ap.add_argument("--print-known", action="store_true",
                    help="print the current mismatches in the known-file format")
    ap.add_argument("--no-toml", action="store_true",
                    help="skip the export check of the bundled TOML behavior trees")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("files", nargs="*", type=Path)
    a = ap.parse_args()
    if a.worker:
        worker_main()
        return 0
    try:
        import behaviortreepy  # noqa: F401, PLC0415
    except ImportError:
        print("accept_btcpp: needs the Python bindings of BehaviorTree.CPP 4: "
              "pip install behaviortreepy==0.1.4", file=sys.stderr)
        return 2
    exe = find_btfsm(a.btfsm)
    if not exe:
        print("accept_btcpp: no btfsm binary (cargo build --release, or --btfsm PATH / $BTFSM)",
              file=sys.stderr)
        return 2
    files = [p.resolve() for p in a.files] if a.files else fixture_files()
    known = read_known(a.known)
    results, mismatches, toml_results = [], [], []
    tmp = Path(tempfile.mkdtemp(prefix="accept-btcpp-"))
    try:
        todo = [(f, str(f.relative_to(REPO)) if f.is_relative_to(REPO) else str(f)) for f in files]
        if not a.files and not a.no_toml:
            pdir = tmp / "xml-probes"
            pdir.mkdir()
            for name, body in XML_PROBES:
                f = pdir / f"{name}.xml"
                f.write_text(f'<root BTCPP_format="4">\n  <BehaviorTree ID="probe">\n    {body}\n'
                             f'  </BehaviorTree>\n</root>\n')
                todo.append((f, f"probe:{name}"))
        for i, (f, rel) in enumerate(todo):
            work = tmp / f"f{i}"
            work.mkdir()
            b = btcpp(f, work / "orig")
            if b["ok"] and b.get("tick_errors"):
                # BehaviorTree.CPP checks some child counts only when the node
                # runs: an error at the first tick (all dummies SUCCESS) is a
                # rejection too.
                b["ok"] = False
                b["error"] = "first tick: " + next(iter(b["tick_errors"].values()))
            code, why = btfsm_validate(exe, f)
            r = {"file": rel, "btcpp_ok": b["ok"], "btcpp_mode": b["mode"],
                 "btcpp_error": b["error"], "btfsm_exit": code, "btfsm_error": why,
                 "registered": b.get("regs", {}), "controls_as_sequence": b.get("controls", [])}
            btfsm_ok = code == 0
            if code not in (0, 2) or btfsm_ok != b["ok"]:
                mismatches.append((rel, "accept",
                                   "accept" if b["ok"] else "reject",
                                   {0: "accept", 2: "reject"}.get(code, f"exit {code}"),
                                   (f"[{b['mode']}] " if b["mode"] != "main" else "") + short(b["error"]),
                                   short(why)))
            if btfsm_ok:
                check_export(exe, f, rel, work, b, r, mismatches)
            results.append(r)
            print(f"[{i + 1}/{len(todo)}] {rel}: btcpp={'accept' if b['ok'] else 'reject'} "
                  f"btfsm={'accept' if btfsm_ok else 'reject' if code == 2 else code}",
                  file=sys.stderr)
        if not a.files and not a.no_toml:
            check_probes(exe, tmp, mismatches, toml_results)
            for i, f in enumerate(toml_files()):
                rel = str(f.relative_to(REPO))
                work = tmp / f"t{i}"
                work.mkdir()
                r = {"file": rel, "toml": True}
                check_export(exe, f, rel, work, None, r, mismatches)
                if r.get("export_exit") != "not a BT":
                    toml_results.append(r)
                    print(f"[toml] {rel}: export={r.get('export_btcpp_ok')}", file=sys.stderr)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)

    seen = {(m[0], m[1]) for m in mismatches}
    new = [m for m in mismatches if (m[0], m[1]) not in known]
    checked = {str(p.relative_to(REPO)) if p.is_relative_to(REPO) else str(p) for p in files}
    checked |= {r["file"] for r in toml_results}
    checked |= ({f"probe:{p[0]}" for p in PROBES} | {f"probe:{p[0]}" for p in XML_PROBES}
                if not a.files and not a.no_toml else set())
    stale = [k for k in known if k not in seen and k[0] in checked]
    missing = [k for k in known if k[0] not in checked and not a.files]

    print(f"\n{len(files)} fixture files + {len(results) - len(files)} probe trees; BehaviorTree.CPP accepts {sum(r['btcpp_ok'] for r in results)}, "
          f"btfsm accepts {sum(r['btfsm_exit'] == 0 for r in results)}; "
          f"exports loaded {sum(bool(r.get('export_btcpp_ok')) for r in results + toml_results)}"
          f"/{sum('export_btcpp_ok' in r for r in results + toml_results)} "
          f"(with {len(toml_results)} TOML BTs and probes), same shape "
          f"{sum(bool(r.get('shape_equal')) for r in results)}/{sum('shape_equal' in r for r in results)}; "
          f"{len(mismatches)} mismatches ({len(mismatches) - len(new)} known, {len(new)} new), "
          f"{len(stale) + len(missing)} stale known entries\n")
    if mismatches:
        print("| file | check | BehaviorTree.CPP | btfsm | BehaviorTree.CPP says | btfsm says | known |")
        print("|---|---|---|---|---|---|---|")
        for m in mismatches:
            k = known.get((m[0], m[1]))
            print(f"| {m[0]} | {m[1]} | {m[2]} | {m[3]} | {m[4].replace('|', '/')} | "
                  f"{m[5].replace('|', '/')} | {('yes: ' + k.replace('|', '/')) if k else 'NEW'} |")
    for k in stale:
        print(f"STALE known mismatch (no longer mismatches, remove it from {a.known.name}): {k[0]} {k[1]}")
    for k in missing:
        print(f"STALE known mismatch (file no longer checked): {k[0]} {k[1]}")
    if a.print_known:
        print("\n# --print-known")
        for m in mismatches:
            print(f"{m[0]} {m[1]} {known.get((m[0], m[1]), '?: ' + (m[4] or m[5]))}")
    if a.json:
        Path(a.json).write_text(json.dumps({"results": results + toml_results,
                                            "mismatches": mismatches}, indent=1))
    return 1 if new or stale or missing else 0


if __name__ == "__main__":
    sys.exit(main())
