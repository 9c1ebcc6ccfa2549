#!/usr/bin/env python3
"""How the translation-known thresholds (map.json options.link_analysis.translation: max_sigma_deg,
min_parallax_px and min_rival_cost_gap) would split the links of evaluated maps. Per set of thresholds and map:
the links flagged,
the unflagged ones more than 90 deg off, and the unflagged ones usable and strictly right (translation judged
whatever the parallax), as `vmap eval` judged them. The flag does not change the pose, so one build serves
every threshold. Reads MAP/map.json and MAP/eval.json (`vmap eval MAP`); docs/link-poses.md.

  /usr/bin/python3 bench/translation_threshold.py NAME=MAP_DIR ... [--sigmas 2,3,5,180] [--parallaxes 0,3,5,10]
      [--rival-gaps 0,8]

The rival gap (links[].translation_rival_cost_gap, null when no rival) depends on rival_angle_deg, which is
fixed when the map is built (--rival-translation-angle).
"""
import argparse
import itertools
import json
import os


def links(directory):
    with open(os.path.join(directory, "map.json")) as f:
        map_links = json.load(f)["links"]
    with open(os.path.join(directory, "eval.json")) as f:
        evaluated = json.load(f)["links"]
    rows = []
    for link, e in zip(map_links, evaluated):
        sigma = link.get("translation_sigma_deg")
        error = e["translation_error_deg"]
        gap = link.get("translation_rival_cost_gap")
        rows.append({"sigma": 180.0 if sigma is None else sigma, "gap": float("inf") if gap is None else gap, "parallax": link.get("parallax_px") or 0.0,
                     "error": 180.0 if error is None else error, "usable": e["usable"],
                     "strict": e.get("strict_usable", False), "pose": link.get("pose") is not None})
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("maps", nargs="+", help="NAME=MAP_DIR (a map evaluated by `vmap eval`)")
    parser.add_argument("--sigmas", default="2,3,5,180", help="max_sigma_deg values (180: no limit)")
    parser.add_argument("--parallaxes", default="0,3,5,10", help="min_parallax_px values")
    parser.add_argument("--rival-gaps", default="0,8", help="min_rival_cost_gap values (0: no rival test)")
    args = parser.parse_args()
    maps = [(item.split("=", 1)[0], links(item.split("=", 1)[1])) for item in args.maps]
    print("| max sigma | min parallax | min rival gap | " +
          " | ".join(f"{name}: flagged, unflagged >90° off, unflagged usable, unflagged strictly right"
                     for name, _ in maps) + " |")
    print("|---:|---:|---:|" + "---|" * len(maps))
    values = lambda text: [float(v) for v in text.split(",")]
    for max_sigma, min_parallax, min_gap in itertools.product(values(args.sigmas), values(args.parallaxes),
                                                              values(args.rival_gaps)):
        cells = []
        for _, rows in maps:
            known = [r for r in rows if r["pose"] and r["sigma"] <= max_sigma and r["parallax"] >= min_parallax
                     and r["gap"] >= min_gap]
            reversed_ = sum(r["error"] > 90 for r in known)
            usable = sum(r["usable"] for r in known)
            strict = sum(r["strict"] for r in known)
            cells.append(f"{len(rows) - len(known)}, {reversed_}, {usable}/{len(known)}, {strict}/{len(known)}")
        sigma = "∞" if max_sigma >= 180 else f"{max_sigma:g}°"
        print(f"| {sigma} | {min_parallax:g} px | {min_gap:g} | " + " | ".join(cells) + " |")

if __name__ == "__main__":
    main()
