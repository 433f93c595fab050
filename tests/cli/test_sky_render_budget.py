"""CLI contract of `sky-render budget` (docs/sky-methods.md, "The model budget"): a real run whose
CSV another program reads, the same bytes at any thread count, located errors."""
import csv
import io
import os
import unittest

from skytest import SRC, TempDirTestCase, run, tool
from test_sky_render import rayleigh_atmosphere


class SkyRenderBudgetCli(TempDirTestCase):
    def budget(self, *extra, out="budget.csv"):
        atm = rayleigh_atmosphere(self.tmp)
        args = [tool("sky-render"), "budget", atm, "-o", self.path(out), "--wavelengths", "400:700:20",
                "--sun-zenith-deg", "40,80", "--quality", "low", "--quiet"] + list(extra)
        return run(args)

    def rows(self, path):
        with open(path) as f:
            text = f.read()
        self.assertTrue(text.startswith("# source: sky-render budget; evaluator: method: ms-approx"))
        return list(csv.DictReader(io.StringIO(text.split("\n", 1)[1])))

    def test_real_run_reports_every_item(self):
        r = self.budget("--tolerance", "2%", "--depfile", self.path("budget.csv.d"))
        self.assertEqual(r.returncode, 0, r.stderr)
        rows = {row["name"]: row for row in self.rows(self.path("budget.csv"))}
        # No aerosol layer: no phase items; a 20 nm grid has no coarser-grid items; the rest are all there.
        for name in ("rgb", "profiles-exponential", "no-ozone", "orders-1", "orders-2", "orders-3", "orders-4", "altitude",
                     "azimuth", "sun-zenith"):
            self.assertIn(name, rows)
        self.assertNotIn("phase-hg", rows)
        self.assertNotIn("wavelengths-20nm", rows)
        # Physics the numbers must show: single scattering alone is far off, the 4-order truncation
        # of the series is closer than 2 orders; the sky is not azimuthally symmetric in daylight.
        self.assertGreater(float(rows["orders-1"]["rms_rel"]), 0.1)
        self.assertLess(float(rows["orders-4"]["rms_rel"]), float(rows["orders-2"]["rms_rel"]))
        self.assertEqual(rows["azimuth"]["within_tolerance"], "no")
        self.assertEqual(rows["rgb"]["wavelengths"], "3")
        self.assertTrue(r.stdout.startswith("tolerance 2 % (rms); baseline: 16 wavelengths"), r.stdout)
        self.assertIn("orders-4", r.stdout)
        with open(self.path("budget.csv.d")) as f:
            self.assertIn("config.ocio", f.read())

    def test_same_bytes_at_any_thread_count(self):
        self.assertEqual(self.budget("--threads", "1", out="a.csv").returncode, 0)
        self.assertEqual(self.budget("--threads", "2", out="b.csv").returncode, 0)
        with open(self.path("a.csv"), "rb") as a, open(self.path("b.csv"), "rb") as b:
            self.assertEqual(a.read(), b.read())

    def test_bad_usage(self):
        r = self.budget("--tolerance", "one percent")
        self.assertEqual(r.returncode, 2)
        self.assertIn("sky-render: --tolerance: expected a positive number or percentage (e.g. 1% or 0.01), got 'one percent'",
                      r.stderr)
        r = self.budget("--method", "path")
        self.assertEqual(r.returncode, 2)
        self.assertIn("sky-render: --method: the budget needs a deterministic method (", r.stderr)
        r = self.budget("--altitude-range-m", "300:0")
        self.assertEqual(r.returncode, 2)
        self.assertIn("--altitude-range-m: expected lo:hi with 0 <= lo <= hi", r.stderr)
        self.assertFalse(os.path.exists(self.path("budget.csv")))

    def test_bad_atmosphere_is_located(self):
        bad = self.write("bad.yaml", "planet: {radius_km: 6371, top_km: 100}\nair: {profile: ussa1976}\n"
                                     "sun: {angular_diameter_deg: 0.5}\n")
        r = run([tool("sky-render"), "budget", bad, "-o", self.path("x.csv"), "--quiet"])
        self.assertEqual(r.returncode, 1)
        self.assertEqual(r.stderr, "sky-render: %s:3: missing key 'sun.spectrum': expected a mapping\n" % bad)
        self.assertFalse(os.path.exists(self.path("x.csv")))


if __name__ == "__main__":
    unittest.main()
