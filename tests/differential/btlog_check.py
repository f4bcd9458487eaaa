#!/usr/bin/env python3
"""Log oracle: logs that BehaviorTree.CPP 4 itself writes (FileLogger2,
through behaviortreepy) are read exactly by `btfsm log report`.

For each tree (the paper's Figs. 1, 3 and 16a exported by `btfsm convert --to
btcpp-xml`, a tree of built-in controls and decorators, and one with a
SubTree), leaves are
registered as dummies whose outcomes follow a seeded script; the tree is
ticked with a FileLogger attached. This script then parses the raw log
itself (independently: its own reader of the documented layout) and
requires btfsm's JSON to agree: the number of records, per node the status
changes by status and the activations (IDLE to another status), and the
first timestamp. A truncated copy of each log must be refused (exit 2) with
the byte offset of the record cut short.

Usage: btlog_check.py --btfsm PATH [--keep DIR]
"""
import argparse
import json
import os
import random
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
STATUS = {0: "IDLE", 1: "RUNNING", 2: "SUCCESS", 3: "FAILURE", 4: "SKIPPED"}


def parse_raw(data):
    """Our own reader of the layout in BehaviorTree.CPP's bt_file_logger_v2.cpp."""
    assert data[:18] == b"BTCPP4-FileLogger2" and data[18] == 1
    n = struct.unpack_from("<i", data, 19)[0]
    p = 23 + n
    t0 = struct.unpack_from("<q", data, p)[0]
    p += 8
    recs = []
    while p + 9 <= len(data):
        t = int.from_bytes(data[p:p + 6], "little")
        uid = struct.unpack_from("<H", data, p + 6)[0]
        recs.append((t, uid, data[p + 8]))
        p += 9
    assert p == len(data), "trailing bytes"
    return t0, recs


def expected(recs):
    per = {}
    last = {}
    for _t, uid, st in recs:
        d = per.setdefault(uid, {"statuses": {}, "activations": 0})
        name = STATUS[st]
        d["statuses"][name] = d["statuses"].get(name, 0) + 1
        if st != 0 and last.get(uid, 0) == 0:
            d["activations"] += 1
        last[uid] = st
    return per


def make_log(xml_text, leaves, ticks, seed, path):
    import behaviortreepy as bt  # noqa: PLC0415
    rng = random.Random(seed)
    f = bt.BehaviorTreeFactory()
    choices = [bt.NodeStatus.SUCCESS, bt.NodeStatus.FAILURE]
    for name, kind in leaves.items():
        fn = (lambda *_a: rng.choice(choices))
        if kind == "condition":
            f.register_simple_condition(name, fn)
        else:
            f.register_simple_action(name, fn)
    tree = f.create_tree_from_text(xml_text)
    logger = bt.FileLogger(tree, str(path))
    for _ in range(ticks):
        tree.tick_once()
    time.sleep(0.05)
    logger.flush()
    del logger
    time.sleep(0.05)


def leaf_types(xml_text):
    """Leaf tags that BehaviorTree.CPP does not know, as action/condition."""
    import xml.etree.ElementTree as ET  # noqa: PLC0415
    root = ET.fromstring(xml_text)
    known = {"AlwaysSuccess", "AlwaysFailure", "SubTree", "Script", "Sleep", "SetBlackboard"}
    conds = {e.get("ID") for m in root.iter("TreeNodesModel") for e in m if e.tag == "Condition"}
    out = {}
    for t in root.iter("BehaviorTree"):
        for e in t.iter():
            if len(e) == 0 and e.tag not in known and e is not t:
                out[e.tag] = "condition" if e.tag in conds or "Condition" in e.tag or e.tag.startswith("Is") else "action"
    return out


def strip_ports(xml_text):
    # Dummies have no ports: keep name/ID and the reserved attributes only
    # (and no XML declaration, whose attributes are not ports).
    xml_text = re.sub(r"<\?xml[^>]*\?>", "", xml_text)
    return re.sub(r'\s(?!name=|ID=|_|BTCPP_format=|main_tree_to_execute=)[A-Za-z_][\w.-]*="[^"]*"', "", xml_text)


def trees(exe, tmp):
    out = []
    for fig in ["fig01-bt", "fig03-bt", "fig16a-bt"]:
        x = tmp / f"{fig}.xml"
        subprocess.run([exe, "convert", f"policies/paper/{fig}.toml", "--to", "btcpp-xml", "-o", str(x)],
                       cwd=REPO, check=True, capture_output=True)
        text = re.sub(r'\sbtfsm:[\w-]+="[^"]*"', "", x.read_text())
        out.append((fig, strip_ports(text)))
    out.append(("builtins", '<root BTCPP_format="4"><BehaviorTree ID="Main"><ReactiveSequence>'
                '<Inverter><IsBlocked/></Inverter>'
                '<RetryUntilSuccessful num_attempts="3"><Grasp/></RetryUntilSuccessful>'
                '<Parallel success_count="1" failure_count="2"><Look/><Listen/></Parallel>'
                '<Fallback><IsDone/><ForceFailure><Reset/></ForceFailure><Place/></Fallback>'
                '</ReactiveSequence></BehaviorTree></root>'))
    out.append(("subtree", '<root BTCPP_format="4" main_tree_to_execute="Main">'
                '<BehaviorTree ID="Main"><Sequence><SubTree ID="Sub"/><IsOk/></Sequence></BehaviorTree>'
                '<BehaviorTree ID="Sub"><Fallback><IsThere/><Go/></Fallback></BehaviorTree></root>'))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--btfsm", required=True)
    ap.add_argument("--keep", type=Path, help="keep the logs here")
    a = ap.parse_args()
    try:
        import behaviortreepy  # noqa: F401, PLC0415
    except ImportError:
        print("btlog_check: needs behaviortreepy", file=sys.stderr)
        return 2
    exe = str(Path(a.btfsm).resolve())
    tmp = Path(tempfile.mkdtemp(prefix="btlog-"))
    bad = total = 0
    try:
        for name, text in trees(exe, tmp):
            for seed in range(3):
                log = tmp / f"{name}-{seed}.btlog"
                make_log(text, leaf_types(text), 25, seed, log)
                data = log.read_bytes()
                t0, recs = parse_raw(data)
                want = expected(recs)
                r = subprocess.run([exe, "log", "report", str(log), "--format", "json"],
                                   capture_output=True, text=True, timeout=60)
                if r.returncode != 0:
                    print(f"FAIL {log.name}: exit {r.returncode}: {r.stderr[:300]}")
                    bad += 1
                    continue
                got = json.loads(r.stdout)
                gotn = {n["uid"]: {"statuses": n["statuses"], "activations": n["activations"]}
                        for n in got["nodes"] if n["activations"] or n["statuses"]}
                ok = (got["records"] == len(recs) and got["first_timestamp_usec"] == t0 and gotn == want)
                total += 1
                if not ok:
                    bad += 1
                    print(f"FAIL {log.name}: records {got['records']} vs {len(recs)}; "
                          f"nodes differ: {sorted(set(gotn.items()) ^ set(want.items())) if False else ''}")
                    continue
                # A copy cut inside its last record.
                if recs:
                    cut = tmp / f"cut-{log.name}"
                    cut.write_bytes(data[:-4])
                    r = subprocess.run([exe, "log", "report", str(cut)], capture_output=True, text=True)
                    offset = len(data) - 9
                    if r.returncode != 2 or f"byte {offset}:" not in r.stderr:
                        bad += 1
                        print(f"FAIL {cut.name}: exit {r.returncode}, wanted byte {offset}: {r.stderr[:200]}")
                print(f"ok  {log.name}: {len(recs)} records, {len(want)} nodes active")
        if a.keep:
            a.keep.mkdir(parents=True, exist_ok=True)
            for f in tmp.glob("*.btlog"):
                shutil.copy(f, a.keep / f.name)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print(f"btlog_check: {total} logs of BehaviorTree.CPP read exactly, {bad} failures")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
