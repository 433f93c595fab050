#!/usr/bin/env python3
"""Pipeline overhead benchmark: prints the time of a no-op `ninja` on the default
pipeline and the time to regenerate build.ninja.

  bench/pipeline_bench.py [--bin build/release/bin] [--repeat 20]

Runs on the repo's own pipeline.yaml and outputs/ (bakes first if needed: `skybake bake`).
Regeneration is measured two ways: `skybake generate` alone, and `touch pipeline.yaml && ninja`
(ninja's regen edge + restat, nothing downstream re-runs).
"""
import argparse
import os
import statistics
import subprocess
import sys
import time

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))


def timed(cmd, **kw):
    t = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, **kw)
    return time.perf_counter() - t


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "release", "bin"))
    ap.add_argument("--repeat", type=int, default=20)
    a = ap.parse_args()
    skybake = os.path.join(a.bin, "skybake")
    out = os.path.join(ROOT, "outputs")
    print("pipeline_bench: baking once (may take a while on a fresh tree) ...", file=sys.stderr)
    subprocess.run([skybake, "bake", "pipeline.yaml"], cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
    noop = [timed(["ninja", "-C", out]) for _ in range(a.repeat)]
    gen = [timed([skybake, "generate", "--quiet", "pipeline.yaml"], cwd=ROOT) for _ in range(a.repeat)]
    regen = []
    for _ in range(a.repeat):
        os.utime(os.path.join(ROOT, "pipeline.yaml"))
        regen.append(timed(["ninja", "-C", out]))
    with open(os.path.join(out, "build.ninja")) as f:
        edges = sum(1 for line in f if line.startswith("build ") and ": phony" not in line)
    print("build.ninja edges (non-phony): %d" % edges)
    print("no-op ninja:                 median %.1f ms  (min %.1f, max %.1f, n=%d)" %
          (1e3 * statistics.median(noop), 1e3 * min(noop), 1e3 * max(noop), len(noop)))
    print("skybake generate:            median %.1f ms  (min %.1f, max %.1f)" %
          (1e3 * statistics.median(gen), 1e3 * min(gen), 1e3 * max(gen)))
    print("touch pipeline.yaml + ninja: median %.1f ms  (min %.1f, max %.1f)" %
          (1e3 * statistics.median(regen), 1e3 * min(regen), 1e3 * max(regen)))


if __name__ == "__main__":
    main()
