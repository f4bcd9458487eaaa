#!/bin/sh
# Runs each fuzz target for FUZZ_SECONDS (default 600) with a per-input
# timeout, seeding its corpus from the policies in the repository; the last
# libFuzzer stats line of each run goes to fuzz/logs/TARGET.log. Crashes land
# in fuzz/artifacts/TARGET/ (keep each as a regression test:
# tests/fixtures/fuzz-regressions/, see docs/robustness.md).
# Usage: fuzz/run.sh [TARGET...]   (default: every target in fuzz/Cargo.toml:
# toml_policy, compare, btcpp_xml, scxml, yasmin, flexbe, py_trees_dot, scenario, project, domain)
set -eu
cd "$(dirname "$0")"
SECONDS_EACH=${FUZZ_SECONDS:-600}
TIMEOUT=${FUZZ_TIMEOUT:-10}
RSS=${FUZZ_RSS_MB:-2048}
TARGETS=${*:-$(cargo +nightly fuzz list)}
mkdir -p logs
failed=""
for t in $TARGETS; do
  mkdir -p "corpus/$t"
  case $t in
    compare)
      # Pairs of policies: each paper policy against the next one.
      prev=""
      for f in ../policies/paper/*.toml; do
        [ -n "$prev" ] && { cat "$prev"; printf '\n%%%%\n'; cat "$f"; } > "corpus/$t/seed-$(basename "$f")"
        prev=$f
      done ;;
    toml_policy)
      for f in ../policies/paper/*.toml ../policies/paper/lib/*.toml ../tests/fixtures/valid/*.toml ../tests/fixtures/invalid/*.toml ../tests/fixtures/fuzz-regressions/*; do
        [ -f "$f" ] && cp "$f" "corpus/$t/seed-$(basename "$f")"
      done ;;
    btcpp_xml)
      for f in $(find ../tests/fixtures -name '*.xml' 2>/dev/null); do
        cp "$f" "corpus/$t/seed-$(echo "$f" | tr '/.' '__')"
      done ;;
    scxml)
      for f in $(find ../tests/fixtures -name '*.scxml' 2>/dev/null); do
        cp "$f" "corpus/$t/seed-$(echo "$f" | tr '/.' '__')"
      done ;;
    yasmin)
      for f in $(find ../tests/fixtures/corpus/yasmin -name '*.xml' 2>/dev/null); do
        cp "$f" "corpus/$t/seed-$(echo "$f" | tr '/.' '__')"
      done ;;
    flexbe)
      for f in $(find ../tests/fixtures/flexbe -name '*_sm.py' 2>/dev/null); do
        cp "$f" "corpus/$t/seed-$(echo "$f" | tr '/.' '__')"
      done ;;
    py_trees_dot)
      for f in ../tests/fixtures/py_trees_dot/*.dot; do
        cp "$f" "corpus/$t/seed-$(basename "$f")"
      done ;;
    scenario)
      for f in ../policies/scenarios/*.toml ../tests/fixtures/sim-invalid/*.toml; do
        [ -f "$f" ] && cp "$f" "corpus/$t/seed-$(basename "$f")"
      done ;;
    project)
      # A BT including a parameterised subtree, a scenario with two
      # policies, BehaviorTree.CPP files including each other.
      { sed 's#lib/moma.toml#f1.toml#' ../policies/paper/fig16a-bt.toml; printf '\n%%%%\n'; cat ../policies/paper/lib/moma.toml; } > "corpus/$t/seed-fig16a"
      { sed -e 's#\.\./paper/fig01-bt.toml#f1.toml#' -e 's#\.\./paper/fig04-fsm.toml#f2.toml#' -e 's#\.\./paper/fig02-fsm.toml#sub/f.toml#' ../policies/scenarios/exp1-pick-fails.toml
        printf '\n%%%%\n'; cat ../policies/paper/fig01-bt.toml; printf '\n%%%%\n'; cat ../policies/paper/fig04-fsm.toml; printf '\n%%%%\n'; cat ../policies/paper/fig02-fsm.toml; } > "corpus/$t/seed-exp1"
      printf '<root BTCPP_format="4" main_tree_to_execute="M">\n<include path="f1.xml"/>\n<BehaviorTree ID="M"><Sequence><SubTree ID="S"/><AlwaysSuccess/></Sequence></BehaviorTree>\n</root>\n%%%%\n<root BTCPP_format="4">\n<BehaviorTree ID="S"><Fallback><AlwaysFailure/><AlwaysSuccess/></Fallback></BehaviorTree>\n</root>\n' > "corpus/$t/seed-xml"
      for f in ../tests/fixtures/fuzz-regressions/project-*; do
        [ -f "$f" ] && cp "$f" "corpus/$t/"
      done ;;
    domain)
      for f in ../policies/domains/*.toml ../tests/fixtures/fuzz-regressions/domain-*; do
        [ -f "$f" ] && cp "$f" "corpus/$t/seed-$(basename "$f")"
      done ;;
    *)
      for f in ../tests/fixtures/fuzz-regressions/*; do
        [ -f "$f" ] && cp "$f" "corpus/$t/"
      done ;;
  esac
  dict=""
  [ -f "$t.dict" ] && dict="-dict=$t.dict"
  case $t in toml_policy|compare|scenario|project|domain) dict="-dict=toml.dict" ;; esac
  echo "== fuzzing $t for ${SECONDS_EACH}s"
  nice cargo +nightly fuzz run "$t" "corpus/$t" -- \
    -max_total_time="$SECONDS_EACH" -timeout="$TIMEOUT" -rss_limit_mb="$RSS" \
    -print_final_stats=1 $dict 2>&1 | tee "logs/$t.full.log" | grep -E '^#[0-9]+.*(DONE|pulse)|ERROR|crash|timeout' || true
  grep -E '^#[0-9]+' "logs/$t.full.log" | tail -1 > "logs/$t.log"
  grep -E '^(stat::|Done)' "logs/$t.full.log" >> "logs/$t.log" || true
  cat "logs/$t.log"
  if ls "artifacts/$t"/crash-* "artifacts/$t"/timeout-* "artifacts/$t"/oom-* >/dev/null 2>&1; then
    echo "fuzz: $t found failing inputs in fuzz/artifacts/$t/" >&2
    failed="$failed $t"
  fi
done
if [ -n "$failed" ]; then
  echo "fuzz: failing inputs for:$failed" >&2
  exit 1
fi
