"""The fog-fit stage of the generated pipeline, on a temporary copy of the repo, with a
reduced set: three basis skies (clear, hazed, cloudy2), `orders` at low quality on 7 wavelengths,
a 4x8 fog LUT on 5 slices (gt7:3+2), an 8x8 attenuation LUT, two depth tables (sun 40 and 85 deg,
3 elevations x 2 azimuths x 4 depths), a tiny particle type for every aerosol, no sky references.

Checks: a fresh bake runs one fog render and one fit per sky, then has no work; editing hazed.yaml
re-runs only hazed's render and fit, and clear's and cloudy2's fog products keep their bytes and
mtimes; missingdeps is clean; an unknown basis sky fails with pipeline.yaml:line; and the golden
check of the fog textures and parameters against tests/fog/golden/.

Golden check (docs/fog.md, "Golden check"), lut-pack's rule (tests/pipeline/test_lut_pipeline.py):
every R11G11B10F code of the fog, shadowed fog and attenuation textures of the three skies within
one step of the stored golden's (a float difference between compilers or CPUs that crosses a
rounding boundary moves a code by one; more is a change of the physics, the mapping or the
packing), at most 2 % of the codes different at all; sizes and the texel grid equal; the per-slice
(a, p) within 1e-3 relative (a) and 1e-3 absolute (p): the fit stops at 1e-12 (fog/fog_fit.cpp),
so only its float32 input can move them, by ~1e-6; the fit's RMS error near the camera within
0.001 (0.1 point). Update mode: SKYBAKE_UPDATE_GOLDENS=1 rewrites tests/fog/golden/ from this bake,
says what changed and skips the comparison (reported skipped, not passed).
"""
import hashlib
import json
import os
import re
import shutil
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "cli"))
from skytest import SRC, PipelineTestCase, run, tool  # noqa: E402
from test_lut_pipeline import (GOLDENS_REWRITTEN, TINY_PARTICLE, check_codes, edges_run, ktx2_texels,  # noqa: E402
                               load_golden_manifest, write_golden_manifest, write_golden_textures)

GOLDEN = os.path.join(SRC, "tests", "fog", "golden")

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
  depth_tables: {sun_zenith_deg: [40, 85], elevations: 3, azimuths_deg: [0, 180], depths: 4}
  skies: [clear, hazed, cloudy2]
"""

SKIES = ("clear", "hazed", "cloudy2")
TEXTURES = ["fog_%s%s.ktx2" % (sky, kind) for sky in SKIES for kind in ("", "_shadowed", "_attenuation")]


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
                           "_attenuation.ktx2", "_attenuation.dds", "_params.ktx2", ".exr", "_report.json",
                           "_residuals.png"):
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

    def test_golden_reduced_bake(self):
        r = run([tool("skybake"), "bake", "pipeline.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        fog = os.path.join(self.out, "fog")
        summary = {"textures": {}, "parameters": {}}
        for name in TEXTURES:
            w, h, d, layers, level = ktx2_texels(os.path.join(fog, name))
            summary["textures"][name] = {"size": [w, h, d, layers], "texels_sha256": hashlib.sha256(level).hexdigest()}
        for sky in SKIES:
            with open(os.path.join(fog, "fog_%s.json" % sky)) as f:
                model = json.load(f)["model"]
            with open(os.path.join(fog, "fog_%s_report.json" % sky)) as f:
                report = json.load(f)
            ps = model["per_slice"]
            summary["parameters"][sky] = {
                "parameters": model["parameters"],
                "fog_a": ps["fog"]["a"], "fog_p": ps["fog"]["p"],
                "shadowed_a": ps["shadowed"]["a"], "shadowed_p": ps["shadowed"]["p"],
                # a at the elevation nodes, flattened per slice (nodes x R, G, B)
                "fog_a_nodes": [[c for node in row for c in node] for row in ps["elevation_nodes"]["fog"]["a"]],
                "shadowed_a_nodes": [[c for node in row for c in node] for row in ps["elevation_nodes"]["shadowed"]["a"]],
                "fit_near_camera_rms": report["errors"]["fog"]["fit"]["near_camera"]["rms"]}
        with open(os.path.join(fog, "fog_clear.ktx2"), "rb") as f:
            summary["texel_grid"] = "nodes" if b"skybake.texel_grid\x00nodes\x00" in f.read() else "centres"
        if os.environ.get("SKYBAKE_UPDATE_GOLDENS") == "1":
            self.update_goldens(fog, summary)
            self.skipTest(GOLDENS_REWRITTEN)  # rewritten from this bake, so not compared with it
        golden = load_golden_manifest(self, GOLDEN)
        self.assertEqual(summary["texel_grid"], golden["texel_grid"])
        lines = []
        for name in TEXTURES:
            self.assertEqual(summary["textures"][name]["size"], golden["textures"][name]["size"], name)
            lines.append(check_codes(self, name, ktx2_texels(os.path.join(fog, name))[4],
                                     os.path.join(GOLDEN, name + ".texels")))
        for sky in SKIES:
            ours, theirs = summary["parameters"][sky], golden["parameters"][sky]
            self.assertEqual(ours["parameters"], theirs["parameters"], sky)
            for key in ("fog_a", "fog_p", "shadowed_a", "shadowed_p", "fog_a_nodes", "shadowed_a_nodes"):
                self.assertEqual(len(ours[key]), len(theirs[key]), (sky, key))
                for row_o, row_t in zip(ours[key], theirs[key]):
                    for a, b in zip(row_o, row_t):
                        if key.endswith("_a") or key.endswith("_nodes"):
                            self.assertLessEqual(abs(a / b - 1), 1e-3, (sky, key, a, b))
                        else:
                            self.assertLessEqual(abs(a - b), 1e-3, (sky, key, a, b))
            self.assertLessEqual(abs(ours["fit_near_camera_rms"] - theirs["fit_near_camera_rms"]), 1e-3, sky)
        print("fog golden check:\n  " + "\n  ".join(lines))

    def update_goldens(self, fog, summary):
        old = write_golden_textures(GOLDEN, fog, TEXTURES, summary)
        for sky in SKIES:
            state = "unchanged" if old.get("parameters", {}).get(sky) == summary["parameters"][sky] else "UPDATED"
            print("golden parameters %s: %s" % (sky, state))
        write_golden_manifest(GOLDEN, summary)

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
