#!/usr/bin/python3
"""Same-season guards of a localizer change: does it move any frame where the world did not change?

A rule written for changing appearance must leave the maps whose repeat looks like their teach as they were
(issue 35: "same-season maps localize as well as now or better"). For each guard below, the first binary builds one map
(so every binary localizes against the same key images), every binary localizes the guard's frames against it, and
each frame's status and key image are compared with the first binary's. A row per guard and binary: the frames
that differ, the frames steered by (tracking or relocalized) and frames/s; under it the first differing frames.

Guards (docs/measurements/localization-conditions.md, "A tracker held where the next key image sees nothing is
questioned"): lab_floor's first 400 frames against a map of them, pepper_corridor's and rccar_room's frames against
their own maps, redkitchen's repeat (frames 500-999, every second) against a map of frames 0-499.

usage: bench/same_season_guards.py --vmap OLD/vmap,NEW/vmap [--matchers xfeat,orb] [--guards lab_floor,...]
                                   [--localize "FLAGS"] [--work DIR] [--named-frames N]
(from the repository root; ../shared must be there; exits 1 when any frame differs)"""
import argparse, json, os, subprocess, sys, tempfile

SHARED = "../shared"
# name: (input, build flags of the map, localize flags of the frames localized against it)
GUARDS = {
    "lab_floor": (SHARED + "/data/lab_floor/lab_floor.mp4", ["--last", "399"], ["--last", "399"]),
    "pepper_corridor": (SHARED + "/eval/pepper_corridor/images", [], []),
    "rccar_room": (SHARED + "/data/rccar_room/images", [], []),
    "redkitchen_repeat": (SHARED + "/data/redkitchen", ["--last", "499"], ["--first", "500", "--stride", "2"]),
}


def run(command):
    done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if done.returncode != 0:
        sys.exit("failed: %s\n%s" % (" ".join(command), done.stdout))


def localized_frames(vmap, map_directory, query, flags, output):
    run([vmap, "localize", map_directory, query, "-q", "--json", output] + flags)
    with open(output) as f:
        doc = json.load(f)
    return doc["frames"], doc["summary"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--vmap", required=True, help="comma-separated binaries; the first is the reference")
    parser.add_argument("--matchers", default="xfeat,orb")
    parser.add_argument("--guards", default=",".join(GUARDS))
    parser.add_argument("--localize", default="", help="more flags for vmap localize (every binary)")
    parser.add_argument("--work", help="keep the maps here (reused) instead of a temporary folder")
    parser.add_argument("--named-frames", type=int, default=8, help="name at most this many differing frames a row")
    args = parser.parse_args()
    binaries = args.vmap.split(",")
    unknown = [g for g in args.guards.split(",") if g not in GUARDS]
    if unknown:
        sys.exit("unknown guard %s (known: %s)" % (",".join(unknown), ",".join(GUARDS)))
    work = args.work or tempfile.mkdtemp(prefix="vmap_guards_")
    differing_total = 0
    print("| guard | matcher | binary | frames differing | steered by | frames/s |")
    print("|---|---|---|---|---|---|")
    for guard in args.guards.split(","):
        images, build_flags, localize_flags = GUARDS[guard]
        for matcher in args.matchers.split(","):
            map_directory = os.path.join(work, "%s_%s" % (guard, matcher))
            if not os.path.exists(os.path.join(map_directory, "map.json")):
                run([binaries[0], "build", images, "-q", "--matcher", matcher, "-o", map_directory] + build_flags)
            reference = None
            for index, vmap in enumerate(binaries):
                output = os.path.join(work, "%s_%s_%d.json" % (guard, matcher, index))
                frames, summary = localized_frames(vmap, map_directory, images, localize_flags + args.localize.split(),
                                                   output)
                seen = [(f["status"], f["key"]) for f in frames]
                if reference is None:
                    reference = seen
                    differing = []
                elif len(seen) != len(reference):
                    sys.exit("%s %s: %d frames localized by %s, %d by %s" % (guard, matcher, len(seen), vmap,
                                                                          len(reference), binaries[0]))
                else:
                    differing = [(frames[i]["source_index"], reference[i], seen[i])
                                 for i in range(len(seen)) if seen[i] != reference[i]]
                differing_total += len(differing)
                steered = sum(status in ("tracking", "relocalized") for status, _ in seen)
                print("| %s | %s | %s | %d of %d | %d | %.1f |" % (guard, matcher, vmap, len(differing), len(seen),
                                                                  steered, summary.get("frames_per_second", 0.0)))
                for source, (old_status, old_key), (new_status, new_key) in differing[:args.named_frames or None]:
                    print("|  | | frame %d: %s at %d -> %s at %d | | | |" % (source, old_status, old_key, new_status,
                                                                            new_key))
    sys.exit(1 if differing_total else 0)


if __name__ == "__main__":
    main()
