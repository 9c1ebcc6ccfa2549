#!/usr/bin/python3
"""vmap.match from Python against `vmap match` on the same 640x480 pair, side by side in one run.

What is compared: the work of matching one pair (both images' feature extraction, matching, verification).
  - CLI: `vmap match A.png B.png --json OUT`, run as a process per repetition; its own time_s (extract + match +
    verify), measured inside the process, so process start, image decoding and matcher creation (time_s.load: the
    plugin load for a deep matcher) are excluded: they are not part of the work and Python pays them once.
  - Python: the wall time of one vmap.match(gray0, gray1) call on numpy arrays, everything included: keyword
    parsing, creating the matcher, numpy in and out, the GIL released and taken back.
Both use the CLI's process-wide settings (vmap.initialize_runtime(): OpenCV on one thread, as the CLI runs it).
The layer's own cost is also measured directly: the call's wall time minus the library's time_s for the same
steps inside that call. Repetitions alternate CLI and Python so that load on a shared machine hits both alike; medians are reported.

Usage: PYTHONPATH=build/python /usr/bin/python3 bench/python_match_bench.py [--cli build/vmap] [--reps 30]
       [--matcher orb]
The pair: the first two key images of a map of lab_floor's first 60 frames, built here (PNG files for the CLI,
the same files decoded by vmap, in grey, for Python: the inputs are identical).
"""
import argparse
import json
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import vmap

ROOT = pathlib.Path(__file__).resolve().parents[1]


def pair_from_lab_floor(work):
    video = ROOT.parent / "shared" / "data" / "lab_floor" / "lab_floor.mp4"
    if not video.is_file():
        sys.exit(f"{video} not found (../shared)")
    m = vmap.build_map(str(video), work / "map", first=0, last=59)
    return [str(m.directory / k.image_file) for k in m.key_images[:2]], m.key_images[0].gray, m.key_images[1].gray


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cli", default=str(ROOT / "build" / "vmap"))
    parser.add_argument("--reps", type=int, default=30)
    parser.add_argument("--matcher", default="orb")
    args = parser.parse_args()
    vmap.initialize_runtime()
    vmap.set_log_level("quiet")
    with tempfile.TemporaryDirectory() as tmp:
        work = pathlib.Path(tmp)
        paths, gray0, gray1 = pair_from_lab_floor(work)
        out = work / "match.json"
        cli_s, cli_wall_s, py_s, layer_s = [], [], [], []
        matcher = vmap.Matcher(matcher=args.matcher)
        reference = None
        for _ in range(args.reps):
            start = time.perf_counter()
            subprocess.run([args.cli, "match", *paths, "--matcher", args.matcher, "--json", str(out), "-q"],
                           check=True, stdout=subprocess.DEVNULL)
            cli_wall_s.append(time.perf_counter() - start)
            record = json.loads(out.read_text())
            cli_s.append(record["time_s"]["extract"] + record["time_s"]["match"] + record["time_s"]["verify"])
            start = time.perf_counter()
            result = vmap.match(gray0, gray1, matcher=args.matcher)
            py_s.append(time.perf_counter() - start)
            # The same steps timed inside the library: what the call adds around them is the layer's cost.
            layer_s.append(py_s[-1] - sum(result.time_s.values()))
            reference = (record["num_tentative"], record["num_verified"])
            assert (result.num_tentative, result.num_verified) == reference, "the module and the CLI disagree"
        reused_s = []
        for _ in range(args.reps):
            start = time.perf_counter()
            matcher.match(gray0, gray1)
            reused_s.append(time.perf_counter() - start)
    cli, py = statistics.median(cli_s), statistics.median(py_s)
    print(f"pair            {paths[0]} {paths[1]} ({gray0.shape[1]}x{gray0.shape[0]}), {args.matcher}, "
          f"{reference[0]} tentative, {reference[1]} verified")
    print(f"repetitions     {args.reps}, alternating")
    print(f"vmap match      {cli * 1e3:.2f} ms median (extract + match + verify inside the process; "
          f"process wall {statistics.median(cli_wall_s) * 1e3:.1f} ms)")
    print(f"vmap.match      {py * 1e3:.2f} ms median (whole call)")
    print(f"Matcher.match   {statistics.median(reused_s) * 1e3:.2f} ms median (matcher created once)")
    layer = statistics.median(layer_s)
    print(f"layer           {layer * 1e3:.3f} ms median per vmap.match call outside the library's steps "
          f"({100 * layer / py:.2f} % of the call)")
    print(f"ratio           {py / cli:.3f} (vmap.match / vmap match)")


if __name__ == "__main__":
    main()
