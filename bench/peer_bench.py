#!/usr/bin/python3
"""vmap build against the paper-style Python peer (bench/paper_style_peer.py), side by side.

For each sequence, every repeat runs, one after the other: the peer, `vmap build --exhaustive --min-key-displacement 0` (the paper: no repeated-frame rule), `vmap build`
(so a change in the machine's load touches all three alike). Each run is a child process; its wall time and its
CPU time (user + system, all threads, from wait4) are recorded. Printed per sequence: the medians, the ratios
peer / vmap for wall time and vmap / peer for CPU time (median of the per-repeat ratios), and whether the peer
chose the same key images as `vmap build --exhaustive` (it must: same ORB, same matching, same USAC_MAGSAC call,
same Algorithm 1) and as `vmap build`.

Needs Debian's python3-opencv and python3-numpy for the peer: `apt-get install python3-opencv python3-numpy`
(the script checks and says so). Run from the repository root after building vmap:

  /usr/bin/python3 bench/peer_bench.py [--vmap build/vmap] [--repeat 3] [--tau 0.5] [SEQUENCE ...]

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
SHARED = os.path.join(HERE, "..", "..", "shared", "data")
DEFAULT_SEQUENCES = ["rccar_room/images", "lab_floor/lab_floor.mp4", "kitti07", "redkitchen"]


def check_peer_dependencies():
    probe = subprocess.run(["/usr/bin/python3", "-c", "import cv2, numpy"], capture_output=True)
    if probe.returncode != 0:
        sys.exit("peer_bench: the peer needs Debian's OpenCV and NumPy for /usr/bin/python3:\n"
                 "  apt-get install python3-opencv python3-numpy")


def run(command):
    """Runs a child process; returns (wall seconds, CPU seconds, stdout)."""
    start = time.perf_counter()
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _, status, usage = os.wait4(process.pid, 0)
    wall = time.perf_counter() - start
    out = process.stdout.read()
    err = process.stderr.read()
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit("peer_bench: %s failed:\n%s%s" % (" ".join(command), out, err))
    return wall, usage.ru_utime + usage.ru_stime, out


def key_frames_of_map(directory):
    with open(os.path.join(directory, "map.json")) as f:
        return [k["frame_index"] for k in json.load(f)["key_images"]]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sequences", nargs="*")
    parser.add_argument("--vmap", default="build/vmap")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--tau", type=float, default=0.5)
    args = parser.parse_args()
    check_peer_dependencies()
    sequences = args.sequences or [os.path.normpath(os.path.join(SHARED, s)) for s in DEFAULT_SEQUENCES]
    peer = os.path.join(HERE, "paper_style_peer.py")
    rows = []
    with tempfile.TemporaryDirectory(prefix="peer_bench_") as tmp:
        for sequence in sequences:
            times = {"peer": [], "exhaustive": [], "vmap": []}
            same_exhaustive = same_fast = True
            for r in range(args.repeat):
                peer_json = os.path.join(tmp, "peer.json")
                wall, cpu, _ = run(["/usr/bin/python3", peer, sequence, "--tau", str(args.tau),
                                    "-o", os.path.join(tmp, "peer_keys_%d" % r), "--json", peer_json])
                times["peer"].append((wall, cpu))
                with open(peer_json) as f:
                    peer_keys = json.load(f)["key_frames"]
                for name, extra in (("exhaustive", ["--exhaustive", "--min-key-displacement", "0"]), ("vmap", [])):
                    out_dir = os.path.join(tmp, "%s_%d" % (name, r))
                    wall, cpu, _ = run([args.vmap, "build", sequence, "--tau", str(args.tau), "-q",
                                        "-o", out_dir] + extra)
                    times[name].append((wall, cpu))
                    same = key_frames_of_map(out_dir) == peer_keys
                    if name == "exhaustive":
                        same_exhaustive &= same
                    else:
                        same_fast &= same
            med = {k: (statistics.median(w for w, _ in v), statistics.median(c for _, c in v)) for k, v in times.items()}
            speed = {k: statistics.median(p[0] / t[0] for p, t in zip(times["peer"], times[k])) for k in ("exhaustive", "vmap")}
            cpu = {k: statistics.median(t[1] / p[1] for p, t in zip(times["peer"], times[k])) for k in ("exhaustive", "vmap")}
            rows.append((os.path.relpath(sequence, SHARED) if sequence.startswith(os.path.normpath(SHARED)) else sequence,
                         med, speed, cpu, same_exhaustive, same_fast))
            print("%s: done" % sequence, file=sys.stderr)

    print("tau %.2f, median of %d interleaved repeats; wall and CPU seconds (CPU = user + system, all threads)"
          % (args.tau, args.repeat))
    print()
    print("| sequence | peer wall / CPU | vmap --exhaustive wall / CPU | vmap wall / CPU | peer / vmap (wall) |"
          " vmap CPU / peer CPU | peer / vmap --exhaustive (wall) | same keys as peer: --exhaustive, default |")
    print("|---|---|---|---|---|---|---|---|")
    for name, med, speed, cpu, same_exhaustive, same_fast in rows:
        print("| %s | %.2f / %.2f | %.2f / %.2f | %.2f / %.2f | **%.2fx** | %.2f | %.2fx | %s, %s |" % (
            name, med["peer"][0], med["peer"][1], med["exhaustive"][0], med["exhaustive"][1], med["vmap"][0],
            med["vmap"][1], speed["vmap"], cpu["vmap"], speed["exhaustive"],
            "yes" if same_exhaustive else "NO", "yes" if same_fast else "no"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
