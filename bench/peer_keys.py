#!/usr/bin/python3
"""m and Q of the paper-style peer, vmap build --exhaustive (also with --min-key-displacement 0) and vmap build.
usage: peer_keys.py VMAP SEQUENCE...  (run from the repository root)"""
import json, os, subprocess, sys, tempfile
vmap, seqs = sys.argv[1], sys.argv[2:]
print("| sequence | peer m, Q | --exhaustive m, Q (same keys as peer) | --exhaustive --min-key-displacement 0 m, Q (same keys) | default m, Q (same keys; key images in one and not the other) |")
print("|---|---|---|---|---|")
with tempfile.TemporaryDirectory(prefix="i12_pk_") as tmp:
    for s in seqs:
        pj = os.path.join(tmp, "peer.json")
        subprocess.run(["/usr/bin/python3", "bench/paper_style_peer.py", s, "--json", pj], check=True, capture_output=True)
        p = json.load(open(pj))
        cells = ["%d, %.4f" % (len(p["key_frames"]), p["quality"])]
        for name, extra in (("ex", ["--exhaustive"]), ("ex0", ["--exhaustive", "--min-key-displacement", "0"]), ("d", [])):
            d = os.path.join(tmp, name)
            subprocess.run([vmap, "build", s, "-q", "-o", d] + extra, check=True)
            m = json.load(open(os.path.join(d, "map.json")))
            k = [x["frame_index"] for x in m["key_images"]]
            same = "yes" if k == p["key_frames"] else "no"
            extra_txt = same if name != "d" else "%s; %d" % (same, len(set(k) ^ set(p["key_frames"])))
            cells.append("%d, %.4f (%s)" % (len(k), m["quality"], extra_txt))
        print("| %s | %s |" % (os.path.relpath(s, "../shared/data"), " | ".join(cells)), flush=True)
