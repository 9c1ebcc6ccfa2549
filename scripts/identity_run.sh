#!/bin/bash
# Byte-identity proof of a refactoring: runs one vmap binary over the shared sequences into OUT (ORB, defaults).
# usage: scripts/identity_run.sh VMAP OUT   (then scripts/identity_compare.py OUT_BEFORE OUT_AFTER)
set -euo pipefail
BIN=$1; OUT=$2; D=${VMAP_SHARED_DIR:-$(cd "$(dirname "$0")/../../shared" && pwd)}/data
mkdir -p "$OUT"
run() { /usr/bin/time -f "%e s wall  $*" "$@" >/dev/null 2>>"$OUT/log.txt"; }
run "$BIN" build "$D/lab_floor/lab_floor.mp4" -o "$OUT/lab_floor"
run "$BIN" build "$D/rccar_room" -o "$OUT/rccar_room"
run "$BIN" build "$D/kitti07" -o "$OUT/kitti07"
run "$BIN" sweep "$D/rccar_room" --thresholds 0.1:0.9:0.1 -o "$OUT/sweep"
run "$BIN" localize "$OUT/lab_floor" "$D/lab_floor/desk.mp4" --csv "$OUT/localize_desk.csv" --json "$OUT/localize_desk.json"
run "$BIN" localize "$OUT/lab_floor" "$D/lab_floor/lab_floor.mp4" --csv "$OUT/localize_self.csv"
run "$BIN" eval "$OUT/kitti07" --json "$OUT/eval_kitti07.json"
run "$BIN" report "$OUT/rccar_room"
"$BIN" info "$OUT/rccar_room" >"$OUT/info_rccar_room.txt"
mkdir -p "$OUT/help"
for command in build sweep localize eval match info report route draw weights; do
  "$BIN" "$command" --help >"$OUT/help/$command.txt"
done
run "$BIN" report "$OUT/localize_desk.json" -o "$OUT/localize_report"
