#!/usr/bin/env bash
# Peak memory of `btfsm analyze DIR` on a folder of many small policies
# (issue 34: memory bounded by the largest file, not the count).
#
# Writes COUNT copies of a small Behavior Tree (TOML, 11 nodes, each with its
# own name) into a temporary folder (100,000 entries is the walk's limit,
# `discover::MAX_WALK_ENTRIES`), then runs
# `btfsm analyze DIR --format FORMAT > /dev/null` under GNU time and prints
# the count, the wall and CPU time and the peak RSS.
#
# Usage: bench/analyze_many.sh BTFSM [COUNT] [FORMAT]   (default 100000 json)
set -euo pipefail
BTFSM=${1:?usage: bench/analyze_many.sh BTFSM [COUNT] [FORMAT]}
COUNT=${2:-100000}
FORMAT=${3:-json}
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
DIR=$WORK/policies
mkdir "$DIR"
python3 - "$DIR" "$COUNT" <<'PY'
import os, sys
d, n = sys.argv[1], int(sys.argv[2])
tmpl = '''kind = "bt"
name = "many {i}"
root = "root"

[nodes]
root = {{ fallback = ["done", "work"] }}
done = {{ condition = "Done{i}" }}
work = {{ sequence = ["pick", "check", "place"] }}
pick = {{ fallback = ["holding", "grasp"] }}
holding = {{ condition = "Holding" }}
grasp = {{ action = "Grasp" }}
check = {{ condition = "InReach" }}
place = {{ fallback = ["placed", "put"] }}
placed = {{ condition = "Placed" }}
put = {{ action = "Put" }}
'''
for i in range(n):
    with open(os.path.join(d, f"p{i:06d}.toml"), "w") as f:
        f.write(tmpl.format(i=i))
PY
/usr/bin/time -f "%e %U %S %M" -o "$WORK/time" "$BTFSM" analyze "$DIR" --format "$FORMAT" --max-total-nodes 100000000 > /dev/null
read -r wall user sys rss < "$WORK/time"
echo "analyze $COUNT files ($FORMAT): ${wall} s wall, $(echo "$user + $sys" | bc) s CPU, peak RSS $((rss / 1024)) MB"
