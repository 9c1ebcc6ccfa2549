#!/bin/bash
# Builds the default map of every sequence with ground truth in ../shared and evaluates it with `vmap eval`:
# the table of docs/measurements/links.md. Extra arguments go to `vmap build` (e.g. --pose fundamental).
#   scripts/eval-sequences.sh [build options...]
# Maps are written under $VMAP_EVAL_DIR (default: a temporary folder, removed at the end).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
vmap=${VMAP:-$root/build/vmap}
shared=${VMAP_SHARED:-$root/../shared}
out=${VMAP_EVAL_DIR:-}
if [ -z "$out" ]; then
  out=$(mktemp -d)
  trap 'rm -rf "$out"' EXIT
fi
if ! /usr/bin/python3 -c "import json" 2>/dev/null; then echo "needs /usr/bin/python3" >&2; exit 1; fi

sequences=(
  "kitti07|$shared/data/kitti07|"
  "redkitchen|$shared/data/redkitchen|"
  "redkitchen 0-499|$shared/data/redkitchen|--last 499"
  "kitti00 (eval)|$shared/eval/kitti00|"
  "kitti06_short (eval)|$shared/eval/kitti06_short|"
  "kitti01_short (eval)|$shared/eval/kitti01_short|"
)
echo "| sequence | frames | key images | links | usable links | rotation error, median | translation error, median | verified matches within 2 px of the true epipolar line | rejected ones |"
echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|"
i=0
for entry in "${sequences[@]}"; do
  IFS='|' read -r name input options <<<"$entry"
  [ -e "$input" ] || { echo "| $name | (missing: $input) |"; continue; }
  map="$out/map_$i"
  i=$((i + 1))
  # shellcheck disable=SC2086
  "$vmap" build "$input" -o "$map" -q $options "$@" >/dev/null
  "$vmap" eval "$map" --no-table --no-save --json "$map.eval.json" >/dev/null
  /usr/bin/python3 - "$name" "$map/map.json" "$map.eval.json" <<'PY'
import json, sys
name, map_file, eval_file = sys.argv[1:]
m = json.load(open(map_file)); s = json.load(open(eval_file))["summary"]
f = lambda v, d, u="": "-" if v is None else f"{v:.{d}f}{u}"
share = "-" if s["usable_share"] is None else f"{100 * s['usable_share']:.1f}%"
print(f"| {name} | {m['num_frames']} | {m['num_key_images']} | {s['links']} | {s['usable_links']} ({share}) | "
      f"{f(s['rotation_error_deg_median'], 2, ' deg')} | {f(s['translation_error_deg_median'], 1, ' deg')} | "
      f"{f(100 * s['verified_within_threshold_mean'] if s['verified_within_threshold_mean'] is not None else None, 0, '%')} | "
      f"{f(100 * s['rejected_within_threshold_mean'] if s['rejected_within_threshold_mean'] is not None else None, 0, '%')} |")
PY
done
