#!/bin/bash
# Issue 38's speed goal: the limits on hostile input must leave good input as fast as it was. Two vmap binaries
# (before and after) run side by side, alternating, on the same good inputs: every recording container
# (`recording_bench --write`: 300 frames of lab_floor.mp4 as bgr8 images), read by `vmap info` and built by
# `vmap build`, the video itself built, and a localization of the zstd MCAP against its map. Prints the median
# wall time of each over REPEATS runs and new/old.
#
#   bench/hostile_speed.sh OLD_VMAP NEW_VMAP [REPEATS]     (run from the repository root, after scripts/build.sh)
set -euo pipefail
old=$(realpath "$1")
new=$(realpath "$2")
repeats=${3:-3}
video=../shared/data/lab_floor/lab_floor.mp4
dir=$(mktemp -d /tmp/vmap_hostile_speed_XXXXXX)
trap 'rm -rf "$dir"' EXIT
build/bench/recording_bench "$video" --frames 300 --write "$dir/rec" >/dev/null
"$new" build "$dir/rec/zstd.mcap" -o "$dir/map" -q
# One copy of the map per binary, its key-image cache written once before the timing: each binary then localizes warm,
# as a robot does after its first start, instead of replacing the other's cache every run.
for which in old new; do
  cp -r "$dir/map" "$dir/map_$which"
  binary=$old
  [[ $which == new ]] && binary=$new
  "$binary" localize "$dir/map_$which" "$dir/rec/zstd.mcap" --last 0 -q >/dev/null 2>&1 || true
done

# Seconds of one run (its output goes to the log; a failure ends the script).
seconds() {
  local start end
  start=$(date +%s.%N)
  "$@" >>"$dir/log" 2>&1 || { echo "failed: $*" >&2; tail -5 "$dir/log" >&2; exit 1; }
  end=$(date +%s.%N)
  echo "$end - $start" | bc
}
median() { printf '%s\n' "$@" | sort -g | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }

run_case() {  # name, then the arguments after the binary; "@OUT@" is replaced by a fresh output path, "@MAP@" by the
  # binary's own copy of the map
  local name=$1
  shift
  local old_times=() new_times=()
  for ((r = 0; r < repeats; ++r)); do
    for which in old new; do
      local binary=$old
      [[ $which == new ]] && binary=$new
      rm -rf "$dir/out" "$dir/out.csv"
      local arguments=("${@//@OUT@/$dir/out}")
      arguments=("${arguments[@]//@MAP@/$dir/map_$which}")
      local t
      t=$(seconds "$binary" "${arguments[@]}")
      if [[ $which == old ]]; then old_times+=("$t"); else new_times+=("$t"); fi
    done
  done
  local o n
  o=$(median "${old_times[@]}")
  n=$(median "${new_times[@]}")
  printf '| %s | %.2f | %.2f | %.3f |\n' "$name" "$o" "$n" "$(echo "$n / $o" | bc -l)"
}

echo "| good input (median of $repeats) | old s | new s | new/old |"
echo "|---|---|---|---|"
for recording in plain.mcap zstd.mcap rosbag2 none.bag lz4.bag; do
  run_case "vmap info $recording" info "$dir/rec/$recording"
done
for recording in plain.mcap zstd.mcap rosbag2 none.bag lz4.bag; do
  run_case "vmap build $recording" build "$dir/rec/$recording" -o @OUT@ -q
done
run_case "vmap build lab_floor.mp4 (300 frames)" build "$video" --last 299 -o @OUT@ -q
run_case "vmap localize map zstd.mcap" localize @MAP@ "$dir/rec/zstd.mcap" --csv @OUT@.csv -q
run_case "vmap info map" info "$dir/map"
