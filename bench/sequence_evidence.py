#!/usr/bin/python3
"""Sequence evidence (SeqSLAM's point), measured against chance: does "the same key images winning, in route order,
over N consecutive frames" tell a right place from a wrong one where each frame alone cannot? (docs/measurements/
localization-conditions.md, "Sequence evidence across seasons".)

Input: every frame of a run against every key image of its map (build/bench/evidence_dump MAP QUERY, or
bench/route_conditions.py --evidence-dir), the map's map.json (its key images' teach frames: frame i of the repeat run
is right at the key images bracketing teach frames i-2..i+2, corridor_conditions' ground truth) and optionally the
run's `vmap localize --csv` (its uncertain frames).

Each frame's verified matches over the key images are made z-scores (SeqSLAM's contrast normalization). A window of
N frames ending at frame i scores the best straight line through (frame, key image) at 0 to 1 key images a frame: the
mean z along it; its key image at frame i is the window's place. Chance: the same score over N frames drawn at random
from the run (--chance samples, seed 1), so no line through them is a place; the threshold at a false acceptance rate
is that distribution's quantile. Printed per N: windows accepted at 5 %, 1 % and 0.25 %, right and wrong among them.

usage: bench/sequence_evidence.py EVIDENCE.csv MAP/map.json [--csv RUN.csv] [--windows 3,5,8] [--chance 2000]"""
import argparse, csv, json, random, statistics


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("evidence")
    parser.add_argument("map_json")
    parser.add_argument("--csv", help="the run's vmap localize CSV: also report its uncertain frames' windows")
    parser.add_argument("--windows", default="3,5,8")
    parser.add_argument("--chance", type=int, default=2000)
    args = parser.parse_args()
    sources = [k["source_index"] for k in json.load(open(args.map_json))["key_images"]]
    keys = len(sources)
    rows = [r for r in csv.DictReader(open(args.evidence)) if r["frame"].isdigit()]
    frames = max(int(r["frame"]) for r in rows) + 1
    verified = [[0.0] * keys for _ in range(frames)]
    for r in rows:
        verified[int(r["frame"])][int(r["key"])] = float(r["verified"])

    def zscores(values):
        mean, deviation = statistics.mean(values), statistics.pstdev(values) or 1.0
        return [(x - mean) / deviation for x in values]

    z = [zscores(v) for v in verified]

    def around(source):
        before = max((k for k in range(keys) if sources[k] <= source), default=None, key=lambda k: sources[k])
        after = min((k for k in range(keys) if sources[k] >= source), default=None, key=lambda k: sources[k])
        return {k for k in (before, after) if k is not None}

    def right(i):
        out = set()
        for j in range(max(0, i - 2), min(frames - 1, i + 2) + 1):
            out |= around(j)
        return out

    speeds = [s / 10 for s in range(11)]

    def best_line(window):
        best = (float("-inf"), None)
        for speed in speeds:
            for end in range(keys):
                total = 0.0
                for j, f in enumerate(window):
                    k = round(end - speed * (len(window) - 1 - j))
                    if k < 0:
                        total = float("-inf")
                        break
                    total += z[f][k]
                if total > best[0]:
                    best = (total, end)
        return best[0] / len(window), best[1]

    status = {}
    if args.csv:
        status = {int(r["source_index"]): r["status"] for r in csv.DictReader(open(args.csv))}
    alone = sum(max(range(keys), key=lambda k: verified[f][k]) in right(f) for f in range(frames))
    print("%d frames, %d key images; the key image of most verified matches is right for %d frames" %
          (frames, keys, alone))
    for n in map(int, args.windows.split(",")):
        windows = []
        for end in range(n - 1, frames):
            score, key = best_line(list(range(end - n + 1, end + 1)))
            windows.append((score, key in right(end), end))
        rng = random.Random(1)
        chance = sorted(best_line(rng.sample(range(frames), n))[0] for _ in range(args.chance))
        for rate in (0.05, 0.01, 0.0025):
            threshold = chance[min(len(chance) - 1, int((1 - rate) * len(chance)))]
            accepted = [w for w in windows if w[0] > threshold]
            line = "N %d, false acceptance %.2f %% against chance (mean z > %.2f): %d of %d windows accepted, %d right, %d wrong" % (
                n, 100 * rate, threshold, len(accepted), len(windows), sum(w[1] for w in accepted),
                sum(not w[1] for w in accepted))
            if status:
                uncertain = [w for w in accepted if status.get(w[2]) == "uncertain"]
                line += "; of the run's uncertain frames %d accepted (%d right, %d wrong)" % (
                    len(uncertain), sum(w[1] for w in uncertain), sum(not w[1] for w in uncertain))
            print(line, flush=True)


if __name__ == "__main__":
    main()
