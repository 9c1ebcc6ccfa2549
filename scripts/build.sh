#!/usr/bin/env bash
# Configures and builds vmap (Release, Ninja) into ./build (or $VMAP_BUILD_DIR).
# Extra arguments go to CMake, e.g. scripts/build.sh -DVMAP_WITH_TORCH=OFF
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${VMAP_BUILD_DIR:-build}
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
# Two jobs: LibTorch translation units take ~2 GB of RAM each to compile.
cmake --build "$build_dir" -j "${VMAP_JOBS:-2}"
