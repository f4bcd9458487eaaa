#!/usr/bin/env python3
"""A SqliteLogger `.db3` made from runs of BehaviorTree.CPP 4, and
`btfsm log report` checked against SQL counts of it.

behaviortreepy (the PyPI bindings used for logs) has no SqliteLogger, so
this script writes the database itself with Python's sqlite3, in the schema
of BehaviorTree.CPP's src/loggers/bt_sqlite_logger.cpp (read at commit
0ce11efc03ea35052f4b517adecbc7a67488a7a2): tables Definitions, Nodes and
Transitions, one session per run, the tree XML the FileLogger2 log embeds,
and per record of that log one transition whose timestamp is the absolute
time in µs made strictly increasing (as the logger does: max(previous + 1,
t)). The runs are the FileLogger2 logs BehaviorTree.CPP wrote for
tests/fixtures/logs/ (compare-nominal.btlog, then compare-pick-fails.btlog).

Then, per session, `btfsm log report X.db3 --session N --format json` must
give per node the status changes that `SELECT uid, state, COUNT(*) ...
GROUP BY uid, state` gives, and as many records as the session's rows.

Usage: btlog_db3.py --btfsm PATH [--keep DIR]
"""
import argparse
import json
import shutil
import sqlite3
import struct
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
LOGS = ["compare-nominal.btlog", "compare-pick-fails.btlog"]
STATUS = {0: "IDLE", 1: "RUNNING", 2: "SUCCESS", 3: "FAILURE", 4: "SKIPPED"}
SCHEMA = """
CREATE TABLE IF NOT EXISTS Transitions (timestamp INTEGER PRIMARY KEY NOT NULL,
  session_id INTEGER NOT NULL, uid INTEGER NOT NULL, duration INTEGER,
  state INTEGER NOT NULL, metadata VARCHAR);
CREATE TABLE IF NOT EXISTS Nodes (session_id INTEGER NOT NULL, fullpath VARCHAR,
  uid INTEGER NOT NULL);
CREATE TABLE IF NOT EXISTS Definitions (session_id INTEGER PRIMARY KEY AUTOINCREMENT,
  date TEXT NOT NULL, xml_tree TEXT NOT NULL);
"""


def read_btlog(data):
    assert data[:18] == b"BTCPP4-FileLogger2" and data[18] == 1
    n = struct.unpack_from("<i", data, 19)[0]
    xml = data[23:23 + n].decode()
    p = 23 + n
    t0 = struct.unpack_from("<q", data, p)[0]
    p += 8
    recs = []
    while p + 9 <= len(data):
        t = int.from_bytes(data[p:p + 6], "little")
        recs.append((t0 + t, struct.unpack_from("<H", data, p + 6)[0], data[p + 8]))
        p += 9
    return xml, recs


def write_db3(path):
    db = sqlite3.connect(path)
    db.executescript(SCHEMA)
    last = 0
    for i, name in enumerate(LOGS):
        xml, recs = read_btlog((REPO / "tests/fixtures/logs" / name).read_bytes())
        cur = db.execute("INSERT INTO Definitions (date, xml_tree) VALUES (?, ?)",
                         (f"2026-11-2{i} 10:00:00", xml))
        sid = cur.lastrowid
        started = {}
        for t, uid, st in recs:
            last = max(last + 1, t)
            dur = 0
            if st == 1:
                started[uid] = last
            elif uid in started:
                dur = last - started.pop(uid)
            db.execute("INSERT INTO Transitions VALUES (?, ?, ?, ?, ?, NULL)", (last, sid, uid, dur, st))
    db.commit()
    db.close()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--btfsm", required=True)
    ap.add_argument("--keep", type=Path)
    a = ap.parse_args()
    exe = str(Path(a.btfsm).resolve())
    tmp = Path(tempfile.mkdtemp(prefix="btlog-db3-"))
    bad = 0
    try:
        db3 = tmp / "sessions.db3"
        write_db3(db3)
        db = sqlite3.connect(db3)
        for sid in (1, 2):
            want = {}
            for uid, st, k in db.execute(
                    "SELECT uid, state, COUNT(*) FROM Transitions WHERE session_id = ? GROUP BY uid, state", (sid,)):
                want.setdefault(uid, {})[STATUS[st]] = k
            rows = db.execute("SELECT COUNT(*) FROM Transitions WHERE session_id = ?", (sid,)).fetchone()[0]
            r = subprocess.run([exe, "log", "report", str(db3), "--session", str(sid), "--format", "json"],
                               capture_output=True, text=True, timeout=60)
            if r.returncode != 0:
                print(f"session {sid}: exit {r.returncode}: {r.stderr}")
                bad += 1
                continue
            v = json.loads(r.stdout)
            got = {n["uid"]: n["statuses"] for n in v["nodes"] if n["statuses"]}
            ok = got == want and v["records"] == rows and v["session"] == sid
            print(f"session {sid}: {rows} transitions, {len(want)} nodes {'ok' if ok else 'WRONG'}")
            bad += not ok
        db.close()
        if a.keep:
            a.keep.mkdir(parents=True, exist_ok=True)
            shutil.copy(db3, a.keep / "sessions.db3")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print(f"btlog_db3: {'ok' if not bad else f'{bad} wrong'}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
