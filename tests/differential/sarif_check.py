#!/usr/bin/env python3
"""SARIF oracle: every SARIF log `btfsm lint --format sarif` writes validates
against the official SARIF 2.1.0 JSON schema (tests/fixtures/sarif/), with
the PyPI `jsonschema` validator (draft 4, the schema's own).

Logs checked: the lint fixtures (each bad and good one, so empty and
non-empty result lists; each file of a folder fixture alone, which does not
load), the fixture folders, the paper's policies (every rule that fires
there), the Nav2 layout of tests/fixtures/lint-real/, a file that does not
load, and a file whose path needs percent-encoding. Besides the schema:
every log has one invocation, which is not successful when lint exits 2
(a file not linted), with a `load-error` result and a notification naming
the file. Exit 0 when all validate, 1 otherwise, 2 when the check cannot
run.

Usage: sarif_check.py --btfsm PATH
"""
import argparse
import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
SCHEMA = REPO / "tests" / "fixtures" / "sarif" / "sarif-schema-2.1.0.json"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--btfsm", required=True)
    a = ap.parse_args()
    try:
        import jsonschema  # noqa: PLC0415
    except ImportError:
        print("sarif_check: needs jsonschema (pip install jsonschema)", file=sys.stderr)
        return 2
    schema = json.loads(SCHEMA.read_text("utf-8"))
    validator = jsonschema.Draft4Validator(schema, format_checker=jsonschema.FormatChecker())
    lint_dir = REPO / "tests" / "fixtures" / "lint"
    inputs = [[str(p)] for p in sorted(lint_dir.rglob("*.*"))]
    inputs += [[str(p)] for p in sorted(lint_dir.glob("*/*")) if p.is_dir()]
    inputs.append([str(REPO / "policies" / "paper")])
    inputs.append([str(REPO / "tests" / "fixtures" / "lint-real" / "nav2")])
    tmp = Path(tempfile.mkdtemp(prefix="sarif-"))
    odd = tmp / "fig 03 #1.toml"
    shutil.copy(REPO / "policies" / "paper" / "fig03-bt.toml", odd)
    inputs.append([str(odd)])
    broken = tmp / "broken.xml"
    broken.write_text('<root BTCPP_format="4"><BehaviorTree ID="M">')
    inputs.append([str(broken), str(odd)])
    bad = results = 0
    for args in inputs:
        r = subprocess.run([a.btfsm, "lint", *args, "--format", "sarif", "--no-config"],
                           capture_output=True, text=True, cwd=REPO, timeout=120)
        if r.returncode not in (0, 1, 2):
            print(f"FAIL {args}: exit {r.returncode}: {r.stderr[:300]}")
            bad += 1
            continue
        log = json.loads(r.stdout)
        errors = sorted(validator.iter_errors(log), key=lambda e: list(e.path))
        results += len(log["runs"][0]["results"])
        for e in errors[:5]:
            print(f"FAIL {args}: {'/'.join(map(str, e.path))}: {e.message[:200]}")
        bad += bool(errors) or not invocation_ok(args, r.returncode, log["runs"][0])
    shutil.rmtree(tmp, ignore_errors=True)
    print(f"sarif_check: {len(inputs)} logs, {results} results, {bad} invalid")
    return 1 if bad else 0


def invocation_ok(args, code, run):
    """One invocation; a run that exits 2 did not lint a file: the
    invocation is not successful and says which, and a `load-error` result
    is there."""
    invs = run.get("invocations", [])
    if len(invs) != 1:
        print(f"FAIL {args}: {len(invs)} invocations")
        return False
    inv = invs[0]
    if code == 2:
        notes = inv.get("toolExecutionNotifications", [])
        named = any("was not linted" in n["message"]["text"] for n in notes)
        loaded = any(x["ruleId"] == "load-error" for x in run["results"])
        if inv["executionSuccessful"] or not named or not loaded:
            print(f"FAIL {args}: exit 2, but the log says every file was linted")
            return False
    return True


if __name__ == "__main__":
    sys.exit(main())
