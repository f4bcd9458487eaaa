#!/bin/sh
# `btfsm review` on a 200-file change (issue 30: "finishes within a few
# seconds on 2 cores"): a temporary repository of 200 real Nav2 trees
# (tests/fixtures/field/bt-xml/nav2, Apache-2.0) at their Humble version,
# a second commit with each at its main version, plus 20 unchanged trees
# including a changed SubTree file; times text, markdown and JSON reviews
# (best of 3 wall-clock runs each). Uses the release binary (set BTFSM to
# use another). Not run by `make test`.
#
# usage: bench/review.sh [FILES]   (default: 200)
set -eu
cd "$(dirname "$0")/.."
N=${1:-200}
if [ -z "${BTFSM:-}" ]; then
  cargo build --release --locked --quiet
  BTFSM=${CARGO_TARGET_DIR:-target}/release/btfsm
fi
BTFSM=$(cd "$(dirname "$BTFSM")" && pwd)/$(basename "$BTFSM")
NAV=tests/fixtures/field/bt-xml/nav2
F=navigate_to_pose_w_replanning_and_recovery.xml
DIR=$(mktemp -d "${TMPDIR:-/tmp}/btfsm-review-bench.XXXXXX")
trap 'rm -rf "$DIR"' EXIT
G="git -C $DIR -c user.name=bench -c user.email=bench@example.org -c commit.gpgsign=false"
$G init -q -b main
mkdir -p "$DIR/bt" "$DIR/sub"
i=0
while [ "$i" -lt "$N" ]; do
  cp "$NAV/humble/$F" "$DIR/bt/t$i.xml"
  i=$((i + 1))
done
cat > "$DIR/sub/sub.xml" <<'XML'
<root BTCPP_format="4"><BehaviorTree ID="Sub"><Sequence><AlwaysSuccess/></Sequence></BehaviorTree></root>
XML
i=0
while [ "$i" -lt 20 ]; do
  cat > "$DIR/sub/user$i.xml" <<'XML'
<root BTCPP_format="4" main_tree_to_execute="Main"><include path="sub.xml"/>
<BehaviorTree ID="Main"><Sequence><SubTree ID="Sub"/><AlwaysSuccess/></Sequence></BehaviorTree></root>
XML
  i=$((i + 1))
done
$G add -A && $G commit -q -m base
i=0
while [ "$i" -lt "$N" ]; do
  cp "$NAV/main/$F" "$DIR/bt/t$i.xml"
  i=$((i + 1))
done
sed -i 's#<AlwaysSuccess/></Sequence>#<AlwaysSuccess/><AlwaysFailure/></Sequence>#' "$DIR/sub/sub.xml"
$G add -A && $G commit -q -m head
echo "files changed: $N (+1 SubTree file, 20 trees that include it); nproc: $(nproc)"
for fmt in text markdown json; do
  best=""
  for _ in 1 2 3; do
    s=$(date +%s.%N)
    (cd "$DIR" && "$BTFSM" review --base HEAD~1 --head HEAD --format "$fmt" > "$DIR/out.$fmt")
    e=$(date +%s.%N)
    t=$(echo "$e - $s" | bc)
    if [ -z "$best" ] || [ "$(echo "$t < $best" | bc)" = 1 ]; then best=$t; fi
  done
  echo "review --format $fmt: ${best} s, $(wc -c < "$DIR/out.$fmt") bytes"
done
python3 - "$DIR/out.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
st = {}
for f in d["files"]:
    st[f["status"]] = st.get(f["status"], 0) + 1
print("files reviewed by status:", dict(sorted(st.items())))
PY
