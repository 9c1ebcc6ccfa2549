#!/usr/bin/env bash
# Installs everything vmap needs on Debian 12 (bookworm) from Debian's own packages.
# Usage: scripts/install-deps.sh [--with-browser] [--with-ros] [--with-fuzzers]
#   --with-browser  also installs Chromium, used by the report tests.
#   --with-ros      also installs ROS 1 (Debian's ROS Noetic packages): the node in ros/ and its tests against a
#                   real rosmaster (docs/ros.md). The vmap binary never needs it.
#   --with-fuzzers  also installs clang and its libFuzzer, for the fuzz targets (fuzz/, docs/fuzzing.md); without
#                   them the build skips the fuzz targets and ctest reports their runs as skipped.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libopencv-dev                 # OpenCV 4.6 with the FFmpeg video backend and USAC (MAGSAC)
  libavformat-dev libavcodec-dev libswscale-dev libavutil-dev  # FFmpeg: vmap decodes videos itself
  libtorch-dev                  # LibTorch 1.13 (CPU) for the deep matchers
  libopenblas0-openmp           # without it LibTorch uses the reference BLAS and runs 30-50x slower
  libcli11-dev nlohmann-json3-dev libspdlog-dev libfmt-dev libeigen3-dev
  libgtest-dev libgmock-dev googletest libbenchmark-dev
  libsqlite3-dev libzstd-dev liblz4-dev libbz2-dev python3-rosbag  # recordings (python3-rosbag: test fixtures)
  ffmpeg                        # only used by tests: videos with a display rotation, live streams on the loopback
  time                          # GNU time: tests and benchmarks measure a run's own peak memory with it
  pybind11-dev python3-numpy python3-pytest  # the Python module (python/, docs/python.md) and its tests
)
ros_packages=(
  ros-core                      # rosmaster, rosout, rostopic, roslaunch, rosbag play and record
  rosbash                       # rosrun (docs/ros.md runs the simulator node and the node with it)
  libroscpp-dev libtopic-tools-dev libcv-bridge-dev  # the node: roscpp, any image type (ShapeShifter), the debug image
  libsensor-msgs-dev libgeometry-msgs-dev libnav-msgs-dev libstd-msgs-dev libstd-srvs-dev  # message headers
  ros-sensor-msgs ros-geometry-msgs ros-nav-msgs ros-std-msgs ros-std-srvs  # their .msg files (genmsg, rostopic)
  python3-gencpp python3-genpy  # the generators of the vmap_ros messages (C++ and Python)
  python3-sensor-msgs python3-geometry-msgs python3-nav-msgs python3-std-srvs  # rostopic echo of the node's topics
)
for flag in "$@"; do
  case "$flag" in
    --with-browser) packages+=(chromium) ;;
    --with-ros) packages+=("${ros_packages[@]}") ;;
    --with-fuzzers) packages+=(clang libclang-rt-14-dev) ;;
    *) echo "install-deps: unknown option $flag (use --with-browser, --with-ros, --with-fuzzers)" >&2; exit 2 ;;
  esac
done

sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then sudo_cmd=(sudo); fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "install-deps: installing ${missing[*]}"
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "install-deps: all packages present"
fi
