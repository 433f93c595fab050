"""The generator on the peers' parametric atmospheres: a pipeline of bruneton2017 and an AFGL
1986 climate bakes with no mie-tables edge, and an edit to a parametric optic (the aerosol's
phase g) re-runs the sky only, while an edit to a profile re-runs
profile-import and the sky."""
import os
import shutil
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "cli"))
from skytest import SRC, PipelineTestCase  # noqa: E402
from test_pipeline import edges_run  # noqa: E402

PIPELINE = """outputs: outputs
altitude_step_m: 100
wavelengths: {min_nm: 360, max_nm: 830, step_nm: 10}
atmospheres:
  - atmospheres/peers/bruneton2017.yaml
  - atmospheres/afgl1986/tropical.yaml
sky: {size: 4x2, sun_zenith_deg: [40], target_error: 0.5, preview: false}
"""


class PeersPipelineTest(PipelineTestCase):
    def setUp(self):
        super().setUp()
        shutil.copytree(os.path.join(SRC, "atmospheres"), self.path("atmospheres"))
        shutil.copytree(os.path.join(SRC, "ocio"), self.path("ocio"))
        self.write("pipeline.yaml", PIPELINE)
        self.out = self.path("outputs")

    def test_parametric_edits_rebuild_what_they_touch(self):
        r = self.bake()
        self.assertEqual(sorted(edges_run(r.stdout)), ["profile-import afgl1986_tropical/profiles.exr",
                                                       "profile-import bruneton2017/profiles.exr",
                                                       "sky-render afgl1986_tropical/sky.exr",
                                                       "sky-render bruneton2017/sky.exr"])
        self.assertFalse(os.path.exists(os.path.join(self.out, "mie")))
        self.edit("atmospheres/peers/bruneton2017.yaml", "g: 0.8", "g: 0.7")
        self.assertEqual(edges_run(self.ninja().stdout), ["Regenerating build.ninja", "sky-render bruneton2017/sky.exr"])
        self.edit("atmospheres/peers/bruneton2017.yaml", "scale_height_km: 1.2", "scale_height_km: 1.0")
        self.assertEqual(edges_run(self.ninja().stdout), ["Regenerating build.ninja", "profile-import bruneton2017/profiles.exr",
                                                          "sky-render bruneton2017/sky.exr"])
        self.assertIn("no work to do", self.ninja("-n").stdout)


if __name__ == "__main__":
    unittest.main()
