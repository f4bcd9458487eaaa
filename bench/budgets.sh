#!/bin/sh
# Budget overshoot (docs/robustness.md "Budgets"): per-mode `millis` of
# `compare --format json --timeout-ms T` on the random pairs written by
# bench/budgets_gen.py, and the wall time of `sim --runs --timeout-ms T`
# against T. Uses the release binary; takes about a minute. Not run by
# `make test`.
# Wall times include starting the process and reading the inputs.
#
# usage: bench/budgets.sh [compare|sim]   (default: both)
set -eu
cd "$(dirname "$0")/.."
cargo build --release --locked --quiet
B=target/release/btfsm
DIR=${BUDGET_DIR:-/tmp/btfsm-budget-pairs}
python3 bench/budgets_gen.py "$DIR"
what=${1:-all}

if [ "$what" = all ] || [ "$what" = compare ]; then
  echo "pair T_ms structural_ms labeled_ms named_ms wall_s"
  for p in fsm500 fsm2000 bt5000 bt100000; do
    for T in 20 100 1000; do
      s=$(date +%s.%N)
      $B compare "$DIR/$p-a.toml" "$DIR/$p-b.toml" --timeout-ms "$T" --format json > "$DIR/out.json" 2> "$DIR/err.txt"
      e=$(date +%s.%N)
      python3 - "$DIR/out.json" "$p" "$T" "$s" "$e" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
for m in ("structural", "labeled", "named"):
    r = d[m]
    assert r["lower_bound"] <= r["upper_bound"] == r["ged"], m
print(sys.argv[2], sys.argv[3], *(d[m]["millis"] for m in ("structural", "labeled", "named")),
      "%.2f" % (float(sys.argv[5]) - float(sys.argv[4])))
PY
    done
  done
fi

if [ "$what" = all ] || [ "$what" = sim ]; then
  # exp1-nominal with a step budget of 10^6 and a disturbance that never
  # fires, so that no run ends before 10^6 steps (about 4 x 10^6 steps an
  # episode): far more work than any of the budgets allows (as in
  # tests/cli/sim.rs).
  # The policies go beside it: files a scenario names stay inside its root.
  cp policies/paper/fig01-bt.toml policies/paper/fig02-fsm.toml policies/paper/fig04-fsm.toml "$DIR/"
  sed -e "s#file = \"../paper/#file = \"#" -e 's/^seed = /max_steps = 1000000\nseed = /' \
    policies/scenarios/exp1-nominal.toml > "$DIR/sim-huge.toml"
  printf '\n[[disturbances]]\nat = 1000000000.0\nbattery = 100.0\n' >> "$DIR/sim-huge.toml"
  echo "T_ms sim_millis wall_ms episodes_completed exit    (--runs 1000)"
  for T in 20 100 1000; do
    s=$(date +%s%N)
    code=0
    $B sim "$DIR/sim-huge.toml" --runs 1000 --timeout-ms "$T" --format json > "$DIR/sim.json" || code=$?
    e=$(date +%s%N)
    python3 - "$DIR/sim.json" "$T" "$s" "$e" "$code" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
assert d["budget"]["exhausted"], d["budget"]
print(sys.argv[2], d["millis"], (int(sys.argv[4]) - int(sys.argv[3])) // 1000000,
      d["runs"], sys.argv[5])
PY
  done
  echo "T_ms sim_millis wall_ms outcomes:steps    (one run per policy)"
  for T in 20 100 1000; do
    s=$(date +%s%N)
    $B sim "$DIR/sim-huge.toml" --timeout-ms "$T" --format json > "$DIR/sim.json"
    e=$(date +%s%N)
    python3 - "$DIR/sim.json" "$T" "$s" "$e" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
print(sys.argv[2], d["budget"]["millis"], (int(sys.argv[4]) - int(sys.argv[3])) // 1000000,
      " ".join("%s:%d" % (p["outcome"], p["steps"]) for p in d["policies"]))
PY
  done
fi
