#!/usr/bin/env python3
"""JUnit oracle: every report `btfsm lint --format junit` writes is read by
the tools its users read it with, and they count what `lint` found.

Readers: Python's `xml.etree` (a well-formed XML 1.0 document, which
GitLab's and Jenkins's parsers need first), PyPI `junitparser` (the
testsuite and testcase model many CI plugins use) and PyPI
`colcon-test-result` (what `colcon test-result` runs on a ROS workspace:
its counts and its `--verbose` lines). Reports checked: every lint fixture
(bad and good), the fixture folders, the paper's policies, the Nav2 layout
of tests/fixtures/lint-real/, a file that does not load, and a file whose
name carries XML markup, quotes and control characters. For each, against
`lint --format json` of the same inputs (btfsm's own findings, not the
report): one testcase per file, a `failure` exactly for the files with an
error finding, an `error` exactly for the files that do not load (exit 2),
counts on the suite equal to the testcases' and to colcon's summary, and
every error finding's message in its testcase's failure. Exit 0 when all
agree, 1 otherwise, 2 when the check cannot run.

Usage: junit_check.py --btfsm PATH
"""
import argparse
import json
import re
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def inputs(tmp):
    lint_dir = REPO / "tests" / "fixtures" / "lint"
    out = [[str(p)] for p in sorted(lint_dir.rglob("*.*"))]
    out += [[str(p)] for p in sorted(lint_dir.glob("*/*")) if p.is_dir()]
    out.append([str(REPO / "policies" / "paper")])
    out.append([str(REPO / "tests" / "fixtures" / "lint-real" / "nav2")])
    odd = tmp / "fig <03> & \"q\" \x1b[31m.toml"
    shutil.copy(REPO / "policies" / "paper" / "fig03-bt.toml", odd)
    broken = tmp / "broken.xml"
    broken.write_text('<root BTCPP_format="4"><BehaviorTree ID="M">')
    out.append([str(odd)])
    out.append([str(broken), str(odd), str(REPO / "policies" / "paper" / "fig01-bt.toml")])
    return out


def run(btfsm, args, fmt):
    r = subprocess.run([btfsm, "lint", *args, "--format", fmt, "--no-config"],
                       capture_output=True, text=True, cwd=REPO, timeout=120)
    return r.returncode, r.stdout, r.stderr


def shown(name):
    """A name as btfsm prints it: control characters as Rust escapes."""
    return "".join(f"\\u{{{ord(c):x}}}" if ord(c) < 0x20 or 0x7f <= ord(c) <= 0x9f else c
                   for c in name)


def not_linted(stderr):
    """How many files lint says it did not lint (on stderr)."""
    m = re.search(r"(\d+) files? not linted", stderr)
    return int(m.group(1)) if m else 0


def colcon_counts(xml_text, tmp):
    """colcon test-result's summary line and verbose lines for the report."""
    base = tmp / "colcon"
    shutil.rmtree(base, ignore_errors=True)
    (base / "pkg").mkdir(parents=True)
    (base / "pkg" / "btfsm-lint.xml").write_text(xml_text, "utf-8")
    colcon = Path(sys.executable).parent / "colcon"
    r = subprocess.run([str(colcon), "test-result", "--test-result-base", str(base), "--verbose"],
                       capture_output=True, text=True, timeout=120)
    summary = [ln for ln in r.stdout.splitlines() if ln.startswith("Summary:")]
    return r.returncode, (summary[0] if summary else r.stdout + r.stderr), r.stdout


def check(args, btfsm, tmp, junitparser):
    """The problems with the report of `args` (an empty list when none)."""
    code, xml_text, stderr = run(btfsm, args, "junit")
    jcode, js, _ = run(btfsm, args, "json")
    problems = []
    if code not in (0, 1, 2) or code != jcode:
        return [f"exit {code} (json: {jcode})"]
    try:
        root = ET.fromstring(xml_text)
    except ET.ParseError as e:
        return [f"not well-formed XML: {e}"]
    findings = json.loads(js)
    errors_by_file = {}
    for f in findings:
        if f["level"] == "error":
            errors_by_file.setdefault(shown(f["file"]), []).append(f)
    loads_not = {shown(f["file"]) for f in findings if f["code"] == "load-error"}
    xml = junitparser.JUnitXml.fromstring(xml_text.encode("utf-8"))
    suites = list(xml)
    if len(suites) != 1:
        return [f"{len(suites)} testsuites"]
    suite = suites[0]
    cases = list(suite)
    names = [c.name for c in cases]
    if len(set(names)) != len(names):
        problems.append(f"a file is two testcases: {names}")
    failed, errored = set(), set()
    for c in cases:
        kinds = {type(r).__name__ for r in c.result}
        if "Failure" in kinds:
            failed.add(c.name)
        if "Error" in kinds:
            errored.add(c.name)
        for f in errors_by_file.get(c.name, []):
            texts = " ".join((r.text or "") + (r.message or "") for r in c.result)
            if shown(f["message"]) not in texts:
                problems.append(f"{c.name}: error `{f['message'][:80]}` not in its testcase")
    want_failed = {f for f in errors_by_file if f not in errored}
    if failed != want_failed:
        problems.append(f"failures {sorted(failed)} != files with errors {sorted(want_failed)}")
    if not loads_not <= errored:
        problems.append(f"load errors {sorted(loads_not)} not all testcase errors {sorted(errored)}")
    if not_linted(stderr) != len(errored):
        problems.append(f"{not_linted(stderr)} files not linted but {len(errored)} testcase errors")
    if code == 2 and not errored and not stderr:
        problems.append("exit 2 and no testcase error")
    for node in (suite, xml):
        if (node.tests, node.failures, node.errors) != (len(cases), len(failed), len(errored)):
            problems.append(f"counts {node.tests}/{node.failures}/{node.errors} != "
                            f"{len(cases)}/{len(failed)}/{len(errored)}")
    rc, summary, verbose = colcon_counts(xml_text, tmp)
    want = (f"Summary: {len(cases)} test{'s' if len(cases) != 1 else ''}, {len(errored)} error{'s' if len(errored) != 1 else ''}, "
            f"{len(failed)} failure{'s' if len(failed) != 1 else ''}, 0 skipped")
    if summary != want:
        problems.append(f"colcon: {summary!r}, expected {want!r}")
    if (rc != 0) != bool(failed or errored):
        problems.append(f"colcon exit {rc} with {len(failed)} failures, {len(errored)} errors")
    for name in failed | errored:
        if f"btfsm.lint {name}" not in verbose.replace("\n", " ") and "\x1b" not in name:
            problems.append(f"colcon --verbose does not name {name}")
    return problems


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--btfsm", required=True)
    a = ap.parse_args()
    try:
        import junitparser  # noqa: PLC0415
    except ImportError:
        print("junit_check: needs junitparser and colcon-test-result "
              "(tests/differential/requirements.txt)", file=sys.stderr)
        return 2
    tmp = Path(tempfile.mkdtemp(prefix="junit-"))
    bad = reports = 0
    try:
        for args in inputs(tmp):
            reports += 1
            problems = check(args, a.btfsm, tmp, junitparser)
            for p in problems[:5]:
                print(f"FAIL {[Path(x).name for x in args]}: {p}")
            bad += bool(problems)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print(f"junit_check: {reports} reports read by xml.etree, junitparser and colcon, {bad} disagree")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
