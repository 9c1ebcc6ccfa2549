#!/bin/bash
# Issue 35's speed goal: localization with the belief over the route must stay at >= 60 frames/s with ORB and
# >= 15 frames/s with XFeat on this machine's CPU. Two vmap binaries (before and after) run side by side,
# alternating, on the same maps: a same-season run (lab_floor.mp4 against its own map: tracking) and the
# cross-season corridor (corridor_conditions repeat/ against a map of teach/: where the belief questions frames),
# each with ORB and XFeat. Each binary localizes its own copy of each map (the key-image cache is per vmap
# version). Prints the median frames/s (`vmap localize`'s own summary: frames over wall-clock time, decoding and
# extraction included) over REPEATS runs and new/old. Run on a quiet machine (nothing else building).
#
#   bench/localize_speed.sh OLD_VMAP NEW_VMAP [REPEATS]     (from the repository root; ../shared must be there)
#   e.g. bench/localize_speed.sh /work/tools/old-ed88a06/vmap build/vmap 3
set -euo pipefail
old=$(realpath "$1")
new=$(realpath "$2")
repeats=${3:-3}
frames=${VMAP_SPEED_FRAMES:-}  # for a quick check of the script: localize only this many frames of each query
lab=../shared/data/lab_floor/lab_floor.mp4
teach=../shared/data/corridor_conditions/teach
repeat=../shared/data/corridor_conditions/repeat
dir=$(mktemp -d /tmp/vmap_localize_speed_XXXXXX)
trap 'rm -rf "$dir"' EXIT
last=()
[[ -n $frames ]] && last=(--last $((frames - 1)))

for matcher in orb xfeat; do
  "$new" build "$lab" -q --matcher "$matcher" -o "$dir/lab_$matcher" "${last[@]}" >>"$dir/log" 2>&1
  "$new" build "$teach" -q --matcher "$matcher" -o "$dir/corridor_$matcher" >>"$dir/log" 2>&1
  for which in old new; do
    for set in lab corridor; do
      cp -r "$dir/${set}_$matcher" "$dir/${set}_${matcher}_$which"
      rm -f "$dir/${set}_${matcher}_$which/localization_cache.bin"
    done
  done
done

fps() {  # binary map query -> frames/s of one run
  "$1" localize "$2" "$3" -q --json "$dir/run.json" "${last[@]}" >>"$dir/log" 2>&1 ||
    { echo "failed: $*" >&2; tail -5 "$dir/log" >&2; exit 1; }
  python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["summary"]["frames_per_second"])' "$dir/run.json"
}
median() { printf '%s\n' "$@" | sort -g | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }

echo "| run | old frames/s | new frames/s | new/old | goal |"
echo "|---|---|---|---|---|"
for matcher in orb xfeat; do
  goal=60
  [[ $matcher == xfeat ]] && goal=15
  for set in lab corridor; do
    query=$lab
    [[ $set == corridor ]] && query=$repeat
    # A first run of each writes its key-image cache (not timed).
    fps "$old" "$dir/${set}_${matcher}_old" "$query" >/dev/null
    fps "$new" "$dir/${set}_${matcher}_new" "$query" >/dev/null
    old_fps=() new_fps=()
    for ((r = 0; r < repeats; ++r)); do
      old_fps+=("$(fps "$old" "$dir/${set}_${matcher}_old" "$query")")
      new_fps+=("$(fps "$new" "$dir/${set}_${matcher}_new" "$query")")
    done
    o=$(median "${old_fps[@]}")
    n=$(median "${new_fps[@]}")
    name="lab_floor.mp4 against its map"
    [[ $set == corridor ]] && name="corridor_conditions repeat against teach"
    printf '| %s, %s | %.1f | %.1f | %.3f | >= %d |\n' "$name" "$matcher" "$o" "$n" "$(echo "$n / $o" | bc -l)" "$goal"
  done
done
