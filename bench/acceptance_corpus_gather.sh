#!/bin/sh
# Gathers the held-out corpus of docs/lint.md, "Measured on a held-out
# corpus": the XML files (BehaviorTree.CPP trees, their node models,
# Groot projects, SCXML) of public repositories that btfsm's own tests do not
# use, each extracted at the commit listed below with its repository layout
# (so that a tree's <include>s and the repository's *tree_nodes*.xml are
# where the tree expects them), into OUT/<name>/. For Nav2 and
# BehaviorTree.CPP, every release tag whose tree files differ from the
# commits the tests and docs/lint.md's precision table already use: a file
# is kept only when its blob (its exact text) is new, the node models always.
#
# Usage: bench/acceptance_corpus_gather.sh MIRROR OUT
#   MIRROR: a folder of bare repositories MIRROR/OWNER+NAME/repo (as the
#   project's `fetch` brings them, or `git clone --bare` into that layout).
#   Then: python3 bench/acceptance_corpus.py OUT
set -eu
M=$(realpath "$1"); O=$(realpath -m "$2"); mkdir -p "$O"

# name owner/repo commit (a tag or a commit)
REPOS='
btgenbot AIRLab-POLIMI/BTGenBot ab29e153ba4b
groot1 BehaviorTree/Groot 70973d004365
cyberdog_nav2 MiRoboticsLab/cyberdog_nav2 77c65782bd2e
robotx_bt OUXT-Polaris/robotx_behavior_tree 5918a4cdde29
moveit_pro_training_ws PickNikRobotics/moveit_pro_training_ws 9f64a32c6c53
moveit_pro_ur_config PickNikRobotics/moveit_pro_ur_config bab77dd0862b
moveit_studio_kortex_ws PickNikRobotics/moveit_studio_kortex_ws 6187581b6aaf
moveit_studio_parallel_pick PickNikRobotics/moveit_studio_parallel_pick b4eba1edef4c
scut_r2 SCUT-RobotIC/BeHaviorTree_R2.ROS2 b546febea036
aerostack2 aerostack2/aerostack2 afc0c529bb82
bt_mtc captain-yoshi/BehaviorTree.MTC baf81c94ee31
fkie_bt fkie/fkie_behavior_trees 7b7e6e98fb59
nav2_examples iamtony-ca/nav2-examples 3154823ba1d8
polymath_bt polymathrobotics/ros2_behavior_tree_example 2205049e59cb
plansys2_examples PlanSys2/ros2_planning_system_examples 4c4fe955f7d8
sigyn_bt wimblerobotics/sigyn_behavior_trees d9d14795e15d
robocup_bt IntelligentRoboticsLabs/robocup_behavior_trees 38726ee78dc2
bt_navigation Juhyung-L/behavior_tree_navigation da2c62d9be8c
'

git_dir() {
  g=$M/$(echo "$1" | tr / +)/repo
  [ -d "$g/.git" ] && g=$g/.git
  echo "$g"
}

# extract GITDIR COMMIT DEST [SEEN]: the policy-like files of COMMIT.
# With SEEN (a file of blob ids), a tree file whose blob is listed is left
# out and each new blob is appended; node models are always written.
extract() {
  eg=$1; ecommit=$2; edest=$3; eseen=${4:-}
  git --git-dir="$eg" ls-tree -r "$ecommit" | grep -E '\.(xml|btproj|scxml)$' |
    while read -r _mode type obj path; do
      [ "$type" = blob ] || continue
      if [ -n "$eseen" ]; then
        case "$path" in
          *tree_nodes*) ;;
          *)
            grep -qx "$obj" "$eseen" && continue
            echo "$obj" >> "$eseen" ;;
        esac
      fi
      mkdir -p "$edest/$(dirname "$path")"
      git --git-dir="$eg" cat-file blob "$obj" > "$edest/$path"
    done
  mkdir -p "$edest/.git"
  echo "$ecommit" > "$edest/.git/COMMIT"
}

echo "$REPOS" | while read -r name repo commit; do
  [ -n "$name" ] || continue
  [ -d "$O/$name" ] && continue
  g=$(git_dir "$repo")
  full=$(git --git-dir="$g" rev-parse "$commit")
  extract "$g" "$full" "$O/$name"
  echo "$name $repo $full"
done

# Release tags. The blobs of the commits the tests and docs/lint.md already
# use are seen first, so that only files new since are kept.
tags() { # gitdir, paths regex, used commits, tags
  g=$1; re=$2; used=$3; shift 3
  seen=$O/.seen-$(basename "$(dirname "$g")")
  : > "$seen"
  for c in $used; do
    git --git-dir="$g" ls-tree -r "$c" | awk '{print $3}' >> "$seen"
  done
  for t in "$@"; do
    dest=$O/$(basename "$(dirname "$g")" | sed 's/.*+//')-$t
    [ -d "$dest" ] && continue
    tmp=$(mktemp -d)
    extract "$g" "$t" "$tmp" "$seen"
    # Only the folders of the tree files (and the node models).
    (cd "$tmp" && find . -type f | grep -E "$re" | while read -r f; do
      mkdir -p "$dest/$(dirname "$f")"; cp "$f" "$dest/$f"; done)
    [ -d "$dest" ] && mkdir -p "$dest/.git" && git --git-dir="$g" rev-parse "$t" > "$dest/.git/COMMIT" &&
      echo "$(basename "$dest") $(cat "$dest/.git/COMMIT")"
    rm -rf "$tmp"
  done
}

NAV2=$(git_dir ros-navigation/navigation2)
tags "$NAV2" 'behavior_trees/|tree_nodes|/test/.*\.xml$' \
  'a097086719c88f781aa59788eca29ac6ca5e56db ddd1b4d49209722cbd4400ea3eadacae0a17e024 f4108e5b1c2bce804a1aa0c7be6673a8eb4a1501 3478badb7e2802c9ff1f805fb5493dc1d0792a5a a3a97043ee93d92fe8d70ec56d183933169beb1c' \
  $(git --git-dir="$NAV2" tag | sort -V)

BTCPP=$(git_dir BehaviorTree/BehaviorTree.CPP)
tags "$BTCPP" '^\./(examples|tests|sample_nodes|fuzzing)/' \
  '879522c75cce5e67f3dd7b5591bcb96eb3557a42 9d624dc7797b4752e5f8616793ffcee4b540a185' \
  $(git --git-dir="$BTCPP" tag | grep -E '^v?[34]\.' | sort -V)

# BehaviorTree.CPP 4.10.0's own unit tests: the trees written inline in
# tests/*.cpp (raw string literals holding a <root> with a <BehaviorTree>),
# one file each, identical texts once. (docs/lint.md's precision table uses
# the examples' inline trees, not the tests'.)
dest=$O/btcpp-4.10.0-tests-inline
if [ ! -d "$dest" ]; then
  mkdir -p "$dest/.git"
  echo 879522c75cce5e67f3dd7b5591bcb96eb3557a42 > "$dest/.git/COMMIT"
  git --git-dir="$BTCPP" ls-tree -r --name-only 879522c75cce5e67f3dd7b5591bcb96eb3557a42 -- tests |
    grep -E '\.cpp$' | while read -r f; do
      git --git-dir="$BTCPP" show "879522c75cce5e67f3dd7b5591bcb96eb3557a42:$f" > "$dest/$(basename "$f").src"
    done
  python3 - "$dest" <<'PY'
import hashlib, pathlib, re, sys
root = pathlib.Path(sys.argv[1])
seen = set()
for cpp in sorted(root.glob("*.cpp.src")):
    text = cpp.read_text(errors="replace")
    for i, m in enumerate(re.finditer(r'R"(\w*)\((.*?)\)\1"', text, re.S)):
        body = m.group(2).strip() + "\n"
        digest = hashlib.sha1(body.encode()).hexdigest()
        if "<root" in body and "<BehaviorTree" in body and digest not in seen:
            seen.add(digest)
            line = text.count("\n", 0, m.start()) + 1
            (root / f"{cpp.name[:-8]}.L{line}.xml").write_text(body)
    cpp.unlink()
PY
  echo "btcpp-4.10.0-tests-inline $(ls "$dest" | wc -l) files"
fi
