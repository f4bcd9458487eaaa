#!/usr/bin/env python3
"""SARIF oracle: every SARIF log `btfsm lint --format sarif` writes validates
against the official SARIF 2.1.0 JSON schema (tests/fixtures/sarif/), with
the PyPI `jsonschema` validator (draft 4, the schema's own).

Logs checked: the lint fixtures (each bad and good one, so empty and
non-empty result lists), the paper's policies (every rule that fires
there), and a file whose path needs percent-encoding. Exit 0 when all
validate, 1 otherwise, 2 when the check cannot run.

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
    inputs = [[str(p)] for p in sorted((REPO / "tests" / "fixtures" / "lint").rglob("*.*"))]
    inputs.append([str(REPO / "policies" / "paper")])
    tmp = Path(tempfile.mkdtemp(prefix="sarif-"))
    odd = tmp / "fig 03 #1.toml"
    shutil.copy(REPO / "policies" / "paper" / "fig03-bt.toml", odd)
    inputs.append([str(odd)])
    bad = results = 0
    for args in inputs:
        r = subprocess.run([a.btfsm, "lint", *args, "--format", "sarif", "--no-config"],
                           capture_output=True, text=True, cwd=REPO, timeout=120)
        if r.returncode not in (0, 1):
            print(f"FAIL {args}: exit {r.returncode}: {r.stderr[:300]}")
            bad += 1
            continue
        log = json.loads(r.stdout)
        errors = sorted(validator.iter_errors(log), key=lambda e: list(e.path))
        results += len(log["runs"][0]["results"])
        for e in errors[:5]:
            print(f"FAIL {args}: {'/'.join(map(str, e.path))}: {e.message[:200]}")
        bad += bool(errors)
    shutil.rmtree(tmp, ignore_errors=True)
    print(f"sarif_check: {len(inputs)} logs, {results} results, {bad} invalid")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
