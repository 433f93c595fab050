#!/usr/bin/env python3
"""The GT7 case study as a measurement would give it: the five log-normal modes of
particles/gt7_case_study.yaml sampled as dV/d ln r at AERONET's 22 radii (0.05-15 um), built
"as is" as a tabulated type, against the modes (docs/mie.md, "The case study: modes against a table").

  python3 bench/aerosol_table_case.py --bin build/release/bin [--write-shipped] [--rows 22] [--sky]

--write-shipped writes particles/data/gt7_case_study_22_bins.csv (the table the shipped type
particles/gt7_case_study_22_bins.yaml reads). Otherwise the script writes the table for --rows
radii to a temporary folder, builds both Mie tables on the pipeline's grid (360-830 nm, 5 nm,
2161 angles) and prints, per wavelength 450/550/650 nm: the relative difference of C_sca per unit
volume, of the albedo and of g; the phase function's largest relative difference and its L1
distance; and the single-scattering aerosol sky per unit optical depth, omega P(theta), at
5, 30, 90 and 150 degrees - the table against the modes, in per cent. Numbers, not a pass/fail.
--sky also renders the sky of atmospheres/clear.yaml with each of the two as its aerosol (optical
depth 0.3 at 550 nm) by `sky-render points --method orders` (all orders of scattering, Rayleigh
and ozone included) on the almucantar of a sun at 60 degrees zenith and at the zenith, and prints
the radiance's relative difference, per cent.

The density of the modes (particle_type.h): each mode i is a volume log-normal of median r_V,i and
s_i = ln sigma_g, normalised to its volume inside [0.05, 15] um and weighted by its relative
volume w_i, so dV/d ln r = sum_i w_i / Z_i N(ln r; ln r_V,i, s_i), Z_i the volume fraction inside.
"""
import argparse
import csv
import io
import json
import math
import os
import subprocess
import tempfile

ROOT = os.path.normpath(os.path.join(os.path.dirname(__file__), ".."))
# AERONET's 22 radii, um (the size-distribution columns of its inversion files).
AERONET_RADII_UM = [0.050000, 0.065604, 0.086077, 0.112939, 0.148184, 0.194429, 0.255105, 0.334716, 0.439173,
                    0.576227, 0.756052, 0.991996, 1.301571, 1.707757, 2.240702, 2.939966, 3.857452, 5.061260,
                    6.640745, 8.713145, 11.432287, 15.000000]
# particles/gt7_case_study.yaml: (volume median radius um, ln sigma_g, relative volume).
GT7_MODES = [(0.12, 0.45, 1.0), (0.27, 0.25, 1.0), (0.71, 0.22, 0.74), (1.81, 0.20, 1.0), (4.0, 0.55, 1.0)]
R_MIN_UM, R_MAX_UM = 0.05, 15.0


def Phi(x):
    return 0.5 * math.erfc(-x / math.sqrt(2.0))


def DvDlnr(r_um):
    total = 0.0
    for r_v, s, w in GT7_MODES:
        z_in = Phi((math.log(R_MAX_UM) - math.log(r_v)) / s) - Phi((math.log(R_MIN_UM) - math.log(r_v)) / s)
        z = (math.log(r_um) - math.log(r_v)) / s
        total += w / z_in * math.exp(-0.5 * z * z) / (math.sqrt(2.0 * math.pi) * s)
    return total


def Radii(rows):
    if rows == 22:
        return AERONET_RADII_UM
    a, b = math.log(R_MIN_UM), math.log(R_MAX_UM)
    return [math.exp(a + (b - a) * i / (rows - 1)) for i in range(rows)]


def TableCsv(rows):
    out = ["# source: the five modes of particles/gt7_case_study.yaml (GT7 talk, \"The Case Study\") sampled by "
           "bench/aerosol_table_case.py at %s; dV/dlnr per unit total volume inside 0.05-15 um" %
           ("AERONET's 22 radii (0.05-15 um)" if rows == 22 else "%d radii log-spaced over 0.05-15 um" % rows),
           "radius_um,dV_dlnr_relative"]
    for r in Radii(rows):
        out.append("%.9g,%.9g" % (r, DvDlnr(r) / sum(w for _, _, w in GT7_MODES)))
    return "\n".join(out) + "\n"


def Build(bin_dir, yaml, exr):
    subprocess.run([os.path.join(bin_dir, "mie-tables"), "build", yaml, "-o", exr, "--quiet"], check=True)


def Dump(bin_dir, exr, what, wl=None):
    args = [os.path.join(bin_dir, "mie-tables"), "dump", exr, "--what", what]
    if wl is not None:
        args += ["--wavelength-nm", str(wl)]
    text = subprocess.run(args, check=True, capture_output=True, text=True).stdout
    return list(csv.DictReader(line for line in io.StringIO(text) if not line.startswith("#")))


SKY_AZIMUTHS_DEG = [5, 10, 30, 60, 90, 120, 180]


def Sky(bin_dir, tmp, mie_dir, names):
    """Radiance at 450/550/650 nm per geometry for each particle type name (clear.yaml's air)."""
    with open(os.path.join(ROOT, "atmospheres", "clear.yaml")) as f:
        clear = f.read()
    data = os.path.join(ROOT, "atmospheres", "data") + "/"
    geo = os.path.join(tmp, "geometry.csv")
    with open(geo, "w") as f:
        f.write("# source: the almucantar of a sun at 60 degrees zenith, and the zenith\n"
                "sun_zenith_deg,view_zenith_deg,relative_azimuth_deg\n")
        for az in SKY_AZIMUTHS_DEG:
            f.write("60,60,%d\n" % az)
        f.write("60,0,0\n")
    out = {}
    for name in names:
        text = clear.replace("file: data/", "file: " + data)
        text = text.replace("particle: ../particles/continental.yaml", "particle: %s.yaml" % name)
        text = text.replace("optical_depth_550nm: 0.1", "optical_depth_550nm: 0.3")
        atm = os.path.join(tmp, "sky_%s.yaml" % name)
        with open(atm, "w") as f:
            f.write(text)
        csv_out = os.path.join(tmp, "sky_%s.csv" % name)
        subprocess.run([os.path.join(bin_dir, "sky-render"), "points", atm, "--mie-dir", mie_dir, "--geometry", geo,
                        "-o", csv_out, "--method", "orders", "--wavelengths-out", "450,550,650", "--quiet"], check=True)
        with open(csv_out) as f:
            out[name] = list(csv.DictReader(line for line in f if not line.startswith("#")))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "release", "bin"))
    ap.add_argument("--rows", type=int, default=22)
    ap.add_argument("--write-shipped", action="store_true")
    ap.add_argument("--sky", action="store_true")
    a = ap.parse_args()
    if a.write_shipped:
        with open(os.path.join(ROOT, "particles", "data", "gt7_case_study_22_bins.csv"), "w") as f:
            f.write(TableCsv(22))
        return
    tmp = tempfile.mkdtemp(prefix="skybake_case_")
    with open(os.path.join(tmp, "table.csv"), "w") as f:
        f.write(TableCsv(a.rows))
    water = os.path.join(ROOT, "atmospheres", "data", "water_refractive_index_segelstein_1981.csv")
    with open(os.path.join(tmp, "gt7_table.yaml"), "w") as f:
        f.write("refractive_index: {table: %s}\nmodes:\n  - name: measured\n    size_table: table.csv\n"
                "    weight: {relative_volume: 1.0}\n" % water)
    modes_exr, table_exr = os.path.join(tmp, "gt7_case_study.exr"), os.path.join(tmp, "gt7_table.exr")
    Build(a.bin, os.path.join(ROOT, "particles", "gt7_case_study.yaml"), modes_exr)
    Build(a.bin, os.path.join(tmp, "gt7_table.yaml"), table_exr)
    sm, st = Dump(a.bin, modes_exr, "spectral"), Dump(a.bin, table_exr, "spectral")
    print("%d-radius table against the five modes (per cent; C_sca per unit particle volume)" % a.rows)
    print("wl_nm  dCsca/V  dalbedo  dg      dP_max  P_L1    d(wP)5deg  30deg  90deg  150deg")
    vol = {}
    for name, exr in (("modes", modes_exr), ("table", table_exr)):
        with open(exr.replace(".exr", ".report.json")) as f:
            report = json.load(f)
        vol[name] = report["mean_particle_volume_m3"]
        print("%s: %d radii over 95 wavelengths (%d at most per wavelength)" %
              (name, report["summary"]["radii_total"], report["summary"]["radii_max_per_wavelength"]))
    for wl in (450, 550, 650):
        rm = next(r for r in sm if abs(float(r["wavelength_nm"]) - wl) < 1e-9)
        rt = next(r for r in st if abs(float(r["wavelength_nm"]) - wl) < 1e-9)
        csca_v = (float(rt["csca_m2"]) / vol["table"]) / (float(rm["csca_m2"]) / vol["modes"]) - 1.0
        dssa = float(rt["ssa"]) / float(rm["ssa"]) - 1.0
        dg = float(rt["g"]) / float(rm["g"]) - 1.0
        pm, pt = Dump(a.bin, modes_exr, "phase", wl), Dump(a.bin, table_exr, "phase", wl)
        dmax, l1 = 0.0, 0.0
        for j in range(len(pm)):
            p0, p1 = float(pm[j]["phase_sr"]), float(pt[j]["phase_sr"])
            dmax = max(dmax, abs(p1 / p0 - 1.0))
            if j + 1 < len(pm):
                dmu = float(pm[j]["mu"]) - float(pm[j + 1]["mu"])
                q0, q1 = float(pm[j + 1]["phase_sr"]), float(pt[j + 1]["phase_sr"])
                l1 += math.pi * dmu * (abs(p1 - p0) + abs(q1 - q0))
        sky = []
        for deg in (5, 30, 90, 150):
            j = min(range(len(pm)), key=lambda i: abs(float(pm[i]["theta_deg"]) - deg))
            sky.append((float(rt["ssa"]) * float(pt[j]["phase_sr"])) / (float(rm["ssa"]) * float(pm[j]["phase_sr"])) - 1.0)
        print("%5d  %+7.3f  %+7.3f  %+7.3f  %6.3f  %6.3f  %+7.3f  %+7.3f  %+7.3f  %+7.3f" %
              (wl, 100 * csca_v, 100 * dssa, 100 * dg, 100 * dmax, 100 * l1, *(100 * v for v in sky)))
    if a.sky:
        # sky-render finds a type's table as <mie-dir>/<name>.exr; the atmospheres name the YAMLs.
        for name in ("gt7_case_study", "gt7_table"):
            src = os.path.join(ROOT, "particles", "gt7_case_study.yaml") if name == "gt7_case_study" else None
            if src:
                with open(src) as f, open(os.path.join(tmp, name + ".yaml"), "w") as g:
                    g.write(f.read().replace("../atmospheres/data/", os.path.join(ROOT, "atmospheres", "data") + "/"))
        rows = Sky(a.bin, tmp, tmp, ["gt7_case_study", "gt7_table"])
        print("sky of clear.yaml with optical depth 0.3: table against modes, per cent (orders)")
        print("view                      450nm    550nm    650nm")
        for i, r in enumerate(rows["gt7_case_study"]):
            t = rows["gt7_table"][i]
            label = "zenith" if float(r["view_zenith_deg"]) == 0 else "almucantar az %s" % r["relative_azimuth_deg"]
            print("%-24s" % label + "".join("  %+7.3f" % (100 * (float(t["radiance_%dnm_W_m2_sr_nm" % wl]) /
                                                                  float(r["radiance_%dnm_W_m2_sr_nm" % wl]) - 1.0))
                                             for wl in (450, 550, 650)))


if __name__ == "__main__":
    main()
