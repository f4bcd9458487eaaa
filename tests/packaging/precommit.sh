#!/usr/bin/env bash
# The pre-commit hooks of .pre-commit-hooks.yaml, run as a user's
# repository runs them: a `.pre-commit-config.yaml` naming a snapshot of
# this work tree (its uncommitted changes included) at one commit, run by
# `pre-commit run --all-files` in temporary git repositories. pre-commit
# installs the hooks' environment once into a PRE_COMMIT_HOME shared by
# every run (pip builds the wheel of pyproject.toml: maturin, then cargo
# with the caller's CARGO_TARGET_DIR, so dependencies already built are
# reused). `pre-commit try-repo` does the same with a store of its own per
# call, so one build per call: the runs below share one instead.
# - btfsm-validate and btfsm-lint: pass on good files (a TOML policy, a
#   BehaviorTree.CPP tree, a ROS package.xml and a Cargo.toml, which hold
#   no policy), fail on a node type the tree's model does not declare
#   and on a file that does not load;
# - btfsm-render: writes NAME.svg beside each policy (new files, which the
#   user adds); once they are committed, a change to a policy that changes
#   its drawing fails the hook ("files were modified", as formatters do)
#   until the new drawing is added; without Graphviz's dot it fails
#   saying what to install.
# Prints each step's time. Exit 0 when all pass, 1 otherwise.
#
# Usage: tests/packaging/precommit.sh PRE_COMMIT
#   (PRE_COMMIT: the pre-commit command, e.g. .venv/bin/pre-commit)
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
pc=${1:?usage: precommit.sh PRE_COMMIT}
pc=$(cd "$(dirname "$pc")" && pwd)/$(basename "$pc")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export PRE_COMMIT_HOME=$tmp/cache
export GIT_AUTHOR_NAME=t GIT_AUTHOR_EMAIL=t@example.org GIT_COMMITTER_NAME=t GIT_COMMITTER_EMAIL=t@example.org
start=$(date +%s)

# The hooks' repository: this work tree as it is (tracked and untracked
# files not ignored), one commit.
snap=$tmp/hooks
mkdir -p "$snap"
(cd "$repo" && git ls-files -z --cached --others --exclude-standard \
  | xargs -0 sh -c 'for f do [ -e "$f" ] && printf "%s\0" "$f"; done' sh \
  | tar --null -T - -cf -) | tar -C "$snap" -xf -
git -C "$snap" init -q
git -C "$snap" add -A
git -C "$snap" commit -qm snapshot
rev=$(git -C "$snap" rev-parse HEAD)

cat >"$tmp/config.yaml" <<CONFIG
repos:
  - repo: $snap
    rev: $rev
    hooks:
      - id: btfsm-validate
      - id: btfsm-lint
      - id: btfsm-render
CONFIG

fail=0
try() { # WANTED(pass|fail) HOOK DIR [GREP]
  local want=$1 hook=$2 dir=$3 grep=${4:-} t0 code=0
  t0=$(date +%s)
  (cd "$dir" && "$pc" run "$hook" --all-files --config "$tmp/config.yaml") >"$tmp/out" 2>&1 || code=$?
  local got=pass
  [ "$code" = 0 ] || got=fail
  if [ "$got" != "$want" ] || { [ -n "$grep" ] && ! grep -q -- "$grep" "$tmp/out"; }; then
    echo "FAIL $hook in $(basename "$dir"): $got (exit $code), expected $want${grep:+ with \`$grep\`}"
    tail -30 "$tmp/out"
    fail=1
  else
    echo "ok   $hook in $(basename "$dir"): $want ($(( $(date +%s) - t0 )) s)"
  fi
}
repo_with() { # NAME FILE... (pairs: SOURCE DEST)
  local d=$tmp/$1
  shift
  mkdir -p "$d"
  git -C "$d" init -q
  while [ $# -gt 0 ]; do
    mkdir -p "$(dirname "$d/$2")"
    cp "$1" "$d/$2"
    shift 2
  done
  printf '<?xml version="1.0"?>\n<package format="3"><name>demo</name></package>\n' >"$d/package.xml"
  printf '[package]\nname = "demo"\n' >"$d/Cargo.toml"
  git -C "$d" add -A
  echo "$d"
}
f=$repo/tests/fixtures
# Trees whose node model is in the file (Groot2 saves it so).
good=$(repo_with good "$repo/policies/paper/fig01-bt.toml" policies/fig01.toml \
  "$f/lint/unknown-node-type/good.xml" trees/tree.xml)
unknown=$(repo_with unknown "$f/lint/unknown-node-type/bad.xml" trees/tree.xml)
broken=$(repo_with broken "$repo/policies/paper/fig01-bt.toml" policies/fig01.toml)
mkdir -p "$broken/trees"
printf '<root BTCPP_format="4"><BehaviorTree ID="M">' >"$broken/trees/broken.xml"
git -C "$broken" add -A

t0=$(date +%s)
(cd "$good" && "$pc" install-hooks --config "$tmp/config.yaml") >"$tmp/out" 2>&1 \
  || { echo "FAIL pre-commit install-hooks:"; tail -30 "$tmp/out"; exit 1; }
echo "ok   pre-commit installed the hooks (pip -> maturin -> cargo): $(( $(date +%s) - t0 )) s"
try pass btfsm-validate "$good" "Passed"
try pass btfsm-lint "$good" "Passed"
try fail btfsm-lint "$unknown" "unknown-node-type"
try fail btfsm-validate "$unknown" "ComputePathToPos"
try fail btfsm-validate "$broken" "broken.xml"
try fail btfsm-lint "$broken" "broken.xml"
try pass btfsm-render "$good" "Passed"
for svg in policies/fig01.svg trees/tree.svg; do
  head -c 200 "$good/$svg" 2>/dev/null | grep -q "<svg\|<?xml" || { echo "FAIL btfsm-render wrote no $svg"; fail=1; }
done
[ ! -e "$good/package.svg" ] && [ ! -e "$good/Cargo.svg" ] || { echo "FAIL btfsm-render drew a file that holds no policy"; fail=1; }
# Once the drawings are committed, a changed policy whose drawing changes
# fails the hook, as a formatter does, until the new drawing is added.
git -C "$good" add -A
cp "$repo/policies/paper/fig03-bt.toml" "$good/policies/fig01.toml"
git -C "$good" add -A
try fail btfsm-render "$good" "files were modified by this hook"
git -C "$good" add -A
try pass btfsm-render "$good" "Passed"

# btfsm-render without Graphviz: its entry run with a PATH that has btfsm
# and no dot.
bin=$(find "$PRE_COMMIT_HOME" -path '*/bin/btfsm' -type f | head -1)
mkdir -p "$tmp/nodot"
ln -s "$bin" "$tmp/nodot/btfsm"
entry=$("$(dirname "$pc")/python" - "$repo/.pre-commit-hooks.yaml" <<'EOF'
import shlex, sys, yaml
hooks = {h["id"]: h for h in yaml.safe_load(open(sys.argv[1]))}
print(shlex.split(hooks["btfsm-render"]["entry"])[2])
EOF
)
code=0
(cd "$good" && PATH=$tmp/nodot /bin/sh -c "$entry" btfsm-render policies/fig01.toml) >"$tmp/out" 2>&1 || code=$?
if [ "$code" = 2 ] && grep -q "needs Graphviz dot on PATH" "$tmp/out"; then
  echo "ok   btfsm-render without Graphviz: exit 2, says what to install"
else
  echo "FAIL btfsm-render without Graphviz: exit $code: $(cat "$tmp/out")"
  fail=1
fi
echo "pre-commit hooks: $(( $(date +%s) - start )) s in all"
exit $fail
