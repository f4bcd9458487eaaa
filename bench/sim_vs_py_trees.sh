#!/bin/sh
# Ticks the 80-node five-cube BT with btfsm and with py_trees in the same run
# and prints the ratio; also the simulation speed and the time of 1,000 Monte
# Carlo episodes of exp4-five-cubes; and with BehaviorTree.CPP 4 (its Python
# bindings, tick_exactly_once, built-in leaves) as a second anchor. Installs
# py_trees and the pinned behaviortreepy from PyPI into a venv.
set -eu
cd "$(dirname "$0")/.."
VENV=${VENV:-/tmp/btfsm-py-trees-venv}
[ -x "$VENV/bin/python" ] || python3 -m venv "$VENV"
"$VENV/bin/pip" install -q py_trees -r tests/differential/requirements.txt
PY=$("$VENV/bin/python" bench/py_trees_tick.py 20000)
CPP=$("$VENV/bin/python" bench/btcpp_tick.py 200000)
RS=$(cargo bench --locked --bench sim 2>/dev/null)
echo "$PY"
echo "$CPP"
echo "$RS"
py=$(echo "$PY" | awk '/py_trees_ticks_per_s/ {print $2}')
rs=$(echo "$RS" | awk '/btfsm_bt_ticks_per_s/ {print $2}')
tr=$(echo "$RS" | awk '/btfsm_bt_traced_ticks_per_s/ {print $2}')
echo "ratio_btfsm_over_py_trees $(awk "BEGIN {printf \"%.0f\", $rs / $py}")"
sw=$(echo "$RS" | awk '/btfsm_bt_stack_walk_ticks_per_s/ {print $2}')
echo "ratio_btfsm_traced_over_py_trees $(awk "BEGIN {printf \"%.0f\", $tr / $py}")"
echo "ratio_btfsm_stack_walk_over_py_trees $(awk "BEGIN {printf \"%.0f\", $sw / $py}")"
cpp=$(echo "$CPP" | awk '/btcpp_ticks_per_s/ {print $2}')
echo "ratio_btfsm_over_btcpp $(awk "BEGIN {printf \"%.0f\", $rs / $cpp}")"
