#!/usr/bin/python3
"""The evidence of one comparison, fitted: how much likelier a comparison's outcome is at a right key image than at
a wrong one (localization/route_evidence.cc, docs/localize.md "The belief over the route").

Input: the CSVs of bench/route_conditions.py --evidence-dir (every frame against every key image of its map, from
build/bench/evidence_dump): corridor_MATCHER.csv (frame i of the repeat is right at the key images around teach
frames i-2..i+2) and michigan_MATCHER.csv (frame i right at key image i). The corridor's maps need their key images'
source indices: --corridor-map-MATCHER MAP_DIR (as route_conditions.py --work left them).

Fits, by logistic regression (Newton's method), the log odds of "right" on a matched comparison's significance
s = clamp(-log10 NFA, lo, hi) and its share of the key image's link (verified / link_verified, at most 1), and
the log odds of an unmatched one; subtracting the log prior odds gives log likelihood ratios. Prints them, per set and
pooled, and the false acceptance rate (wrong among those accepted) of the localizer's acceptance rule and of the
fitted ratio above 0.

With --rank, also the ranking's evidence (EvidenceModel::rank_alone and the model of a comparison given its rank;
docs/localize.md, "The ranking is evidence"), on the corridor and on michigan's 5-place routes; --rank-by standout
buckets the key images by how far their votes stand out of the frame's instead of by rank.

usage: bench/evidence_fit.py DIR [--corridor-map-orb MAP] [--corridor-map-xfeat MAP] [--lo -5] [--hi 12] [--rank]
                             [--rank-by rank|standout]"""
import argparse, csv, json, math, os, sys

import numpy as np


def keys_around(key_sources, source):
    before = max((k for k, s in enumerate(key_sources) if s <= source), default=None, key=lambda k: key_sources[k])
    after = min((k for k, s in enumerate(key_sources) if s >= source), default=None, key=lambda k: key_sources[k])
    return {k for k in (before, after) if k is not None}


def load(path, right_of):
    rows = []
    with open(path) as f:
        for r in csv.DictReader(f):
            rows.append((int(r["matched"]), int(r["accepted"]), float(r["log10_nfa"]), int(r["verified"]),
                         int(r["link_verified"]), 1 if right_of(r) else 0))
    return rows


def features(rows, lo, hi):
    x, y, unmatched = [], [], []
    for matched, accepted, nfa, verified, link, right in rows:
        if not matched:
            unmatched.append(right)
            continue
        s = min(max(-nfa, lo), hi)
        share = min(1.0, verified / link) if link > 0 else 0.0
        x.append([1.0, s, share])
        y.append(right)
    return np.array(x), np.array(y, dtype=float), unmatched


def logistic(x, y, iterations=50, ridge=1e-3):
    w = np.zeros(x.shape[1])
    for _ in range(iterations):
        p = 1.0 / (1.0 + np.exp(-x @ w))
        g = x.T @ (y - p) - ridge * w
        h = (x * (p * (1 - p))[:, None]).T @ x + ridge * np.eye(len(w))
        step = np.linalg.solve(h, g)
        w += step
        if np.abs(step).max() < 1e-9:
            break
    return w


def report(name, rows, lo, hi):
    x, y, unmatched = features(rows, lo, hi)
    right = sum(r[5] for r in rows)
    wrong = len(rows) - right
    prior = math.log(right / wrong)
    w = logistic(x, y) if len(y) and 0 < y.sum() < len(y) else np.zeros(3)
    u_right = sum(unmatched)
    u_wrong = len(unmatched) - u_right
    unmatched_llr = math.log((u_right + 0.5) / (u_wrong + 0.5)) - prior
    accepted = [r for r in rows if r[1]]
    false_accepted = sum(1 for r in accepted if not r[5])
    llr = x @ w - prior if len(y) else np.array([])
    positive = llr > 0
    print("%s: %d comparisons (%d right), matched %d; llr = %.3f + %.3f s + %.3f share (matched), %.3f unmatched" % (
        name, len(rows), right, len(y), w[0] - prior, w[1], w[2], unmatched_llr))
    print("    accepted by the localizer's rule: %d, of them wrong %d (%.1f %%); right ones accepted: %.1f %%" % (
        len(accepted), false_accepted, 100.0 * false_accepted / max(1, len(accepted)),
        100.0 * sum(1 for r in accepted if r[5]) / max(1, right)))
    if len(y):
        print("    fitted llr > 0: %d, of them wrong %d (%.1f %%); right ones with llr > 0: %.1f %%" % (
            positive.sum(), int((positive & (y == 0)).sum()), 100.0 * (positive & (y == 0)).sum() / max(1, positive.sum()),
            100.0 * (positive & (y == 1)).sum() / max(1, right)))
    return w, prior


RANK_BUCKETS = ((0, 0), (1, 2), (3, 4), (5, 9), (10, 1 << 30))  # localization/route_evidence.cc, RankBucket
# By how far a key image's votes stand out of the frame's: (votes - median) / sqrt(median), the median's counting noise
# (binary descriptors; measured, not weighed: docs/measurements/localization-conditions.md, "ORB's ranking by how its
# votes stand out"); a frame whose median is 0 is left out (its ranking would weigh nothing).
STANDOUT_EDGES = (0.5, 1.5, 2.5, 3.5)


def rank_bucket(rank):
    return next(b for b, (lo, hi) in enumerate(RANK_BUCKETS) if lo <= rank <= hi)


def standout_bucket(standout):
    return sum(1 for edge in STANDOUT_EDGES if standout >= edge)


def frame_medians(path):
    """The median ranking score of each frame of the dump (its rows grouped by everything but the key's columns)."""
    scores = {}
    with open(path) as f:
        for r in csv.DictReader(f):
            scores.setdefault(frame_of(r), []).append(float(r["rank_score"]))
    return {frame: float(np.median(s)) for frame, s in scores.items()}


def frame_of(r):
    return (r.get("teach"), r.get("repeat"), r["frame"])


def report_rank(name, path, right_of, lo, hi, by_standout=False):
    """The ranking as evidence (EvidenceModel::rank_alone, rank_given): the log ratio of each rank bucket alone, and a
    matched comparison's model given its rank (bucket indicators beside s and the share; the last bucket the base).
    by_standout: the buckets by how far the key image's votes stand out of the frame's (STANDOUT_EDGES), the last the
    highest; the base then is the first (the lowest)."""
    buckets = len(STANDOUT_EDGES) + 1 if by_standout else len(RANK_BUCKETS)
    base = 0 if by_standout else buckets - 1
    medians = frame_medians(path) if by_standout else {}
    alone_right, alone_wrong = [0] * buckets, [0] * buckets
    x, y = [], []
    with open(path) as f:
        for r in csv.DictReader(f):
            right = 1 if right_of(r) else 0
            if by_standout:
                median = medians[frame_of(r)]
                if median <= 0:
                    continue
                bucket = standout_bucket((float(r["rank_score"]) - median) / math.sqrt(median))
            else:
                bucket = rank_bucket(int(r["rank"]))
            (alone_right if right else alone_wrong)[bucket] += 1
            if int(r["matched"]):
                s = min(max(-float(r["log10_nfa"]), lo), hi)
                link = int(r["link_verified"])
                share = min(1.0, int(r["verified"]) / link) if link > 0 else 0.0
                x.append([1.0, s, share] + [1.0 if bucket == b else 0.0 for b in range(buckets) if b != base])
                y.append(right)
    right, wrong = sum(alone_right), sum(alone_wrong)
    prior = math.log(right / wrong)
    alone = [math.log(((alone_right[b] + 0.5) / right) / ((alone_wrong[b] + 0.5) / wrong)) for b in range(buckets)]
    w = logistic(np.array(x), np.array(y, dtype=float))
    given = list(w[3:])
    given.insert(base, 0.0)
    if by_standout:
        names = ["<%.1f" % STANDOUT_EDGES[0]] + ["%.1f-%.1f" % e for e in zip(STANDOUT_EDGES, STANDOUT_EDGES[1:])]
        names.append(">=%.1f" % STANDOUT_EDGES[-1])
        label = "(votes - median) / sqrt(median)"
    else:
        names = ["%d-%d" % b if b[1] < 1 << 20 else "%d+" % b[0] for b in RANK_BUCKETS]
        label = "ranks"
    print("%s, the ranking: rank_alone (%s %s) = %s  [right %s, wrong %s]" % (
        name, label, ", ".join(names), ", ".join("%.2f" % a for a in alone), alone_right, alone_wrong))
    print("    given the rank: llr = %.3f + %.3f s + %.3f share + rank_given (%s)" % (
        w[0] - prior, w[1], w[2], ", ".join("%.2f" % c for c in given)))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("directory")
    parser.add_argument("--corridor-map-orb")
    parser.add_argument("--corridor-map-xfeat")
    parser.add_argument("--lo", type=float, default=-5.0)
    parser.add_argument("--hi", type=float, default=12.0)
    parser.add_argument("--rank", action="store_true",
                        help="also the ranking's evidence (the dump's `rank` column)")
    parser.add_argument("--rank-by", choices=("rank", "standout"), default="rank",
                        help="the ranking's buckets: by rank (float descriptors) or by how far the votes stand out of "
                             "the frame's, (votes - median) / sqrt(median) (binary descriptors)")
    args = parser.parse_args()
    pooled = []
    for matcher in ("orb", "xfeat"):
        path = os.path.join(args.directory, "corridor_%s.csv" % matcher)
        map_directory = getattr(args, "corridor_map_" + matcher)
        if os.path.exists(path) and map_directory:
            with open(os.path.join(map_directory, "map.json")) as f:
                key_sources = [k["source_index"] for k in json.load(f)["key_images"]]

            def right(r, key_sources=key_sources):
                i = int(r["source_index"])
                keys = set()
                for j in range(max(0, i - 2), min(110, i + 2) + 1):
                    keys |= keys_around(key_sources, j)
                return int(r["key"]) in keys

            rows = load(path, right)
            report("corridor %s" % matcher, rows, args.lo, args.hi)
            if args.rank:
                report_rank("corridor %s" % matcher, path, right, args.lo, args.hi, args.rank_by == "standout")
            pooled += rows
        path = os.path.join(args.directory, "michigan_%s.csv" % matcher)
        if os.path.exists(path):
            rows = load(path, lambda r: int(r["key"]) == int(r["source_index"]))
            report("michigan %s" % matcher, rows, args.lo, args.hi)
            if args.rank:  # 5-place routes: ranks 0-4 only, the buckets past them are empty
                report_rank("michigan %s" % matcher, path, lambda r: int(r["key"]) == int(r["source_index"]), args.lo,
                            args.hi, args.rank_by == "standout")
            pooled += rows
    if pooled:
        report("pooled", pooled, args.lo, args.hi)


if __name__ == "__main__":
    main()
