#!/usr/bin/env python3
"""`orders` against the path tracer on a peer's atmosphere at explicit geometries
(docs/peers.md, "Agreement with our path tracer"): `sky-render points --method orders` and
`--method path` on the same geometry CSV (sun zenith 0-94 deg; view zenith 0, 60, 85 deg; the
sun's azimuth and the opposite one), then per row the relative difference of the luminance and
of the radiance at each output wavelength, with the path tracer's standard error. Prints a
table; writes only into its work folder.

  bench/peers_orders_vs_path.py [--bin build/release/bin] [--atmosphere atmospheres/peers/bruneton2017.yaml]
                                [--wavelengths 360:830:10] [--wavelengths-out 440,550,680]
                                [--quality medium] [--target-error 0.01] [--max-paths 400000]
                                [--threads 0] [--work /tmp/peers_orders_vs_path]
"""
import argparse
import csv
import os
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
SUN_ZENITHS = (0, 30, 60, 80, 90, 94)
VIEWS = ((0, 0), (60, 0), (60, 180), (85, 0), (85, 90), (85, 180))


def read_rows(path):
    with open(path) as f:
        lines = f.read().splitlines()
    source = lines[0]
    return source, list(csv.DictReader(l for l in lines if not l.startswith("#")))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "release", "bin"))
    ap.add_argument("--atmosphere", default=os.path.join(ROOT, "atmospheres", "peers", "bruneton2017.yaml"))
    ap.add_argument("--wavelengths", default="360:830:10")
    ap.add_argument("--wavelengths-out", default="440,550,680")
    ap.add_argument("--quality", default="medium")
    ap.add_argument("--target-error", default="0.01")
    ap.add_argument("--max-paths", default="400000")
    ap.add_argument("--threads", default="0")
    ap.add_argument("--work", default="/tmp/peers_orders_vs_path")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    geom = os.path.join(a.work, "geometry.csv")
    with open(geom, "w") as f:
        f.write("# source: bench/peers_orders_vs_path.py (sun zenith 0-94 deg x six views)\n")
        f.write("sun_zenith_deg,view_zenith_deg,relative_azimuth_deg\n")
        for sza in SUN_ZENITHS:
            for vz, az in VIEWS:
                f.write("%g,%g,%g\n" % (sza, vz, az))
    out = {}
    for method in ("orders", "path"):
        dst = os.path.join(a.work, method + ".csv")
        cmd = [os.path.join(a.bin, "sky-render"), "--quiet", "--threads", a.threads, "points", a.atmosphere,
               "--method", method, "--wavelengths", a.wavelengths, "--wavelengths-out", a.wavelengths_out,
               "--geometry", geom, "-o", dst]
        cmd += ["--quality", a.quality] if method == "orders" else ["--target-error", a.target_error,
                                                                     "--max-paths", a.max_paths]
        t0 = time.time()
        subprocess.run(cmd, check=True)
        out[method] = read_rows(dst)
        print("%s: %.1f s  (%s)" % (method, time.time() - t0, out[method][0][:160]))
    wls = a.wavelengths_out.split(",")
    print("\n| sun zenith | view zenith | azimuth | Y path cd/m^2 | Y orders/path - 1 | path s.e. | " +
          " | ".join("%s nm" % w for w in wls) + " |")
    print("|---|---|---|---|---|---|" + "---|" * len(wls))
    worst = {}
    for o, p in zip(out["orders"][1], out["path"][1]):
        y, yp, se = float(o["Y_cd_m2"]), float(p["Y_cd_m2"]), float(p["Y_stderr_cd_m2"])
        cells = []
        for w in wls:
            lo, lp = float(o["radiance_%snm_W_m2_sr_nm" % w]), float(p["radiance_%snm_W_m2_sr_nm" % w])
            sp = float(p["stderr_%snm_W_m2_sr_nm" % w])
            cells.append("%+.2f %% (±%.2f)" % (100 * (lo / lp - 1), 100 * sp / lp) if lp > 0 else "-")
        rel = y / yp - 1 if yp > 0 else float("nan")
        sza = float(p["sun_zenith_deg"])
        band = "day (sza <= 80)" if sza <= 80 else "horizon and twilight (sza 90-94)"
        worst[band] = max(worst.get(band, 0.0), abs(rel))
        print("| %s | %s | %s | %.4g | %+.2f %% | %.2f %% | %s |" % (p["sun_zenith_deg"], p["view_zenith_deg"],
              p["relative_azimuth_deg"], yp, 100 * rel, 100 * se / yp if yp > 0 else 0, " | ".join(cells)))
    for band, v in worst.items():
        print("largest |Y orders/path - 1|, %s: %.2f %%" % (band, 100 * v))
    return 0


if __name__ == "__main__":
    sys.exit(main())
