#!/bin/sh
# Ticks the 80-node five-cube BT with btfsm and with py_trees in the same run
# and prints the ratio; also the simulation speed and the time of 1,000 Monte
# Carlo episodes of exp4-five-cubes. Installs py_trees from PyPI into a venv.
set -eu
cd "$(dirname "$0")/.."
VENV=${VENV:-/tmp/btfsm-py-trees-venv}
[ -x "$VENV/bin/python" ] || python3 -m venv "$VENV"
"$VENV/bin/pip" install -q py_trees
PY=$("$VENV/bin/python" bench/py_trees_tick.py 20000)
RS=$(cargo bench --locked --bench sim 2>/dev/null)
echo "$PY"
echo "$RS"
py=$(echo "$PY" | awk '/py_trees_ticks_per_s/ {print $2}')
rs=$(echo "$RS" | awk '/btfsm_bt_ticks_per_s/ {print $2}')
tr=$(echo "$RS" | awk '/btfsm_bt_traced_ticks_per_s/ {print $2}')
echo "ratio_btfsm_over_py_trees $(awk "BEGIN {printf \"%.0f\", $rs / $py}")"
sw=$(echo "$RS" | awk '/btfsm_bt_stack_walk_ticks_per_s/ {print $2}')
echo "ratio_btfsm_traced_over_py_trees $(awk "BEGIN {printf \"%.0f\", $tr / $py}")"
echo "ratio_btfsm_stack_walk_over_py_trees $(awk "BEGIN {printf \"%.0f\", $sw / $py}")"
