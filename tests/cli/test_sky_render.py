"""CLI contract and behaviour of sky-render (runs the real binary, small renders)."""
import os
import struct
import unittest

from skytest import SRC, CliContract, TempDirTestCase, run, tool

DATA = os.path.join(SRC, "atmospheres", "data")


def rayleigh_atmosphere(tmp):
    """The clear atmosphere without its aerosol layer (no Mie table needed), data by absolute path."""
    with open(os.path.join(SRC, "atmospheres", "clear.yaml")) as f:
        text = f.read()
    text = text[:text.index("aerosols:")] + text[text.index("ground:"):]
    text = text.replace("file: data/", "file: %s/" % DATA)
    p = os.path.join(tmp, "rayleigh.yaml")
    with open(p, "w") as f:
        f.write(text)
    return p


class SkyRenderCli(CliContract, TempDirTestCase):
    TOOL = "sky-render"

    def render(self, *extra, out="sky.exr", size="8x4", wavelengths="400:700:20"):
        atm = rayleigh_atmosphere(self.tmp)
        args = [tool("sky-render"), "render", atm, "-o", self.path(out), "--size", size, "--sun-zenith-deg", "40",
                "--target-error", "0.2", "--wavelengths", wavelengths, "--quiet"] + list(extra)
        return run(args)

    def test_real_run_is_read_back_by_a_second_program(self):
        r = self.render("--preview", self.path("sky.png"), "--depfile", self.path("sky.exr.d"))
        self.assertEqual(r.returncode, 0, r.stderr)
        info = run(["oiiotool", "--info", "-v", "-a", self.path("sky.exr")])
        self.assertEqual(info.returncode, 0, info.stderr)
        for part in ("sky.sza_040.00", "transmittance", "sun", "irradiance"):
            self.assertIn('name: "%s"' % part, info.stdout)
        stats = run(["oiiotool", "--stats", self.path("sky.exr")])
        self.assertEqual(stats.returncode, 0, stats.stderr)
        png = run(["oiiotool", "--info", self.path("sky.png")])
        self.assertIn("8 x    4", png.stdout)
        with open(self.path("sky.exr.d")) as f:
            dep = f.read()
        for needle in ("astm_g173_03_solar_spectrum.csv", "cie2006_2deg_xyz_cmf_1nm.csv", "config.ocio"):
            self.assertIn(needle, dep)

    def test_same_bytes_at_any_thread_count(self):
        self.assertEqual(self.render("--threads", "1", out="a.exr").returncode, 0)
        self.assertEqual(self.render("--threads", "2", out="b.exr").returncode, 0)
        with open(self.path("a.exr"), "rb") as a, open(self.path("b.exr"), "rb") as b:
            self.assertEqual(a.read(), b.read())

    def test_bad_usage(self):
        r = self.render(size="8by4")
        self.assertEqual(r.returncode, 2)
        self.assertIn("sky-render: --size: expected WxH with sides from 2 to 8192, e.g. 64x32, got '8by4'", r.stderr)
        r = self.render("--method", "magic")
        self.assertEqual(r.returncode, 2)
        self.assertIn("sky-render: --method: expected path, ", r.stderr)
        self.assertIn("got 'magic'", r.stderr)
        r = self.render(wavelengths="400:700")
        self.assertEqual(r.returncode, 2)
        self.assertIn("sky-render: --wavelengths: expected min:max:step in nm, got '400:700'", r.stderr)
        self.assertFalse(os.path.exists(self.path("sky.exr")))

    def test_bad_quality_is_a_usage_error(self):
        # --quality takes a preset name (transport/quality.h) in every subcommand, whatever the method.
        r = self.render("--quality", "best")
        self.assertEqual(r.returncode, 2)
        self.assertIn("sky-render: --quality: expected low, medium or high, got 'best'", r.stderr)
        atm = rayleigh_atmosphere(self.tmp)
        for sub, extra in (("points", ["--geometry", self.path("g.csv")]), ("budget", []), ("fog", [])):
            r = run([tool("sky-render"), sub, atm, "-o", self.path("x.out"), "--quality", "Medium", "--quiet"] + extra)
            self.assertEqual(r.returncode, 2, sub)
            self.assertIn("sky-render: --quality: expected low, medium or high, got 'Medium'", r.stderr)
        self.assertFalse(os.path.exists(self.path("sky.exr")))
        self.assertFalse(os.path.exists(self.path("x.out")))
        r = run([tool("sky-render"), "render", "--help"])
        self.assertEqual(r.returncode, 0)
        self.assertRegex(r.stdout, r"--quality TEXT=medium +Deterministic methods: low, medium or high")
        self.assertIn("Rendering method: path (the Monte-Carlo reference), single, orders, ms-approx, analytic", r.stdout)

    def test_bad_atmosphere_is_located(self):
        bad = self.write("bad.yaml", "planet: {radius_km: 6371, top_km: 100}\nair: {profile: ussa1976}\n"
                                     "sun: {angular_diameter_deg: 0.5}\n")
        r = run([tool("sky-render"), "render", bad, "-o", self.path("x.exr"), "--quiet"])
        self.assertEqual(r.returncode, 1)
        self.assertEqual(r.stderr, "sky-render: %s:3: missing key 'sun.spectrum': expected a mapping\n" % bad)
        self.assertFalse(os.path.exists(self.path("x.exr")))

    def test_aerosol_layer_without_mie_dir_is_a_usage_error(self):
        atm = rayleigh_atmosphere(self.tmp)
        with open(atm, "a") as f:
            f.write("aerosols:\n  - name: haze\n    particle: %s\n    profile: {exponential: {scale_height_km: 1.2}}\n"
                    "    scale: {optical_depth_550nm: 0.1}\n" % os.path.join(SRC, "particles", "continental.yaml"))
        r = run([tool("sky-render"), "render", atm, "-o", self.path("x.exr"), "--quiet"])
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("sky-render: aerosol layer 'haze' needs its Mie table: pass --mie-dir (the folder of continental.exr, "
                      "written by mie-tables)", r.stderr)

    def test_points_csv(self):
        atm = rayleigh_atmosphere(self.tmp)
        geom = self.write("g.csv", "# source: test geometries\nsun_zenith_deg,view_zenith_deg,relative_azimuth_deg\n"
                                   "30,0,0\n30,60,180\n")
        r = run([tool("sky-render"), "points", atm, "--geometry", geom, "-o", self.path("out.csv"),
                 "--wavelengths", "400:700:20", "--wavelengths-out", "440,560", "--paths", "2000", "--target-error", "0.2"])
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(self.path("out.csv")) as f:
            lines = [l for l in f.read().splitlines() if not l.startswith("#")]
        self.assertEqual(len(lines), 3)
        header = lines[0].split(",")
        self.assertIn("radiance_440nm_W_m2_sr_nm", header)
        row = dict(zip(header, lines[1].split(",")))
        # Zenith sky at 440 nm is bluer (brighter per nm) than at 560 nm (Rayleigh ~ lambda^-4).
        self.assertGreater(float(row["radiance_440nm_W_m2_sr_nm"]), float(row["radiance_560nm_W_m2_sr_nm"]))

    def test_points_bad_geometry_row(self):
        atm = rayleigh_atmosphere(self.tmp)
        geom = self.write("g.csv", "# source: test\nsun_zenith_deg,view_zenith_deg,relative_azimuth_deg\n30,0,0\n30,x,0\n")
        r = run([tool("sky-render"), "points", atm, "--geometry", geom, "-o", self.path("out.csv"), "--wavelengths", "400:700:20",
                 "--quiet"])
        self.assertEqual(r.returncode, 1)
        self.assertEqual(r.stderr, "sky-render: %s:4: column 'view_zenith_deg': expected a number, got \"x\"\n" % geom)

    def points(self, geom_text, *extra, out="out.csv"):
        atm = rayleigh_atmosphere(self.tmp)
        geom = self.write("g.csv", geom_text)
        return run([tool("sky-render"), "points", atm, "--geometry", geom, "-o", self.path(out), "--wavelengths",
                    "400:700:20", "--wavelengths-out", "440,560,680", "--quiet"] + list(extra)), geom

    def read_points(self, name="out.csv"):
        with open(self.path(name)) as f:
            lines = [l for l in f.read().splitlines() if not l.startswith("#")]
        header = lines[0].split(",")
        return [dict(zip(header, l.split(","))) for l in lines[1:]]

    GEOM = ("# source: test geometries\nsun_zenith_deg,view_zenith_deg,relative_azimuth_deg,observer_altitude_km\n"
            "30,0,0,0\n60,80,30,0\n60,80,30,2\n")

    def test_points_every_column_has_its_error_and_the_bytes_do_not_depend_on_threads(self):
        for threads, out in (("1", "a.csv"), ("2", "b.csv")):
            r, _ = self.points(self.GEOM, "--target-error", "0.05", "--threads", threads, out=out)
            self.assertEqual(r.returncode, 0, r.stderr)
        with open(self.path("a.csv"), "rb") as a, open(self.path("b.csv"), "rb") as b:
            self.assertEqual(a.read(), b.read())
        rows = self.read_points("a.csv")
        self.assertEqual([r["observer_altitude_m"] for r in rows], ["0", "0", "2000"])
        for row in rows:
            for w in ("440", "560", "680"):
                L, se = float(row["radiance_%snm_W_m2_sr_nm" % w]), float(row["stderr_%snm_W_m2_sr_nm" % w])
                self.assertLessEqual(se, 0.05 * L)  # the stopping rule covers the spectral columns
                self.assertLess(float(row["single_%snm_W_m2_sr_nm" % w]), L)
                self.assertTrue(0.0 < float(row["sun_transmittance_%snm" % w]) < 1.0)
            self.assertLessEqual(float(row["Y_stderr_cd_m2"]), 0.05 * float(row["Y_cd_m2"]))
        # A higher observer sees the sun through less air.
        self.assertGreater(float(rows[2]["sun_transmittance_440nm"]), float(rows[1]["sun_transmittance_440nm"]))

    def test_points_orders_agrees_with_path(self):
        r, _ = self.points(self.GEOM, "--method", "orders", "--quality", "low", out="o.csv")
        self.assertEqual(r.returncode, 0, r.stderr)
        r, _ = self.points(self.GEOM, "--target-error", "0.02", out="p.csv")
        self.assertEqual(r.returncode, 0, r.stderr)
        for o, p in zip(self.read_points("o.csv"), self.read_points("p.csv")):
            self.assertEqual(o["stderr_440nm_W_m2_sr_nm"], "0.000e+00")
            # docs/sky-methods.md: orders low within 3-4 % of the path tracer on the clear sky (+ 3 sigma).
            Y, Yp, se = float(o["Y_cd_m2"]), float(p["Y_cd_m2"]), float(p["Y_stderr_cd_m2"])
            self.assertLessEqual(abs(Y - Yp), 0.04 * Yp + 3 * se)
            self.assertEqual(o["sun_transmittance_560nm"], p["sun_transmittance_560nm"])

    def test_points_bad_altitude_and_method(self):
        r, geom = self.points(self.GEOM.replace("60,80,30,2", "60,80,30,200"))
        self.assertEqual(r.returncode, 1)
        self.assertEqual(r.stderr, "sky-render: %s:5: observer_altitude_km: the observer must be inside the atmosphere "
                                   "(0 to 100000 m), got 200000 m\n" % geom)
        self.assertFalse(os.path.exists(self.path("out.csv")))
        r, _ = self.points(self.GEOM, "--method", "magic")
        self.assertEqual(r.returncode, 2)
        self.assertIn("sky-render: --method: expected path, ", r.stderr)


if __name__ == "__main__":
    unittest.main()
