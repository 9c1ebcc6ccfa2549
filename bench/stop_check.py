#!/usr/bin/python3
"""A robot that stops on its own route: is it stepped on? (docs/measurements/localization-conditions.md, "A lost
frame's heading where the route goes next, and a robot that stops").

michigan_seasons as routes (as bench/route_conditions.py's michigan set): for every ordered pair of sessions (a, b), a
`--tau 1` map of session a's five places, and session b's places 1..p as frames, then b's place p four more times (the
robot stopped there), localized from key image 0 (`--start-key 0`). Frame i of the route is right at key image i, every
stop frame at key image p - 1. Rows, each per binary:

  stop, identical frames: the four stop frames the same image file (a still camera, no noise);
  stop, with noise: each stop frame its own copy of the image with a camera's noise (ffmpeg's noise filter, uniform
    +-NOISE grey levels, seeded: the same copies for every binary);
  season at a standstill (not a robot's stop): session a's own image at place p, then b's image at p four times,
    from key image p - 1 (`--start-key p-1`), p = 1..5. The season changes while the robot stands: no camera sees that,
    and no image test can tell it from a step (docs/measurements/localization-conditions.md, "A robot that stops: what
    the check measures"); kept to show what a rule does there.

Per row: the stop frames placed right (tracking or relocalized at key image p - 1), stepped on (placed at a key image
after it), placed back (before it), uncertain, lost; and the route's frames before the stop (right / wrong / lost), whose
lost frames a rule may place. A stepped-on frame is named (map, session, p, frame). A rule's safety on a stop: stepped
on not more than the old binary's in the rows of a robot's stop.

usage: bench/stop_check.py --vmap OLD[,NEW] [--places 2,3,4,5] [--rows identical,noisy,season] [--noise 6]
                           [--seeds S,S,...] [--localize "FLAGS"] [--sessions 01,...,12] [--work DIR] [--jobs N]
(from the repository root; ../shared must be there; ffmpeg for the noisy row)"""
import argparse, collections, concurrent.futures, csv, os, subprocess, sys, tempfile

IMAGES = os.path.join("../shared/data", "michigan_seasons", "images")
SESSIONS = ["%02d" % s for s in range(1, 13)]
STOP_FRAMES = 4  # frames after the route's frame at place p that show place p again


def run(command):
    done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if done.returncode != 0:
        sys.exit("failed: %s\n%s" % (" ".join(command), done.stdout))
    return done.stdout


def image(session, place):
    return os.path.abspath(os.path.join(IMAGES, "%s%02d.png" % (session, place)))


def noisy_image(work, session, place, copy, noise):
    """Copy `copy` of the image with uniform noise of +-`noise` grey levels, seeded by the image and the copy."""
    path = os.path.join(work, "noisy", "%s%02d_%d.png" % (session, place, copy))
    if not os.path.exists(path):
        os.makedirs(os.path.dirname(path), exist_ok=True)
        seed = int(session) * 100 + place * 10 + copy
        # ffmpeg's strength is the noise's full range (alls=12: -5..+6 grey levels).
        run(["ffmpeg", "-loglevel", "error", "-y", "-i", image(session, place), "-vf",
             "noise=alls=%d:allf=u:all_seed=%d" % (2 * noise, seed), "-pix_fmt", "gray", path + ".tmp.png"])
        os.replace(path + ".tmp.png", path)
    return path


def folder_of(path, frames):
    """A folder of links to `frames`, in order (01.png, 02.png, ...)."""
    if not os.path.isdir(path):
        os.makedirs(path + ".tmp", exist_ok=True)
        for i, frame in enumerate(frames):
            os.symlink(frame, os.path.join(path + ".tmp", "%02d.png" % (i + 1)))
        os.replace(path + ".tmp", path)
    return path


def runs_of(row, sessions, places, work, noise):
    """(name, frames, start key, map session, right key of each frame, index of the first stop frame) of a row."""
    runs = []
    for a in sessions:
        for b in sessions:
            if a == b:
                continue
            if row == "season":
                for p in range(1, 6):
                    frames = [image(a, p)] + [image(b, p)] * STOP_FRAMES
                    runs.append(("%s->%s p%d" % (b, a, p), frames, p - 1, a, [p - 1] * len(frames), 1))
                continue
            for p in places:
                route = [image(b, place) for place in range(1, p + 1)]
                if row == "identical":
                    stop = [image(b, p)] * STOP_FRAMES
                else:
                    stop = [noisy_image(work, b, p, copy, noise) for copy in range(STOP_FRAMES)]
                frames = route + stop
                runs.append(("%s->%s p%d" % (b, a, p), frames, 0, a, [min(i, p - 1) for i in range(len(frames))], p))
    return runs


def localize(vmap, map_directory, query, start_key, flags, output):
    run([vmap, "localize", map_directory, query, "-q", "--start-key", str(start_key), "--csv", output] + flags)
    with open(output) as f:
        return list(csv.DictReader(f))


def tally_run(rows, right_keys, first_stop, name, counts, stepped):
    for r in rows:
        i = int(r["frame"])
        part = "stop" if i >= first_stop else "route"
        status = r["status"]
        if status in ("lost", "uncertain"):
            counts[part, status] += 1
            continue
        key, right = int(r["key"]), right_keys[i]
        if key == right:
            counts[part, "right"] += 1
        elif part == "route":
            counts[part, "wrong"] += 1
        elif key > right:
            counts[part, "stepped on"] += 1
            stepped.append("%s frame %d at key %d (%s)" % (name, i, key, status))
        else:
            counts[part, "placed back"] += 1
            stepped.append("%s frame %d back at key %d (%s)" % (name, i, key, status))


ROW_NAMES = {"identical": "stop, identical frames", "noisy": "stop, with noise",
             "season": "season at a standstill (not a robot's stop)"}


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--vmap", default="build/vmap", help="comma-separated binaries, compared side by side")
    parser.add_argument("--places", default="2,3,4,5", help="the places p the robot stops at (stop rows)")
    parser.add_argument("--rows", default="identical,noisy,season")
    parser.add_argument("--noise", type=int, default=6, help="the noisy row's uniform noise, +- grey levels")
    parser.add_argument("--seeds", help="comma-separated seeds of the verifier (vmap localize --verifier-seed), a row "
                        "per seed (default: the map's seed only, no flag passed)")
    parser.add_argument("--localize", default="", help="more flags for vmap localize")
    parser.add_argument("--work", help="keep maps, folders and noisy copies here (reused) instead of a temporary folder")
    parser.add_argument("--sessions", default=",".join(SESSIONS), help="michigan's sessions taken as maps and routes")
    parser.add_argument("--jobs", type=int, default=1, help="runs localized at once")
    args = parser.parse_args()
    places = [int(p) for p in args.places.split(",")]
    if any(p < 1 or p > 5 for p in places):
        parser.error("--places: michigan_seasons' routes have places 1 to 5")
    seeds = args.seeds.split(",") if args.seeds else [None]
    sessions = args.sessions.split(",")
    print("| binary, row | runs | stop frames | right | stepped on | placed back | uncertain | lost | "
          "route frames right / wrong / lost |\n|---|---|---|---|---|---|---|---|---|", flush=True)
    with tempfile.TemporaryDirectory(prefix="vmap_stop_check_") as scratch:
        work = args.work or scratch
        for index, vmap in enumerate(args.vmap.split(",")):
            binary_work = os.path.join(work, "binary%d" % index)
            maps = {}
            for a in sessions:
                maps[a] = os.path.join(binary_work, "map_" + a)
                if not os.path.exists(os.path.join(maps[a], "map.json")):
                    session = folder_of(os.path.join(work, "session_" + a), [image(a, p) for p in range(1, 6)])
                    run([vmap, "build", session, "-q", "--matcher", "orb", "--tau", "1", "-o", maps[a]])
            for row in args.rows.split(","):
                runs = runs_of(row, sessions, places, work, args.noise)
                for seed in seeds:
                    flags = args.localize.split() + (["--verifier-seed", seed] if seed is not None else [])
                    counts, stepped = collections.Counter(), []

                    def one(numbered):
                        n, (name, frames, start_key, a, right_keys, first_stop) = numbered
                        query = folder_of(os.path.join(work, row, name.replace("->", "_on_").replace(" ", "_")),
                                          frames)
                        out = os.path.join(binary_work, "csv", row + ("_s" + seed if seed else ""), "%04d.csv" % n)
                        os.makedirs(os.path.dirname(out), exist_ok=True)
                        return localize(vmap, maps[a], query, start_key, flags, out)

                    with concurrent.futures.ThreadPoolExecutor(max(1, args.jobs)) as pool:
                        results = list(pool.map(one, enumerate(runs)))
                    for (name, frames, start_key, a, right_keys, first_stop), rows in zip(runs, results):
                        tally_run(rows, right_keys, first_stop, name, counts, stepped)
                    stop = sum(v for (part, _), v in counts.items() if part == "stop")
                    print("| %s: %s%s | %d | %d | %d | %d | %d | %d | %d | %d / %d / %d |" % (
                        vmap, ROW_NAMES[row], ", seed " + seed if seed else "", len(runs), stop,
                        counts["stop", "right"], counts["stop", "stepped on"], counts["stop", "placed back"],
                        counts["stop", "uncertain"], counts["stop", "lost"], counts["route", "right"],
                        counts["route", "wrong"], counts["route", "lost"]), flush=True)
                    for line in stepped[:12]:
                        print("    " + line)
                    if len(stepped) > 12:
                        print("    ... %d more" % (len(stepped) - 12))


if __name__ == "__main__":
    main()
