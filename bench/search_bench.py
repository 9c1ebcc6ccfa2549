#!/usr/bin/python3
"""Key-image search with a deep matcher: `--search bisect` against `--search sequential` (Algorithm 1 as
written), side by side.

For each sequence, every repeat runs `vmap build --matcher MATCHER --search sequential` then `... --search
bisect` as child processes (wall time and CPU time, user + system over all threads, from wait4). Printed per
sequence: the medians, the speed-up and CPU ratio (median of per-repeat ratios), the comparisons each made
(map.json evaluations), m and Q of each, whether the key images are the same, and how many of the sequential
run's key images the bisect run has within +-2 frames.

  /usr/bin/python3 bench/search_bench.py [--vmap build/vmap] [--matcher loftr] [--repeat 1] [--tau 0.5]
                                         [-- extra vmap options] [SEQUENCE ...]

Default sequences: every sequence of ../shared/data.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SHARED = os.path.normpath(os.path.join(HERE, "..", "..", "shared", "data"))
DEFAULT_SEQUENCES = ["rccar_room/images", "lab_floor/lab_floor.mp4", "kitti07", "redkitchen"]


def run(command):
    start = time.perf_counter()
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _, status, usage = os.wait4(process.pid, 0)
    wall = time.perf_counter() - start
    out, err = process.stdout.read(), process.stderr.read()
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit("search_bench: %s failed:\n%s%s" % (" ".join(command), out, err))
    return wall, usage.ru_utime + usage.ru_stime


def summary(directory):
    with open(os.path.join(directory, "map.json")) as f:
        m = json.load(f)
    return {"keys": [k["frame_index"] for k in m["key_images"]], "quality": m["quality"],
            "comparisons": len(m["evaluations"]["frame"]), "below_tau": sum(l["below_tau"] for l in m["links"])}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sequences", nargs="*")
    parser.add_argument("--vmap", default="build/vmap")
    parser.add_argument("--matcher", default="loftr")
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--tau", type=float, default=0.5)
    parser.add_argument("--extra", default="", help="more vmap options, e.g. \"--last 199\"")
    args = parser.parse_args()
    sequences = args.sequences or [os.path.join(SHARED, s) for s in DEFAULT_SEQUENCES]
    print("matcher %s, tau %.2f, %s; median of %d interleaved repeats" % (args.matcher, args.tau,
                                                                       args.extra or "all frames", args.repeat))
    print()
    print("| sequence | n | comparisons: sequential, bisect | m: sequential, bisect | Q: sequential, bisect |"
          " same key images | sequential keys within +-2 frames | speed-up (wall) | CPU ratio |")
    print("|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory(prefix="search_bench_") as tmp:
        for sequence in sequences:
            times = {"sequential": [], "bisect": []}
            maps = {}
            for r in range(args.repeat):
                for search in ("sequential", "bisect"):
                    out = os.path.join(tmp, search)
                    times[search].append(run([args.vmap, "build", sequence, "--matcher", args.matcher, "--tau",
                                              str(args.tau), "--search", search, "-q", "-o", out]
                                             + args.extra.split()))
                    maps[search] = summary(out)
            with open(os.path.join(tmp, "sequential", "map.json")) as f:
                n = json.load(f)["num_frames"]
            seq, bis = maps["sequential"], maps["bisect"]
            near = sum(any(abs(k - b) <= 2 for b in bis["keys"]) for k in seq["keys"])
            speed = statistics.median(s[0] / b[0] for s, b in zip(times["sequential"], times["bisect"]))
            cpu = statistics.median(b[1] / s[1] for s, b in zip(times["sequential"], times["bisect"]))
            name = os.path.relpath(sequence, SHARED) if sequence.startswith(SHARED) else sequence
            print("| %s | %d | %d, %d | %d, %d | %.3f, %.3f | %s | %d of %d | %.2fx | %.2f |" % (
                name, n, seq["comparisons"], bis["comparisons"], len(seq["keys"]), len(bis["keys"]), seq["quality"],
                bis["quality"], "yes" if seq["keys"] == bis["keys"] else "no", near, len(seq["keys"]), speed, cpu),
                flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
