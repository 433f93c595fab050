#!/usr/bin/env python3
"""Sharded LUT renders (docs/cluster.md): the default LUT set with 1, 2 and 4 shards per sky on
this machine - the overhead of sharding and merging per sky - and a projection to a 16-node farm
from the measured per-shard times. Prints a table; writes only into its work folder.

  bench/cluster_bench.py [--bin build/release/bin] [--pipeline pipeline.yaml] [--work /tmp/cluster_bench]
                         [--skies clear,hazed,...] [--shards 1,2,4] [--nodes 16] [--quality Q] [--size WxH]

The pipeline (default: the repository's pipeline.yaml) is copied with its atmospheres, particle
types and OCIO config into the work folder and generated there; each sky's profiles and Mie tables
are baked by ninja, then each sky's LUT render - the command of its `lut_sky.exr` edge in
build.ninja, unchanged - is timed whole, and as N shards (`--shard k/N`, one after the other, each
with every core) plus `sky-render merge`, whose output is checked to be the whole render's bytes.
--quality / --size replace every sky's (a reduced set, to run in less time).

Overhead per sky = (sum of its shard times + merge) - whole time: for `orders` mostly the
per-atmosphere tables every shard recomputes. Projection: the set's jobs (every sky's N shards,
then its merge) on `--nodes` identical nodes, longest first onto the earliest free node (LPT list
scheduling, R. L. Graham, "Bounds on multiprocessing timing anomalies", SIAM J. Appl. Math. 17(2),
1969), with each job's time as measured here, the merge after its sky's last shard.
"""
import argparse
import filecmp
import os
import re
import shlex
import shutil
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))


def run(args, cwd):
    r = subprocess.run(args, cwd=cwd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("failed: %s\n%s%s" % (" ".join(args), r.stdout, r.stderr))
    return r.stdout


def timed(args, cwd):
    t0 = time.perf_counter()
    run(args, cwd)
    return time.perf_counter() - t0


def render_command(out, sky):
    """The LUT render command of `sky` as build.ninja has it, split, without its depfile."""
    line = run(["ninja", "-C", out, "-t", "commands", "%s/lut_sky.exr" % sky], ROOT).strip().split("\n")[-1]
    args = shlex.split(line)
    i = args.index("--depfile")
    del args[i:i + 2]
    return args


def with_output(args, output):
    args = list(args)
    args[args.index("-o") + 1] = output
    return args


def project(jobs, nodes):
    """Makespan (s) of (sky, kind, seconds) jobs on `nodes` nodes: every sky's shards, longest
    first, each on the node that frees first; a sky's merge starts after its last shard."""
    free = [0.0] * nodes
    done = {}
    for sky, kind, t in sorted((j for j in jobs if j[1] == "shard"), key=lambda j: -j[2]):
        n = min(range(nodes), key=lambda i: free[i])
        free[n] += t
        done[sky] = max(done.get(sky, 0.0), free[n])
    end = 0.0
    for sky, kind, t in sorted((j for j in jobs if j[1] == "merge"), key=lambda j: done[j[0]]):
        n = min(range(nodes), key=lambda i: free[i])
        free[n] = max(free[n], done[sky]) + t
        end = max(end, free[n])
    return max(end, max(free))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "release", "bin"))
    ap.add_argument("--pipeline", default=os.path.join(ROOT, "pipeline.yaml"))
    ap.add_argument("--work", default="/tmp/cluster_bench")
    ap.add_argument("--skies", default="")
    ap.add_argument("--shards", default="1,2,4")
    ap.add_argument("--nodes", type=int, default=16)
    ap.add_argument("--quality", default="")
    ap.add_argument("--size", default="")
    a = ap.parse_args()
    shutil.rmtree(a.work, ignore_errors=True)
    os.makedirs(a.work)
    for d in ("atmospheres", "particles", "ocio", "clouds"):
        shutil.copytree(os.path.join(os.path.dirname(os.path.abspath(a.pipeline)), d), os.path.join(a.work, d))
    text = open(a.pipeline).read()
    text = re.sub(r"^outputs:.*$", "outputs: outputs", text, flags=re.M)
    # The luts section (up to the next top-level key) is the only one --quality / --size change.
    start = text.index("\nluts:") + 1
    end = start + re.search(r"\n\S", text[start:]).start() + 1
    luts = text[start:end]
    if a.quality:
        luts = re.sub(r"(\{atmosphere: *\w+, *size: *\w+)(, *quality: *\w+)?", r"\1, quality: %s" % a.quality, luts)
    if a.size:
        luts = re.sub(r"(\{atmosphere: *\w+, *size: *)\w+", r"\g<1>%s" % a.size, luts)
    text = text[:start] + luts + text[end:]
    with open(os.path.join(a.work, "pipeline.yaml"), "w") as f:
        f.write(text)
    run([os.path.join(a.bin, "skybake"), "generate", "pipeline.yaml"], a.work)
    out = os.path.join(a.work, "outputs")
    skies = re.findall(r"\{atmosphere: *(\w+), *size", luts)
    if a.skies:
        skies = [s for s in skies if s in a.skies.split(",")]
    counts = [int(n) for n in a.shards.split(",")]
    # The renders' inputs (profiles, Mie tables), not timed.
    inputs = run(["ninja", "-C", out, "-t", "inputs"] + ["%s/lut_sky.exr" % s for s in skies], ROOT).split()
    run(["ninja", "-C", out] + [i for i in inputs if i.endswith(".exr")], ROOT)
    os.makedirs(os.path.join(out, "bench"), exist_ok=True)

    print("sharded LUT renders, %d skies (%s), %d cores, shard counts %s" % (len(skies), ", ".join(skies), os.cpu_count(),
                                                                          a.shards))
    print("%-10s %6s %10s %12s %10s %10s %10s" % ("sky", "shards", "whole_s", "shards_s", "merge_s", "overhead_s", "overhead"))
    jobs = {n: [] for n in counts}
    for sky in skies:
        cmd = render_command(out, sky)
        whole_file = "bench/%s_whole.exr" % sky
        whole = timed(with_output(cmd, whole_file), out)
        for n in counts:
            if n == 1:
                jobs[n].append((sky, "shard", whole))
                print("%-10s %6d %10.2f %12s %10s %10s %10s" % (sky, 1, whole, "-", "-", "-", "-"))
                continue
            files, times = [], []
            for k in range(n):
                files.append("bench/%s_%d-of-%d.exr" % (sky, k, n))
                times.append(timed(with_output(cmd, files[-1]) + ["--shard", "%d/%d" % (k, n)], out))
            merged = "bench/%s_merged_%d.exr" % (sky, n)
            merge = timed([cmd[0], "--quiet", "merge", "-o", merged] + files, out)
            if not filecmp.cmp(os.path.join(out, merged), os.path.join(out, whole_file), shallow=False):
                sys.exit("%s: the merge of %d shards is not the whole render's bytes" % (sky, n))
            for t in times:
                jobs[n].append((sky, "shard", t))
            jobs[n].append((sky, "merge", merge))
            over = sum(times) + merge - whole
            print("%-10s %6d %10.2f %12s %10.2f %10.2f %9.0f%%" % (
                sky, n, whole, "/".join("%.2f" % t for t in times), merge, over, 100.0 * over / whole))
    print()
    print("projection to %d nodes (each job as timed here on one %d-core node, LPT list scheduling):" % (a.nodes, os.cpu_count()))
    print("%6s %8s %14s %12s" % ("shards", "jobs", "makespan_s", "vs 1 node"))
    serial = sum(t for _, _, t in jobs[counts[0]])
    for n in counts:
        span = project(jobs[n], a.nodes)
        print("%6d %8d %14.2f %11.1fx" % (n, len(jobs[n]), span, serial / span))


if __name__ == "__main__":
    main()
