#!/usr/bin/env python3
"""fog-fit figures (docs/fog.md): render and fit times, the model's error near the camera and at
the horizon per basis sky, where a and p live (per slice and elevation, per slice, global), per-
channel vs shared (luminance) fits, path vs elevation angle, cross-validation of the parameter
interpolation, the texel grid, the cut altitude, and the LUT sizes. Prints tables; writes nothing
outside its work folder.

  bench/fog_bench.py [--bin build/fog/bin] [--mie-dir outputs/mie] [--skies clear,hazed]
                     [--renders outputs] [--cuts-km 1,2,3.5] [--grid-skies clear,hazed] [--work /tmp/fog_bench]

1. Per basis sky (--skies): the pipeline's fog render (outputs/<sky>/fog.exr, from `scripts/bake`
   or `skybake bake`; rendered here with the pipeline's settings if absent, and timed) and
   `fog-fit fit` on it (timed, the pipeline's --params per-slice-elevation); from its report: the
   error of the fit (exact LUT x depth function) and of the evaluator (packed LUTs) near the camera
   (depth <= 1 km), at the horizon (elevation <= 1 deg) and at infinite depth (the LUT alone), and
   the fit diagnostics (near the camera: global pair, a pair per depth table, per table and
   azimuth, k per table and elevation; in-sample).
2. The same render fitted with --params per-slice and global (the talk's model), --channels
   luminance and --angle elevation (the talk's theta): RMS near the camera / horizon / all, and the
   evaluator near the camera.
3. Cross-validation in the sun angle: fitted on the 6 tables 30, 60, 80, 88, 92, 96 deg only, the
   fit and evaluator RMS near the camera on the 8 other tables.
4. Cross-validation in the elevation (--grid-skies): the render with 17 elevations, fitted on every
   2nd (the pipeline's 9), measured on all 17.
5. The texel grid (--grid-skies): the render with --lut-texels centres (lut-pack's grid) vs the
   pipeline's nodes: the evaluator near the camera and at x = 1.
6. The cut: for each of --cut-skies, depth tables with a 2x2 LUT (64 slices) at each --cuts-km, fit error.
7. Bytes of every texture of the first sky.
"""
import argparse
import json
import os
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))

# The pipeline's fog settings (pipeline.yaml `fog:`); the depth tables as there.
SUNS = "0,15,30,45,60,70,80,84,88,90,92,94,96,98"
TABLES = ["--sun-zenith-deg", SUNS, "--elevations", "9", "--azimuths-deg", "0,30,90,150,180",
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


def render_fog(a, sky, out, *extra, elevations="9"):
    tables = [elevations if prev == "--elevations" else t for prev, t in zip([None] + TABLES, TABLES)]
    return run([os.path.join(a.bin, "sky-render"), "--quiet", "fog", os.path.join(ROOT, "atmospheres", sky + ".yaml"),
                "--mie-dir", a.mie_dir, "--cut-altitude-km", "1", "-o", out] + tables + list(extra))


def rms_of(per_sun, suns):
    rows = [p for p in per_sun if p["sun_zenith_deg"] in suns]
    return (sum(p["near_camera_rms"] ** 2 for p in rows) / len(rows)) ** 0.5 if rows else float("nan")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "fog", "bin"))
    ap.add_argument("--mie-dir", default=os.path.join(ROOT, "outputs", "mie"))
    ap.add_argument("--renders", default=os.path.join(ROOT, "outputs"))
    ap.add_argument("--skies", default="clear,hazed")
    ap.add_argument("--grid-skies", default="clear,hazed")
    ap.add_argument("--cuts-km", default="0.25,0.5,1,2,3.5")
    ap.add_argument("--cut-skies", default="clear,hazed,cloudy2")
    ap.add_argument("--work", default="/tmp/fog_bench")
    ap.add_argument("--only", default="", help="comma-separated section numbers to run (default: all; 2-5 need 1)")
    a = ap.parse_args()
    only = set(a.only.split(",")) if a.only else {"1", "2", "3", "4", "5", "6", "7"}
    skies = a.skies.split(",")
    os.makedirs(a.work, exist_ok=True)

    reports = {}
    if "1" in only:
        print("1. Per basis sky: pipeline settings (orders low, spectral stride 4, cut 1 km, 32x32x64 fog LUT on the node grid,"
              " 64x64 attenuation, depth tables 14 suns x 9 elevations x 5 azimuths x 16 depths, --params per-slice-elevation)")
        print("   error = |Y_model / Y_ref - 1| (luminance), RMS / max in %; near = depth <= 1 km; horizon = elevation <= 1 deg")
        print("%-8s %7s %6s | %-12s %-12s %-12s | %-12s %-12s %-12s | %s" % (
            "sky", "render", "fit", "fit near", "fit horizon", "fit all", "eval near", "eval horizon", "eval x=1",
            "diagnostics near RMS: global / per table / per table+azimuth / per table+elevation"))
        for sky in skies:
            render = os.path.join(a.renders, sky, "fog.exr")
            render_s = float("nan")
            if not os.path.isfile(render):
                render = os.path.join(a.work, sky + "_fog.exr")
                render_s = render_fog(a, sky, render)
            seconds, rep = fit(a.bin, render, os.path.join(a.work, "default"), sky)
            reports[sky] = (render, rep)
            e = rep["errors"]["fog"]
            cell = lambda x: "%s/%s" % (pct(x["rms"]), pct(x["max"]))
            diag = " / ".join("%.1f" % (100 * d["near_camera"]["rms"]) for d in rep["fit_diagnostics"])
            print("%-8s %6.1fs %5.2fs | %s %s %s | %s %s %s | %s" % (
                sky, render_s, seconds, cell(e["fit"]["near_camera"]), cell(e["fit"]["horizon"]), cell(e["fit"]["all"]),
                cell(e["evaluator"]["near_camera"]), cell(e["evaluator"]["horizon"]), cell(e["evaluator"]["infinite_depth"]), diag))
            s = rep["errors"]["shadowed"]["fit"]
            print("%-8s %s shadowed fog fit: all %s/%s near %s/%s horizon %s/%s; attenuation max |dT| R %.4f G %.4f B %.4f" % (
                "", " " * 14, pct(s["all"]["rms"]), pct(s["all"]["max"]), pct(s["near_camera"]["rms"]), pct(s["near_camera"]["max"]),
                pct(s["horizon"]["rms"]), pct(s["horizon"]["max"]), rep["attenuation"]["max_abs"]["R"],
                rep["attenuation"]["max_abs"]["G"], rep["attenuation"]["max_abs"]["B"]))
        print("   render: wall time of sky-render fog (nan: taken from --renders); fit: wall time of fog-fit fit")

    if "2" in only:
        print("\n2. Variants of the fit on the same renders: fit RMS % near camera / horizon / all; evaluator RMS % near camera")
        variants = (("default", None), ("per_slice", ["--params", "per-slice"]), ("global", ["--params", "global"]),
                    ("luminance", ["--channels", "luminance"]), ("elevation", ["--angle", "elevation"]))
        print("%-8s " % "sky" + " ".join("%-27s" % v for v, _ in variants))
        for sky in skies:
            render, rep = reports[sky]
            cols = []
            for variant, extra in variants:
                r = rep if extra is None else fit(a.bin, render, os.path.join(a.work, variant), sky, *extra)[1]
                f = r["errors"]["fog"]["fit"]
                cols.append("%s/%s/%s; %s" % (pct(f["near_camera"]["rms"]), pct(f["horizon"]["rms"]), pct(f["all"]["rms"]),
                                              pct(r["errors"]["fog"]["evaluator"]["near_camera"]["rms"])))
            print("%-8s " % sky + " ".join("%-27s" % c for c in cols))

    if "3" in only:
        print("\n3. Cross-validation in the sun angle: fitted on 30,60,80,88,92,96 deg only; RMS % near the camera on the other tables"
              " (fit, evaluator)")
        held = set(float(z) for z in SUNS.split(",")) - {30.0, 60.0, 80.0, 88.0, 92.0, 96.0}
        for sky in skies:
            render, _ = reports[sky]
            cols = []
            for params in ("per-slice-elevation", "per-slice", "global"):
                r = fit(a.bin, render, os.path.join(a.work, "xsun_" + params), sky, "--params", params,
                        "--fit-sun-zenith-deg", "30,60,80,88,92,96")[1]["errors"]["fog"]
                cols.append("%s: %s, %s" % (params, pct(rms_of(r["fit"]["per_sun"], held)), pct(rms_of(r["evaluator"]["per_sun"], held))))
            print("  %-8s %s" % (sky, "   ".join(cols)))

    grid_skies = a.grid_skies.split(",") if a.grid_skies else []
    if "4" in only:
        print("\n4. Cross-validation in the elevation: 17 elevations rendered, fitted on every 2nd (9); fit RMS % near camera"
              " (all 17 rows) and the same fitted on all 17")
        for sky in grid_skies:
            render = os.path.join(a.work, sky + "_el17.exr")
            render_fog(a, sky, render, elevations="17")
            r2 = fit(a.bin, render, os.path.join(a.work, "el_stride2"), sky, "--fit-elevation-stride", "2")[1]["errors"]["fog"]["fit"]
            r1 = fit(a.bin, render, os.path.join(a.work, "el_stride1"), sky)[1]["errors"]["fog"]["fit"]
            print("  %-8s fitted on 9: near %s/%s   fitted on 17: near %s/%s" % (
                sky, pct(r2["near_camera"]["rms"]), pct(r2["near_camera"]["max"]), pct(r1["near_camera"]["rms"]), pct(r1["near_camera"]["max"])))

    if "5" in only:
        print("\n5. Texel grid of the fog LUT: evaluator RMS/max % near the camera and at x = 1 (the LUT alone)")
        for sky in grid_skies:
            render = os.path.join(a.work, sky + "_centres.exr")
            seconds = render_fog(a, sky, render, "--lut-texels", "centres")
            c = fit(a.bin, render, os.path.join(a.work, "centres"), sky)[1]["errors"]["fog"]["evaluator"]
            n = reports[sky][1]["errors"]["fog"]["evaluator"] if sky in reports else fit(
                a.bin, os.path.join(a.renders, sky, "fog.exr"), os.path.join(a.work, "default"), sky)[1]["errors"]["fog"]["evaluator"]
            print("  %-8s centres: near %s/%s, x=1 %s/%s   nodes: near %s/%s, x=1 %s/%s   (centres render %.1f s)" % (
                sky, pct(c["near_camera"]["rms"]), pct(c["near_camera"]["max"]), pct(c["infinite_depth"]["rms"]),
                pct(c["infinite_depth"]["max"]), pct(n["near_camera"]["rms"]), pct(n["near_camera"]["max"]),
                pct(n["infinite_depth"]["rms"]), pct(n["infinite_depth"]["max"]), seconds))

    if "6" in only:
        print("\n6. The cut (2x2 LUT on 64 slices, the pipeline's depth tables): fit error RMS % near camera / horizon / all,"
              " render time")
        for sky in a.cut_skies.split(","):
            for cut in a.cuts_km.split(","):
                render = os.path.join(a.work, "%s_cut%s.exr" % (sky, cut))
                seconds = run([os.path.join(a.bin, "sky-render"), "--quiet", "fog", os.path.join(ROOT, "atmospheres", sky + ".yaml"),
                               "--mie-dir", a.mie_dir, "--cut-altitude-km", cut, "--lut-size", "2x2",
                               "-o", render] + TABLES)  # 64 slices: the per-slice parameters need the product's slices
                f = fit(a.bin, render, os.path.join(a.work, "cut" + cut), sky)[1]["errors"]["fog"]["fit"]
                print("  %-8s cut %4s km: %s / %s / %s   (%.1f s)" % (sky, cut, pct(f["near_camera"]["rms"]), pct(f["horizon"]["rms"]),
                                                                    pct(f["all"]["rms"]), seconds))
    if "7" in only:
        sky = skies[0]
        print("\n7. Bytes (%s)" % sky)
        d = os.path.join(a.work, "default")
        for name in sorted(os.listdir(d)):
            if name.startswith("fog_%s" % sky):
                print("  %-32s %9d" % (name, os.path.getsize(os.path.join(d, name))))


if __name__ == "__main__":
    main()
