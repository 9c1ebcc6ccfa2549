#!/usr/bin/env bash
# Configures and builds vmap (Release, Ninja) into ./build (or $VMAP_BUILD_DIR): usage() says how.
set -euo pipefail
usage() {
  cat <<'EOF'
Usage: scripts/build.sh [--targets TARGET...] [CMAKE_ARGS...]
Configures and builds vmap (Release, Ninja, $VMAP_JOBS jobs: 2 unless set) into ./build (or $VMAP_BUILD_DIR).
  no --targets      builds everything: the vmap binary, the LibTorch plugin, the tests and the benchmarks
  --targets vmap    builds only the binary, enough for ORB (the default matcher); the deep matchers also need
                    vmap_torch (the plugin libvmap_torch.so): --targets vmap vmap_torch, or a later run without
                    --targets
  --targets T...    builds these targets only (e.g. vmap vmap_torch vmap_tests)
  -h, --help        prints this and exits
Other arguments go to CMake, e.g. scripts/build.sh -DVMAP_WITH_TORCH=OFF
EOF
}
cd "$(dirname "$0")/.."
build_dir=${VMAP_BUILD_DIR:-build}
targets=()
cmake_args=()
while (($#)); do
  if [[ "$1" == "-h" || "$1" == "--help" ]]; then
    usage
    exit 0
  elif [[ "$1" == "--targets" ]]; then
    shift
    while (($#)) && [[ "$1" != -* ]]; do targets+=("$1"); shift; done
    if ((${#targets[@]} == 0)); then echo "build.sh: --targets needs at least one target name" >&2; exit 2; fi
  else
    cmake_args+=("$1"); shift
  fi
done
# The vmap target builds the plugin too (a plugin older than the binary must never be loaded), except when
# targets without vmap_torch are asked for: then the binary alone is built and no plugin exists yet.
binary_builds_plugin=ON
if ((${#targets[@]})) && [[ " ${targets[*]} " != *" vmap_torch "* ]]; then binary_builds_plugin=OFF; fi
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DVMAP_BINARY_BUILDS_PLUGIN=$binary_builds_plugin \
  "${cmake_args[@]}" >/dev/null
# Two jobs: LibTorch translation units take ~2 GB of RAM each to compile.
cmake --build "$build_dir" -j "${VMAP_JOBS:-2}" ${targets[@]:+--target "${targets[@]}"}
