#!/usr/bin/env bash
# Runs one fuzz target (fuzz/) for SECONDS on its seeds and on what earlier runs found, with the bounds vmap
# promises (10 s an input, 2 GB); a crash, a sanitizer's report, a hang or an input past the memory bound fails
# it, and the input is kept in FUZZ_DIR/artifacts/ (replay it: FUZZ_DIR/TARGET FILE).
# Usage: scripts/run-fuzzer.sh FUZZ_DIR TARGET SECONDS [libFuzzer options...]
#   FUZZ_DIR  the fuzz build (build/fuzz), with seeds/ written by write_fuzz_seeds (ctest's fuzz_seeds)
# Exits 77 (ctest: skipped) when the target was not built: no clang++ with libFuzzer on this machine.
set -euo pipefail
dir=$1 target=$2 seconds=$3
shift 3
if [[ ! -x "$dir/$target" ]]; then
  echo "$target: not built (it needs clang++ and libFuzzer: scripts/install-deps.sh installs clang and libclang-rt-14-dev); skipped"
  exit 77
fi
corpus="$dir/corpus/$target"
seeds="$dir/seeds/${target#fuzz_}"
mkdir -p "$corpus" "$dir/artifacts"
exec "$dir/$target" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
  -artifact_prefix="$dir/artifacts/$target-" "$@" "$corpus" "$seeds"
