#!/usr/bin/python3
"""CLI `vmap sweep --thresholds 0.1:0.9:0.1` against one `vmap build` (default tau), interleaved, child processes.
usage: sweep_vs_build.py VMAP REPEAT SEQUENCE...   (run from the repository root)"""
import os, statistics, subprocess, sys, tempfile, time

def run(cmd):
    t = time.perf_counter()
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, st, ru = os.wait4(p.pid, 0)
    w = time.perf_counter() - t
    if os.waitstatus_to_exitcode(st):
        sys.exit("failed: %s\n%s" % (" ".join(cmd), p.stderr.read().decode()))
    return w, ru.ru_utime + ru.ru_stime

vmap, repeat, seqs = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
print("| sequence | build wall / CPU s | sweep wall / CPU s | sweep / build (wall) | sweep / build (CPU) | per-repeat wall ratios |")
print("|---|---|---|---|---|---|")
with tempfile.TemporaryDirectory(prefix="i12_svb_") as tmp:
    for s in seqs:
        b, w = [], []
        for r in range(repeat):
            b.append(run([vmap, "build", s, "-q", "-o", os.path.join(tmp, "b%d" % r)]))
            w.append(run([vmap, "sweep", s, "-q", "--thresholds", "0.1:0.9:0.1", "-o", os.path.join(tmp, "s%d" % r)]))
        rw = [y[0] / x[0] for x, y in zip(b, w)]
        rc = [y[1] / x[1] for x, y in zip(b, w)]
        med = lambda v, i: statistics.median(x[i] for x in v)
        print("| %s | %.2f / %.2f | %.2f / %.2f | **%.2fx** | %.2fx | %s |" % (
            os.path.relpath(s, "../shared/data"), med(b, 0), med(b, 1), med(w, 0), med(w, 1),
            statistics.median(rw), statistics.median(rc), " ".join("%.2f" % x for x in rw)), flush=True)
