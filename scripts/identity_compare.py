#!/usr/bin/env python3
"""Compares two scripts/identity_run.sh outputs: maps (map.json without seconds, keys/, correspondences.bin), sweep, CSVs,
the localization run's JSON, eval.json, the reports, `vmap info` and every command's --help."""
import csv, filecmp, json, os, re, sys

a, b = sys.argv[1], sys.argv[2]
ok = True

# Timings, and sweep.json's pairs_matched: pairs compared ahead by the workers and not needed count too, a
# number that depends on the threads' timing (main's binary gave 2199 and 2204 in two runs).
TIMING = {"seconds", "pairs_matched", "key_image_seconds", "frames_per_second", "max_localize_seconds",
          "mean_extract_seconds", "mean_localize_seconds"}

def strip(x):
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items() if k not in TIMING}
    if isinstance(x, list):
        return [strip(v) for v in x]
    return x

def report(name, same):
    global ok
    ok &= same
    print(f"{'identical' if same else 'DIFFERENT'}  {name}")

def same_bytes(p, q):
    return filecmp.cmp(p, q, shallow=False)

for m in ["lab_floor", "rccar_room", "kitti07"]:
    pa, pb = os.path.join(a, m), os.path.join(b, m)
    ja, jb = (strip(json.load(open(os.path.join(p, "map.json")))) for p in (pa, pb))
    report(f"{m}/map.json (seconds removed)", ja == jb)
    ta, tb = (re.sub(r'"seconds": *[0-9.e+-]+', '"seconds": 0', open(os.path.join(p, "map.json")).read())
              for p in (pa, pb))
    report(f"{m}/map.json as text, byte for byte (seconds' values removed)", ta == tb)
    keys_a, keys_b = sorted(os.listdir(os.path.join(pa, "keys"))), sorted(os.listdir(os.path.join(pb, "keys")))
    report(f"{m}/keys/ ({len(keys_a)} files)", keys_a == keys_b and all(
        same_bytes(os.path.join(pa, "keys", k), os.path.join(pb, "keys", k)) for k in keys_a))
    report(f"{m}/correspondences.bin", same_bytes(os.path.join(pa, "correspondences.bin"),
                                                   os.path.join(pb, "correspondences.bin")))
    cache_a, cache_b = os.path.join(pa, "localization_cache.bin"), os.path.join(pb, "localization_cache.bin")
    if os.path.exists(cache_a) or os.path.exists(cache_b):
        # 16 bytes of magic, then an 8-byte hash of map.json (whose "seconds" is a timing), then the payload.
        ca, cb = open(cache_a, "rb").read(), open(cache_b, "rb").read()
        report(f"{m}/localization_cache.bin after its map.json hash ({len(ca) - 24} bytes)",
               len(ca) == len(cb) and ca[:16] == cb[:16] and ca[24:] == cb[24:])
report("sweep/sweep.csv", same_bytes(os.path.join(a, "sweep/sweep.csv"), os.path.join(b, "sweep/sweep.csv")))
md_a, md_b = (open(os.path.join(p, "sweep/sweep.md")).read().split("\n") for p in (a, b))
report("sweep/sweep.md after its title line (which gives the run's seconds)", md_a[1:] == md_b[1:])
report("sweep/sweep.json (seconds, pairs_matched removed)",
       strip(json.load(open(os.path.join(a, "sweep/sweep.json")))) ==
       strip(json.load(open(os.path.join(b, "sweep/sweep.json")))))
report("sweep/sweep.json: options, as text",
       json.dumps(json.load(open(os.path.join(a, "sweep/sweep.json")))["options"]) ==
       json.dumps(json.load(open(os.path.join(b, "sweep/sweep.json")))["options"]))
for f in ["localize_desk.csv", "localize_self.csv"]:
    def rows(p):
        r = list(csv.reader(open(p)))
        drop = r[0].index("seconds")
        return [row[:drop] + row[drop + 1:] for row in r]
    ra, rb = rows(os.path.join(a, f)), rows(os.path.join(b, f))
    report(f"{f} ({len(ra) - 1} frames, column 'seconds' removed)", ra == rb)
def text(root, name):
    # The run's own folder is named in some outputs (the map's path); it differs by construction.
    return open(os.path.join(root, name)).read().replace(os.path.abspath(root), "OUT")

def exists_in_both(name):
    return os.path.exists(os.path.join(a, name)) and os.path.exists(os.path.join(b, name))

if exists_in_both("localize_desk.json"):
    la, lb = (json.loads(text(p, "localize_desk.json")) for p in (a, b))
    report("localize_desk.json: options, as text", json.dumps(la["options"]) == json.dumps(lb["options"]))
    report("localize_desk.json (timings removed)", strip(la) == strip(lb))
for f in ["eval_kitti07.json", "kitti07/eval.json"]:
    if exists_in_both(f):
        report(f"{f}, byte for byte (its folder's path named alike)", text(a, f) == text(b, f))

def html(root, name):
    # Durations ("16.5 s", "1 min 3 s") and the run's speeds are timings.
    page = re.sub(r'[0-9.]+</div>\s*<div class="label">frames/s', "T", text(root, name))  # a card's speed
    return re.sub(r"[0-9.]+ (s|min|ms|frames/s|fps)\b", "T", page)
for f in ["rccar_room/report.html", "localize_report/report.html"]:
    if exists_in_both(f):
        report(f"{f} (durations removed)", html(a, f) == html(b, f))
if exists_in_both("info_rccar_room.txt"):
    ia, ib = ([l for l in open(os.path.join(p, "info_rccar_room.txt")) if not l.startswith("time ")] for p in (a, b))
    report("info_rccar_room.txt (its time line removed)", ia == ib)
if exists_in_both("help"):
    for f in sorted(os.listdir(os.path.join(a, "help"))):
        ha, hb = (re.sub(r"Usage: \S+", "Usage: vmap", open(os.path.join(p, "help", f)).read()) for p in (a, b))
        if ha == hb:
            report(f"help/{f}", True)
        else:
            # The same lines, only in another order, is reported apart (the flags of a nested struct come together).
            same_lines = sorted(ha.split("\n")) == sorted(hb.split("\n"))
            print(f"{'reordered' if same_lines else 'DIFFERENT'}  help/{f}" +
                  (" (the same lines in another order)" if same_lines else ""))
            ok_lines = same_lines
            globals()["ok"] &= ok_lines
print("ALL IDENTICAL" if ok else "DIFFERENCES FOUND")
sys.exit(0 if ok else 1)
