#!/usr/bin/env python3
"""`quality: auto` on the basis skies (docs/sky-methods.md "Automatic quality"): what the choice
costs, what it saves on each LUT render, and how far each automatic LUT is from the full model's.
Prints a table; writes only into its work folder.

  bench/auto_quality_bench.py [--bin build/test/bin] [--outputs outputs] [--pipeline pipeline.yaml]
                              [--skies clear,hazed,...] [--work /tmp/auto_quality_bench]
                              [--tolerance 0.5%] [--max-tolerance 2%] [--twilight-tolerance 3%]

Needs a baked outputs/ (profiles and Mie tables, from `scripts/bake`). For every basis sky of the
pipeline's `luts` section, at the pipeline's size and time mapping:
  choose   `sky-render choose` with the tolerances (its wall time: the full model and every
           candidate it tried, on the 91 chart directions at 7 sun angles);
  auto     the LUT render with `--settings` of that choice;
  hand     the LUT render at the pipeline's own quality and spectral stride (what the default bake
           runs), for the time saved;
  full     the LUT render of the full model (high, every wavelength), the yardstick.
Each of auto and hand is compared with full over every texel of every slice: the relative error of
Y (cd/m^2), RMS and max over the daylight slices (sun zenith < 90 deg) and RMS over the twilight
slices (the LUT's texels include the 1 deg aureole that choose leaves out, so the max can exceed
choose's). Wall seconds on this machine's threads (default: all).
"""
import argparse
import math
import os
import re
import subprocess
import sys

import yaml

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
sys.path.insert(0, os.path.dirname(__file__))
from sky_lut_bench import luts_section, timed  # noqa: E402


def slices_y(path):
    """{sun zenith deg: [Y per texel]} of a LUT render (oiiotool reads it: --info for the slice
    angles, --dumpdata for the texels; channel G is Y of CIE-XYZ-D65)."""
    info = subprocess.run(["oiiotool", "--info", "-a", "-v", path], stdout=subprocess.PIPE, text=True, check=True).stdout
    names, angles = [], []
    for block in re.split(r"\n subimage +\d+:", info)[1:]:
        m = re.search(r'oiio:subimagename: "([^"]+)"', block)
        names.append(m.group(1) if m else "")
        z = re.search(r"skybake\.sun_zenith_deg: ([-\d.e+]+)", block)
        angles.append(float(z.group(1)) if z else None)
    dump = subprocess.run(["oiiotool", "-a", "--dumpdata", path], stdout=subprocess.PIPE, text=True, check=True).stdout
    out, k = {}, -1
    for line in dump.split("\n"):
        if line.startswith(" subimage"):
            k += 1
            continue
        if k < 0 or not names[k].startswith("sky.") or angles[k] is None:
            continue
        if line.lstrip().startswith("Pixel"):
            out.setdefault(angles[k], []).append(float(line.split(":")[1].split()[1]))
    return out


def compare(test, full):
    day, twi = [], []
    for z, ref in full.items():
        for a, b in zip(test[z], ref):
            if b > 0:
                (day if z < 90 else twi).append(a / b - 1.0)
    rms = lambda v: 100 * math.sqrt(sum(x * x for x in v) / len(v)) if v else float("nan")
    return rms(day), 100 * max(abs(x) for x in day), rms(twi)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "test", "bin"))
    ap.add_argument("--outputs", default=os.path.join(ROOT, "outputs"))
    ap.add_argument("--pipeline", default=os.path.join(ROOT, "pipeline.yaml"))
    ap.add_argument("--skies", default="")
    ap.add_argument("--work", default="/tmp/auto_quality_bench")
    ap.add_argument("--tolerance", default="0.5%")
    ap.add_argument("--max-tolerance", default="2%")
    ap.add_argument("--twilight-tolerance", default="3%")
    a = ap.parse_args()
    method, _, time_mapping, _, skies = luts_section(a.pipeline)
    if a.skies:
        keep = a.skies.split(",")
        skies = [s for s in skies if s[0] in keep]
    sr = os.path.join(a.bin, "sky-render")
    os.makedirs(a.work, exist_ok=True)
    rows = []
    for sky, size, quality, stride in skies:
        w = os.path.join(a.work, sky)
        os.makedirs(w, exist_ok=True)
        scene = ["%s/components/render.yaml" % sky, "--profiles", "%s/profiles.exr" % sky, "--mie-dir", "mie",
                 "--wavelengths", "360:830:5", "--quiet"]
        lut = ["--mapping", "gt7", "--size", size, "--time-mapping", time_mapping]
        choice = os.path.join(w, "lut_quality.yaml")
        t_choose, _ = timed([sr, "choose"] + scene + ["--method", method, "--tolerance", a.tolerance, "--max-tolerance",
                                                      a.max_tolerance, "--twilight-tolerance", a.twilight_tolerance, "-o", choice],
                            a.outputs)
        with open(choice) as f:
            chosen = yaml.safe_load(f)
        t_auto, _ = timed([sr, "render"] + scene + lut + ["--settings", choice, "-o", os.path.join(w, "auto.exr")], a.outputs)
        if quality == "auto":  # the pipeline has no settings by hand for this sky: compare auto with itself
            quality = chosen["quality"]
            stride_hand = str(chosen["spectral_stride"])
        else:
            stride_hand = stride
        t_hand, _ = timed([sr, "render"] + scene + lut + ["--method", method, "--quality", quality, "--spectral-stride", stride_hand,
                                                          "-o", os.path.join(w, "hand.exr")], a.outputs)
        t_full, _ = timed([sr, "render"] + scene + lut + ["--method", method, "--quality", "high", "-o", os.path.join(w, "full.exr")],
                          a.outputs)
        full = slices_y(os.path.join(w, "full.exr"))
        e_auto = compare(slices_y(os.path.join(w, "auto.exr")), full)
        e_hand = compare(slices_y(os.path.join(w, "hand.exr")), full)
        rows.append((sky, size, "%s/%s" % (chosen["quality"], chosen["spectral_stride"]), t_choose, t_auto, e_auto,
                     "%s/%s" % (quality, stride_hand), t_hand, e_hand, t_full))
        print("%s done" % sky, file=sys.stderr)
    print("tolerances: daylight RMS %s, max %s; twilight RMS %s (against the full model: high, every wavelength)"
          % (a.tolerance, a.max_tolerance, a.twilight_tolerance))
    print("| sky | size | auto: quality/stride | choose s | auto render s | auto vs full: day RMS / max, twilight RMS (%) "
          "| hand: quality/stride | hand render s | hand vs full (%) | saved per render s | full render s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for sky, size, qa, tc, ta, ea, qh, th, eh, tf in rows:
        print("| %s | %s | %s | %.1f | %.1f | %.2f / %.2f, %.2f | %s | %.1f | %.2f / %.2f, %.2f | %+.1f | %.1f |"
              % (sky, size, qa, tc, ta, ea[0], ea[1], ea[2], qh, th, eh[0], eh[1], eh[2], th - ta, tf))
    tot = [sum(r[i] for r in rows) for i in (3, 4, 7, 9)]
    print("| total | | | %.1f | %.1f | | | %.1f | | %+.1f | %.1f |" % (tot[0], tot[1], tot[2], tot[2] - tot[1], tot[3]))


if __name__ == "__main__":
    main()
