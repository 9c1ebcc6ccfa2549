#!/usr/bin/python3
"""Localization along a route whose appearance changed (docs/measurements/localization-conditions.md).

corridor: ../shared/data/corridor_conditions: a map of teach/ (`vmap build`), repeat/ localized against it; repeat
  frame i was taken where teach frame i was, and a frame is right when its key image is one of those around any
  teach frame i-2..i+2 (the key images bracketing it, with the data set's +-2 frames).
places: corridor_conditions as a map of places, as a path taught once per place (the issue's snowy park: 101 places a
  few metres apart, frame i of the repeat at key image i of a `--tau 1` map): every third teach frame a key image
  (`vmap build --tau 1 --stride 3`) and every third repeat frame localized against it, so the run passes a key image
  every frame; right as the corridor's (the data set's +-2 frames).
third-rate: the corridor's repeat at a third of the teach run's frame rate, as its own recording: every third repeat
  frame in a folder of links numbered on, 0.3 s apart (a timestamps.txt), against a map of the teach run's frames 0.1 s
  apart (the same key images as the corridor's: a folder of links with its timestamps.txt), so its input indices say a
  frame and its times say three (a camera at a lower frame rate, a node that drops frames while it localizes).
  third-rate-places: the same repeat against the places map built from the timed teach run (a key image a frame).
speed: the corridor's repeat driven at 1 to 4 times the teach speed (teach frames passed a frame: 1,1,2,2,3,3,4,4,4,4,
  3,3,2,2,1,1, again and again), the camera at the teach run's frame rate: its frames, a folder of links numbered on,
  0.1 s apart, against the timed teach run's map, so its indices and times say a frame of the teach run and it went
  one to four. speed-odometry: the same with both runs' odometry, from the frame alignment (a straight line, teach frame
  i at 0.1 i m, the repeat's frame where its teach frame was: perfect odometry), given to vmap localize
  (--teach-odometry, --odometry); --odometry-scale S makes the repeat's S times as long (a scale error).
  speed-places, speed-odometry-places: the same against the places map.
michigan: ../shared/data/michigan_seasons as routes: for every ordered pair of sessions (a, b), a map of session a's
  five places in order (`--tau 1`: every place a key image) and session b's five places localized against it
  (frame i right at key image i). 132 routes of 5 frames.
kidnapped: corridor_conditions' repeat frames 0-50, 80-110, 20-40 as one run (a folder of links in that order), against
  the corridor's map: a robot carried on twice, forwards then back (docs/localize.md, "A far relocalization needs two
  frames"). A run frame is right as its repeat frame is in the corridor set; the back-jumps count the second jump
  (one is the carried robot's, not the localizer's).
elsewhere: runs that start elsewhere than --start-key says (a user passes --start-key 0 by habit while the robot is
  further on): the corridor's repeat from frames 20, 50 and 90 and the kidnapped run from its frame 51 (repeat frame 80),
  each localized with `--first N`, their frames summed in one row (the far frames name their run).
Per run: frames right (at a right key image, whatever the status), right and not uncertain, localized wrong, confidently wrong by more than 2 places (status tracking or relocalized at a
key image more than 2 key images from every right one), uncertain and lost, frames/s, and back-jumps (a frame steered
by, tracking or relocalized, at a key image before the previous steered-by frame's: the route goes forwards, and the
held-out robot corridor's goal is none). Several vmap binaries
(`--vmap A,B`) run one after the other on the same maps' inputs (each builds its own maps), so they compare side by
side.

Under each row, its frames confidently > 2 places off and its back-jumps are named, the first 8 (--named-frames N:
the first N; 0: all of them).

With --evidence-dir DIR, also every frame of each run against every key image of its map (the evidence_dump of the
binary's own build, BUILD/bench/evidence_dump) into DIR/corridor_MATCHER.csv and DIR/michigan_MATCHER.csv (DIR/binaryN/
with several binaries), written anew by each invocation: the input of bench/evidence_fit.py.

--start-key K (default 0): every run is localized with `vmap localize --start-key K`: a repeat run starts where its
teach run started (corridor: repeat frame 0 at teach frame 0; michigan: frame 0 at key image 0), as a teach-and-repeat
robot does; "none" for binaries before the option (68a4a54 and older) or to start anywhere (docs/localize.md, "The
start").

With --build "FLAGS", every map is built with these flags too (e.g. ORB's extraction: "--orb-grid-cell 30
--orb-edge-threshold 16"); the localizer follows what the map records.

With --seeds 0,1,2,3, each binary localizes every run once per seed of the verifier (`vmap localize --verifier-seed
S`; the maps as built, once), one row per seed, then a row of each column's mean and [min-max] over the seeds: ORB's
near comparisons sit at chance's boundary and the seed moves corridor ORB's right frames by 5-7 (sd), so a change of
a few frames is judged on the means (docs/measurements/localization-conditions.md, "The verifier's seed: the spread
of every figure"). Default: the map's seed only, the flag not passed (binaries before the flag take no --seeds).

usage: bench/route_conditions.py --vmap build/vmap[,old/vmap] [--sets corridor,kidnapped,elsewhere,places,third-rate,third-rate-places,speed,speed-odometry,speed-places,speed-odometry-places,michigan] [--matchers orb,xfeat]
                                 [--tau T] [--start-key K|none] [--build "FLAGS"] [--localize "FLAGS"] [--repeat-stride N] [--odometry-scale S] [--work DIR] [--csv-dir DIR]
                                 [--evidence-dir DIR] [--seeds S,S,...] [--named-frames N]
(from the repository root; ../shared must be there)"""
import argparse, json, os, subprocess, sys, tempfile

SHARED = "../shared/data"


def run(command):
    done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if done.returncode != 0:
        sys.exit("failed: %s\n%s" % (" ".join(command), done.stdout))
    return done.stdout


def build(vmap, images, matcher, flags, directory):
    if not os.path.exists(os.path.join(directory, "map.json")):
        run([vmap, "build", images, "-q", "--matcher", matcher, "-o", directory] + flags)
    with open(os.path.join(directory, "map.json")) as f:
        return json.load(f)


def localize(vmap, map_directory, query, flags, output):
    run([vmap, "localize", map_directory, query, "-q", "--json", output] + flags)
    with open(output) as f:
        return json.load(f)


def keys_around(key_sources, source):
    """The key images bracketing teach frame `source` (the last at or before it, the first at or after it)."""
    before = max((k for k, s in enumerate(key_sources) if s <= source), default=None, key=lambda k: key_sources[k])
    after = min((k for k, s in enumerate(key_sources) if s >= source), default=None, key=lambda k: key_sources[k])
    return {k for k in (before, after) if k is not None}


class Tally:
    def __init__(self):
        self.frames = self.right = self.right_sure = self.wrong = self.confidently_far = self.uncertain = self.lost = 0
        self.back_jumps = 0
        self.seconds = 0.0
        self.far = []  # the far frames and back-jumps, in the order they came: report() names the first ones

    def add(self, doc, right_keys_of, label, name_of=lambda f: "frame %d" % f["source_index"]):
        """`right_keys_of(frame)`: the set of right key images of that frame; `name_of(frame)`: how `far` names it."""
        steered_key = None  # the key image of the last frame steered by
        for f in doc["frames"]:
            self.frames += 1
            if f["status"] in ("tracking", "relocalized"):
                if steered_key is not None and f["key"] < steered_key:
                    self.back_jumps += 1
                    self.far.append("%s %s: back-jump to key %d from %d" % (label, name_of(f), f["key"], steered_key))
                steered_key = f["key"]
            right = right_keys_of(f)
            status = f["status"]
            if status == "lost":
                self.lost += 1
                continue
            if status == "uncertain":
                self.uncertain += 1
            if f["key"] in right:
                self.right += 1
                self.right_sure += status != "uncertain"
                continue
            if status == "uncertain":
                continue
            self.wrong += 1
            if min(abs(f["key"] - k) for k in right) > 2:
                self.confidently_far += 1
                self.far.append("%s %s at key %d (right %s)" % (label, name_of(f), f["key"],
                                                                ",".join(map(str, sorted(right)))))
        self.seconds += doc["summary"]["seconds"]

    def row(self, name):
        n = max(1, self.frames)
        return "| %s | %d | %d (%.1f %%) | %d (%.1f %%) | %d | %d | %d | %d | %.1f | %d |" % (
            name, self.frames, self.right, 100.0 * self.right / n, self.right_sure, 100.0 * self.right_sure / n,
            self.wrong, self.confidently_far, self.uncertain, self.lost,
            self.frames / self.seconds if self.seconds > 0 else 0.0, self.back_jumps)


HEADER = ("| run | frames | right | right, not uncertain | localized wrong | confidently > 2 places off | uncertain | "
          "lost | frames/s | back-jumps |\n|---|---|---|---|---|---|---|---|---|---|")


def evidence_dump_of(vmap):
    """The evidence_dump of the build `vmap` is from (its bench/ folder): another build's would compare otherwise."""
    dump = os.path.join(os.path.dirname(os.path.abspath(vmap)), "bench", "evidence_dump")
    if not os.path.exists(dump):
        sys.exit("--evidence-dir needs %s, the evidence_dump of %s's build" % (dump, vmap))
    return dump


STARTED_EVIDENCE = set()  # the evidence files this invocation has begun: each is written anew once, then appended to


def dump_evidence(vmap, map_directory, query, output, prefix=""):
    """Adds evidence_dump's rows of `query` against the map to `output` (replaced by the first call of this invocation,
    with its header), each row after `prefix` (for michigan: the teach and repeat sessions)."""
    text = run([evidence_dump_of(vmap), map_directory, query])
    lines = text.splitlines()
    header = [l for l in lines if l.startswith("frame,")]
    rows = [l for l in lines if l and l[0].isdigit()]
    os.makedirs(os.path.dirname(output) or ".", exist_ok=True)
    new = output not in STARTED_EVIDENCE
    STARTED_EVIDENCE.add(output)
    with open(output, "w" if new else "a") as f:
        if new:
            f.write(("teach,repeat," if prefix else "") + header[0] + "\n")
        for row in rows:
            f.write(prefix + row + "\n")


CORRIDOR = os.path.join(SHARED, "corridor_conditions")


def flags_tag(flags):
    """Build flags as part of a map folder's name: joined without dashes, a path's slashes as underscores (a
    --camera-mask FILE stays one folder)."""
    return "".join(flags).replace("-", "").replace("/", "_")


def corridor_map(vmap, matcher, tau_flags, work):
    """The map of the corridor's teach run (built once per binary) and its key images' teach frames."""
    map_directory = os.path.join(work, "corridor_%s_%s" % (matcher, flags_tag(tau_flags)))
    built = build(vmap, os.path.join(CORRIDOR, "teach"), matcher, tau_flags, map_directory)
    return map_directory, [k["source_index"] for k in built["key_images"]]


def corridor_right_keys(key_sources, i):
    """The right key images of repeat frame i: those bracketing any teach frame i-2..i+2 (the data set's +-2)."""
    keys = set()
    for j in range(max(0, i - 2), min(110, i + 2) + 1):
        keys |= keys_around(key_sources, j)
    return keys


def corridor(vmap, matcher, tau_flags, localize_flags, stride, work, csv_dir, evidence_dir=None, tally=None,
             label="corridor"):
    repeat = os.path.join(CORRIDOR, "repeat")
    map_directory, key_sources = corridor_map(vmap, matcher, tau_flags, work)
    flags = localize_flags + (["--stride", str(stride)] if stride > 1 else [])
    if csv_dir:
        flags += ["--csv", os.path.join(csv_dir, "%s_%s.csv" % (label.replace(" ", "_"), matcher))]
    doc = localize(vmap, map_directory, repeat, flags, os.path.join(work, "run.json"))
    if evidence_dir:
        dump_evidence(vmap, map_directory, repeat, os.path.join(evidence_dir, "corridor_%s.csv" % matcher))

    tally = tally or Tally()
    tally.add(doc, lambda f: corridor_right_keys(key_sources, f["source_index"]), label)
    return tally, len(key_sources)


# The places set's map and repeat: every third frame, every teach frame kept a key image.
PLACES_BUILD = ["--tau", "1", "--stride", "3"]
PLACES_STRIDE = 3


# The third-rate sets' frame times: the teach run's frames (its rate is not known; any will do, both runs share it).
TEACH_SECONDS_PER_FRAME = 0.1
THIRD_RATE_STRIDE = 3


def linked_folder(folder, frames, seconds_per_frame):
    """A folder of links to `frames` (paths), numbered on from 0, with a timestamps.txt of frames `seconds_per_frame`
    apart: a recording of its own."""
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "timestamps.txt"), "w") as times:
        for number, frame in enumerate(frames):
            name = "%07d.jpg" % number
            link = os.path.join(folder, name)
            if not os.path.exists(link):
                os.symlink(os.path.abspath(frame), link)
            times.write("%s %.6f\n" % (name, number * seconds_per_frame))
    return folder


def timed_repeat(vmap, matcher, map_flags, localize_flags, work, csv_dir, label, repeat_of, seconds_per_frame,
                 with_odometry=False, odometry_scale=1.0):
    """The repeat frames `repeat_of` (run frame -> repeat frame) as a recording of their own, `seconds_per_frame`
    apart, against a map of the timed teach run built with `map_flags`. `with_odometry`: both runs' odometry as the
    frame alignment gives it (a straight line, teach frame i at i x TEACH_METRES_PER_FRAME; repeat frame i where teach
    frame i was), passed to vmap localize (--teach-odometry, --odometry): perfect odometry; the repeat's measuring
    every distance `odometry_scale` times as long (a wheel odometry's scale error)."""
    teach = linked_folder(os.path.join(work, "timed_teach"),
                          [os.path.join(CORRIDOR, "teach", "%07d.jpg" % i) for i in range(111)],
                          TEACH_SECONDS_PER_FRAME)
    repeat = linked_folder(os.path.join(work, label + "_repeat"),
                           [os.path.join(CORRIDOR, "repeat", "%07d.jpg" % i) for i in repeat_of], seconds_per_frame)
    map_directory = os.path.join(work, "timed_corridor_%s_%s" % (matcher, flags_tag(map_flags)))
    key_sources = [k["source_index"] for k in build(vmap, teach, matcher, map_flags, map_directory)["key_images"]]
    flags = list(localize_flags)
    if with_odometry:
        teach_odometry = os.path.join(work, "timed_teach_odometry.csv")
        write_odometry(teach_odometry, [(i * TEACH_SECONDS_PER_FRAME, i * TEACH_METRES_PER_FRAME) for i in range(111)])
        repeat_odometry = os.path.join(work, "%s_odometry_%g.csv" % (label, odometry_scale))
        write_odometry(repeat_odometry, [(f * seconds_per_frame, i * TEACH_METRES_PER_FRAME * odometry_scale)
                                         for f, i in enumerate(repeat_of)])
        flags += ["--teach-odometry", teach_odometry, "--odometry", repeat_odometry]
    if csv_dir:
        flags += ["--csv", os.path.join(csv_dir, "%s_%s.csv" % (label, matcher))]
    doc = localize(vmap, map_directory, repeat, flags, os.path.join(work, "run.json"))
    tally = Tally()
    tally.add(doc, lambda f: corridor_right_keys(key_sources, repeat_of[f["source_index"]]), label,
              lambda f: "run frame %d (repeat %d)" % (f["source_index"], repeat_of[f["source_index"]]))
    return tally


def write_odometry(path, poses):
    """A CSV of timestamp,x,y,yaw as vmap reads it: `poses` (seconds, metres along a straight line)."""
    with open(path, "w") as f:
        f.write("timestamp,x,y,yaw\n")
        for seconds, metres in poses:
            f.write("%.6f,%.6f,0,0\n" % (seconds, metres))


def third_rate(vmap, matcher, map_flags, localize_flags, work, csv_dir, label):
    return timed_repeat(vmap, matcher, map_flags, localize_flags, work, csv_dir, label,
                        list(range(0, 111, THIRD_RATE_STRIDE)), TEACH_SECONDS_PER_FRAME * THIRD_RATE_STRIDE)


# The speed sets' repeat: teach frames passed a frame, in a cycle (1 to 4 times the teach speed, 2.5 on average),
# the camera at the teach run's frame rate.
SPEED_STRIDES = (1, 1, 2, 2, 3, 3, 4, 4, 4, 4, 3, 3, 2, 2, 1, 1)
TEACH_METRES_PER_FRAME = 0.1  # any will do: both runs' odometry share it


def speed_repeat_frames():
    frames, i = [], 0
    while i <= 110:
        frames.append(i)
        i += SPEED_STRIDES[(len(frames) - 1) % len(SPEED_STRIDES)]
    return frames


def speed(vmap, matcher, map_flags, localize_flags, work, csv_dir, label, with_odometry, odometry_scale=1.0):
    return timed_repeat(vmap, matcher, map_flags, localize_flags, work, csv_dir, label, speed_repeat_frames(),
                        TEACH_SECONDS_PER_FRAME, with_odometry, odometry_scale)


# The kidnapped run's stretches of repeat frames, first and last included, in the order the robot saw them.
KIDNAPPED = ((0, 50), (80, 110), (20, 40))


def kidnapped(vmap, matcher, tau_flags, localize_flags, work, csv_dir, tally=None, label="kidnapped"):
    map_directory, key_sources = corridor_map(vmap, matcher, tau_flags, work)
    repeat_of = [i for first, last in KIDNAPPED for i in range(first, last + 1)]  # run frame -> repeat frame
    folder = os.path.join(work, "kidnapped_repeat")
    os.makedirs(folder, exist_ok=True)
    for run_frame, i in enumerate(repeat_of):
        link = os.path.join(folder, "%07d.jpg" % run_frame)
        if not os.path.exists(link):
            os.symlink(os.path.abspath(os.path.join(CORRIDOR, "repeat", "%07d.jpg" % i)), link)
    flags = list(localize_flags)
    if csv_dir:
        flags += ["--csv", os.path.join(csv_dir, "%s_%s.csv" % (label.replace(" ", "_"), matcher))]
    doc = localize(vmap, map_directory, folder, flags, os.path.join(work, "run.json"))
    tally = tally or Tally()
    tally.add(doc, lambda f: corridor_right_keys(key_sources, repeat_of[f["source_index"]]), label,
              lambda f: "run frame %d (repeat %d)" % (f["source_index"], repeat_of[f["source_index"]]))
    return tally


# The started-elsewhere runs: (set, first frame of the run), each started with the bench's --start-key.
ELSEWHERE = (("corridor", 20), ("corridor", 50), ("corridor", 90), ("kidnapped", 51))


def elsewhere(vmap, matcher, tau_flags, localize_flags, work, csv_dir):
    tally = Tally()
    for name, first in ELSEWHERE:
        flags = list(localize_flags) + ["--first", str(first)]
        label = "%s from %d" % (name, first)
        if name == "corridor":
            corridor(vmap, matcher, tau_flags, flags, 1, work, csv_dir, tally=tally, label=label)
        else:
            kidnapped(vmap, matcher, tau_flags, flags, work, csv_dir, tally=tally, label=label)
    return tally


def michigan(vmap, matcher, localize_flags, work, evidence_dir=None, build_flags=(), csv_dir=None):
    images = os.path.join(SHARED, "michigan_seasons", "images")
    sessions = ["%02d" % s for s in range(1, 13)]
    folders = {}
    for s in sessions:
        folder = os.path.join(work, "michigan_session_" + s)
        os.makedirs(folder, exist_ok=True)
        for place in range(1, 6):
            link = os.path.join(folder, "%d.png" % place)
            if not os.path.exists(link):
                os.symlink(os.path.abspath(os.path.join(images, "%s%02d.png" % (s, place))), link)
        folders[s] = folder
    tally = Tally()
    for a in sessions:
        map_directory = os.path.join(work, "michigan_%s_map_%s%s" % (matcher, a, flags_tag(build_flags)))
        build(vmap, folders[a], matcher, ["--tau", "1"] + list(build_flags), map_directory)
        for b in sessions:
            if a == b:
                continue
            flags = list(localize_flags)
            if csv_dir:
                flags += ["--csv", os.path.join(csv_dir, "michigan_%s_%s_to_%s.csv" % (matcher, b, a))]
            doc = localize(vmap, map_directory, folders[b], flags, os.path.join(work, "run.json"))
            tally.add(doc, lambda f: {f["source_index"]}, "%s->%s" % (b, a))
            if evidence_dir:
                dump_evidence(vmap, map_directory, folders[b], os.path.join(evidence_dir, "michigan_%s.csv" % matcher),
                              "%s,%s," % (a, b))
    return tally


def report(tally, name, named_frames):
    """Prints the tally's row and the first `named_frames` frames it names (far, back-jumps; 0: all of them)."""
    print(tally.row(name), flush=True)
    for line in tally.far[:named_frames or None]:
        print("    " + line)


def spread_row(tallies, name):
    """One row over the tallies of several seeds: each column's mean and, in brackets, its min and max."""
    def column(values, percent=False):
        mean = sum(values) / len(values)
        text = "%.1f [%d-%d]" % (mean, min(values), max(values))
        if percent:
            text += " (%.1f %%)" % (100.0 * mean / max(1, tallies[0].frames))
        return text
    fps = [t.frames / t.seconds if t.seconds > 0 else 0.0 for t in tallies]
    return "| %s | %d | %s | %s | %s | %s | %s | %s | %.1f | %s |" % (
        name, tallies[0].frames, column([t.right for t in tallies], True),
        column([t.right_sure for t in tallies], True), column([t.wrong for t in tallies]),
        column([t.confidently_far for t in tallies]), column([t.uncertain for t in tallies]),
        column([t.lost for t in tallies]), sum(fps) / len(fps), column([t.back_jumps for t in tallies]))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--vmap", default="build/vmap", help="comma-separated binaries, compared side by side")
    parser.add_argument("--sets", default="corridor,michigan")
    parser.add_argument("--matchers", default="orb,xfeat")
    parser.add_argument("--tau", help="the corridor map's tau (default: the matcher's)")
    parser.add_argument("--build", default="", help="more flags for vmap build (every map)")
    parser.add_argument("--localize", default="", help="more flags for vmap localize")
    parser.add_argument("--start-key", default="0", help="vmap localize --start-key (none: not passed)")
    parser.add_argument("--repeat-stride", type=int, default=1, help="corridor: every Nth repeat frame (a faster robot)")
    parser.add_argument("--odometry-scale", type=float, default=1.0, help="speed-odometry sets: the repeat's odometry "
                        "measures every distance this many times as long as it is (a wheel odometry's scale error)")
    parser.add_argument("--seeds", help="comma-separated seeds of the verifier (vmap localize --verifier-seed): each "
                        "run once per seed on the same maps, then the mean [min-max] of each column (default: the "
                        "map's seed only, no flag passed)")
    parser.add_argument("--work", help="keep maps here (reused) instead of a temporary folder")
    parser.add_argument("--csv-dir", help="write each run's CSV here (michigan: michigan_MATCHER_REPEAT_to_TEACH.csv per route); with several binaries, "
                        "each binary's in DIR/binaryN (N: its place in --vmap, from 0); with --seeds, each seed's in "
                        "seedS below that")
    parser.add_argument("--evidence-dir", help="write every frame's comparisons with every key image here")
    parser.add_argument("--named-frames", type=int, default=8, help="under each row, name at most this many of its "
                        "frames confidently > 2 places off and back-jumps, the first ones (0: all of them)")
    args = parser.parse_args()
    if args.seeds and args.evidence_dir:
        parser.error("--evidence-dir dumps evidence_dump's comparisons, which take no seed of the localizer's: give it without --seeds")
    if args.start_key != "none":
        args.localize += " --start-key " + args.start_key
    tau_flags = (["--tau", args.tau] if args.tau else []) + args.build.split()
    build_flags = args.build.split()
    print(HEADER)
    sets = args.sets.split(",")
    localize_flags = args.localize.split()
    binaries = args.vmap.split(",")
    seeds = args.seeds.split(",") if args.seeds else [None]
    with tempfile.TemporaryDirectory(prefix="vmap_route_conditions_") as scratch:
        for index, vmap in enumerate(binaries):
            work = os.path.join(args.work or scratch, "binary%d" % index)
            os.makedirs(work, exist_ok=True)
            # Side by side, each binary's CSVs apart: they are compared frame by frame.
            binary_csv_dir = args.csv_dir and (os.path.join(args.csv_dir, "binary%d" % index) if len(binaries) > 1
                                               else args.csv_dir)
            evidence_dir = args.evidence_dir and (os.path.join(args.evidence_dir, "binary%d" % index)
                                                  if len(binaries) > 1 else args.evidence_dir)

            def runs(name, run_set):
                """`run_set(flags, csv_dir)` once per seed (the map's alone: once, without the flag), reported."""
                tallies = []
                for seed in seeds:
                    flags = localize_flags + (["--verifier-seed", seed] if seed is not None else [])
                    csv_dir = binary_csv_dir and (os.path.join(binary_csv_dir, "seed" + seed) if seed is not None
                                                  else binary_csv_dir)
                    if csv_dir:
                        os.makedirs(csv_dir, exist_ok=True)
                    tallies.append(run_set(flags, csv_dir))
                    report(tallies[-1], name + (", seed " + seed if seed is not None else ""), args.named_frames)
                if len(tallies) > 1:
                    print(spread_row(tallies, "%s, seeds %s: mean [min-max]" % (name, ",".join(seeds))), flush=True)

            for matcher in args.matchers.split(","):
                if "corridor" in sets:
                    keys = len(corridor_map(vmap, matcher, tau_flags, work)[1])
                    runs("%s: corridor, %s, %d key images%s" % (
                        vmap, matcher, keys, ", repeat stride %d" % args.repeat_stride if args.repeat_stride > 1
                        else ""), lambda flags, csv_dir: corridor(vmap, matcher, tau_flags, flags, args.repeat_stride,
                                                                  work, csv_dir, evidence_dir)[0])
                if "places" in sets:
                    places_flags = PLACES_BUILD + build_flags
                    keys = len(corridor_map(vmap, matcher, places_flags, work)[1])
                    runs("%s: corridor as places (every third frame, --tau 1), %s, %d key images" % (vmap, matcher, keys),
                         lambda flags, csv_dir: corridor(vmap, matcher, places_flags, flags, PLACES_STRIDE, work, csv_dir,
                                                         label="places")[0])
                if "third-rate" in sets:
                    runs("%s: corridor at a third of the teach run's frame rate, timed, %s" % (vmap, matcher),
                         lambda flags, csv_dir: third_rate(vmap, matcher, tau_flags, flags, work, csv_dir, "third_rate"))
                if "third-rate-places" in sets:
                    runs("%s: corridor at a third of the teach run's frame rate, timed, against places, %s" % (
                        vmap, matcher), lambda flags, csv_dir: third_rate(vmap, matcher, PLACES_BUILD + build_flags,
                                                                          flags, work, csv_dir, "third_rate_places"))
                for odometry in (False, True):
                    for places in (False, True):
                        name = "speed" + ("-odometry" if odometry else "") + ("-places" if places else "")
                        if name in sets:
                            scale = ", the repeat's %g times as long" % args.odometry_scale if (
                                odometry and args.odometry_scale != 1.0) else ""
                            runs("%s: corridor driven at 1-4 times the teach speed, timed%s%s%s, %s" % (
                                vmap, ", with both runs' odometry" if odometry else "", scale,
                                ", against places" if places else "", matcher),
                                lambda flags, csv_dir, places=places, odometry=odometry, name=name: speed(
                                    vmap, matcher, PLACES_BUILD + build_flags if places else tau_flags, flags, work,
                                    csv_dir, name.replace("-", "_"), odometry, args.odometry_scale))
                if "kidnapped" in sets:
                    runs("%s: kidnapped corridor (repeat %s), %s" % (vmap, ", ".join("%d-%d" % s for s in KIDNAPPED),
                                                                    matcher),
                         lambda flags, csv_dir: kidnapped(vmap, matcher, tau_flags, flags, work, csv_dir))
                if "elsewhere" in sets:
                    runs("%s: started elsewhere than --start-key (%s), %s" % (
                        vmap, ", ".join("%s from %d" % e for e in ELSEWHERE), matcher),
                        lambda flags, csv_dir: elsewhere(vmap, matcher, tau_flags, flags, work, csv_dir))
                if "michigan" in sets:
                    runs("%s: michigan 132 routes, %s" % (vmap, matcher),
                         lambda flags, csv_dir: michigan(vmap, matcher, flags, work, evidence_dir, build_flags,
                                                         csv_dir))


if __name__ == "__main__":
    main()
