"""The `clouds` section of pipeline.yaml on a temporary copy: noise-gen and cumulus-map
edges, and their independence - an edit to the cumulus settings re-runs no noise volume and an
edit to one volume re-runs only that volume; a sequence of map times; errors located in the file
that has them."""
import os
import re
import shutil
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "cli"))
from skytest import SRC, TempDirTestCase, run, tool  # noqa: E402

# Small recipes so that a fresh bake takes about a second (the repository's volumes are
# exercised at full size by tests/noise and tests/cli).
SMALL_LOW = """resolution: 16
tile_size_km: 5
seed: 7
format: r16_sfloat
normalize: zero_mean
channels:
  - perlin_worley: {perlin: {frequency: 2, octaves: 2}, worley: {frequency: 2, weights: [0.625, 0.25, 0.125]}}
"""
SMALL_HIGH = """resolution: 16
tile_size_km: 0.3
seed: 11
format: r8_unorm
normalize: min_max
channels:
  - worley: {frequency: 2, weights: [0.625, 0.25, 0.125]}
"""

# A minimal atmosphere (no aerosols, so no mie-tables edges): the clouds do not depend on it, but
# pipeline.yaml requires one. It has no ground or sun, so the pipeline renders no sky of it
# (`sky: {atmospheres: []}`).
ATMOSPHERE = """name: plain
planet: {radius_km: 6371, top_km: 100}
air: {profile: ussa1976}
"""

PIPELINE = """outputs: outputs
atmospheres:
  - atmospheres/plain.yaml
clouds:
  noise: [clouds/low.yaml, clouds/high.yaml]
  cumulus: clouds/cumulus.yaml
  cumulus_times_s: %s
  coverage: clouds/coverage.yaml
sky: {atmospheres: []}
"""


def edges_run(ninja_stdout):
    """The cloud edges ninja ran ("[1/2] noise-gen x" -> "noise-gen x"); other stages are ignored."""
    return [m.group(1) for m in re.finditer(r"^\[\d+/\d+\] (.*)$", ninja_stdout, re.M)
            if m.group(1).startswith(("noise-gen ", "cumulus-map "))]


class CloudsPipelineTest(TempDirTestCase):
    def setUp(self):
        super().setUp()
        self.write("atmospheres/plain.yaml", ATMOSPHERE)
        os.makedirs(self.path("clouds"))
        for name in ("cumulus.yaml", "coverage.yaml"):
            shutil.copy(os.path.join(SRC, "clouds", name), self.path("clouds", name))
        self.write("clouds/low.yaml", SMALL_LOW)
        self.write("clouds/high.yaml", SMALL_HIGH)
        self.write("pipeline.yaml", PIPELINE % "[0]")
        self.out = self.path("outputs")

    def bake(self, expect=0):
        r = run([tool("skybake"), "bake", "pipeline.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, expect, r.stdout + r.stderr)
        return r

    def edit(self, rel, old, new):
        with open(self.path(rel)) as f:
            text = f.read()
        self.assertIn(old, text)
        with open(self.path(rel), "w") as f:
            f.write(text.replace(old, new, 1))

    def test_fresh_bake_builds_every_cloud_product_then_no_work(self):
        r = self.bake()
        self.assertEqual(sorted(edges_run(r.stdout)), [
            "cumulus-map clouds/coverage.ktx2", "cumulus-map clouds/cumulus_map_t0s.ktx2",
            "noise-gen clouds/noise/high.ktx2", "noise-gen clouds/noise/low.ktx2"])
        for rel in ("clouds/noise/low.ktx2", "clouds/noise/low.exr", "clouds/noise/low.png", "clouds/noise/high.ktx2",
                    "clouds/cumulus_map_t0s.ktx2", "clouds/cumulus_map_t0s.png", "clouds/coverage.ktx2", "clouds/coverage.exr"):
            self.assertTrue(os.path.isfile(os.path.join(self.out, rel)), rel)
        self.assertIn("no work to do", run(["ninja", "-C", self.out]).stdout)
        self.assertIn("No missing dependencies", run(["ninja", "-C", self.out, "-t", "missingdeps"]).stdout)

    def test_cumulus_edit_rebuilds_no_noise_and_noise_edit_rebuilds_one_volume(self):
        self.bake()
        self.edit("clouds/cumulus.yaml", "coverage: 0.45", "coverage: 0.55")
        self.assertEqual(edges_run(self.bake().stdout), ["cumulus-map clouds/cumulus_map_t0s.ktx2"])
        self.edit("clouds/coverage.yaml", "base_km: 1.0", "base_km: 0.9")
        self.assertEqual(edges_run(self.bake().stdout), ["cumulus-map clouds/coverage.ktx2"])
        self.edit("clouds/high.yaml", "seed: 11", "seed: 12")
        self.assertEqual(edges_run(self.bake().stdout), ["noise-gen clouds/noise/high.ktx2"])

    def test_a_sequence_of_map_times(self):
        self.write("pipeline.yaml", PIPELINE % "[0, 600, 1200]")
        r = self.bake()
        maps = sorted(e for e in edges_run(r.stdout) if "cumulus_map" in e)
        self.assertEqual(maps, ["cumulus-map clouds/cumulus_map_t0s.ktx2", "cumulus-map clouds/cumulus_map_t1200s.ktx2",
                                "cumulus-map clouds/cumulus_map_t600s.ktx2"])
        with open(os.path.join(self.out, "clouds", "cumulus_map_t600s.ktx2"), "rb") as f:
            self.assertIn(b"skybake.time_s\x00600\x00", f.read())

    def test_malformed_recipe_fails_with_its_file_and_line_and_keeps_outputs(self):
        self.bake()
        low = os.path.join(self.out, "clouds", "noise", "low.ktx2")
        before = os.stat(low).st_mtime_ns
        self.edit("clouds/low.yaml", "resolution: 16", "resolution: sixteen")
        r = self.bake(expect=1)
        self.assertIn("noise-gen: ../clouds/low.yaml:1: key 'resolution': expected an integer from 4 to 256 "
                      "(texels per side), got \"sixteen\"", r.stdout + r.stderr)
        self.assertEqual(os.stat(low).st_mtime_ns, before)

    def test_missing_cloud_file_is_reported_in_pipeline_yaml(self):
        self.write("pipeline.yaml", (PIPELINE % "[0]").replace("clouds/high.yaml", "clouds/nope.yaml"))
        r = self.bake(expect=1)
        self.assertRegex(r.stderr, r"skybake: .*pipeline\.yaml:5: key 'clouds\.noise\[1\]': .*nope\.yaml")

    def test_unknown_clouds_key(self):
        self.write("pipeline.yaml", (PIPELINE % "[0]").replace("cumulus_times_s", "cumulus_time_s"))
        r = self.bake(expect=1)
        self.assertIn("unknown key 'clouds.cumulus_time_s' (did you mean 'cumulus_times_s'?)", r.stderr)


if __name__ == "__main__":
    unittest.main()
