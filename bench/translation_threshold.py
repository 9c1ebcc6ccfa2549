#!/usr/bin/env python3
"""How the translation-known threshold (link_analysis.translation.max_sigma_deg) splits the links of evaluated
maps: per threshold and map, the links it flags, the unflagged ones more than 90 deg off, and the shares of
unflagged links that are usable / strictly right (translation judged whatever the parallax) and of flagged
links that were wrong. Reads eval.json files written by `vmap eval` (docs/link-poses.md).

  bench/translation_threshold.py NAME=MAP/eval.json ... [--thresholds 1,2,3,5,8,10,15,20,30]
"""
import argparse
import json


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("evals", nargs="+", help="NAME=path/to/eval.json")
    parser.add_argument("--thresholds", default="1,2,3,4,5,6,8,10,15,20,30")
    parser.add_argument("--max-translation-error", type=float, default=20.0)
    parser.add_argument("--max-rotation-error", type=float, default=5.0)
    args = parser.parse_args()
    thresholds = [float(t) for t in args.thresholds.split(",")]
    maps = []
    for item in args.evals:
        name, path = item.split("=", 1)
        links = [l for l in json.load(open(path))["links"] if l["has_ground_truth"]]
        maps.append((name, links))
    print("| max sigma (deg) | map | links | flagged | flagged wrong | unflagged >90 deg off | unflagged usable | "
          "unflagged strictly right |")
    print("|---:|---|---:|---:|---:|---:|---:|---:|")
    for threshold in thresholds:
        for name, links in maps:
            def known(l):
                sigma = l.get("translation_sigma_deg")
                return l["pose_source"] == "stored" and sigma is not None and sigma <= threshold
            def strict(l):
                r, t = l["rotation_error_deg"], l["translation_error_deg"]
                return r is not None and t is not None and r < args.max_rotation_error and t < args.max_translation_error
            unflagged = [l for l in links if known(l)]
            flagged = [l for l in links if not known(l)]
            reversed_ = sum(1 for l in unflagged if (l["translation_error_deg"] or 0) > 90)
            usable = sum(1 for l in unflagged if l["usable"])
            right = sum(1 for l in unflagged if strict(l))
            wrong = sum(1 for l in flagged if not strict(l))
            pct = lambda a, b: f"{a}/{b} ({100.0 * a / b:.0f}%)" if b else "-"
            print(f"| {threshold:g} | {name} | {len(links)} | {len(flagged)} | {pct(wrong, len(flagged))} | {reversed_} | "
                  f"{pct(usable, len(unflagged))} | {pct(right, len(unflagged))} |")


if __name__ == "__main__":
    main()
