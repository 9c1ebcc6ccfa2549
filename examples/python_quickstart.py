#!/usr/bin/python3
"""vmap from Python in a few lines: build a map, look at it, match a pair, follow the map frame by frame.

Run from the repository root after building (docs/python.md):
    PYTHONPATH=build/python /usr/bin/python3 examples/python_quickstart.py ../shared/data/lab_floor/lab_floor.mp4
"""
import sys
import tempfile

import vmap

video = sys.argv[1] if len(sys.argv) > 1 else "../shared/data/lab_floor/lab_floor.mp4"
with tempfile.TemporaryDirectory() as tmp:
    # `vmap build VIDEO -o MAP --last 149 --stride 2 --tau 0.5`, as a call returning the map.
    m = vmap.build_map(video, f"{tmp}/map", last=149, stride=2, tau=0.5)
    print(m, "links:", len(m.links))
    for link in m.links[:3]:
        print(link, "F[0] =", link.F[0], "t =", link.t)

    # One pair through ORB and MAGSAC, as `vmap match` (numpy images: grey or BGR).
    a, b = m.key_images[0], m.key_images[1]
    result = vmap.match(a.image, b.image, matcher="orb")
    print(f"match: {result.num_verified} of {result.num_tentative} verified, S = {result.similarity:.3f}")

    # The robot's loop: one frame at a time (here the map's own key images stand in for camera frames). Options are
    # keywords named as their fields (or as the CLI's flags): here 3 ranked key images verified when relocalizing.
    localizer = vmap.Localizer(m, relocalization_candidates=3)
    for key in m.key_images[:5]:
        r = localizer.localize(key.image, timestamp=key.timestamp)
        print(f"frame {key.frame_index}: {r.status} at key {r.key} -> {r.next_key}, heading {r.heading_px} px")
