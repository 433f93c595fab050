#!/usr/bin/env python3
"""lut-pack figures (docs/lut-pack.md): decode error between slices, blending error, packing
error and bytes. Prints tables; writes nothing outside its work folder.

  bench/lut_pack_bench.py [--bin build/release/bin] [--luts outputs/luts] [--mie-dir outputs/mie]
                          [--method orders] [--quality medium] [--work /tmp/lut_pack_bench]
                          [--skies clear,hazed] [--slices 0,1,5,10,16,23,30,40,46,48,52,56,60,62]

Needs a baked set (outputs/luts/, from `scripts/bake`) and the Mie tables of its atmospheres.
1. Packing: per texture, the luminance error distribution and clamping from report.json.
2. Decode check: for each basis sky in --skies, a direct equirectangular 64x32 render by the same
   method at the sun angles half-way between slices i and i+1 (slice coordinate i + 0.5), and
   `lut-pack check` of its LUT there: RMS over the upper hemisphere (solid-angle weighted), the
   largest error and where; geometric and linear time interpolation.
3. Blending (GT7 "Interpolation of Basis Skies"): an intermediate atmosphere - clear's aerosol at
   half its optical depth plus hazed's at half its optical depth, the average of the two aerosol
   fields - rendered directly, against (a) 0.5 clear + 0.5 hazed of direct renders (the error of
   linear blending itself) and (b) the same blend of the two decoded LUTs.
"""
import argparse
import json
import os
import math
import re
import subprocess
import sys

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))


def run(args, **kw):
    r = subprocess.run(args, capture_output=True, text=True, **kw)
    if r.returncode != 0:
        sys.exit("failed: %s\n%s" % (" ".join(args), r.stderr))
    return r


def mid_zenith(report, i):
    """Sun zenith (deg) at slice coordinate i + 1/2: the time mapping of lut/gt7_mapping.h
    recomputed from the report's radii and name, inverted by bisection (`lut-pack check` prints
    the coordinate it decodes at, which confirms it)."""
    tm = report["time_mapping"]
    r, R = tm["observer_radius_m"], tm["top_radius_m"]
    name = tm["name"]
    base, _, counts = name.partition(":")
    nu, nl = (48, 16) if not counts else map(int, counts.split("+"))
    p = 2.0 if base == "gt7-quadratic" else 1.0
    dmin, dmax = R - r, math.sqrt((R - r) * (R + r))

    def coord(theta):
        if theta <= math.pi / 2:
            c = math.cos(theta)
            k = (R - r) * (R + r)
            d = k / (math.sqrt(r * r * c * c + k) + r * c)
            return (nu - 1) * max(0.0, (d - dmin) / (dmax - dmin)) ** (1.0 / p)
        return min(nu + (nl - 1) * math.sqrt((math.degrees(theta) - 90.0) / 10.0), nu + nl - 1.0)

    lo, hi = 0.0, math.radians(100.0)
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if coord(mid) < i + 0.5:
            lo = mid
        else:
            hi = mid
    return math.degrees(0.5 * (lo + hi))


def render_direct(bin_dir, atmosphere, out, zeniths, a, profiles=None):
    args = [os.path.join(bin_dir, "sky-render"), "render", atmosphere, "--mie-dir", a.mie_dir, "--method", a.method,
            "--quality", a.quality, "--size", "64x32", "--sun-zenith-deg", ",".join("%.10g" % z for z in zeniths),
            "--quiet", "-o", out]
    if profiles:
        args += ["--profiles", profiles]
    run(args)


def check(bin_dir, luts, direct, out, interp="geometric"):
    run([os.path.join(bin_dir, "lut-pack"), "check"] + luts + ["--direct", direct, "-o", out, "--time-interpolation", interp,
                                                             "--quiet"])
    with open(out) as f:
        return json.load(f)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "release", "bin"))
    ap.add_argument("--luts", default=os.path.join(ROOT, "outputs", "luts"))
    ap.add_argument("--mie-dir", default=os.path.join(ROOT, "outputs", "mie"))
    ap.add_argument("--method", default="orders")
    ap.add_argument("--quality", default="medium")
    ap.add_argument("--work", default="/tmp/lut_pack_bench")
    ap.add_argument("--skies", default="clear,hazed")
    ap.add_argument("--slices", default="0,1,5,10,16,23,30,40,46,48,52,56,60,62")
    ap.add_argument("--no-blend", action="store_true")
    ap.add_argument("--no-decode", action="store_true")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    with open(os.path.join(a.luts, "report.json")) as f:
        report = json.load(f)

    print("== packing (%s, %s) ==" % (report["time_mapping"]["name"], report["format"].split(":")[0]))
    print("%-14s %10s %8s %8s %8s %8s %8s %10s %9s %7s" % ("texture", "texels", "rms %", "p50 %", "p99 %", "p99.9 %",
                                                          "max %", "clamped", "max val", "neg"))
    rows = [(s["name"], s["pack"]) for s in report["skies"]] + [(k, report["other_luts"][k]["pack"])
                                                                for k in ("transmittance", "sun", "ambient")]
    for name, p in rows:
        e = p["luminance_relative_error"]
        print("%-14s %10d %8.3f %8.3f %8.3f %8.3f %8.3f %10d %9.4g %7d" % (
            name, p["texels"], 100 * e["rms"], 100 * e["p50"], 100 * e["p99"], 100 * e["p99.9"], 100 * e["max"],
            p["clamped_above_max"]["texels"], p["clamped_above_max"]["largest_component_before_clamping"],
            p["negative_rec2020"]["texels"]))
    for s in report["skies"]:
        w = s["where"]["clamped_texel_farthest_from_the_sun"]
        if w:
            print("  %s: clamped texels reach %.2f deg from the sun (slice %d)" % (s["name"], w["angle_from_sun_deg"], w["slice"]))
    b = report["budget"]
    print("sky LUT texels: %d bytes = %.4f MiB (budget %.4f MiB); all files %d bytes" % (
        b["sky_lut_texel_bytes"], b["sky_lut_MiB"], b["limit_bytes"] / 1048576.0, report["files_total_bytes"]))

    slices = [int(s) for s in a.slices.split(",")]
    zeniths = [mid_zenith(report, i) for i in slices]
    renders = {s["name"]: s["render"] for s in report["skies"]}
    print("\n== decode vs direct render half-way between slices (%s %s, upper hemisphere) ==" % (a.method, a.quality))
    for sky in ([] if a.no_decode else a.skies.split(",")):
        atm = os.path.join(ROOT, "atmospheres", sky + ".yaml")
        direct = os.path.join(a.work, "direct_%s.exr" % sky)
        render_direct(a.bin, atm, direct, zeniths, a)
        lut = os.path.join(a.luts, "sky_%s.ktx2" % sky)
        g = check(a.bin, [lut], direct, os.path.join(a.work, "check_%s.json" % sky))
        l = check(a.bin, [lut], direct, os.path.join(a.work, "check_%s_linear.json" % sky), "linear")
        print("%s (LUT render: %s)" % (sky, renders.get(sky, "?")))
        print("  %-7s %9s %9s %9s %9s %9s  %s" % ("slices", "zenith", "rms %", "rms>5deg", "rms lin %", "max %",
                                                   "where (view zenith, azimuth, from sun)"))
        for i, sg, sl in zip(slices, g["slices"], l["slices"]):
            m = sg["max_upper"]
            print("  %2d-%-4d %9.3f %9.3f %9.3f %9.3f %+9.2f  (%.1f, %.1f, %.1f)" % (
                i, i + 1, sg["sun_zenith_deg"], 100 * sg["rms_upper"], 100 * sg["rms_upper_outside_sun_cone"],
                100 * sl["rms_upper"], 100 * m["relative_error"], m["view_zenith_deg"], m["azimuth_from_sun_deg"],
                m["angle_from_sun_deg"]))
        print("  all: RMS %.3f %% (geometric), %.3f %% (linear); worst pair %.3f %%" % (
            100 * g["rms_upper_all"], 100 * l["rms_upper_all"], 100 * g["worst_slice_rms_upper"]))

    if a.no_blend:
        return
    print("\n== blending clear and hazed vs the intermediate atmosphere ==")
    mid = write_mid_atmosphere(os.path.join(a.work, "mid.yaml"))
    zs = [30.0, 60.0, 80.0, 88.0, 92.0]
    render_direct(a.bin, mid, os.path.join(a.work, "direct_mid.exr"), zs, a)
    for sky in ("clear", "hazed"):
        render_direct(a.bin, os.path.join(ROOT, "atmospheres", sky + ".yaml"), os.path.join(a.work, "blend_%s.exr" % sky), zs, a)
    # (b) the decoded blend of the two LUTs against the direct intermediate render.
    luts = [os.path.join(a.luts, "sky_clear.ktx2") + ":0.5", os.path.join(a.luts, "sky_hazed.ktx2") + ":0.5"]
    rb = check(a.bin, luts, os.path.join(a.work, "direct_mid.exr"), os.path.join(a.work, "blend_luts.json"))
    # (a) the blend of the two direct renders against the intermediate one, in luminance (Y = the
    # EXRs' G channel, read with oiiotool), solid-angle weighted over the upper hemisphere.
    ya = luminance_rms(os.path.join(a.work, "blend_clear.exr"), os.path.join(a.work, "blend_hazed.exr"),
                       os.path.join(a.work, "direct_mid.exr"), zs, a.work)
    print("  the intermediate atmosphere: clear's aerosol at tau 0.05 + hazed's at tau 0.25 (the mean of the fields)")
    print("  %-10s %14s %14s %12s %14s" % ("sun zenith", "0.5/0.5 rms %", "LUT blend %", "best w_clear", "best-w rms %"))
    for z, s, (y, w, yw) in zip(zs, rb["slices"], ya):
        print("  %-10.1f %14.3f %14.3f %12.3f %14.3f   (LUT blend max %+.2f %% at view zenith %.1f, %.1f deg from the sun)" % (
            z, 100 * y, 100 * s["rms_upper"], w, 100 * yw, 100 * s["max_upper"]["relative_error"],
            s["max_upper"]["view_zenith_deg"], s["max_upper"]["angle_from_sun_deg"]))


def write_mid_atmosphere(path):
    """clear.yaml with clear's aerosol at half its optical depth plus hazed's at half its own."""
    with open(os.path.join(ROOT, "atmospheres", "clear.yaml")) as f:
        clear = f.read()
    with open(os.path.join(ROOT, "atmospheres", "hazed.yaml")) as f:
        hazed = f.read()
    layer = re.search(r"\naerosols:\n((?:  .*\n)+)", hazed).group(1)
    layer = layer.replace("name: continental", "name: hazed_aerosol").replace("optical_depth_550nm: 0.5",
                                                                              "optical_depth_550nm: 0.25")
    text = clear.replace("optical_depth_550nm: 0.1", "optical_depth_550nm: 0.05")
    text = re.sub(r"(\naerosols:\n(?:  .*\n)+)", lambda m: m.group(1) + layer, text, count=1)
    text = text.replace("name: clear", "name: clear_hazed_mid")
    data = os.path.join(ROOT, "atmospheres", "data")
    text = text.replace("file: data/", "file: %s/" % data).replace("../particles/", os.path.join(ROOT, "particles") + "/")
    with open(path, "w") as f:
        f.write(text)
    return path


def exr_y(path, part, work):
    """Y (the G channel) of sky part `part`, texel by texel (oiiotool)."""
    tmp = os.path.join(work, "part_y.exr")
    run(["oiiotool", path, "--subimage", str(part), "--ch", "G", "-o", tmp])
    r = run(["oiiotool", "--dumpdata", tmp])
    return [float(m.group(1)) for m in re.finditer(r"^\s*Pixel \(\d+, \d+\):\s*(\S+)", r.stdout, re.M)]


def luminance_rms(a_exr, b_exr, mid_exr, zs, work):
    """Per sun angle: RMS relative luminance error of 0.5 a + 0.5 b against mid, the weight w of
    a that minimises it (weighted least squares: e = (w ya + (1 - w) yb - ym) / ym is linear in
    w) and that minimum, over the upper hemisphere of a 64x32 equirectangular grid, weighted by
    the texels' solid angles."""
    out = []
    for k in range(len(zs)):
        ya, yb, ym = exr_y(a_exr, k, work), exr_y(b_exr, k, work), exr_y(mid_exr, k, work)
        rows = []
        for t, (x, y, m) in enumerate(zip(ya, yb, ym)):
            row = t // 64
            if row >= 16 or m <= 0:
                continue  # upper hemisphere only
            rows.append((math.cos(math.pi * row / 32) - math.cos(math.pi * (row + 1) / 32), x / m, y / m))
        sw = sum(sa for sa, _, _ in rows)

        def rms(w):
            return math.sqrt(sum(sa * (w * x + (1 - w) * y - 1) ** 2 for sa, x, y in rows) / sw)

        # e = w (x - y) + (y - 1): minimise sum sa e^2 -> w = -sum sa (x - y)(y - 1) / sum sa (x - y)^2
        den = sum(sa * (x - y) ** 2 for sa, x, y in rows)
        w = -sum(sa * (x - y) * (y - 1) for sa, x, y in rows) / den if den > 0 else 0.5
        out.append((rms(0.5), w, rms(w)))
    return out


if __name__ == "__main__":
    main()
