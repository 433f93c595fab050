#!/usr/bin/env python3
"""Speed of the fast deterministic sky (`orders`) on the GT7 LUT set (the speed target:
the 8 basis skies x 64 sun slices x their texels at >= 40 wavelengths in <= 30 s on 2 cores, each sky within its accuracy target;
docs/sky-methods.md "orders"). Prints a table; writes only into its work folder.

  bench/sky_lut_bench.py [--bin build/release/bin] [--outputs outputs] [--pipeline pipeline.yaml]
                         [--skies clear,hazed,...] [--threads 1,2] [--work /tmp/sky_lut_bench]
                         [--wavelengths 360:830:5] [--spectral-stride K] [--size WxH] [--quality Q]
                         [--repeat N]

Needs a baked outputs/ (profiles and Mie tables, from `scripts/bake`). For every basis sky of the
pipeline's `luts` section, the exact LUT render the pipeline runs (sky-render render --method
orders --mapping gt7 --time-mapping ... --size ...) is timed at each thread count, and once with
a 2x2 mapping: what does not depend on the LUT's size - the tables (the solve of the orders,
the sun tables), the ambient LUT's 640 directions per slice and the transmittance LUT; the
texels of 2x2x64 are negligible. The set's total at 2 threads is compared with the 30 s target, and
the scaling 1 -> 2 threads is printed (target >= 1.9x). --size WxH renders every sky at that size
instead of the pipeline's (32x128 for all 8: every sky at the clear sky's size; the pipeline
follows the GT7 talk's memory budget, 16x64 for the cloudy skies). Each sky renders at its quality
in pipeline.yaml (high for clear and hazed, whose LUTs the LUT accuracy target
(docs/benchmarks.md) covers; medium for the cloudy skies); --quality Q renders every sky at Q instead
(--quality medium: the cheaper preset, 2.2 % RMS off on the hazed sky; docs/benchmarks.md).
"""
import argparse
import os
import re
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))


def luts_section(pipeline):
    """(method, quality, time_mapping, spectral_stride, [(sky, size, quality)]) from pipeline.yaml's luts section
    (a sky's own quality, if it names one, else the section's)."""
    text = open(pipeline).read()
    sec = text[text.index("\nluts:"):]
    sec = sec[:re.search(r"\n\S", sec[1:]).start() + 1]
    sec = re.sub(r"#[^\n]*", "", sec)  # comments may quote a sky mapping; only the YAML counts
    get = lambda k, d: (re.search(r"\n  %s: *([^\s#]+)" % k, sec) or [None, d])[1]
    quality = get("quality", "medium")
    skies = [(a, size, q or quality)
             for a, size, q in re.findall(r"\{atmosphere: *(\w+), *size: *(\d+x\d+)(?:, *quality: *(\w+))?\}", sec)]
    return (get("method", "orders"), quality, get("time_mapping", "gt7-quadratic"), get("spectral_stride", "1"), skies)


def timed(args, cwd):
    t0 = time.perf_counter()
    r = subprocess.run(args, cwd=cwd, capture_output=True, text=True)
    dt = time.perf_counter() - t0
    if r.returncode != 0:
        sys.exit("failed: %s\n%s" % (" ".join(args), r.stderr))
    return dt


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
    a = ap.parse_args()
    method, quality, time_mapping, stride, skies = luts_section(a.pipeline)
    if a.spectral_stride:
        stride = a.spectral_stride
    if a.size:
        skies = [(sky, a.size, q) for sky, _, q in skies]
    if a.quality:
        quality = a.quality
        skies = [(sky, size, a.quality) for sky, size, _ in skies]
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
    print("sky-render --method %s --quality %s --time-mapping %s --spectral-stride %s, %d wavelengths (%s nm), %d cpus (%s)%s"
          % (method, quality, time_mapping, stride, nwl, a.wavelengths, os.cpu_count(), cpu,
             ", shortest of %d" % a.repeat if a.repeat > 1 else ""))
    print("%-8s %-7s %-7s %8s %12s %s" % ("sky", "size", "quality", "build_s", "render_s", "(wall s at threads " + a.threads + ")"))
    totals = {t: 0.0 for t in threads}
    for sky, size, sky_quality in skies:
        base = [os.path.join(os.path.abspath(a.bin), "sky-render"), "--quiet", "render", "--method", method,
                "--quality", sky_quality, "--profiles", "%s/profiles.exr" % sky, "--mie-dir", "mie",
                "--wavelengths", a.wavelengths, "--mapping", "gt7", "--time-mapping", time_mapping,
                "--spectral-stride", stride]
        comp = "%s/components/render.yaml" % sky
        build = min(timed(base + ["--size", "2x2", "--threads", str(max(threads)), "-o",
                                  os.path.join(a.work, sky + "_build.exr"), comp], out) for _ in range(a.repeat))
        walls = []
        for t in threads:
            w = min(timed(base + ["--size", size, "--threads", str(t), "-o", os.path.join(a.work, "%s_t%d.exr" % (sky, t)), comp], out)
                    for _ in range(a.repeat))
            totals[t] += w
            walls.append(w)
        same = len({open(os.path.join(a.work, "%s_t%d.exr" % (sky, t)), "rb").read() for t in threads}) == 1
        print("%-8s %-7s %-7s %8.1f %12s %s" % (sky, size, sky_quality, build, " ".join("%.1f" % w for w in walls),
                                           "same bytes" if same else "BYTES DIFFER between thread counts"))
    for t in threads:
        print("set total at %d thread%s: %.1f s" % (t, "s" if t > 1 else "", totals[t]))
    if 1 in totals and 2 in totals and totals[2] > 0:
        print("scaling 1 -> 2 threads: %.2fx (target >= 1.9x)" % (totals[1] / totals[2]))
    if 2 in totals:
        print("target: the set in <= 30 s on 2 cores: %s" % ("met" if totals[2] <= 30 else "NOT met"))


if __name__ == "__main__":
    main()
