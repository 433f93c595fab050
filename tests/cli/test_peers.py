"""The peers' atmospheres and the parametric constituents through the real tools: every shipped
peer and AFGL 1986 atmosphere renders, Bruneton 2017's vertical transmittance is its closed form,
and bad parametric input is refused with file:line before any output is written."""
import csv
import math
import os
import unittest

from skytest import SRC, TempDirTestCase, run, tool

DATA = os.path.join(SRC, "atmospheres", "data")
GEOMETRY = "# source: test geometries\nsun_zenith_deg,view_zenith_deg,relative_azimuth_deg\n0,0,0\n60,80,90\n"


def read_rows(path):
    with open(path) as f:
        return list(csv.DictReader(l for l in f if not l.startswith("#")))


class PeersCli(TempDirTestCase):
    def points(self, atmosphere, wavelengths, out="out.csv", method="single", extra=()):
        geom = self.write("g.csv", GEOMETRY)
        return run([tool("sky-render"), "--quiet", "points", atmosphere, "--method", method, "--quality", "low",
                    "--wavelengths", wavelengths, "--geometry", geom, "-o", self.path(out)] + list(extra))

    def test_every_shipped_peer_and_climate_renders(self):
        files = [("peers", "bruneton2017", "360:830:10"), ("peers", "hillaire2020", "rgb"),
                 ("peers", "unreal_default", "rgb")]
        files += [("afgl1986", n, "360:830:10") for n in ("tropical", "midlatitude_summer", "midlatitude_winter",
                                                           "subarctic_summer", "subarctic_winter", "us_standard")]
        for folder, name, wl in files:
            r = self.points(os.path.join(SRC, "atmospheres", folder, name + ".yaml"), wl, out=name + ".csv")
            self.assertEqual(r.returncode, 0, name + ": " + r.stderr)
            for row in read_rows(self.path(name + ".csv")):
                y = float(row["Y_cd_m2"])
                self.assertTrue(math.isfinite(y) and y > 0, (name, row))

    def test_bruneton2017_vertical_transmittance_is_the_closed_form(self):
        # demo.cc: Rayleigh 1.24062e-6 (lambda/um)^-4 m^-1 x 8 km, Mie 4.44e-6 m^-1 x 1.2 km, ozone
        # tent 10-40 km with peak density 300 DU x 2.687e20 m^-2 / 15 km and the 233 K cross-section;
        # top 60 km: tau = beta H (1 - exp(-60/H)) + sigma n_peak 15 km.
        r = self.points(os.path.join(SRC, "atmospheres", "peers", "bruneton2017.yaml"), "360:830:10",
                        extra=["--wavelengths-out", "440,550,680"])
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(DATA, "bruneton_demo_10nm_solar_ozone.csv")) as f:
            sigma = {float(row["wavelength_nm"]): float(row["ozone_cross_section_233K_m2"])
                     for row in csv.DictReader(l for l in f if not l.startswith("#"))}
        row = read_rows(self.path("out.csv"))[0]
        for nm in (440, 550, 680):
            tau = (1.24062e-6 * (nm / 1000.0) ** -4 * 8e3 * (1 - math.exp(-60 / 8.0)) +
                   4.44e-6 * 1.2e3 * (1 - math.exp(-60 / 1.2)) + sigma[nm] * 300 * 2.687e20 / 15e3 * 15e3)
            t = float(row["sun_transmittance_%dnm" % nm])
            self.assertAlmostEqual(t, math.exp(-tau), delta=2e-5 * math.exp(-tau), msg=nm)

    def test_orders_states_how_many_orders_it_summed(self):
        r = self.points(os.path.join(SRC, "atmospheres", "peers", "bruneton2017.yaml"), "360:830:10", method="orders")
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(self.path("out.csv")) as f:
            settings = dict(l[2:].split(": ", 1) for l in f.read().splitlines()[1:] if l.startswith("# "))
        self.assertEqual(settings["method"], "orders")
        # Bruneton's demo sums 4 orders; a sky of optical depth ~0.3 at 440 nm needs more to converge.
        self.assertGreaterEqual(int(settings["orders_computed"]), 4)

    def bad(self, old, new, wavelengths="360:830:10"):
        with open(os.path.join(SRC, "atmospheres", "peers", "bruneton2017.yaml")) as f:
            text = f.read().replace("file: ../data/", "file: %s/" % DATA)
        self.assertIn(old, text)
        path = self.write("bad.yaml", text.replace(old, new, 1))
        line = text[:text.index(old)].count("\n") + 1
        r = self.points(path, wavelengths)
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertFalse(os.path.exists(self.path("out.csv")))
        return r.stderr, path, line

    def test_bad_parametric_input_is_located(self):
        particle = "    particle: %s\n" % os.path.join(SRC, "particles", "continental.yaml")
        err, path, line = self.bad("  - name: mie\n", "  - name: mie\n" + particle)
        self.assertEqual(err, "sky-render: %s:%d: key 'aerosols[0].particle': give either 'particle' (a measured type) or "
                              "'extinction', 'single_scattering_albedo' and 'phase' (parametric optics), not both\n"
                         % (path, line + 1))
        err, path, line = self.bad("per_m: 4.44e-6", "per_m: -4.44e-6")
        self.assertEqual(err, "sky-render: %s:%d: key 'aerosols[0].extinction.per_m': expected a number from 0 to 10 in "
                              "m^-1, got \"-4.44e-6\"\n" % (path, line))
        err, path, line = self.bad("g: 0.8", "g: 1.0")
        self.assertEqual(err, "sky-render: %s:%d: key 'aerosols[0].phase.cornette_shanks.g': expected an asymmetry "
                              "parameter strictly between -1 and 1, got \"1.0\"\n" % (path, line))
        err, path, line = self.bad("single_scattering_albedo: 0.9", "single_scattering_albedo: 1.5")
        self.assertEqual(err, "sky-render: %s:%d: key 'aerosols[0].single_scattering_albedo': expected a number from 0 "
                              "to 1, got \"1.5\"\n" % (path, line))
        err, path, line = self.bad("per_m: 1.24062e-6", "per_m: .nan")
        self.assertIn("%s:%d: key 'air.scattering.per_m': expected a number from 0 to 10 in m^-1" % (path, line), err)
        err, path, line = self.bad("depolarization: 0.0", "co2_ppm: 400")
        self.assertIn("%s:%d: key 'air.co2_ppm': co2_ppm sets the measured (Bodhaine 1999) cross-section" % (path, line), err)
        # An RGB form is three numbers, not a spectrum: refused on a spectral grid where it is written.
        err, path, line = self.bad("per_m: 4.44e-6 ", "rgb_per_m: [4.44e-6, 4.44e-6, 4.44e-6] ")
        self.assertTrue(err.startswith("sky-render: %s:%d: an RGB form (three values at 680, 550, 440 nm) needs "
                                       "--wavelengths rgb" % (path, line)), err)


if __name__ == "__main__":
    unittest.main()
