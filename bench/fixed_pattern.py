#!/usr/bin/python3
"""The camera's own pattern among the verified matches: how many of a pair's F-verified matches do not move, and how
many lie outside the lens's image circle (a fisheye's dark rim and its ring), where the scene cannot be
(docs/measurements/localization-conditions.md, "The lens rim's matches and the key images that verify everywhere").

corridor_conditions: repeat frame i (every --step-th) against teach frame i (the same place) and against teach frame
i + --far-offset, wrapped (another place of the corridor). At another place a match that does not move (both points
within --still-px of each other) is not the scene's: the two images see different things at that pixel; what the
lens or the robot shows in every image matches itself. Per set of pairs: the mean verified matches, those that do not
move, those that do not move or lie outside the circle (--circle CX,CY,R in pixels; none: not asked), the rest; and
at how many of the frames the same place verifies more than the other place, by all verified matches and by the rest
alone.

Each pair is `vmap match --matcher M --json` (cached in --work: a second run reads them back).

With --learn, also the pattern as the teach run alone shows it (what a map could learn without a user's mask): teach
frame i (every 6th) against teach frames i + 20 and i + 45, other places; every tentative match that does not move
marks its 8 x 8 px cell in the first image; the cells marked by at least 2, 3 and 5 such matches are the learnt
pattern. Printed: how many of those matches lie outside the circle (with --circle), and per threshold the cells, those
whose centre lies inside the circle, and the share of the repeat-against-teach pairs' verified matches with a point in
a learnt cell.

With --evidence CSV --map MAP/map.json (every repeat frame against every key image of the corridor's map:
build/bench/evidence_dump, or bench/route_conditions.py --evidence-dir), also the key images that verify everywhere:
per key image, the median verified matches and log10 NFA of its comparisons with frames of other places (more than two
key images from every right one; a frame is right at the key images bracketing teach frames i-2..i+2), and how well
the log10 NFA tells right from other places (the area under the ROC curve) raw and less its key image's median there.
The medians come from the repeat run itself, so the second area is what knowing each key image's chance at best adds.

usage: bench/fixed_pattern.py --vmap build/vmap [--matcher xfeat] [--circle 74.5,60,64] [--step 2] [--far-offset 40]
                              [--still-px 1.6] [--work DIR] [--learn] [--evidence CSV --map MAP/map.json]
(from the repository root; ../shared must be there)"""
import argparse, csv, json, math, os, statistics, subprocess, sys, tempfile

CORRIDOR = "../shared/data/corridor_conditions"
FRAMES = 111
CELL = 8  # px: the learnt pattern's cells
CELLS = (160 // CELL) * (120 // CELL)  # of corridor_conditions' 160 x 120 frames


def matches(vmap, matcher, teach, other, work, run="repeat", verified=True):
    """The matches of teach frame `teach` (image0) with frame `other` of `run` (image1), F-verified ones or all the
    tentative ones: (x0, y0, x1, y1)."""
    output = os.path.join(work, "%s_t%d_%s%d.json" % (matcher, teach, run[0], other))
    if not os.path.exists(output):
        image0 = os.path.join(CORRIDOR, "teach", "%07d.jpg" % teach)
        image1 = os.path.join(CORRIDOR, run, "%07d.jpg" % other)
        done = subprocess.run([vmap, "match", "--matcher", matcher, image0, image1, "--json", output],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if done.returncode != 0:
            sys.exit("failed: vmap match teach %d %s %d\n%s" % (teach, run, other, done.stdout))
    with open(output) as f:
        pair = json.load(f)
    return [(m["x0"], m["y0"], m["x1"], m["y1"]) for m in pair["matches"] if m["inlier"] or not verified]


def cell(x, y):
    return int(x) // CELL, int(y) // CELL


def learn_pattern(args, circle, work, pairs_by_set):
    """The cells the teach run's still matches between other places mark, and what they would take of `pairs_by_set`
    (set name -> list of verified match lists)."""
    hits, still, outside = {}, 0, 0
    for teach in range(0, FRAMES, 6):
        for later in (teach + 20, teach + 45):
            if later >= FRAMES:
                continue
            for x0, y0, x1, y1 in matches(args.vmap, args.matcher, teach, later, work, run="teach", verified=False):
                if math.hypot(x1 - x0, y1 - y0) >= args.still_px:
                    continue
                still += 1
                outside += circle is not None and math.hypot(x0 - circle[0], y0 - circle[1]) > circle[2]
                hits[cell(x0, y0)] = hits.get(cell(x0, y0), 0) + 1
    print("\nthe teach run's still tentative matches between other places: %d%s" % (
        still, ", %d outside the circle" % outside if circle else ""))
    print("\n| cells marked by at least | cells (of %d) | centre inside the circle | verified matches in them: %s |"
          % (CELLS, " | ".join(pairs_by_set)))
    print("|---|---|---|" + "---|" * len(pairs_by_set))
    for least in (2, 3, 5):
        learnt = {c for c, n in hits.items() if n >= least}
        inside = sum(math.hypot((cx + 0.5) * CELL - circle[0], (cy + 0.5) * CELL - circle[1]) < circle[2]
                     for cx, cy in learnt) if circle else "-"
        shares = []
        for pairs in pairs_by_set.values():
            total = sum(len(p) for p in pairs) or 1
            taken = sum(cell(x0, y0) in learnt or cell(x1, y1) in learnt for p in pairs for x0, y0, x1, y1 in p)
            shares.append("%.0f %%" % (100.0 * taken / total))
        print("| %d | %d | %s | %s |" % (least, len(learnt), inside, " | ".join(shares)))


def tally(matches, still_px, circle):
    """(verified, still, still or outside the circle)."""
    still = outside = 0
    for x0, y0, x1, y1 in matches:
        moves = math.hypot(x1 - x0, y1 - y0) >= still_px
        out = circle is not None and max(math.hypot(x0 - circle[0], y0 - circle[1]),
                                         math.hypot(x1 - circle[0], y1 - circle[1])) > circle[2]
        still += not moves
        outside += (not moves) or out
    return len(matches), still, outside


def right_keys(sources, repeat):
    """The key images bracketing teach frames repeat-2..repeat+2 (corridor_conditions' ground truth)."""
    right = set()
    for teach in range(max(0, repeat - 2), min(FRAMES - 1, repeat + 2) + 1):
        before = [k for k, s in enumerate(sources) if s <= teach]
        after = [k for k, s in enumerate(sources) if s >= teach]
        if before: right.add(max(before, key=lambda k: sources[k]))
        if after: right.add(min(after, key=lambda k: sources[k]))
    return right


def area_under_curve(right, other):
    """The chance that a right comparison scores lower (a lower log10 NFA: likelier) than one at another place."""
    wins = sum((r < o) + 0.5 * (r == o) for r in right for o in other)
    return wins / (len(right) * len(other))


def key_images_that_verify_everywhere(evidence_path, map_path):
    with open(map_path) as f:
        sources = [k["source_index"] for k in json.load(f)["key_images"]]
    with open(evidence_path) as f:
        rows = [r for r in csv.DictReader(f) if r["frame"].isdigit()]
    elsewhere = {k: [] for k in range(len(sources))}  # (verified, log10 NFA) with frames of other places
    pairs = []  # (right, key image, log10 NFA)
    for r in rows:
        key, right = int(r["key"]), right_keys(sources, int(r["source_index"]))
        nfa = min(float(r["log10_nfa"]), 5.0) if r["matched"] == "1" else 5.0  # unmatched: beyond any chance
        if key in right:
            pairs.append((True, key, nfa))
        elif min(abs(key - k) for k in right) > 2:
            pairs.append((False, key, nfa))
            elsewhere[key].append((int(r["verified"]), nfa))
    print("\n| key image | teach frame | with other places: median verified | median log10 NFA |")
    print("|---|---|---|---|")
    median_nfa = {}
    for k, s in enumerate(sources):
        median_nfa[k] = statistics.median(n for _, n in elsewhere[k])
        print("| %d | %d | %.1f | %.1f |" % (k, s, statistics.median(v for v, _ in elsewhere[k]), median_nfa[k]))
    scores = (("log10 NFA", lambda k, n: n),
              ("log10 NFA less its key image's median", lambda k, n: n - median_nfa[k]))
    for name, score in scores:
        right = [score(k, n) for is_right, k, n in pairs if is_right]
        other = [score(k, n) for is_right, k, n in pairs if not is_right]
        print("area under the ROC curve, right against other places, by %s: %.3f (%d right, %d other)" % (
            name, area_under_curve(right, other), len(right), len(other)))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--vmap", default="build/vmap")
    parser.add_argument("--matcher", default="xfeat")
    parser.add_argument("--circle", help="the lens's image circle CX,CY,R (px); matches beyond it are the rim's")
    parser.add_argument("--step", type=int, default=2)
    parser.add_argument("--far-offset", type=int, default=40)
    parser.add_argument("--still-px", type=float, default=1.6)
    parser.add_argument("--work", help="where the pairs' JSON files are kept (default: a temporary folder)")
    parser.add_argument("--learn", action="store_true", help="also the pattern the teach run alone shows")
    parser.add_argument("--evidence", help="evidence_dump's CSV of the corridor's repeat run against its map")
    parser.add_argument("--map", help="that map's map.json")
    args = parser.parse_args()
    if bool(args.evidence) != bool(args.map):
        parser.error("--evidence and --map go together")
    circle = [float(v) for v in args.circle.split(",")] if args.circle else None
    work = args.work or tempfile.mkdtemp(prefix="fixed_pattern_")
    os.makedirs(work, exist_ok=True)
    pairs = {"same place": [], "another place": []}
    for repeat in range(0, FRAMES, args.step):
        pairs["same place"].append(matches(args.vmap, args.matcher, repeat, repeat, work))
        other = (repeat + args.far_offset) % FRAMES
        pairs["another place"].append(matches(args.vmap, args.matcher, other, repeat, work))
    sets = {name: [tally(p, args.still_px, circle) for p in found] for name, found in pairs.items()}
    print("| pairs | n | verified (mean) | not moving | not moving or outside the circle | the rest |")
    print("|---|---|---|---|---|---|")
    for name, rows in sets.items():
        n = len(rows)
        total = sum(r[0] for r in rows) or 1
        still, outside = sum(r[1] for r in rows), sum(r[2] for r in rows)
        print("| %s | %d | %.1f | %.1f (%.0f %%) | %s | %.1f |" % (
            name, n, total / n, still / n, 100.0 * still / total,
            "%.1f (%.0f %%)" % (outside / n, 100.0 * outside / total) if circle else "-",
            (total - (outside if circle else still)) / n))
    same, other = sets["same place"], sets["another place"]
    by_all = sum(s[0] > o[0] for s, o in zip(same, other))
    rest = (lambda r: r[0] - r[2]) if circle else (lambda r: r[0] - r[1])
    by_rest = sum(rest(s) > rest(o) for s, o in zip(same, other))
    print("\nthe same place verifies more than the other: %d of %d frames by all verified matches, %d by the rest" % (
        by_all, len(same), by_rest))
    if args.learn:
        learn_pattern(args, circle, work, pairs)
    if args.evidence:
        key_images_that_verify_everywhere(args.evidence, args.map)


if __name__ == "__main__":
    main()
