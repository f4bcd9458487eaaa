#!/usr/bin/env bash
# The GitHub Action (action.yml, action/*.sh) and the example workflow
# (docs/examples/btfsm-review.yml):
# 1. actionlint and zizmor (offline) report nothing on them, laid out as a
#    repository using the action from a checkout (`uses: ./.btfsm`);
# 2. action/review.sh run as the runner runs it — GITHUB_EVENT_PATH a
#    pull_request event, GITHUB_OUTPUT, GITHUB_STEP_SUMMARY, a fake `gh`
#    on PATH recording its arguments and the body it is given — on a
#    repository of two commits: a first run POSTs one comment (the
#    markdown, marker first), writes the SARIF, the summary and the
#    outputs; a second run PATCHes the bot's marked comment (not a user's
#    that carries the marker); a read-only token (a fork) is a warning
#    and the step keeps review's exit code; fail-on error/never; a path
#    input that looks like shell is a path. Part 2 needs a btfsm with the
#    `review` command, else it prints SKIPPED.
# Exit 0 when all pass, 1 otherwise.
#
# Usage: tests/packaging/action.sh VENV_BIN BTFSM
#   (VENV_BIN: the folder holding actionlint and zizmor; BTFSM: the binary)
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
venv_bin=$(cd "${1:?usage: action.sh VENV_BIN BTFSM}" && pwd)
btfsm=$(cd "$(dirname "${2:?}")" && pwd)/$(basename "$2")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
no() { echo "FAIL $*"; fail=1; }

# 1. The linters, on a repository that uses the action from a checkout.
lr=$tmp/lint
mkdir -p "$lr/.github/workflows" "$lr/.btfsm/action"
cp "$repo/docs/examples/btfsm-review.yml" "$lr/.github/workflows/"
cp "$repo/action.yml" "$lr/.btfsm/"
cp "$repo"/action/*.sh "$lr/.btfsm/action/"
git -C "$lr" init -q
if (cd "$lr" && "$venv_bin/actionlint" -no-color) >"$tmp/out" 2>&1; then
  echo "ok   actionlint: nothing on the workflow and the action it uses"
else
  no "actionlint:"; cat "$tmp/out"
fi
if "$venv_bin/zizmor" --offline --no-progress "$lr/.github/workflows/btfsm-review.yml" \
  "$lr/.btfsm/action.yml" >"$tmp/out" 2>&1; then
  echo "ok   zizmor (offline, default persona): nothing on the workflow and action.yml"
else
  no "zizmor:"; cat "$tmp/out"
fi
# No ${{ }} expression inside a script the action runs.
if python3 - "$repo/action.yml" <<'PY'
import re, sys
text = open(sys.argv[1], encoding="utf-8").read()
bad = [ln for ln in text.splitlines() if ln.strip().startswith("run:") and "${{" in ln]
sys.exit(1 if bad else 0)
PY
then echo "ok   action.yml: no expression in a run: line"; else no "action.yml interpolates into run:"; fi

# 2. review.sh against a local repository.
if ! "$btfsm" review --help >/dev/null 2>&1; then
  echo "SKIPPED action/review.sh: $btfsm has no \`review\` command (issue 30, item 1)"
  exit $fail
fi
r=$tmp/repo
mkdir -p "$r/policies"
export GIT_AUTHOR_NAME=t GIT_AUTHOR_EMAIL=t@example.org GIT_COMMITTER_NAME=t GIT_COMMITTER_EMAIL=t@example.org
cp "$repo/policies/paper/fig01-bt.toml" "$r/policies/task.toml"
git -C "$r" init -q -b main
git -C "$r" add -A
git -C "$r" commit -qm base
base_sha=$(git -C "$r" rev-parse HEAD)
cp "$repo/policies/paper/fig03-bt.toml" "$r/policies/task.toml"
git -C "$r" add -A
git -C "$r" commit -qm head
head_sha=$(git -C "$r" rev-parse HEAD)
cat >"$tmp/event.json" <<EOF
{"action": "opened", "number": 7, "pull_request": {"number": 7,
 "base": {"sha": "$base_sha"}, "head": {"sha": "$head_sha", "repo": {"full_name": "someone/fork"}}}}
EOF
# The fake gh: logs each call, copies the body it is given, answers the
# comment list from $FAKE_COMMENTS, fails writes when FAKE_GH_FAIL is set.
mkdir -p "$tmp/bin"
cat >"$tmp/bin/gh" <<'EOF'
#!/usr/bin/env bash
n=$(($(cat "$GH_LOG.n" 2>/dev/null || echo 0) + 1)); echo $n >"$GH_LOG.n"
printf 'call %s:' "$n" >>"$GH_LOG"; printf ' [%s]' "$@" >>"$GH_LOG"; echo >>"$GH_LOG"
method=GET
while [ $# -gt 0 ]; do
  case "$1" in
    --method) method=$2; shift ;;
    --input) cp "$2" "$GH_LOG.body.$n" ;;
  esac
  shift
done
if [ "$method" = GET ]; then cat "$FAKE_COMMENTS"; exit 0; fi
if [ -n "${FAKE_GH_FAIL:-}" ]; then echo "gh: Resource not accessible by integration (HTTP 403)" >&2; exit 1; fi
echo "https://github.example/someone/repo/pull/7#issuecomment-$n"
EOF
chmod +x "$tmp/bin/gh"
ln -s "$btfsm" "$tmp/bin/btfsm"
run_action() { # NAME, then VAR=VALUE... for the environment
  local name=$1
  shift
  rm -f "$tmp/gh.log"* "$tmp/output" "$tmp/summary" "$r/btfsm-review.sarif"
  mkdir -p "$tmp/runner-$name"
  code=0
  (cd "$r" && env PATH="$tmp/bin:$PATH" GH_LOG="$tmp/gh.log" FAKE_COMMENTS="$tmp/comments.json" \
    GITHUB_EVENT_PATH="$tmp/event.json" GITHUB_REPOSITORY=someone/repo GITHUB_OUTPUT="$tmp/output" \
    GITHUB_STEP_SUMMARY="$tmp/summary" RUNNER_TEMP="$tmp/runner-$name" GH_TOKEN=x \
    INPUT_BASE= INPUT_HEAD= INPUT_PATHS= INPUT_CONFIG= INPUT_COMMENT=true \
    INPUT_SARIF=btfsm-review.sarif INPUT_FAIL_ON=gate "$@" \
    bash "$repo/action/review.sh") >"$tmp/log" 2>&1 || code=$?
}
marker='<!-- btfsm-review -->'

# a. No comment yet: one POST of the markdown.
echo '[]' >"$tmp/comments.json"
review_code=$(cd "$r" && "$btfsm" review --base "$base_sha" --format markdown >"$tmp/expected.md" 2>/dev/null; echo $?)
run_action first
[ "$code" = "$review_code" ] || no "first run: exit $code, review's is $review_code"
grep -q "^call 1: \[api\] \[--paginate\] \[repos/someone/repo/issues/7/comments?per_page=100\]" "$tmp/gh.log" || no "no comment list: $(cat "$tmp/gh.log")"
grep -q "^call 2: \[api\] \[--method\] \[POST\] \[repos/someone/repo/issues/7/comments\] \[--input\]" "$tmp/gh.log" || no "no POST: $(cat "$tmp/gh.log")"
[ "$(wc -l <"$tmp/gh.log")" = 2 ] || no "gh called $(wc -l <"$tmp/gh.log") times"
python3 - "$tmp/gh.log.body.2" "$tmp/expected.md" "$marker" <<'PY' || no "the comment body is not review's markdown"
import json, sys
body = json.load(open(sys.argv[1], encoding="utf-8"))["body"]
want = open(sys.argv[2], encoding="utf-8").read()
assert body == want, (body[:200], want[:200])
assert body.startswith(sys.argv[3]) and "task.toml" in body, body[:300]
PY
python3 -c 'import json,sys; v=json.load(open(sys.argv[1])); assert v["version"]=="2.1.0"' "$r/btfsm-review.sarif" \
  || no "no SARIF written"
grep -qx "exit-code=$review_code" "$tmp/output" && grep -qx "sarif=btfsm-review.sarif" "$tmp/output" \
  && grep -q "^comment-url=https://github.example/someone/repo/pull/7#issuecomment-2" "$tmp/output" \
  || no "outputs: $(cat "$tmp/output")"
grep -qF "$marker" "$tmp/summary" || no "the step summary lacks the review"
[ $fail = 0 ] && echo "ok   review.sh: the first run POSTs review's markdown, writes the SARIF, the summary and the outputs"

# b. A bot's marked comment exists (and a user's that carries the marker):
#    the bot's is PATCHed.
cat >"$tmp/comments.json" <<EOF
[{"id": 41, "user": {"login": "mallory", "type": "User"}, "body": "$marker fake"}]
[{"id": 40, "user": {"login": "github-actions[bot]", "type": "Bot"}, "body": "LGTM"},
 {"id": 42, "user": {"login": "github-actions[bot]", "type": "Bot"}, "body": "$marker\nold review"}]
EOF
run_action second
if grep -q "^call 2: \[api\] \[--method\] \[PATCH\] \[repos/someone/repo/issues/comments/42\] \[--input\]" "$tmp/gh.log" \
  && ! grep -q POST "$tmp/gh.log"; then
  echo "ok   review.sh: the second run PATCHes the bot's marked comment (42), across pages, not the user's (41)"
else
  no "second run: $(cat "$tmp/gh.log")"
fi

# c. A fork's read-only token: a warning, review's exit code kept.
echo '[]' >"$tmp/comments.json"
run_action fork FAKE_GH_FAIL=1
if [ "$code" = "$review_code" ] && grep -q "::warning::btfsm review: could not comment" "$tmp/log" \
  && grep -q "read-only token" "$tmp/summary"; then
  echo "ok   review.sh: a read-only token is a warning; the step exits $code as review did"
else
  no "fork: exit $code; $(tail -5 "$tmp/log")"
fi

# d. fail-on: a base revision that does not exist makes review exit 2.
run_action missing-gate INPUT_BASE=0000000000000000000000000000000000000000
c_gate=$code
run_action missing-error INPUT_BASE=0000000000000000000000000000000000000000 INPUT_FAIL_ON=error
c_error=$code
run_action missing-never INPUT_BASE=0000000000000000000000000000000000000000 INPUT_FAIL_ON=never
c_never=$code
if [ "$c_gate/$c_error/$c_never" = 2/2/0 ] && [ ! -s "$tmp/gh.log" ] && grep -q "could not run" "$tmp/summary"; then
  echo "ok   review.sh: review cannot run (exit 2): fail-on gate 2, error 2, never 0; no comment"
else
  no "fail-on: gate $c_gate, error $c_error, never $c_never; gh: $(cat "$tmp/gh.log" 2>/dev/null)"
fi

# e. Inputs are data: a path that looks like shell is a path.
run_action hostile 'INPUT_PATHS=policies/
$(touch pwned)
`touch pwned2`' INPUT_COMMENT=false
if [ ! -e "$r/pwned" ] && [ ! -e "$r/pwned2" ] && [ ! -e "$tmp/bin/pwned" ] && [ ! -s "$tmp/gh.log" ]; then
  echo "ok   review.sh: shell in an input is not run; comment=false calls no gh"
else
  no "hostile input ran or commented"
fi
exit $fail
