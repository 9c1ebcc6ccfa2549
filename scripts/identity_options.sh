#!/bin/bash
# Byte-identity of options (issue 24): non-default options and refused values, through one binary: map.json and the error lines.
# usage: scripts/identity_options.sh VMAP OUT   (then diff OUT_BEFORE/errors.txt OUT_AFTER/errors.txt and k/map.json)
BIN=$1; OUT=$2; D=${VMAP_SHARED_DIR:-$(cd "$(dirname "$0")/../../shared" && pwd)}/data
mkdir -p $OUT
$BIN build $D/kitti07 -o $OUT/k --last 60 --stride 2 --resize 640 --search bisect --pose fundamental --pose-matches verified --quality harmonic --similarity feature-ratio --no-final-key --min-key-displacement 2 --max-translation-sigma 5 --min-translation-parallax 2 --threshold 0.75 --seed 3 --max-samples-to-reject 5000 --tau 0.4 --orb-features 1500 --camera none --search-window 16 > /dev/null 2>&1
for args in "build $D/kitti07 -o $OUT/x --pose-matches some" "build $D/kitti07 -o $OUT/x --threads 300" "build $D/kitti07 -o $OUT/x --verifier lmeds" "build $D/kitti07 -o $OUT/x --quality median" "build $D/kitti07 -o $OUT/x --search bisect --exhaustive" "build $D/kitti07 -o $OUT/x --pose-threshold -1" "build $D/kitti07 -o $OUT/x --format tum" "build $D/kitti07 -o $OUT/x --stride 0" "localize $OUT/k $D/kitti07 --acceptance chance --min-verified 30" "localize $OUT/k $D/kitti07 --ranking bow" "localize $OUT/k $D/kitti07 --heading-min-votes 0" "eval $OUT/k --max-rotation-error -1" "sweep $D/kitti07 -o $OUT/y --thresholds 0.5 --search-window 0"; do
  echo "== $args" | sed "s|$OUT|OUT|g"; $BIN $args 2>&1 | grep "error" | sed "s|$OUT|OUT|g"; echo "status ${PIPESTATUS[0]}"
done > $OUT/errors.txt
