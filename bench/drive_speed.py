#!/usr/bin/python3
"""Issue 34's two speed goals, measured with `vmap simulate` on one thread (run it on a quiet machine):

  control step  features (ORB), localization and control of one 640x480 frame, rendering excluded: goal <= 20 ms
  renderer      frames of the photograph corridor rendered per second at 640x480: goal >= 30 frames/s

Each route given (default straight and turn) is one trial (`--trials 1 --threads 1`, the default law, ORB, the
same appearance, the photographs of bench/drive_bench.py on the walls and floor). Prints one line per route and the
figures over all frames:

  /usr/bin/python3 bench/drive_speed.py [--vmap build/vmap] [--out drive_speed] [--routes straight turn]
"""

import argparse
import json
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from drive_bench import link_photos  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--vmap", default=os.path.join(HERE, "..", "build", "vmap"))
    parser.add_argument("--out", default="drive_speed")
    parser.add_argument("--routes", nargs="+", default=["straight", "turn"])
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    photos = link_photos(args.out)
    frames = step_seconds = render_seconds = 0.0
    for route in args.routes:
        json_path = os.path.join(args.out, "speed_%s.json" % route)
        command = [args.vmap, "simulate", "--route", route, "--trials", "1", "--threads", "1",
                   "--teach-textures", photos, "--json", json_path, "-q"]
        result = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if result.returncode != 0:
            sys.exit("failed: %s\n%s" % (" ".join(command), result.stdout))
        with open(json_path) as f:
            run = json.load(f)
        trial = run["trials"][0]
        n = trial["frames"]
        frames += n
        step_seconds += n * trial["mean_step_ms"] / 1e3
        render_seconds += n * trial["mean_render_ms"] / 1e3
        print("%-9s %4d frames  control step %.1f ms mean (%.1f ms max)  renderer %.0f frames/s" % (
            route, n, trial["mean_step_ms"], trial["max_step_ms"], 1e3 / trial["mean_render_ms"]), flush=True)
    step_ms = 1e3 * step_seconds / frames
    fps = frames / render_seconds
    print("control step (ORB, 640x480, features + localization + control, rendering excluded): %.1f ms mean "
          "(goal <= 20 ms: %s)" % (step_ms, "met" if step_ms <= 20.0 else "NOT met"))
    print("renderer (640x480, photographs): %.0f frames/s (goal >= 30: %s)" % (fps, "met" if fps >= 30.0 else "NOT met"))


if __name__ == "__main__":
    main()
