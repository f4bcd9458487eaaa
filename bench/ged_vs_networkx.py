#!/usr/bin/env python3
"""btfsm vs NetworkX on graph edit distance, measured in one run.

Runs `cargo bench --bench ged`, which times btfsm's exact structural GED on the
paper's policy pairs (SPEC §5, plus the HFSMs converted from the BT pairs) and on
50 seeded random loop-free pairs of 8-12 vertices, and writes the graphs; then
times NetworkX's `graph_edit_distance` (the paper's tool, installed from PyPI
if missing) on the same graphs as MultiDiGraphs, and prints per pair both
values, both times and the speed-up.

NetworkX runs with a per-pair timeout, after which it returns the best value
it has found (not a proven minimum): such pairs are marked `timeout`.
NetworkX mis-scores self-loops (networkx #5400, #8188), so its values are
compared with btfsm's only on loop-free pairs.

Usage: python3 bench/ged_vs_networkx.py [--paper-timeout S] [--random-timeout S]
       [--skip-cargo] [--json OUT]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def ensure_networkx():
    try:
        import networkx, numpy, scipy  # noqa: F401
    except ImportError:
        # graph_edit_distance needs numpy and scipy (its assignment solver).
        subprocess.check_call([sys.executable, "-m", "pip", "install", "--quiet", "networkx", "numpy", "scipy"])
    import networkx
    return networkx


def to_nx(nx, g):
    h = nx.MultiDiGraph()
    h.add_nodes_from(range(g["n"]))
    h.add_edges_from((t, v) for t, v in g["arcs"])
    return h


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--paper-timeout", type=float, default=120.0)
    ap.add_argument("--random-timeout", type=float, default=60.0)
    ap.add_argument("--skip-cargo", action="store_true", help="reuse target/ged-pairs.json")
    ap.add_argument("--json", help="also write the measurements here")
    args = ap.parse_args()

    pairs_file = os.path.join(ROOT, "target", "ged-pairs.json")
    if not args.skip_cargo:
        subprocess.check_call(["cargo", "bench", "--locked", "--bench", "ged", "--", pairs_file], cwd=ROOT)
    with open(pairs_file) as f:
        pairs = json.load(f)["pairs"]

    nx = ensure_networkx()
    print(f"\nNetworkX {nx.__version__}, Python {sys.version.split()[0]}")
    print(f"{'pair':44} {'btfsm':>5} {'nx':>5} {'btfsm ms':>10} {'nx ms':>10} {'speed-up':>10}  note")
    rows = []
    for p in pairs:
        timeout = args.paper_timeout if p["group"] == "paper" else args.random_timeout
        g1, g2 = to_nx(nx, p["a"]), to_nx(nx, p["b"])
        t0 = time.perf_counter()
        value = nx.graph_edit_distance(g1, g2, timeout=timeout)
        nx_s = time.perf_counter() - t0
        finished = nx_s < timeout
        ours = p["btfsm"]
        notes = []
        if not finished:
            notes.append("timeout")
        value = None if value is None else int(value)
        if value != ours["ged"]:
            if p["self_loops"]:
                notes.append("differs (NetworkX mis-scores self-loops)")
            elif not finished:
                notes.append("differs (NetworkX stopped early)")
            else:
                notes.append("DIFFERS")
        ratio = nx_s / ours["seconds"] if ours["seconds"] > 0 else float("inf")
        rows.append({"name": p["name"], "group": p["group"], "btfsm": ours["ged"], "networkx": value,
                     "btfsm_s": ours["seconds"], "networkx_s": nx_s, "finished": finished,
                     "self_loops": p["self_loops"], "speedup": ratio})
        print(f"{p['name']:44} {ours['ged']:>5} {str(value):>5} {ours['seconds']*1e3:>10.3f} "
              f"{nx_s*1e3:>10.1f} {ratio:>9.0f}x  {', '.join(notes)}", flush=True)

    print()
    for group in ("paper", "random"):
        g = [r for r in rows if r["group"] == group]
        done = [r for r in g if r["finished"]]
        worst = max(r["btfsm_s"] for r in g) * 1e3
        line = f"{group}: {len(g)} pairs, btfsm slowest {worst:.3f} ms; NetworkX finished {len(done)}"
        if done:
            line += f", median speed-up on those {statistics.median(r['speedup'] for r in done):.0f}x"
            wrong = [r for r in done if r["networkx"] != r["btfsm"] and not r["self_loops"]]
            line += f", loop-free disagreements {len(wrong)}"
        print(line)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
