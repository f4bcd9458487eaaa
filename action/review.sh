#!/usr/bin/env bash
# The GitHub Action's review step (action.yml): runs `btfsm review
# --format markdown` (and `--sarif`) on the pull request of
# $GITHUB_EVENT_PATH, appends the comment to $GITHUB_STEP_SUMMARY, and
# creates or updates ONE pull request comment, the one a bot wrote that
# starts with the hidden marker `<!-- btfsm-review -->`, through `gh api`
# (list the comments, PATCH the one found, else POST). A token that may
# not comment (a pull request from a fork gets a read-only one) is a
# warning, not a failure. Inputs come as environment variables (INPUT_*),
# never as text in a script. Writes the outputs `exit-code`, `sarif` and
# `comment-url` to $GITHUB_OUTPUT. Exits as INPUT_FAIL_ON says: `gate`
# (default) with review's code, `error` only when review could not run
# (2), `never` 0. Tested by tests/packaging/action.sh.
set -uo pipefail
marker='<!-- btfsm-review -->'
out=${RUNNER_TEMP:-$(mktemp -d)}
md=$out/btfsm-review.md
output=${GITHUB_OUTPUT:-/dev/null}
summary=${GITHUB_STEP_SUMMARY:-/dev/null}

# One field of the pull_request event (empty when there is none).
event_field() {
  [ -n "${GITHUB_EVENT_PATH:-}" ] && [ -f "$GITHUB_EVENT_PATH" ] || return 0
  python3 - "$GITHUB_EVENT_PATH" "$1" <<'PY'
import json, sys
v = json.load(open(sys.argv[1], encoding="utf-8")).get("pull_request") or {}
for k in sys.argv[2].split("."):
    v = v.get(k) if isinstance(v, dict) else None
print("" if v is None else v)
PY
}
pr=$(event_field number)
base=${INPUT_BASE:-$(event_field base.sha)}
head=${INPUT_HEAD:-}

case "${INPUT_FAIL_ON:-gate}" in
  gate | error | never) ;;
  *) echo "::error::fail-on must be gate, error or never" >&2; exit 2 ;;
esac

args=(review --format markdown)
[ -n "$base" ] && args+=(--base "$base")
[ -n "$head" ] && args+=(--head "$head")
[ -n "${INPUT_SARIF:-}" ] && args+=(--sarif "$INPUT_SARIF")
[ -n "${INPUT_CONFIG:-}" ] && args+=(--config "$INPUT_CONFIG")
paths=()
while IFS= read -r p; do
  [ -n "$p" ] && paths+=("$p")
done <<<"${INPUT_PATHS:-}"
[ ${#paths[@]} -gt 0 ] && args+=(-- "${paths[@]}")

code=0
btfsm "${args[@]}" >"$md" 2>"$out/btfsm-review.err" || code=$?
cat "$out/btfsm-review.err" >&2
echo "exit-code=$code" >>"$output"
if [ -n "${INPUT_SARIF:-}" ] && [ -s "$INPUT_SARIF" ]; then
  echo "sarif=$INPUT_SARIF" >>"$output"
fi

if [ -s "$md" ]; then
  cat "$md" >>"$summary"
else
  printf '### btfsm review\n\nbtfsm review could not run (exit %s): the job log says why.\n' "$code" >>"$summary"
fi

# The one comment: found by the marker among the bots' comments.
comment() {
  local repo=${GITHUB_REPOSITORY:?} listed id body url
  listed=$out/btfsm-comments.json
  gh api --paginate "repos/$repo/issues/$pr/comments?per_page=100" >"$listed" || return 1
  id=$(python3 - "$listed" "$marker" <<'PY'
import json, sys
text, marker = open(sys.argv[1], encoding="utf-8").read(), sys.argv[2]
dec, i, found = json.JSONDecoder(), 0, ""
while i < len(text):  # --paginate prints one array per page
    if text[i].isspace():
        i += 1
        continue
    page, i = dec.raw_decode(text, i)
    for c in page:
        if (c.get("user") or {}).get("type") == "Bot" and (c.get("body") or "").startswith(marker):
            found = found or str(c["id"])
print(found)
PY
) || return 1
  body=$out/btfsm-comment.json
  python3 -c 'import json, sys; json.dump({"body": open(sys.argv[1], encoding="utf-8").read()}, open(sys.argv[2], "w"))' "$md" "$body"
  if [ -n "$id" ]; then
    url=$(gh api --method PATCH "repos/$repo/issues/comments/$id" --input "$body" --jq .html_url) || return 1
  else
    url=$(gh api --method POST "repos/$repo/issues/$pr/comments" --input "$body" --jq .html_url) || return 1
  fi
  echo "comment-url=$url" >>"$output"
  if [ -n "$id" ]; then echo "btfsm review: updated $url"; else echo "btfsm review: created $url"; fi
}
if [ "${INPUT_COMMENT:-true}" = true ] && [ -n "$pr" ] && [ -s "$md" ]; then
  if ! comment; then
    echo "::warning::btfsm review: could not comment on the pull request (a pull request from a fork gets a read-only token); the review is in the job summary"
    printf '\n> The pull request comment could not be written (read-only token).\n' >>"$summary"
  fi
fi

case "${INPUT_FAIL_ON:-gate}" in
  gate) exit "$code" ;;
  error) [ "$code" = 2 ] && exit 2; exit 0 ;;
  never) exit 0 ;;
esac
