#!/usr/bin/env bash
# The wheel `pip install btfsm` installs (pyproject.toml, maturin
# `bindings = "bin"`, `python-source = "python"`), installed into a fresh venv
# and run with no Rust toolchain on PATH: `btfsm --version`, `import btfsm`
# (the Python module beside the binary), `btfsm lint` on a bad and a good
# fixture (exit 1 and 0), and — when the binary has the `review` command —
# `btfsm review` on a temporary repository of two commits. Prints the
# wheel's size. Exit 0 when all pass, 1 otherwise.
#
# Usage: tests/packaging/wheel.sh WHEEL_DIR
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
wheel_dir=${1:?usage: wheel.sh WHEEL_DIR}
shopt -s nullglob
wheels=("$wheel_dir"/btfsm-*.whl)
if [ ${#wheels[@]} -ne 1 ]; then
  echo "wheel.sh: expected one btfsm wheel in $wheel_dir, found ${#wheels[@]}" >&2
  exit 1
fi
wheel=${wheels[0]}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
python3 -m venv "$tmp/venv"
"$tmp/venv/bin/pip" install --quiet --disable-pip-version-check --no-index --no-deps "$wheel"

# Everything below runs with an environment of nothing but a PATH of the
# venv and the system folders: no ~/.cargo/bin, no RUSTUP_HOME.
clean() {
  env -i HOME="$tmp" PATH="$tmp/venv/bin:/usr/local/bin:/usr/bin:/bin" LANG=C.UTF-8 "$@"
}
fail=0
check() { # NAME WANTED_EXIT COMMAND...
  local name=$1 want=$2
  shift 2
  local code=0
  clean "$@" >"$tmp/out" 2>"$tmp/err" || code=$?
  if [ "$code" = "$want" ]; then
    echo "ok   $name (exit $code)"
  else
    echo "FAIL $name: exit $code, expected $want"
    head -20 "$tmp/out" "$tmp/err"
    fail=1
  fi
}
if clean sh -c 'command -v cargo || command -v rustc'; then
  echo "FAIL cargo or rustc is on the clean PATH"
  fail=1
fi
check "btfsm on PATH is the venv's" 0 sh -c "test \"\$(command -v btfsm)\" = '$tmp/venv/bin/btfsm'"
check "python -c 'import btfsm'" 0 python -c 'import btfsm; btfsm.from_py_trees; btfsm.from_smach; btfsm.ExportError'
check "btfsm --version" 0 btfsm --version
grep -q "^btfsm $(sed -n 's/^version = "\(.*\)"/\1/p' "$repo/Cargo.toml" | head -1)\$" "$tmp/out" \
  || { echo "FAIL --version printed: $(cat "$tmp/out")"; fail=1; }
bad=$repo/tests/fixtures/lint/chattering-precondition-order/bad.toml
good=$repo/policies/paper/fig01-bt.toml
check "btfsm lint (an error finding)" 1 btfsm lint --no-config "$bad"
grep -q "error\[chattering-precondition-order\]" "$tmp/out" || { echo "FAIL lint output"; fail=1; }
check "btfsm lint (clean)" 0 btfsm lint --no-config "$good"
check "btfsm lint --format junit" 1 btfsm lint --no-config --format junit "$bad" "$good"

if clean btfsm review --help >/dev/null 2>&1; then
  # Two commits: the base has Fig. 1, the head edits it and adds Fig. 3.
  r=$tmp/repo
  mkdir -p "$r/policies"
  cp "$good" "$r/policies/task.toml"
  g() { clean git -C "$r" -c user.name=t -c user.email=t@example.org "$@" >/dev/null; }
  g init -q -b main
  g add -A
  g commit -qm base
  cp "$repo/policies/paper/fig03-bt.toml" "$r/policies/task.toml"
  cp "$repo/policies/paper/fig04-fsm.toml" "$r/policies/new.toml"
  g add -A
  g commit -qm head
  code=0
  clean sh -c "cd '$r' && btfsm review --base HEAD~1 --head HEAD --format markdown" >"$tmp/out" 2>"$tmp/err" || code=$?
  if [ "$code" != 0 ] && [ "$code" != 1 ]; then
    echo "FAIL btfsm review: exit $code"; head -20 "$tmp/err"; fail=1
  elif ! head -1 "$tmp/out" | grep -q '<!-- btfsm-review -->' || ! grep -q 'task.toml' "$tmp/out"; then
    echo "FAIL btfsm review: no marker or no changed file in the comment"; head -20 "$tmp/out"; fail=1
  else
    echo "ok   btfsm review on a two-commit repository (exit $code, $(wc -c <"$tmp/out") bytes of markdown)"
  fi
else
  echo "SKIPPED btfsm review: this binary has no \`review\` command (issue 30, item 1)"
fi
size=$(wc -c <"$wheel")
echo "wheel: $(basename "$wheel"), $((size / 1024)) KiB"
exit $fail
