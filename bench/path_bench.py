#!/usr/bin/env python3
"""Speed of the reference path tracer (sky-render render --method path; docs/sky-render.md):
wall time, paths per second and the thread scaling of one pipeline-style reference render.
Prints a table; writes only into its work folder.

  bench/path_bench.py [--bin build/release/bin] [--outputs outputs] [--skies clear,hazed]
                      [--size 128x32] [--sun-zenith-deg 30] [--target-error 0.01]
                      [--threads 1,2] [--work /tmp/path_bench]

The defaults are the path tracer's reference benchmark: one 32x128 sky slice (128x32 equirectangular texels, one
sun angle) at 1 % standard error of Y per texel, clear and hazed, 1 and 2 threads (about 10 CPU
minutes per sky and thread count on the development machine; use --size 32x8 for a quick look).

Needs a baked outputs/ (profiles and Mie tables, from `scripts/bake`). The path count comes from
sky-render's last progress line ("N sun angles, P paths"); the outputs at the thread counts are
compared byte for byte (the random streams are per texel, so they must be equal).
"""
import argparse
import os
import re
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "release", "bin"))
    ap.add_argument("--outputs", default=os.path.join(ROOT, "outputs"))
    ap.add_argument("--skies", default="clear,hazed")
    ap.add_argument("--size", default="128x32")
    ap.add_argument("--sun-zenith-deg", default="30")
    ap.add_argument("--target-error", default="0.01")
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--wavelengths", default="360:830:5")
    ap.add_argument("--work", default="/tmp/path_bench")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    out = os.path.abspath(a.outputs)
    threads = [int(t) for t in a.threads.split(",")]
    print("sky-render render --method path, %s equirectangular, sun zenith %s deg, target %s, %s nm"
          % (a.size, a.sun_zenith_deg, a.target_error, a.wavelengths))
    print("%-7s %7s %9s %12s %13s %s" % ("sky", "threads", "wall_s", "paths", "paths/s", ""))
    for sky in a.skies.split(","):
        walls, blobs = {}, []
        for t in threads:
            dst = os.path.join(a.work, "%s_t%d.exr" % (sky, t))
            args = [os.path.join(os.path.abspath(a.bin), "sky-render"), "render", "--method", "path",
                    "--profiles", "%s/profiles.exr" % sky, "--mie-dir", "mie", "--wavelengths", a.wavelengths,
                    "--mapping", "equirectangular", "--size", a.size, "--sun-zenith-deg", a.sun_zenith_deg,
                    "--target-error", a.target_error, "--threads", str(t), "-o", dst,
                    "%s/components/render.yaml" % sky]
            t0 = time.perf_counter()
            r = subprocess.run(args, cwd=out, capture_output=True, text=True)
            wall = time.perf_counter() - t0
            if r.returncode != 0:
                sys.exit("failed: %s\n%s" % (" ".join(args), r.stderr))
            m = re.findall(r"(\d+) paths", r.stderr)
            paths = int(m[-1]) if m else 0
            walls[t] = wall
            blobs.append(open(dst, "rb").read())
            print("%-7s %7d %9.1f %12d %13.0f" % (sky, t, wall, paths, paths / wall if wall > 0 else 0))
        if 1 in walls and 2 in walls:
            print("%-7s scaling 1 -> 2 threads: %.2fx; %s" % (sky, walls[1] / walls[2],
                  "same bytes" if len(set(blobs)) == 1 else "BYTES DIFFER"))


if __name__ == "__main__":
    main()
