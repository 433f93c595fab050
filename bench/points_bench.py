#!/usr/bin/env python3
"""Cost of sky-render points per geometry (docs/sky-render.md, "Points"): for each method and
quality, the wall time of one row (loading the scene, building the method - for orders its
tables, once per observer altitude - and one point) and the cost of each further point, from a
run of N rows at one altitude: per point = (t_N - t_1) / (N - 1). Prints a table; writes only
into its work folder.

  bench/points_bench.py [--bin build/release/bin] [--atmosphere A.yaml --mie-dir DIR]
                        [--methods orders:low,orders:medium] [--rows 2000] [--threads 1]
                        [--wavelengths 360:830:5] [--work /tmp/points_bench]

Without --atmosphere the clear sky without its aerosol layer (atmospheres/clear.yaml less
`aerosols`, so no Mie table is needed) is used. The N geometries are random (fixed seed): sun
zenith 0-96 deg, view zenith 0-180 deg, azimuth 0-180 deg.
"""
import argparse
import os
import random
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))


def rayleigh_atmosphere(work):
    with open(os.path.join(ROOT, "atmospheres", "clear.yaml")) as f:
        text = f.read()
    text = text[:text.index("aerosols:")] + text[text.index("ground:"):]
    text = text.replace("file: data/", "file: %s/" % os.path.join(ROOT, "atmospheres", "data"))
    p = os.path.join(work, "rayleigh.yaml")
    with open(p, "w") as f:
        f.write(text)
    return p


def geometry(work, n):
    rng = random.Random(1)
    p = os.path.join(work, "g%d.csv" % n)
    with open(p, "w") as f:
        f.write("# source: bench/points_bench.py, random geometries (seed 1)\n")
        f.write("sun_zenith_deg,view_zenith_deg,relative_azimuth_deg\n")
        for _ in range(n):
            f.write("%.4f,%.4f,%.4f\n" % (rng.uniform(0, 96), rng.uniform(0, 180), rng.uniform(0, 180)))
    return p


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "release", "bin"))
    ap.add_argument("--atmosphere")
    ap.add_argument("--mie-dir")
    ap.add_argument("--methods", default="orders:low,orders:medium")
    ap.add_argument("--rows", type=int, default=2000)
    ap.add_argument("--threads", default="1")
    ap.add_argument("--wavelengths", default="360:830:5")
    ap.add_argument("--work", default="/tmp/points_bench")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    atm = os.path.abspath(a.atmosphere) if a.atmosphere else rayleigh_atmosphere(a.work)
    one, many = geometry(a.work, 1), geometry(a.work, a.rows)
    print("sky-render points, %s, %s nm, %s thread(s), %d rows" % (os.path.basename(atm), a.wavelengths, a.threads, a.rows))
    print("%-10s %-8s %16s %16s %14s" % ("method", "quality", "1 row: wall_s", "%d rows: wall_s" % a.rows, "per point_ms"))
    for mq in a.methods.split(","):
        method, quality = mq.split(":")
        walls = []
        for g in (one, many):
            args = [os.path.join(os.path.abspath(a.bin), "sky-render"), "points", atm, "--geometry", g, "--method", method,
                    "--quality", quality, "--wavelengths", a.wavelengths, "--wavelengths-out", "440,550,680",
                    "--threads", a.threads, "--quiet", "-o", os.path.join(a.work, "out.csv")]
            if a.mie_dir:
                args += ["--mie-dir", os.path.abspath(a.mie_dir)]
            t0 = time.perf_counter()
            r = subprocess.run(args, capture_output=True, text=True)
            walls.append(time.perf_counter() - t0)
            if r.returncode != 0:
                sys.exit("failed: %s\n%s" % (" ".join(args), r.stderr))
        print("%-10s %-8s %16.2f %16.2f %14.3f" % (method, quality, walls[0], walls[1],
                                                  1e3 * (walls[1] - walls[0]) / (a.rows - 1)))


if __name__ == "__main__":
    main()
