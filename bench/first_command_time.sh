#!/usr/bin/env bash
# How long the README's first command takes on a clean clone, install excluded: scripts/build.sh with the given
# arguments, then the first map, with ccache off and no compiler launcher. Prints wall and CPU seconds.
#   bench/first_command_time.sh REPOSITORY REVISION [BUILD_ARGS...]
#   bench/first_command_time.sh /work/main main --targets vmap    # the first command today
#   bench/first_command_time.sh /work/main 748dc23                # before it, when the first command built everything
# Run the revisions one after the other, alternating, on the same machine: the times follow its load.
set -euo pipefail
repository=$1 revision=$2
shift 2
shared=$(cd "$(dirname "$0")/../../shared" && pwd)  # the data folder beside this checkout
work=$(mktemp -d /tmp/vmap-first-command.XXXXXX)
trap 'rm -rf "$work"' EXIT
git clone -q "$repository" "$work/vmap"
git -C "$work/vmap" checkout -q "$revision"
ln -s "$shared" "$work/shared"
cd "$work/vmap"
export CCACHE_DISABLE=1
echo "$(git rev-parse --short HEAD) start $(date -u +%FT%TZ), load $(cut -d' ' -f1-3 /proc/loadavg)"
/usr/bin/time -f "build: wall %e s, CPU %U s user + %S s system" scripts/build.sh "$@" >build.log 2>&1 ||
  { tail -20 build.log; exit 1; }
tail -1 build.log
echo "compiled: $(find build -name '*.o' | wc -l) object files"
/usr/bin/time -f "first map: wall %e s" build/vmap build ../shared/data/lab_floor/lab_floor.mp4 -o lab_floor_map -q
echo "end $(date -u +%FT%TZ), load $(cut -d' ' -f1-3 /proc/loadavg)"
