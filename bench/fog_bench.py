#!/usr/bin/env python3
"""fog-fit figures (docs/fog.md): render and fit times, the model's error near the camera and at
the horizon per basis sky, per-channel vs shared (luminance) fits, path vs elevation angle, the
cut altitude, and the LUT sizes. Prints tables; writes nothing outside its work folder.

  bench/fog_bench.py [--bin build/fog/bin] [--mie-dir outputs/mie] [--skies clear,hazed]
                     [--renders outputs] [--cuts-km 1,2,3.5] [--work /tmp/fog_bench]

1. Per basis sky (--skies): the pipeline's fog render (outputs/<sky>/fog.exr, from `scripts/bake`
   or `skybake bake`; rendered here with the pipeline's settings if absent, and timed) and
   `fog-fit fit` on it (timed); from its report: the fitted (a, p) and the error of the fit (exact
   LUT x depth function) and of the evaluator (packed LUTs) over all samples, near the camera
   (depth <= 1 km), at the horizon (elevation <= 1 deg) and at infinite depth (the LUT alone).
2. The same render fitted with --channels luminance (one a, p for R, G, B) and with --angle
   elevation (the talk's theta): RMS near the camera and at the horizon.
3. The cut: for each of --cut-skies, depth tables only (a 2x2 LUT) at each --cuts-km, fit error.
4. Bytes of every texture of the first sky.
"""
import argparse
import json
import os
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))

# The pipeline's fog settings (pipeline.yaml `fog:`); the depth tables as there.
TABLES = ["--sun-zenith-deg", "30,60,80,88,92,96", "--elevations", "9", "--azimuths-deg", "0,30,90,150,180",
          "--depths", "16", "--quality", "low", "--spectral-stride", "4"]


def run(args):
    t0 = time.monotonic()
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("failed: %s\n%s" % (" ".join(args), r.stderr))
    return time.monotonic() - t0


def fit(bin_dir, render, out_dir, sky, *extra):
    os.makedirs(out_dir, exist_ok=True)
    out = os.path.join(out_dir, "fog_%s.json" % sky)
    seconds = run([os.path.join(bin_dir, "fog-fit"), "--quiet", "fit", render, "--name", sky, "-o", out] + list(extra))
    with open(os.path.join(out_dir, "fog_%s_report.json" % sky)) as f:
        return seconds, json.load(f)


def pct(x):
    return "%5.1f" % (100 * x)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "fog", "bin"))
    ap.add_argument("--mie-dir", default=os.path.join(ROOT, "outputs", "mie"))
    ap.add_argument("--renders", default=os.path.join(ROOT, "outputs"))
    ap.add_argument("--skies", default="clear,hazed")
    ap.add_argument("--cuts-km", default="0.25,0.5,1,2,3.5")
    ap.add_argument("--cut-skies", default="clear,hazed,cloudy2")
    ap.add_argument("--work", default="/tmp/fog_bench")
    a = ap.parse_args()
    skies = a.skies.split(",")
    os.makedirs(a.work, exist_ok=True)

    print("1. Per basis sky: pipeline settings (orders low, spectral stride 4, cut 1 km, 32x32x64 fog LUT, 64x64 attenuation,"
          " depth tables 6 suns x 9 elevations x 5 azimuths x 16 depths)")
    print("   error = |Y_model / Y_ref - 1| (luminance), RMS / max in %; near = depth <= 1 km; horizon = elevation <= 1 deg")
    print("%-8s %7s %6s  %-22s %-22s | %-12s %-12s %-12s %-12s %-10s" % (
        "sky", "render", "fit", "a (R,G,B)", "p (R,G,B)", "fit all", "fit near", "fit horizon", "eval near", "eval x=1"))
    reports = {}
    for sky in skies:
        render = os.path.join(a.renders, sky, "fog.exr")
        render_s = float("nan")
        if not os.path.isfile(render):
            render = os.path.join(a.work, sky + "_fog.exr")
            render_s = run([os.path.join(a.bin, "sky-render"), "--quiet", "fog", os.path.join(ROOT, "atmospheres", sky + ".yaml"),
                            "--mie-dir", a.mie_dir, "--cut-altitude-km", "1", "-o", render] + TABLES)
        seconds, rep = fit(a.bin, render, os.path.join(a.work, "rgb_path"), sky)
        reports[sky] = (render, rep)
        e = rep["errors"]["fog"]
        fa = ",".join("%.3g" % c["a"] for c in rep["fit"]["fog"])
        fp = ",".join("%.3g" % c["p"] for c in rep["fit"]["fog"])
        print("%-8s %6.1fs %5.2fs  %-22s %-22s | %s/%s %s/%s %s/%s %s/%s %s/%s" % (
            sky, render_s, seconds, fa, fp,
            pct(e["fit"]["all"]["rms"]), pct(e["fit"]["all"]["max"]),
            pct(e["fit"]["near_camera"]["rms"]), pct(e["fit"]["near_camera"]["max"]),
            pct(e["fit"]["horizon"]["rms"]), pct(e["fit"]["horizon"]["max"]),
            pct(e["evaluator"]["near_camera"]["rms"]), pct(e["evaluator"]["near_camera"]["max"]),
            pct(e["evaluator"]["infinite_depth"]["rms"]), pct(e["evaluator"]["infinite_depth"]["max"])))
        s = rep["errors"]["shadowed"]["fit"]
        print("%-8s %s shadowed fog fit: all %s/%s near %s/%s horizon %s/%s; attenuation max |dT| R %.4f G %.4f B %.4f" % (
            "", " " * 14, pct(s["all"]["rms"]), pct(s["all"]["max"]), pct(s["near_camera"]["rms"]), pct(s["near_camera"]["max"]),
            pct(s["horizon"]["rms"]), pct(s["horizon"]["max"]), rep["attenuation"]["max_abs"]["R"],
            rep["attenuation"]["max_abs"]["G"], rep["attenuation"]["max_abs"]["B"]))
    print("   render: wall time of sky-render fog (nan: taken from --renders); fit: wall time of fog-fit fit")

    print("\n2. Variants of the fit on the same renders (fit error RMS %, near camera / horizon / all)")
    print("%-8s %-22s %-22s %-22s" % ("sky", "rgb, path (default)", "luminance, path", "rgb, elevation (talk)"))
    for sky in skies:
        render, rep = reports[sky]
        cols = []
        for variant, extra in (("rgb_path", None), ("lum_path", ["--channels", "luminance"]),
                               ("rgb_elev", ["--angle", "elevation"])):
            r = rep if extra is None else fit(a.bin, render, os.path.join(a.work, variant), sky, *extra)[1]
            f = r["errors"]["fog"]["fit"]
            cols.append("%s / %s / %s" % (pct(f["near_camera"]["rms"]), pct(f["horizon"]["rms"]), pct(f["all"]["rms"])))
        print("%-8s %-22s %-22s %-22s" % (sky, cols[0], cols[1], cols[2]))

    print("\n3. The cut (depth tables only, 2x2 LUT): fit error RMS % near camera / horizon / all, render time")
    for sky in a.cut_skies.split(","):
        for cut in a.cuts_km.split(","):
            render = os.path.join(a.work, "%s_cut%s.exr" % (sky, cut))
            seconds = run([os.path.join(a.bin, "sky-render"), "--quiet", "fog", os.path.join(ROOT, "atmospheres", sky + ".yaml"),
                           "--mie-dir", a.mie_dir, "--cut-altitude-km", cut, "--lut-size", "2x2",
                           "--time-mapping", "gt7:2+2", "-o", render] + TABLES)
            f = fit(a.bin, render, os.path.join(a.work, "cut" + cut), sky)[1]["errors"]["fog"]["fit"]
            print("  %-8s cut %4s km: %s / %s / %s   (%.1f s)" % (sky, cut, pct(f["near_camera"]["rms"]), pct(f["horizon"]["rms"]),
                                                                pct(f["all"]["rms"]), seconds))
    sky = skies[0]

    print("\n4. Bytes (%s)" % sky)
    d = os.path.join(a.work, "rgb_path")
    for name in sorted(os.listdir(d)):
        if name.startswith("fog_%s" % sky):
            print("  %-32s %9d" % (name, os.path.getsize(os.path.join(d, name))))


if __name__ == "__main__":
    main()
