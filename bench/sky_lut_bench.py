#!/usr/bin/env python3
"""Speed of the fast deterministic sky (`orders`) on the GT7 LUT set (the speed target:
the 8 basis skies x 64 sun slices x their texels at >= 40 wavelengths in <= 30 s on 2 cores, each sky within its accuracy target;
docs/sky-methods.md "orders"). Prints a table; writes only into its work folder.

  bench/sky_lut_bench.py [--bin build/release/bin] [--outputs outputs] [--pipeline pipeline.yaml]
                         [--skies clear,hazed,...] [--threads 1,2] [--work /tmp/sky_lut_bench]
                         [--wavelengths 360:830:5] [--spectral-stride K] [--size WxH] [--quality Q]
                         [--repeat N] [--references DIR] [--make-references]
                         [--ref-target-error E] [--ref-max-paths N]

Needs a baked outputs/ (profiles and Mie tables, from `scripts/bake`). For every basis sky of the
pipeline's `luts` section, the exact LUT render the pipeline runs (sky-render render --method
orders --mapping gt7 --time-mapping ... --size ...) is timed at each thread count, and once with
a 2x2 mapping: what does not depend on the LUT's size - the tables (the solve of the orders,
the sun tables), the ambient LUT's 640 directions per slice and the transmittance LUT; the
texels of 2x2x64 are negligible. The set's total at 2 threads is compared with the 30 s target, and
the scaling 1 -> 2 threads is printed (target >= 1.9x), with each render's peak resident memory
(wait4's ru_maxrss; target <= 1 GB).

Beside each sky's time, its error: `sky-render points` with the LUT render's method, quality and
spectral stride at 140 geometries (5 view zeniths x 7 azimuths at sun zenith 30, 70, 85 and 95 deg)
against a cached path reference at the same geometries - the noise-corrected RMS and the max of Y
outside the 1 deg aureole in daylight (target 0.5 % / 2 %; the max includes the reference's noise) and the RMS at sun 95 deg
(target 3 %). The references live in <work>/references (or --references DIR): per sky a daylight
and a twilight CSV and the hash of what they depend on (the sky's render.yaml, profiles and Mie
tables, the geometries, the wavelength grid and the path tracer's settings); --make-references path-traces the missing or stale ones (at --ref-target-error, default
0.5 % in daylight and 2 % in twilight; minutes per clear sky, docs/benchmarks.md). A sky without
a fresh reference prints "no reference". --size WxH renders every sky at that size
instead of the pipeline's (32x128 for all 8: every sky at the clear sky's size; the pipeline
follows the GT7 talk's memory budget, 16x64 for the cloudy skies). Each sky renders at its quality
in pipeline.yaml (high for clear and hazed, whose LUTs the LUT accuracy target
(docs/benchmarks.md) covers; medium for the cloudy skies); --quality Q renders every sky at Q instead
(--quality medium: the cheaper preset, 2.2 % RMS off on the hazed sky; docs/benchmarks.md).
"""
import argparse
import hashlib
import math
import os
import re
import subprocess
import sys
import time

import yaml

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))


def luts_section(pipeline):
    """(method, quality, time_mapping, spectral_stride, [(sky, size, quality, spectral_stride)]) from pipeline.yaml's
    luts section (PyYAML; a sky's own quality and stride, if it names them, else the section's)."""
    with open(pipeline) as f:
        luts = yaml.safe_load(f)["luts"]
    quality, stride = str(luts.get("quality", "medium")), str(luts.get("spectral_stride", 1))
    skies = [(s["atmosphere"], s["size"], str(s.get("quality", quality)), str(s.get("spectral_stride", stride)))
             for s in luts["skies"]]
    return (luts.get("method", "orders"), quality, luts.get("time_mapping", "gt7-quadratic"), stride, skies)


def timed(args, cwd):
    """(wall s, peak resident memory MiB) of one run: the child's ru_maxrss (KiB on Linux) from wait4."""
    t0 = time.perf_counter()
    p = subprocess.Popen(args, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    err = p.stderr.read().decode(errors="replace")
    _, status, usage = os.wait4(p.pid, 0)
    dt = time.perf_counter() - t0
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit("failed: %s\n%s" % (" ".join(args), err))
    return dt, usage.ru_maxrss / 1024.0


# The reference geometries (sun zenith, view zenith, relative azimuth; deg): 5 view zeniths x 7
# azimuths at 3 daylight suns (sun elevation 60, 20, 5 deg) and one twilight sun (-5 deg), the
# grid of the method comparisons in docs/sky-methods.md ("Measured accuracy").
DAY_SUNS = (30, 70, 85)
TWILIGHT_SUNS = (95,)
VIEWS = [(vz, az) for vz in (5, 30, 60, 80, 88) for az in (0, 30, 60, 90, 120, 150, 180)]
# The accuracy targets (docs/sky-methods.md "orders"): daylight RMS <= 0.5 %, max <= 2 %; twilight RMS <= 3 %.
TARGET_DAY_RMS, TARGET_DAY_MAX, TARGET_TWILIGHT_RMS = 0.5, 2.0, 3.0


def write_geometry(path, suns):
    with open(path, "w") as f:
        f.write("# source: bench/sky_lut_bench.py reference geometries (5 view zeniths x 7 azimuths at sun zenith %s deg)\n"
                % ", ".join("%g" % z for z in suns))
        f.write("sun_zenith_deg,view_zenith_deg,relative_azimuth_deg\n")
        for sza in suns:
            for vz, az in VIEWS:
                f.write("%g,%g,%g\n" % (sza, vz, az))


def read_points(path):
    """[(sun zenith, view zenith, relative azimuth (deg), Y cd/m2, Y standard error cd/m2)] of a sky-render points CSV."""
    rows = [l for l in open(path) if not l.startswith("#")]
    head = rows[0].strip().split(",")
    cols = [head.index(k) for k in ("sun_zenith_deg", "view_zenith_deg", "relative_azimuth_deg", "Y_cd_m2", "Y_stderr_cd_m2")]
    return [tuple(float(c[i]) for i in cols) for c in (r.strip().split(",") for r in rows[1:] if r.strip())]


def from_sun_deg(sza, vz, az):
    """Angle between the view direction and the sun's centre (deg)."""
    r = math.radians
    c = math.cos(r(sza)) * math.cos(r(vz)) + math.sin(r(sza)) * math.sin(r(vz)) * math.cos(r(az))
    return math.degrees(math.acos(max(-1.0, min(1.0, c))))


def sky_key(out, sky, how):
    """What a reference depends on: the bytes of the sky's render.yaml, profiles and Mie tables, and
    how it is made (`how`: the geometries and the path tracer's settings)."""
    h = hashlib.sha256(how.encode())
    for rel in sorted(["%s/components/render.yaml" % sky, "%s/profiles.exr" % sky] +
                      [os.path.join("mie", m) for m in os.listdir(os.path.join(out, "mie")) if m.endswith(".exr")]):
        with open(os.path.join(out, rel), "rb") as f:
            h.update(rel.encode() + b"\0" + hashlib.sha256(f.read()).digest())
    return h.hexdigest()


def errors(method_csv, ref_csv):
    """(noise-corrected RMS %, max %) of Y against the reference, the metric of docs/sky-methods.md
    "Metrics" without its solid-angle weights: outside the 1 deg aureole (where the disk's handling and
    the reference's noise dominate), RMS = sqrt(max(0, mean(e^2) - mean(s^2))) with e the relative
    difference and s the reference's relative standard error (its noise removed in the mean);
    max = the largest |e| (the reference's noise included)."""
    e = [(m[3] / r[3] - 1.0, r[4] / r[3]) for m, r in zip(read_points(method_csv), read_points(ref_csv))
         if r[3] > 0 and from_sun_deg(*r[:3]) > 1.0]
    return (100.0 * math.sqrt(max(0.0, sum(x * x for x, _ in e) / len(e) - sum(s * s for _, s in e) / len(e))),
            100.0 * max(abs(x) for x, _ in e))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "release", "bin"))
    ap.add_argument("--outputs", default=os.path.join(ROOT, "outputs"))
    ap.add_argument("--pipeline", default=os.path.join(ROOT, "pipeline.yaml"))
    ap.add_argument("--skies", default="")
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--work", default="/tmp/sky_lut_bench")
    ap.add_argument("--wavelengths", default="360:830:5")
    ap.add_argument("--spectral-stride", default="", help="override luts.spectral_stride")
    ap.add_argument("--size", default="", help="render every sky at WxH instead of the pipeline's size")
    ap.add_argument("--quality", default="", help="render every sky at this quality instead of the pipeline's")
    ap.add_argument("--repeat", type=int, default=1,
                    help="time each render N times and keep the shortest (a shared or virtual machine's "
                         "speed drifts by ~20 %% between minutes)")
    ap.add_argument("--references", default="",
                    help="folder of the cached path references (default: <work>/references): <sky>_day.csv and "
                         "<sky>_twilight.csv (`sky-render points --method path` at the bench's 140 geometries) and <sky>.key")
    ap.add_argument("--make-references", action="store_true",
                    help="path-trace the references that are missing or stale (the atmosphere, profiles or Mie "
                         "tables changed) for the skies benched; slow (docs/benchmarks.md)")
    ap.add_argument("--ref-target-error", default="0.005,0.02",
                    help="the references' relative standard error of Y per geometry: daylight,twilight (the twilight "
                         "target is 6x looser; a 1 %% twilight reference needs ~1 M paths per geometry)")
    ap.add_argument("--ref-max-paths", default="1048576", help="the references' paths per geometry at most")
    a = ap.parse_args()
    sys.stdout.reconfigure(line_buffering=True)  # each sky's line as it is measured
    method, quality, time_mapping, stride, skies = luts_section(a.pipeline)
    if a.spectral_stride:
        stride = a.spectral_stride
        skies = [(sky, size, q, a.spectral_stride) for sky, size, q, _ in skies]
    if a.size:
        skies = [(sky, a.size, q, k) for sky, _, q, k in skies]
    if a.quality:
        quality = a.quality
        skies = [(sky, size, a.quality, k) for sky, size, _, k in skies]
    auto = [sky for sky, _, q, _ in skies if q == "auto"]
    if auto:
        sys.exit("sky_lut_bench: %s: quality: auto (bench/auto_quality_bench.py measures those; or --quality Q)" % ", ".join(auto))
    if a.skies:
        keep = a.skies.split(",")
        skies = [s for s in skies if s[0] in keep]
    threads = [int(t) for t in a.threads.split(",")]
    os.makedirs(a.work, exist_ok=True)
    out = os.path.abspath(a.outputs)
    nwl = len(range(*[int(float(x)) for x in a.wavelengths.split(":")])) + 1
    cpu = "?"
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(l.split(":", 1)[1].strip() for l in f if l.startswith("model name"))
    except (OSError, StopIteration):
        pass
    print("sky-render --method %s --quality %s --time-mapping %s --spectral-stride %s (a sky's own where it names one), %d wavelengths (%s nm), %d cpus (%s)%s"
          % (method, quality, time_mapping, stride, nwl, a.wavelengths, os.cpu_count(), cpu,
             ", shortest of %d" % a.repeat if a.repeat > 1 else ""))
    refdir = os.path.abspath(a.references or os.path.join(a.work, "references"))
    os.makedirs(refdir, exist_ok=True)
    parts = [("day", DAY_SUNS, a.ref_target_error.split(",")[0]), ("twilight", TWILIGHT_SUNS, a.ref_target_error.split(",")[-1])]
    for name, suns, _ in parts:
        write_geometry(os.path.join(a.work, "geometry_%s.csv" % name), suns)
    how = repr((parts, VIEWS, a.ref_max_paths, a.wavelengths))
    print("%-8s %-7s %-7s %7s %11s %8s %21s %9s %s" % ("sky", "size", "q/stride", "build_s", "render_s", "peak_MiB",
                                                    "day RMS / max %", "twi RMS %", "(wall s and peak memory at threads "
                                                    + a.threads + "; errors in Y against the path references)"))
    totals = {t: 0.0 for t in threads}
    peak_all = 0.0
    for sky, size, sky_quality, stride in skies:
        scene = ["--profiles", "%s/profiles.exr" % sky, "--mie-dir", "mie", "--wavelengths", a.wavelengths]
        base = [os.path.join(os.path.abspath(a.bin), "sky-render"), "--quiet", "render", "--method", method,
                "--quality", sky_quality] + scene + ["--mapping", "gt7", "--time-mapping", time_mapping,
                "--spectral-stride", stride]
        comp = "%s/components/render.yaml" % sky
        build = min(timed(base + ["--size", "2x2", "--threads", str(max(threads)), "-o",
                                  os.path.join(a.work, sky + "_build.exr"), comp], out)[0] for _ in range(a.repeat))
        walls, peaks = [], []
        for t in threads:
            runs = [timed(base + ["--size", size, "--threads", str(t), "-o", os.path.join(a.work, "%s_t%d.exr" % (sky, t)), comp], out)
                    for _ in range(a.repeat)]
            w = min(r[0] for r in runs)
            totals[t] += w
            walls.append(w)
            peaks.append(max(r[1] for r in runs))
        peak_all = max(peak_all, max(peaks))
        same = len({open(os.path.join(a.work, "%s_t%d.exr" % (sky, t)), "rb").read() for t in threads}) == 1
        points = [os.path.join(os.path.abspath(a.bin), "sky-render"), "--quiet", "points"] + scene + [
            "--wavelengths-out", "550", "--threads", str(max(threads))]
        key, keyfile = sky_key(out, sky, how), os.path.join(refdir, sky + ".key")
        refs = {name: os.path.join(refdir, "%s_%s.csv" % (sky, name)) for name, _, _ in parts}
        fresh = all(os.path.exists(r) for r in refs.values()) and os.path.exists(keyfile) and open(keyfile).read().strip() == key
        if not fresh and a.make_references:
            for name, _, target in parts:
                t0 = time.perf_counter()
                timed(points + ["--geometry", os.path.join(a.work, "geometry_%s.csv" % name), "--method", "path",
                                "--target-error", target, "--max-paths", a.ref_max_paths, "-o", refs[name] + ".tmp", comp], out)
                os.replace(refs[name] + ".tmp", refs[name])
                print("  (%s: %s path reference at %s relative error made in %.0f s)" % (sky, name, target, time.perf_counter() - t0))
            with open(keyfile, "w") as f:
                f.write(key + "\n")
            fresh = True
        if fresh:
            res = {}
            for name, _, _ in parts:
                mine = os.path.join(a.work, "%s_%s_points.csv" % (sky, name))
                timed(points + ["--geometry", os.path.join(a.work, "geometry_%s.csv" % name), "--method", method,
                                "--quality", sky_quality, "--spectral-stride", stride, "-o", mine, comp], out)
                res[name] = errors(mine, refs[name])
            (dr, dm), (tr, _) = res["day"], res["twilight"]
            ok = dr <= TARGET_DAY_RMS and dm <= TARGET_DAY_MAX and tr <= TARGET_TWILIGHT_RMS
            err = "%10.2f / %-8.2f %9.2f" % (dr, dm, tr)
            verdict = "within target" if ok else "NOT within target"
        else:
            err = "%21s %9s" % ("no reference", "-")
            verdict = "(--make-references)" if not os.path.exists(keyfile) else "(reference stale: --make-references)"
        print("%-8s %-7s %-7s %7.1f %11s %8s %s %s, %s" % (sky, size, "%s/%s" % (sky_quality, stride), build, " ".join("%.1f" % w for w in walls),
                                                    "/".join("%.0f" % m for m in peaks), err, verdict,
                                                    "same bytes" if same else "BYTES DIFFER between thread counts"))
    for t in threads:
        print("set total at %d thread%s: %.1f s" % (t, "s" if t > 1 else "", totals[t]))
    if 1 in totals and 2 in totals and totals[2] > 0:
        print("scaling 1 -> 2 threads: %.2fx (target >= 1.9x)" % (totals[1] / totals[2]))
    if 2 in totals:
        print("target: the set in <= 30 s on 2 cores: %s" % ("met" if totals[2] <= 30 else "NOT met"))
    print("peak memory of a render: %.0f MiB (target <= 1 GB = 954 MiB: %s)" % (peak_all, "met" if peak_all <= 1e9 / 2**20 else "NOT met"))


if __name__ == "__main__":
    main()
