#!/bin/sh
# The measurement of docs/lint.md, "Precision on real repositories": lints
# each repository at the commit shown there at default settings (`btfsm
# lint .` from its root) and prints the findings per rule, for a person to
# classify. Also the BehaviorTree.CPP examples' inline XML (raw string
# literals of examples/*.cpp holding a <root>), extracted as files.
#
# Usage: bench/lint_precision.sh BTFSM WORKDIR
#   BTFSM: the btfsm binary; WORKDIR: where the repositories are cloned
#   (git, network) and the JSON findings written (WORKDIR/out/*.json).
# Set MIRROR=DIR to read bare repositories DIR/OWNER+NAME/repo instead of
# cloning.
set -eu
B=$(realpath "$1"); W=$(realpath -m "$2"); mkdir -p "$W/out"

# name owner/repo commit [subfolder to lint]
REPOS='
nav2-1.1.20 ros-navigation/navigation2 a097086719c88f781aa59788eca29ac6ca5e56db
nav2-1.2.10 ros-navigation/navigation2 ddd1b4d49209722cbd4400ea3eadacae0a17e024
nav2-1.3.13 ros-navigation/navigation2 f4108e5b1c2bce804a1aa0c7be6673a8eb4a1501
nav2-1.4.2 ros-navigation/navigation2 3478badb7e2802c9ff1f805fb5493dc1d0792a5a
nav2-main ros-navigation/navigation2 a3a97043ee93d92fe8d70ec56d183933169beb1c
btcpp-4.10.0 BehaviorTree/BehaviorTree.CPP 879522c75cce5e67f3dd7b5591bcb96eb3557a42
btcpp-3.8.8 BehaviorTree/BehaviorTree.CPP 9d624dc7797b4752e5f8616793ffcee4b540a185
moveit_studio_ws PickNikRobotics/moveit_studio_ws a128e75558ef150c846ebc08f46a5cb22dd065b6
moveit_pro_example_ws PickNikRobotics/moveit_pro_example_ws f9f967b74a237212c6d0e9a9fa972aa7f7542f2f
yasmin uleroboticsgroup/yasmin 372a5f4cb513603bfd14dffd38a5822bc0582453
btgenbot CollaborativeRoboticsLab/Fabric-vs-BTGenBot-comparison a08ebb200322ff271728da8fabe186407f202fc6 Experiment_1/BTGenBot/outputs
'

# The policy-like files (XML, Groot projects, TOML) of REPO at COMMIT in
# DEST, with an empty .git folder marking the repository root.
extract() {
  name=$1; repo=$2; commit=$3; dest=$W/$name
  [ -d "$dest" ] && return 0
  if [ -n "${MIRROR:-}" ]; then
    g=$MIRROR/$(echo "$repo" | tr / +)/repo
  else
    g=$W/git/$(echo "$repo" | tr / +)
    [ -d "$g" ] || git clone --quiet --bare "https://github.com/$repo" "$g"
  fi
  mkdir -p "$dest/.git"
  git --git-dir="$g" ls-tree -r "$commit" | grep -E '\.(xml|btproj|toml|cpp)$' |
    while read -r _mode type obj path; do
      [ "$type" = blob ] || continue
      case "$path" in *.cpp) case "$path" in examples/*) ;; *) continue ;; esac ;; esac
      mkdir -p "$dest/$(dirname "$path")"
      git --git-dir="$g" cat-file blob "$obj" > "$dest/$path" 2>/dev/null || rm -f "$dest/$path"
    done
  if [ -d "$dest/examples" ]; then
    python3 - "$dest" <<'EOF'
import pathlib, re, sys
root = pathlib.Path(sys.argv[1])
out = root / "examples" / "inline"
out.mkdir(exist_ok=True)
for cpp in sorted((root / "examples").glob("*.cpp")):
    text = cpp.read_text(errors="replace")
    for i, m in enumerate(re.finditer(r'R"(\w*)\((.*?)\)\1"', text, re.S)):
        if "<root" in m.group(2) and "<BehaviorTree" in m.group(2):
            (out / f"{cpp.stem}.{i}.xml").write_text(m.group(2).strip() + "\n")
    cpp.unlink()
EOF
  fi
}

echo "$REPOS" | while read -r name repo commit sub; do
  [ -n "$name" ] || continue
  extract "$name" "$repo" "$commit"
  dir=$W/$name/${sub:-}
  (cd "$dir" && "$B" lint . --format json > "$W/out/$name.json" 2>/dev/null || true)
  python3 - "$W/out/$name.json" "$name" <<'EOF'
import collections, json, sys
v = json.load(open(sys.argv[1]))
c = collections.Counter(f"{f['code']} ({f['level']})" for f in v)
print(f"{sys.argv[2]}: {len(v)} findings", dict(sorted(c.items())))
EOF
done
