"""The fog-fit stage of the generated pipeline (issue 7), on a temporary copy of the repo, with a
reduced set: three basis skies (clear, hazed, cloudy2), `orders` at low quality on 7 wavelengths,
a 4x8 fog LUT on 5 slices (gt7:3+2), an 8x8 attenuation LUT, one depth table (sun 40 deg, 3
elevations x 2 azimuths x 4 depths), a tiny particle type for every aerosol, no sky references.

Checks: a fresh bake runs one fog render and one fit per sky, then has no work; editing hazed.yaml
re-runs only hazed's render and fit, and clear's and cloudy2's fog products keep their bytes and
mtimes; missingdeps is clean; an unknown basis sky fails with pipeline.yaml:line.
"""
import json
import os
import re
import shutil
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "cli"))
from skytest import SRC, PipelineTestCase, run, tool  # noqa: E402
from test_lut_pipeline import TINY_PARTICLE, edges_run  # noqa: E402

PIPELINE = """outputs: outputs
altitude_step_m: 100
wavelengths: {min_nm: 400, max_nm: 700, step_nm: 50}
atmospheres:
  - atmospheres/clear.yaml
  - atmospheres/hazed.yaml
  - atmospheres/cloudy2.yaml
pools:
  render: 1
sky: {atmospheres: []}
fog:
  method: orders
  quality: low
  cut_altitude_km: 1
  time_mapping: "gt7:3+2"
  lut_size: 4x8
  attenuation_size: 8x8
  depth_tables: {sun_zenith_deg: [40], elevations: 3, azimuths_deg: [0, 180], depths: 4}
  skies: [clear, hazed, cloudy2]
"""

SKIES = ("clear", "hazed", "cloudy2")


class FogPipelineTest(PipelineTestCase):
    def setUp(self):
        super().setUp()
        shutil.copytree(os.path.join(SRC, "atmospheres"), self.path("atmospheres"))
        for extra in ("particles", "ocio"):
            shutil.copytree(os.path.join(SRC, extra), self.path(extra))
        self.write("pipeline.yaml", PIPELINE)
        self.write("particles/tiny.yaml", TINY_PARTICLE)
        for atm in SKIES:
            p = self.path("atmospheres", atm + ".yaml")
            with open(p) as f:
                text = f.read()
            text = re.sub(r"particle: \.\./particles/\w+\.yaml", "particle: ../particles/tiny.yaml", text)
            with open(p, "w") as f:
                f.write(text)
        self.out = self.path("outputs")

    def test_fresh_bake_then_no_work_and_an_edit_reruns_only_its_fog(self):
        r = run([tool("skybake"), "bake", "pipeline.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        ran = edges_run(r.stdout)
        for atm in SKIES:
            self.assertEqual(ran.count("sky-render %s/fog.exr" % atm), 1, ran)
            self.assertEqual(ran.count("fog-fit fog/fog_%s.json" % atm), 1, ran)
            for suffix in (".json", ".ktx2", "_array.ktx2", ".dds", "_shadowed.ktx2", "_shadowed.dds",
                           "_attenuation.ktx2", "_attenuation.dds", ".exr", "_report.json", "_residuals.png"):
                self.assertTrue(os.path.isfile(os.path.join(self.out, "fog", "fog_" + atm + suffix)), atm + suffix)
            with open(os.path.join(self.out, "fog", "fog_%s_report.json" % atm)) as f:
                report = json.load(f)
            self.assertEqual(report["basis_sky"], atm)
            self.assertGreater(report["errors"]["fog"]["fit"]["near_camera"]["samples"], 0)
        self.assertIn("no work to do", self.ninja("-n").stdout)
        self.assertIn("No missing dependencies", self.ninja("-t", "missingdeps").stdout)

        before = self.mtimes()
        self.edit("atmospheres/hazed.yaml", "optical_depth_550nm: 0.5", "optical_depth_550nm: 0.6")
        r = self.ninja()
        self.assertEqual(sorted(edges_run(r.stdout)),
                         sorted(["Regenerating build.ninja", "sky-render hazed/fog.exr", "fog-fit fog/fog_hazed.json"]))
        after = self.mtimes()
        for atm in ("clear", "cloudy2"):
            for f in [k for k in before if k.startswith("fog/fog_%s" % atm) or k == "%s/fog.exr" % atm]:
                self.assertEqual(before[f], after[f], f)
        for f in ("fog/fog_hazed.ktx2", "fog/fog_hazed.json", "fog/fog_hazed_report.json", "hazed/fog.exr"):
            self.assertNotEqual(before[f], after[f], f)
        self.assertIn("no work to do", self.ninja("-n").stdout)

    def test_unknown_basis_sky_is_an_error_at_its_line(self):
        self.edit("pipeline.yaml", "skies: [clear, hazed, cloudy2]", "skies: [clear, hazed, cloudy9]")
        r = run([tool("skybake"), "generate", "pipeline.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
        self.assertIn("pipeline.yaml:19: fog.skies: 'cloudy9' is not an atmosphere of this pipeline (clear, hazed, cloudy2)",
                      r.stderr)
        self.edit("pipeline.yaml", "lut_size: 4x8", "lut_size: 4x")
        r = run([tool("skybake"), "generate", "pipeline.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, 1)
        self.assertIn("pipeline.yaml:16: key 'fog.lut_size'", r.stderr)


if __name__ == "__main__":
    unittest.main()
