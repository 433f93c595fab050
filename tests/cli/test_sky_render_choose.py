"""CLI contract of `sky-render choose` and `render --settings` (docs/sky-methods.md, "Automatic
quality"): a real choice whose file another program (PyYAML) reads, the choice's rules (cost order,
exactly one chosen, the chosen within every tolerance, the full model as the fallback, the
cheapest candidate under a loose tolerance), the same bytes at any thread count, the choice in the
render's provenance, and located errors for bad options and bad settings files.

Scene: the clear atmosphere without aerosols on a 20 nm grid (16 wavelengths), `orders`; each
choice builds the method at most 9 times on it (~5 s on 2 cores)."""
import os
import unittest

import yaml

from skytest import TempDirTestCase, exr_attributes, run, tool
from test_sky_render import rayleigh_atmosphere


class SkyRenderChooseCli(TempDirTestCase):
    def choose(self, *extra, out="quality.yaml"):
        atm = rayleigh_atmosphere(self.tmp)
        args = [tool("sky-render"), "choose", atm, "-o", self.path(out), "--wavelengths", "400:700:20", "--quiet"] + list(extra)
        return run(args)

    def load(self, name="quality.yaml"):
        with open(self.path(name)) as f:
            return yaml.safe_load(f)

    def render(self, *extra, out="sky.exr"):
        atm = rayleigh_atmosphere(self.tmp)
        return run([tool("sky-render"), "render", atm, "-o", self.path(out), "--size", "8x4", "--sun-zenith-deg", "40",
                    "--wavelengths", "400:700:20", "--quiet"] + list(extra))

    def test_real_choice_follows_its_rules(self):
        r = self.choose("--depfile", self.path("quality.yaml.d"))
        self.assertEqual(r.returncode, 0, r.stderr)
        q = self.load()
        self.assertEqual(q["method"], "orders")
        self.assertEqual(q["full_model"], {"quality": "high", "spectral_stride": 1, "wavelengths": 16})
        self.assertEqual(q["tolerance"], {"daylight_rms": 0.005, "daylight_max": 0.02, "twilight_rms": 0.03})
        cands = q["candidates"]
        costs = [c["cost"] for c in cands]
        self.assertEqual(costs, sorted(costs))
        chosen = [c for c in cands if c["status"] == "chosen"]
        self.assertEqual(len(chosen), 1, cands)
        c = chosen[0]
        self.assertEqual((c["quality"], c["spectral_stride"]), (q["quality"], q["spectral_stride"]))
        self.assertEqual(q["chosen"]["quality"], q["quality"])
        self.assertLessEqual(c["daylight_rms"], 0.005)
        self.assertLessEqual(c["daylight_max"], 0.02)
        self.assertLessEqual(c["twilight_rms"], 0.03)
        # Every cheaper candidate was tried and failed, or was coarser than a failed one in both.
        index = cands.index(c)
        for k in cands[:index]:
            self.assertIn(k["status"], ("rejected", "dominated"), k)
            if k["status"] == "rejected":
                self.assertTrue(k["daylight_rms"] > 0.005 or k["daylight_max"] > 0.02 or k["twilight_rms"] > 0.03, k)
        for k in cands[index + 1:]:
            self.assertEqual(k["status"], "not-tried", k)
        # Strides keep both ends of the grid: 16 wavelengths, every 2nd = 9, every 4th = 5.
        self.assertEqual({k["spectral_stride"]: k["wavelengths"] for k in cands}, {1: 16, 2: 9, 4: 5})
        self.assertIn("chosen", r.stdout)
        with open(self.path("quality.yaml.d")) as f:
            self.assertIn("config.ocio", f.read())

    def test_a_tight_tolerance_takes_the_full_model(self):
        r = self.choose("--tolerance", "1e-9", out="tight.yaml")
        self.assertEqual(r.returncode, 0, r.stderr)
        q = self.load("tight.yaml")
        self.assertEqual((q["quality"], q["spectral_stride"]), ("high", 1))
        self.assertEqual(q["candidates"][-1], {"quality": "high", "spectral_stride": 1, "wavelengths": 16, "cost": 1,
                                               "status": "chosen", "daylight_rms": 0, "daylight_max": 0, "twilight_rms": 0})

    def test_same_bytes_at_any_thread_count(self):
        loose = ["--tolerance", "3%", "--max-tolerance", "90%", "--twilight-tolerance", "90%"]  # the full model and a few candidates
        self.assertEqual(self.choose("--threads", "1", *loose, out="a.yaml").returncode, 0)
        self.assertEqual(self.choose("--threads", "2", *loose, out="b.yaml").returncode, 0)
        with open(self.path("a.yaml"), "rb") as a, open(self.path("b.yaml"), "rb") as b:
            self.assertEqual(a.read(), b.read())

    def test_render_with_the_settings_records_the_choice(self):
        # A loose choice (the cheapest candidate), rendered with --settings.
        r = self.choose("--tolerance", "50%", "--max-tolerance", "90%", "--twilight-tolerance", "90%")
        self.assertEqual(r.returncode, 0, r.stderr)
        q = self.load()
        self.assertEqual((q["quality"], q["spectral_stride"]), ("low", 4))
        self.assertEqual(q["candidates"][0]["status"], "chosen")
        r = self.render("--settings", self.path("quality.yaml"), "--depfile", self.path("sky.exr.d"))
        self.assertEqual(r.returncode, 0, r.stderr)
        params = exr_attributes(self.path("sky.exr"))["skybake.parameters"]
        self.assertIn("method: orders\n", params)
        self.assertIn("spectral_stride: 4", params)
        line = [l for l in params.split("\n") if l.startswith("quality_choice: ")]
        self.assertEqual(len(line), 1, params)
        choice = yaml.safe_load(line[0][len("quality_choice: "):])
        self.assertEqual((choice["file"], choice["quality"], choice["spectral_stride"]), ("quality.yaml", "low", 4))
        self.assertEqual(choice["tolerance"]["daylight_rms"], 0.5)
        with open(self.path("sky.exr.d")) as f:
            self.assertIn("quality.yaml", f.read())
        # The same pixels as the preset given by hand (only the provenance differs).
        r = self.render("--method", "orders", "--quality", "low", "--spectral-stride", "4", out="hand.exr")
        self.assertEqual(r.returncode, 0, r.stderr)
        diff = run(["oiiotool", self.path("sky.exr"), self.path("hand.exr"), "--diff"])
        self.assertIn("PASS", diff.stdout, diff.stdout)

    def test_bad_usage(self):
        r = self.choose("--max-tolerance", "lots")
        self.assertEqual(r.returncode, 2)
        self.assertIn("sky-render: --max-tolerance: expected a positive number or percentage", r.stderr)
        r = self.choose("--method", "path")
        self.assertEqual(r.returncode, 2)
        self.assertIn("sky-render: --method: automatic quality needs a deterministic method (", r.stderr)
        self.assertFalse(os.path.exists(self.path("quality.yaml")))
        good = self.write("good.yaml", GOOD)
        r = self.render("--settings", good, "--quality", "high")
        self.assertEqual(r.returncode, 2)
        self.assertIn("sky-render: --quality: not with --settings (the file says it)", r.stderr)
        r = self.render("--settings", good, "--method", "single")
        self.assertEqual(r.returncode, 2)
        self.assertIn("--method single: %s is a choice for method orders" % good, r.stderr)
        self.assertFalse(os.path.exists(self.path("sky.exr")))

    def test_bad_settings_files_are_located(self):
        cases = [
            ("quality: medium", "quality: best", ":2: key 'quality': expected one of"),
            ("spectral_stride: 2", "spectral_stride: 0", ":3: key 'spectral_stride'"),
            ("method: orders", "method: path", ":1: key 'method': 'path' is not a deterministic sky method"),
            ("{quality: medium, spectral_stride: 2,", "{quality: medium, spectral_stride: 4,",
             ":5: key 'chosen': the chosen candidate (medium stride 4) is not the file's quality and spectral_stride (medium stride 2)"),
            ("daylight_max: 0.0061", "daylight_max: nan", ":5: key 'chosen.daylight_max'"),
            ("twilight_rms: 0.03}", "twilight_rms: 0.03, extra: 1}", ":4: unknown key 'tolerance.extra'"),
        ]
        for old, new, message in cases:
            self.assertIn(old, GOOD)
            bad = self.write("bad.yaml", GOOD.replace(old, new, 1))
            r = self.render("--settings", bad)
            self.assertEqual(r.returncode, 1, (new, r.stderr))
            self.assertIn("sky-render: " + bad + message, r.stderr)
            self.assertFalse(os.path.exists(self.path("sky.exr")))
        r = self.render("--settings", self.path("missing.yaml"))
        self.assertEqual(r.returncode, 1)
        self.assertIn("missing.yaml", r.stderr)


GOOD = """method: orders
quality: medium
spectral_stride: 2
tolerance: {daylight_rms: 0.005, daylight_max: 0.02, twilight_rms: 0.03}
chosen: {quality: medium, spectral_stride: 2, wavelengths: 9, daylight_rms: 0.0012, daylight_max: 0.0061, twilight_rms: 0.004}
"""


if __name__ == "__main__":
    unittest.main()
