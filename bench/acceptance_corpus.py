#!/usr/bin/env python3
"""Acceptance and lint on a held-out corpus, measured against
BehaviorTree.CPP 4 (docs/lint.md, "Measured on a held-out corpus";
docs/guide/btcpp-xml.md, "Acceptance on real files").

CORPUS is a folder of repositories (as bench/acceptance_corpus_gather.sh
lays them out: one folder per repository and commit, marked by a `.git`
entry). For every BehaviorTree.CPP XML file below it (a file holding a
<BehaviorTree>; a file that holds only a <TreeNodesModel> is a model):

1. BehaviorTree.CPP 4 (behaviortreepy) creates the tree, as
   tests/differential/accept_btcpp.py does (its functions are used): every
   leaf type BehaviorTree.CPP does not build in is registered as a dummy
   action (a condition where a model says so), a custom decorator or control
   only where a model declares it; the dummies' attributes are dropped (the
   bindings cannot declare ports). The models: the file's own
   <TreeNodesModel>, its includes', and the repository's model files (every
   `*tree_nodes*.xml` and every XML file that holds only a
   <TreeNodesModel>). Then the tree is ticked once (dummies SUCCESS).
2. `btfsm validate --assume-leaf action [--nodes-model M]... FILE` (with
   `--tree ID` for each tree of a file that has several and no main tree):
   exit 0 accepts, 2 rejects, anything else is a crash.
3. `btfsm lint FILE --format json` at default settings, run from the
   repository's root (node models found as lint finds them): the
   error-level findings (codes).

Tallies: valid files (BehaviorTree.CPP creates them) that btfsm validate
rejects (false rejections); files BehaviorTree.CPP refuses that validate
accepts; files BehaviorTree.CPP refuses that lint passes (no error-level
finding: misses); files BehaviorTree.CPP creates on which lint reports an
error (with the codes, to be read: an error can be right where the dummies
are lenient, e.g. a port the real node does not declare); agreement.
Per repository and in total, by the format the file declares.

Usage: acceptance_corpus.py CORPUS [--btfsm PATH] [--json OUT] [--jobs N]
    [--only SUBSTRING]
Requirements: behaviortreepy 0.1.4 (the project's .venv: `make .venv`), a
built btfsm (cargo build --release).
"""

import argparse
import collections
import json
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests" / "differential"))
import accept_btcpp as ac  # noqa: E402


def repo_root(path, corpus):
    """The nearest folder above `path` holding a `.git` entry (else the
    corpus's first-level folder)."""
    p = path.parent
    while p != corpus and p != p.parent:
        if (p / ".git").exists():
            return p
        p = p.parent
    rel = path.relative_to(corpus)
    return corpus / rel.parts[0] if len(rel.parts) > 1 else corpus


def repo_models(root):
    """The repository's model files: *tree_nodes*.xml, and XML files that
    hold only a <TreeNodesModel>."""
    out = []
    for p in sorted(root.rglob("*.xml")):
        if "tree_nodes" in p.name or ac.is_nodes_model_only(ac.parse(p)):
            out.append(p)
    return out


def declared_format(path):
    root = ac.parse(path)
    if root is None:
        return "unparsed"
    return root.get("BTCPP_format") or "none"


# A type the file itself writes in the explicit form with children
# (`<Decorator ID="ForEachString">`, `<Control ID="X">`) is declared by that
# form: the program registers it (MoveIt Pro's ForEachString), so it is
# registered as a dummy of that category, as a model entry would be.
_models_in = ac.models_in


def models_in(root):
    out = _models_in(root)
    if root is not None:
        for el in root.iter():
            kind = ac.local(el.tag)
            if kind in ("Decorator", "Control") and el.get("ID") and len(el):
                out.setdefault(el.get("ID"), kind.lower())
    return out


ac.models_in = models_in

# Format-3 names BehaviorTree.CPP 4 no longer knows (and format 3's Parallel
# ports), which btfsm reads in a file that does not say BTCPP_format="4".
FORMAT3 = ("SequenceStar", "FallbackStar", "RetryUntilSuccesful", "BlackboardCheck",
           "SubTreePlus", "[failure_threshold]", "[success_threshold]", "[threshold]")
# Built-ins of BehaviorTree.CPP 4.10 that the bindings' older 4.x lacks.
NEWER_BUILTINS = ("TryCatch",)
# BehaviorTree.CPP 4.10's load checks (xml_parsing.cpp) that 3.8 lacks.
LOAD_CHECKS_4 = ("Unknown node type: ", "more than one async child",
                 "The tag <BehaviorTree> must have the attribute [ID]",
                 "Missing attribute 'ID' in SubTree")


def explain(r):
    """Why BehaviorTree.CPP and btfsm disagree on a file, when the reason
    is known and not btfsm's error (None otherwise)."""
    err = r["btcpp_error"]
    if any(f"recognized: {n}" in err for n in NEWER_BUILTINS):
        return "bindings older than BehaviorTree.CPP 4.10 (no TryCatch)"
    if any(n in err for n in FORMAT3) and r["format"] != "4":
        return "format-3 file (no BTCPP_format): btfsm reads format 3"
    if any(n in err for n in FORMAT3):
        return "format-3 name in a BTCPP_format=\"4\" file: validate reads it, lint reports it"
    if r["format"] != "4" and any(m in err for m in LOAD_CHECKS_4):
        return ("no BTCPP_format: a load check of BehaviorTree.CPP 4.10 that btfsm applies "
                "only under BTCPP_format=\"4\" (BehaviorTree.CPP 3 loads the file)")
    if "crashed" in err and "Error in script" in err:
        return "created; a script fails on an entry the program sets (BehaviorTree.CPP aborts)"
    if "Node not recognized: " in err and r["custom_with_children"]:
        return "a custom control/decorator no model declares (the program registers it in C++)"
    if "Node not recognized: inverter" in err:
        return "`<inverter>`: btfsm reads the built-in with a warning, lint reports it"
    return None


# The models of each file (a file is checked in one thread; the functions of
# accept_btcpp.py look them up by path).
MODELS = {}
ac.project_models = lambda p: MODELS.get(Path(p).resolve(), [])


def btcpp_verdict(path, root, work):
    b = ac.btcpp(path, work, base=root)
    return {"ok": b["ok"], "error": ac.short(b["error"], 200),
            "tick": ac.short("; ".join(b.get("tick_errors", {}).values()), 200),
            "mode": b["mode"]}


def validate(exe, path):
    return ac.btfsm_validate(exe, path)


def lint(exe, path, root):
    """`btfsm lint FILE` at default settings, from the repository's root
    (its models found as lint finds them)."""
    args = [exe, "lint", str(path.relative_to(root)), "--format", "json"]
    r = subprocess.run(args, capture_output=True, text=True, timeout=ac.WORKER_TIMEOUT,
                       check=False, cwd=root)
    try:
        found = json.loads(r.stdout)
    except json.JSONDecodeError:
        return r.returncode, ["(no JSON: exit %d) %s" % (r.returncode, ac.short(r.stderr, 120))]
    return r.returncode, sorted({f["code"] for f in found if f.get("level") == "error"})


def check(job):
    exe, corpus, path, models, tmp = job
    with tempfile.TemporaryDirectory(dir=tmp) as work:
        b = btcpp_verdict(path, repo_root(path, corpus), Path(work))
    code, why = validate(exe, path)
    lcode, lerrors = lint(exe, path, repo_root(path, corpus))
    bad = b["error"].split("Node not recognized: ", 1)
    custom = len(bad) > 1 and any(
        n > 0 for t, n in ac.node_uses(ac.parse(path)).items() if t == bad[1].split()[0])
    return {"file": str(path.relative_to(corpus)), "custom_with_children": custom, "repo": str(repo_root(path, corpus).relative_to(corpus)),
            "format": declared_format(path), "models": [str(m.relative_to(corpus)) for m in models],
            "btcpp_ok": b["ok"], "btcpp_error": b["error"], "btcpp_tick": b["tick"],
            "validate_exit": code, "validate_error": ac.short(why, 200),
            "lint_exit": lcode, "lint_errors": lerrors}


def verdict(r):
    """valid (created, first tick clean), tick (created, the first tick
    fails: a child count BehaviorTree.CPP checks when the node runs, or an
    entry the program sets), refused (not created), or explained (a
    disagreement whose reason is not btfsm's: `explain`)."""
    if r["btcpp_ok"]:
        return "tick" if r["btcpp_tick"] else "valid"
    return "refused"


def tally(rows):
    t = collections.Counter()
    for r in rows:
        t["files"] += 1
        v, acc, lint_err = verdict(r), r["validate_exit"] == 0, bool(r["lint_errors"])
        why = explain(r)
        t["btcpp_valid"] += v == "valid"
        t["btcpp_tick_fails"] += v == "tick"
        t["btcpp_refuses"] += v == "refused"
        t["validate_accepts"] += acc
        t["crash"] += r["validate_exit"] not in (0, 2)
        t["false_rejections"] += v == "valid" and not acc
        t["false_acceptances"] += v == "refused" and acc and not why
        t["lint_misses"] += v == "refused" and not lint_err and not why
        t["explained"] += v == "refused" and (acc or not lint_err) and bool(why)
        t["lint_errors_on_valid"] += v == "valid" and lint_err
        t["tick_fails_validate_rejects"] += v == "tick" and not acc
        t["agree"] += (v != "refused") == acc if v != "tick" else 1
    return t


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("corpus", type=Path)
    ap.add_argument("--btfsm")
    ap.add_argument("--json")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--only", default="")
    a = ap.parse_args()
    try:
        import behaviortreepy  # noqa: F401, PLC0415
    except ImportError:
        print("acceptance_corpus: needs behaviortreepy (the project's .venv)", file=sys.stderr)
        return 2
    exe = ac.find_btfsm(a.btfsm)
    if not exe:
        print("acceptance_corpus: no btfsm binary (--btfsm PATH)", file=sys.stderr)
        return 2
    corpus = a.corpus.resolve()
    models_of, jobs = {}, []
    tmp = tempfile.mkdtemp(prefix="acceptance-corpus-")
    for p in sorted(corpus.rglob("*.xml")):
        if a.only not in str(p) or ".git" in p.parts:
            continue
        text = p.read_text("utf-8", "replace")
        if "<BehaviorTree" not in text or ac.is_nodes_model_only(ac.parse(p)):
            continue
        root = repo_root(p, corpus)
        if root not in models_of:
            models_of[root] = repo_models(root)
        MODELS[p.resolve()] = models_of[root]
        jobs.append((exe, corpus, p, models_of[root], tmp))
    with ThreadPoolExecutor(max_workers=max(1, a.jobs)) as pool:
        rows = list(pool.map(check, jobs))
    report(rows)
    if a.json:
        Path(a.json).write_text(json.dumps(rows, indent=1))
    return 0


def report(rows):
    by_repo = collections.defaultdict(list)
    for r in rows:
        by_repo[r["repo"].split("/")[0]].append(r)
    cols = ["files", "btcpp_valid", "btcpp_tick_fails", "btcpp_refuses", "validate_accepts",
            "false_rejections", "false_acceptances", "lint_misses", "explained",
            "lint_errors_on_valid", "tick_fails_validate_rejects", "crash"]
    print("| repository | " + " | ".join(cols) + " |")
    print("|---" * (len(cols) + 1) + "|")
    for repo in sorted(by_repo):
        t = tally(by_repo[repo])
        print(f"| {repo} | " + " | ".join(str(t[c]) for c in cols) + " |")
    t = tally(rows)
    print("| **all** | " + " | ".join(str(t[c]) for c in cols) + " |")
    for fmt in sorted({r["format"] for r in rows}):
        ft = tally([r for r in rows if r["format"] == fmt])
        print(f"| BTCPP_format={fmt} | " + " | ".join(str(ft[c]) for c in cols) + " |")
    n = t["files"] - t["btcpp_tick_fails"] or 1
    print(f"\nvalidate agrees with BehaviorTree.CPP on {t['agree'] - t['btcpp_tick_fails']}/{n} "
          f"files it creates or refuses ({100 * (t['agree'] - t['btcpp_tick_fails']) / n:.1f} %)")
    why = collections.Counter()
    for r in rows:
        v, acc, e = verdict(r), r["validate_exit"] == 0, explain(r)
        tag = f"{r['file']} [{r['format']}]"
        if v == "valid" and not acc:
            print(f"FALSE-REJECTION {tag}: {r['validate_error']}")
        if v == "refused" and (acc or not r["lint_errors"]):
            kind = ("FALSE-ACCEPTANCE+LINT-MISS" if acc and not r["lint_errors"] else
                    "FALSE-ACCEPTANCE" if acc else "LINT-MISS")
            if e:
                why[e] += 1
                kind = "EXPLAINED " + kind
            print(f"{kind} {tag}: btcpp: {r['btcpp_error']}" + (f" — {e}" if e else ""))
        if v == "valid" and r["lint_errors"]:
            print(f"LINT-ERROR-ON-VALID {tag}: {' '.join(r['lint_errors'])}")
        if v == "tick":
            print(f"TICK-FAILS {tag} (validate {'accepts' if acc else 'rejects'}): {r['btcpp_tick']}")
    for e, c in why.most_common():
        print(f"explained: {c} x {e}")


if __name__ == "__main__":
    sys.exit(main())
