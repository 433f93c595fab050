"""CLI contract and behaviour of mie-tables (runs the real binary), and its pipeline edges."""
import csv
import io
import json
import math
import os
import shutil
import unittest

from skytest import SRC, CliContract, TempDirTestCase, exr_attributes, run, tool

GT7 = os.path.join(SRC, "particles", "gt7_case_study.yaml")
CONTINENTAL = os.path.join(SRC, "particles", "continental.yaml")
# A short grid keeps the tests fast; the full 360-830 nm grid is the benchmark's job.
GRID = ["--wavelength-min-nm", "450", "--wavelength-max-nm", "650", "--wavelength-step-nm", "100"]

GOOD_TYPE = """refractive_index: {table: %s}
modes:
  - name: fine
    basis: volume
    median_radius_um: 0.12
    ln_sigma_g: 0.45
    r_min_um: 0.05
    r_max_um: 15
    weight: {relative_volume: 1.0}
""" % os.path.join(SRC, "atmospheres", "data", "water_refractive_index_segelstein_1981.csv")


class MieTablesCli(CliContract, TempDirTestCase):
    TOOL = "mie-tables"

    # ---- sphere

    def test_sphere_json_reproduces_miev0_case_10(self):
        # Wiscombe's MIEV0 test case 10 (MVTstNew.f): m = 1.33 - 1e-5 i (MIEV0 sign), x = 100.
        r = run([tool("mie-tables"), "sphere", "--m", "1.33+1e-5i", "--x", "100", "--angles-deg", "0,90,180"])
        self.assertEqual(r.returncode, 0, r.stderr)
        j = json.loads(r.stdout)
        self.assertEqual(j["terms"], 120)
        self.assertAlmostEqual(j["qext"] / 2.101321, 1.0, delta=1e-6)
        self.assertAlmostEqual(j["qsca"] / 2.096594, 1.0, delta=1e-6)
        self.assertAlmostEqual(j["g"] * j["qsca"] / 1.821854, 1.0, delta=1e-6)
        self.assertEqual([a["theta_deg"] for a in j["angles"]], [0, 90, 180])
        s1_90 = j["angles"][1]["s1"]
        self.assertAlmostEqual(s1_90[0] / -3.655758, 1.0, delta=1e-6)
        self.assertAlmostEqual(s1_90[1] / -8.769860, 1.0, delta=1e-6)  # conjugate of MIEV0's +8.769860
        self.assertAlmostEqual(j["qext"], j["qsca"] + j["qabs"], places=14)

    def test_sphere_rejects_a_negative_imaginary_part(self):
        r = run([tool("mie-tables"), "sphere", "--m", "1.33-1e-5i", "--x", "1"])
        self.assertEqual(r.returncode, 2)
        self.assertEqual(r.stderr.splitlines()[0],
                         "mie-tables: --m '1.33-1e-5i': the imaginary part must be >= 0: skybake writes m = n + ik "
                         "with k >= 0 for absorbing media (MIEV0 and some tables write n - ik)")

    def test_sphere_bad_parameters_are_usage_errors(self):
        for args in (["--m", "abc", "--x", "1"], ["--m", "1.5", "--x", "0"], ["--m", "1.5", "--x", "1", "--angles-deg", "200"]):
            r = run([tool("mie-tables"), "sphere"] + args)
            self.assertEqual(r.returncode, 2, args)
            self.assertTrue(r.stderr.startswith("mie-tables: "), r.stderr)

    # ---- build

    def build(self, particle, out, *extra, threads=None):
        args = [tool("mie-tables")] + (["--threads", str(threads)] if threads else []) + \
            ["build", particle, "-o", out, "--quiet"] + GRID + list(extra)
        r = run(args)
        self.assertEqual(r.returncode, 0, r.stderr)
        return r

    def test_real_run_is_read_back_by_other_programs(self):
        out = self.path("gt7.exr")
        self.build(GT7, out, "--depfile", out + ".d")
        # An independent EXR reader sees both parts with the documented channels.
        info = run(["oiiotool", "--info", "-v", "-a", out])
        self.assertEqual(info.returncode, 0, info.stderr)
        self.assertIn("cext_m2", info.stdout)
        self.assertIn("phase_sr", info.stdout)
        self.assertIn("2161 x    3", info.stdout)
        attrs = exr_attributes(out)
        self.assertEqual(attrs["skybake.tool"], "mie-tables")
        self.assertEqual(attrs["skybake.mie.particle"], "gt7_case_study")
        self.assertIn("water_refractive_index_segelstein_1981.csv xxh3:", attrs["skybake.inputs"])
        self.assertIn("ln_sigma_g: 0.45", attrs["skybake.parameters"])
        with open(out + ".d") as f:
            dep = f.read()
        self.assertIn("gt7_case_study.yaml", dep)
        self.assertIn("water_refractive_index_segelstein_1981.csv", dep)
        # The report (JSON) and the dump (CSV, read back through the table reader) agree.
        with open(self.path("gt7.report.json")) as f:
            report = json.load(f)
        self.assertEqual(report["wavelengths_nm"], {"count": 3, "min": 450, "max": 650})
        self.assertEqual(report["angles"], 2161)
        self.assertEqual([m["name"] for m in report["modes"]],
                         ["fine", "accumulation_1", "accumulation_2", "accumulation_3", "coarse"])
        self.assertAlmostEqual(sum(m["number_fraction"] for m in report["modes"]), 1.0, places=12)
        dump = run([tool("mie-tables"), "dump", out, "--what", "spectral"])
        self.assertEqual(dump.returncode, 0, dump.stderr)
        lines = dump.stdout.splitlines()
        self.assertTrue(lines[0].startswith("# source: mie-tables dump of gt7.exr"))
        rows = list(csv.DictReader(io.StringIO("\n".join(lines[1:]))))
        self.assertEqual([float(r["wavelength_nm"]) for r in rows], [450, 550, 650])
        for row, w in zip(rows, report["per_wavelength"]):
            self.assertAlmostEqual(float(row["cext_m2"]) / w["cext_m2"], 1.0, delta=1e-7)  # float32 in the EXR
            self.assertLess(abs(w["phase_norm_error"]), 1e-4)
            self.assertLess(w["last_change"], 1e-4)
            self.assertGreater(w["radii"], 0)
            # Fine-mode aerosol is blue: extinction falls with wavelength (the talk's point).
        self.assertGreater(float(rows[0]["cext_m2"]), float(rows[2]["cext_m2"]))
        phase = run([tool("mie-tables"), "dump", out, "--what", "phase", "--wavelength-nm", "550"])
        self.assertEqual(phase.returncode, 0, phase.stderr)
        prow = list(csv.DictReader(io.StringIO("\n".join(phase.stdout.splitlines()[1:]))))
        self.assertEqual(len(prow), 2161)
        self.assertEqual(float(prow[0]["cdf"]), 0.0)
        self.assertEqual(float(prow[-1]["cdf"]), 1.0)
        # int P dOmega = 1 on the table's grid (trapezoid in mu; the interpolant's exact rule is
        # log-linear, the trapezoid agrees to the grid's resolution).
        total = sum(2 * math.pi * (float(a["mu"]) - float(b["mu"])) * 0.5 * (float(a["phase_sr"]) + float(b["phase_sr"]))
                    for a, b in zip(prow, prow[1:]))
        self.assertAlmostEqual(total, 1.0, delta=2e-3)

    def test_same_bytes_at_any_thread_count(self):
        a, b = self.path("a.exr"), self.path("b.exr")
        self.build(CONTINENTAL, a, threads=1)
        self.build(CONTINENTAL, b, threads=2)
        for x, y in ((a, b), (self.path("a.report.json"), self.path("b.report.json"))):
            with open(x, "rb") as fa, open(y, "rb") as fb:
                self.assertEqual(fa.read(), fb.read(), x)

    def test_unchanged_output_keeps_its_mtime(self):
        out = self.path("g.exr")
        self.build(GT7, out, "--mode", "fine")
        os.utime(out, (1000000000, 1000000000))
        self.build(GT7, out, "--mode", "fine")
        self.assertEqual(os.stat(out).st_mtime, 1000000000)

    def bad(self, text, grid=GRID):
        p = self.write("bad.yaml", text)
        out = self.path("never.exr")
        r = run([tool("mie-tables"), "build", p, "-o", out] + grid)
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertFalse(os.path.exists(out))
        self.assertFalse(os.path.exists(self.path("never.report.json")))
        return p, r.stderr

    def test_bad_particle_file_is_reported_with_file_and_line(self):
        p, err = self.bad(GOOD_TYPE.replace("r_min_um: 0.05", "r_min_um: -1"))
        self.assertEqual(err, "mie-tables: %s:7: key 'modes[0].r_min_um': expected a number from 1e-04 to 100 in um, got \"-1\"\n" % p)
        p, err = self.bad(GOOD_TYPE.replace("ln_sigma_g: 0.45", "sigma_g: 0.45"))
        self.assertEqual(err, "mie-tables: %s:6: key 'modes[0].sigma_g': expected a number from 1.0001 to 5, got \"0.45\"\n" % p)
        p, err = self.bad(GOOD_TYPE.replace("r_max_um: 15", "r_max_um: 0.01"))
        self.assertEqual(err, "mie-tables: %s:8: key 'modes[0].r_max_um': must be greater than r_min_um (0.01 <= 0.05)\n" % p)
        p, err = self.bad(GOOD_TYPE.replace("median_radius_um: 0.12", "median_radius_um: .nan"))
        self.assertEqual(err, "mie-tables: %s:5: key 'modes[0].median_radius_um': expected a number from 1e-04 to 100 in um, got \".nan\"\n" % p)
        p, err = self.bad(GOOD_TYPE.replace("    basis: volume\n", "    basis: volume\n    mean_radius_um: 1\n"))
        self.assertEqual(err, "mie-tables: %s:5: unknown key 'modes[0].mean_radius_um' (did you mean 'median_radius_um'?)\n" % p)

    def test_bad_size_table_is_reported_with_file_and_line(self):
        table = self.write("fine.csv", "# source: test\nradius_um,dV_dlnr_um3_um2\n0.05,0.1\n0.3,-999\n15,0.01\n")
        p, err = self.bad("refractive_index: {n: 1.33}\nmodes:\n  - name: fine\n    size_table: fine.csv\n"
                          "    weight: {relative_volume: 1.0}\n")
        self.assertEqual(err, "mie-tables: %s:4: column 'dV_dlnr_um3_um2': a density must be a finite number >= 0, "
                              "got -999 (AERONET's fill value: a missing retrieval)\n" % table)
        self.write("fine.csv", "# source: test\nradius_um,density\n0.05,0.1\n15,0.01\n")
        p, err = self.bad("refractive_index: {n: 1.33}\nmodes:\n  - name: fine\n    size_table: fine.csv\n"
                          "    weight: {relative_volume: 1.0}\n")
        self.assertTrue(err.startswith("mie-tables: %s:2: expected exactly one density column" % table), err)
        p, err = self.bad("refractive_index: {n: 1.33}\nmodes:\n  - name: fine\n    size_table: fine.csv\n"
                          "    r_min_um: 0.1\n    weight: {relative_volume: 1.0}\n")
        self.assertEqual(err, "mie-tables: %s:5: key 'modes[0].r_min_um': not used with size_table (the table gives "
                              "the distribution and its radii); remove r_min_um\n" % p)

    # ---- import-aeronet

    AERONET = os.path.join(SRC, "tests", "cli", "data", "aeronet_v2_synthetic.csv")

    def import_aeronet(self, source, *extra, expect=0):
        out = self.path("site.yaml")
        r = run([tool("mie-tables"), "import-aeronet", source, "-o", out] + list(extra))
        self.assertEqual(r.returncode, expect, r.stderr)
        if expect != 0:
            self.assertEqual([n for n in os.listdir(self.tmp) if n.startswith("site")], [])
        return r

    def test_import_aeronet_writes_a_type_that_builds_and_its_layer_scale(self):
        self.import_aeronet(self.AERONET, "--row", "1")
        with open(self.path("site_size_distribution.csv")) as f:
            rows = list(csv.reader(line for line in f if not line.startswith("#")))
        self.assertEqual(rows[0], ["radius_um", "dV_dlnr_um3_um2"])
        self.assertEqual(len(rows), 23)
        self.assertEqual(rows[1][0], "0.05")
        self.assertEqual(rows[22][0], "15")
        with open(self.path("site.layer.yaml")) as f:
            layer = f.read()
        aod550 = float(layer.split("optical_depth_550nm: ")[1].rstrip("}\n"))
        self.assertAlmostEqual(aod550, 0.42 * (550.0 / 441.0) ** -1.85, delta=1e-6)
        with open(self.path("site.yaml")) as f:
            text = f.read()
        self.assertIn("points: {wavelength_nm: [441, 675, 871, 1020], n: [1.43, 1.44, 1.45, 1.46], "
                      "k: [0.008, 0.0065, 0.006, 0.0058]}", text)
        self.assertIn("Synthetic_Site, 01:07:2005 13:00:05 UTC (aeronet_v2_synthetic.csv line 5)", text)
        out = self.path("site.exr")
        r = run([tool("mie-tables"), "build", self.path("site.yaml"), "-o", out] + GRID)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(self.path("site.report.json")) as f:
            report = json.load(f)
        self.assertEqual(report["modes"][0]["size_table_rows"], 22)
        # Same input, same bytes.
        with open(self.path("site.yaml"), "rb") as f:
            before = f.read()
        self.import_aeronet(self.AERONET, "--row", "1")
        with open(self.path("site.yaml"), "rb") as f:
            self.assertEqual(f.read(), before)

    def test_import_aeronet_bad_input_is_located_and_writes_nothing(self):
        with open(self.AERONET) as f:
            lines = f.read().splitlines()
        header = lines[3].split(",")
        # Several retrievals and no --row: a usage error.
        r = self.import_aeronet(self.AERONET, expect=2)
        self.assertIn("--row: %s holds 2 retrievals (lines 5-6); choose one with --row 1..2" % self.AERONET, r.stderr)
        # A non-spherical retrieval.
        r = self.import_aeronet(self.AERONET, "--row", "2", expect=1)
        self.assertEqual(r.stderr, "mie-tables: %s:6: column '%%sphericity': 76.2 %% of the particles are spherical, "
                                   "below 95 %%: the retrieval models the rest as spheroids, which Mie spheres do not "
                                   "represent\n" % self.AERONET)
        # A fill value in a size bin and in REFI(675).
        cells = lines[4].split(",")
        cells[header.index("0.148184")] = "-999."
        cells[header.index("REFI(675)")] = "-999."
        bad = self.write("fill.csv", "\n".join(lines[:4] + [",".join(cells)]) + "\n")
        r = self.import_aeronet(bad, expect=1)
        self.assertEqual(r.stderr, "mie-tables: %s:5: column '0.148184': -999, AERONET's fill value: this retrieval has no "
                                   "such value\nmie-tables: %s:5: column 'REFI(675)': -999, AERONET's fill value: this "
                                   "retrieval has no such value\n" % (bad, bad))
        # A missing column and a missing size bin.
        names = [n for n in header if n not in ("%sphericity", "15.000000")]
        keep = [header.index(n) for n in names]
        row = [lines[4].split(",")[i] for i in keep]
        bad = self.write("cols.csv", "\n".join(lines[:3] + [",".join(names), ",".join(row)]) + "\n")
        r = self.import_aeronet(bad, expect=1)
        self.assertEqual(r.stderr, "mie-tables: %s:4: expected the 22 size-distribution columns 0.050000 ... 15.000000 "
                                   "(radius in um), found 21\nmie-tables: %s:4: missing column %%sphericity\n" % (bad, bad))
        # Not an inversion file.
        bad = self.write("other.csv", "a,b\nLevel 2.0 AOD\nx\ny\n1,2\n")
        r = self.import_aeronet(bad, expect=1)
        self.assertEqual(r.stderr, "mie-tables: %s:1: expected the site line 'dd:mm:yyyy,Locations=<site>,...'\n" % bad)
        # A bad output name is a usage error.
        r = run([tool("mie-tables"), "import-aeronet", self.AERONET, "--row", "1", "-o", self.path("Bad-Name.yaml")])
        self.assertEqual(r.returncode, 2)

    def test_wavelength_outside_the_index_table(self):
        p, err = self.bad(GOOD_TYPE, ["--wavelength-min-nm", "250", "--wavelength-max-nm", "850", "--wavelength-step-nm", "100"])
        water = os.path.join(SRC, "atmospheres", "data", "water_refractive_index_segelstein_1981.csv")
        self.assertEqual(err, "mie-tables: %s:1: mode 'fine': the refractive index covers wavelengths "
                              "295.12092-1199.4993 nm of %s, the wavelength grid needs 250-850 nm\n" % (p, os.path.normpath(water)))

    def test_missing_file_and_bad_grid(self):
        r = run([tool("mie-tables"), "build", self.path("nope.yaml"), "-o", self.path("x.exr")])
        self.assertEqual(r.returncode, 1)
        self.assertEqual(r.stderr, "mie-tables: %s: cannot open file\n" % self.path("nope.yaml"))
        r = run([tool("mie-tables"), "build", GT7, "-o", self.path("x.exr"), "--wavelength-step-nm", "7"])
        self.assertEqual(r.returncode, 2)
        self.assertIn("whole number of --wavelength-step-nm", r.stderr)

    def test_dump_of_a_non_table_and_an_untabulated_wavelength(self):
        bad = self.write("x.exr", "not an exr")
        r = run([tool("mie-tables"), "dump", bad])
        self.assertEqual(r.returncode, 1)
        self.assertTrue(r.stderr.startswith("mie-tables: %s: " % bad), r.stderr)
        out = self.path("g.exr")
        self.build(GT7, out, "--mode", "fine")
        r = run([tool("mie-tables"), "dump", out, "--what", "phase", "--wavelength-nm", "500"])
        self.assertEqual(r.returncode, 2)
        self.assertIn("--wavelength-nm 500: not a tabulated wavelength", r.stderr)


class MieTablesPipeline(TempDirTestCase):
    """The generator's mie edges: one per particle type, shared between atmospheres, and not
    re-run by edits elsewhere in an atmosphere."""

    def setUp(self):
        super().setUp()
        for d in ("atmospheres", "particles"):
            shutil.copytree(os.path.join(SRC, d), self.path(d))
        # A second atmosphere using the same particle type.
        with open(self.path("atmospheres", "clear.yaml")) as f:
            clear = f.read()
        self.write("atmospheres/other.yaml", clear.replace("name: clear", "name: other"))
        self.write("pipeline.yaml", "atmospheres: [atmospheres/clear.yaml, atmospheres/other.yaml]\n"
                                    "wavelengths: {min_nm: 500, max_nm: 600, step_nm: 50}\n")

    def generate(self, expect=0):
        r = run([tool("skybake"), "generate", "--quiet", "pipeline.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, expect, r.stderr)
        return r

    def test_one_edge_per_type_and_edits_elsewhere_do_not_rerun_it(self):
        self.generate()
        with open(self.path("outputs", "build.ninja")) as f:
            ninja = f.read()
        self.assertEqual(ninja.count("build mie/continental.exr"), 1)
        self.assertIn("args = build --wavelength-min-nm 500 --wavelength-max-nm 600 --wavelength-step-nm 50", ninja)
        r = run(["ninja", "-C", self.path("outputs"), "mie/continental.exr"])
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertTrue(os.path.exists(self.path("outputs", "mie", "continental.report.json")))
        # An edit to an atmosphere's aerosol profile and a comment in the particle file: the
        # canonical component keeps its bytes, so the table is up to date.
        with open(self.path("atmospheres", "other.yaml")) as f:
            text = f.read()
        self.write("atmospheres/other.yaml", text.replace("optical_depth_550nm: 0.1", "optical_depth_550nm: 0.3"))
        with open(self.path("particles", "continental.yaml"), "a") as f:
            f.write("# a comment\n")
        r = run(["ninja", "-C", self.path("outputs"), "mie/continental.exr"])
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertNotIn("mie-tables", r.stdout)
        # A change to the type re-runs it.
        with open(self.path("particles", "continental.yaml")) as f:
            text = f.read()
        self.write("particles/continental.yaml", text.replace("number_density_cm3: 0.4", "number_density_cm3: 0.5"))
        r = run(["ninja", "-C", self.path("outputs"), "mie/continental.exr"])
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertIn("mie-tables mie/continental.exr", r.stdout)

    def test_two_particle_files_with_one_name_are_an_error(self):
        os.makedirs(self.path("particles2"))
        shutil.copy(self.path("particles", "continental.yaml"), self.path("particles2", "continental.yaml"))
        with open(self.path("atmospheres", "other.yaml")) as f:
            text = f.read()
        self.write("atmospheres/other.yaml", text.replace("../particles/continental.yaml", "../particles2/continental.yaml"))
        with open(self.path("particles2", "continental.yaml")) as f:
            text = f.read()
        self.write("particles2/continental.yaml", text.replace("table: ../atmospheres", "table: ../atmospheres"))
        r = self.generate(expect=1)
        self.assertEqual(r.stderr, "skybake: %s: aerosol layer 'continental': particle types are named by their file, "
                                   "and %s and %s are both named 'continental' (rename one)\n"
                         % (self.path("atmospheres", "other.yaml"), self.path("particles", "continental.yaml"),
                            self.path("particles2", "continental.yaml")))

    def test_bad_particle_file_fails_generation_with_file_and_line(self):
        p = self.path("particles", "continental.yaml")
        with open(p) as f:
            text = f.read()
        self.write("particles/continental.yaml", text.replace("sigma_g: 2.51", "sigma_g: 0.9"))
        r = self.generate(expect=1)
        line = [i + 1 for i, l in enumerate(text.splitlines()) if "sigma_g: 2.51" in l][0]
        self.assertEqual(r.stderr, "skybake: %s:%d: key 'modes[1].sigma_g': expected a number from 1.0001 to 5, got \"0.9\"\n"
                         % (p, line))


if __name__ == "__main__":
    unittest.main()
