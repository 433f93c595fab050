"""The lut-pack stage of the generated pipeline, on a temporary copy of the repo, with a
reduced-resolution set: 4x8 (2x4 for the cloudy sky) x 5 slices (time mapping gt7:3+2), method
`single` at low quality on 7 wavelengths, and a tiny particle type for every aerosol.

Checks: a fresh bake runs the LUT renders and one pack edge, then has no work; editing hazed.yaml
re-renders only hazed (its preview render and its LUT render) and the pack edge, whose clear and
cloudy textures keep their bytes and mtimes; missingdeps is clean; an unknown basis sky fails with
pipeline.yaml:line; and the golden check: the reduced bake's texels against tests/lut/golden/.

Golden check (docs/lut-pack.md, "Golden check"): every R11G11B10F code of every texture must be
within one step of the stored golden's (a rounding boundary crossed by a float difference between
compilers or CPUs moves a code by one; anything larger is a change of the physics or the packing),
and at most 2 % of the codes may differ at all; the report's sizes, slice angles and bytes must be
equal. Update mode: SKYBAKE_UPDATE_GOLDENS=1 rewrites tests/lut/golden/ from this bake, says
what changed and skips the comparison (the test is reported skipped, not passed).
"""
import hashlib
import json
import os
import re
import shutil
import struct
import sys
import unittest

import yaml

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "cli"))
from skytest import SRC, PipelineTestCase, TINY_PARTICLE, run, tool  # noqa: E402

GOLDEN = os.path.join(SRC, "tests", "lut", "golden")

PIPELINE = """outputs: outputs
altitude_step_m: 100
wavelengths: {min_nm: 400, max_nm: 700, step_nm: 50}
atmospheres:
  - atmospheres/clear.yaml
  - atmospheres/hazed.yaml
  - atmospheres/cloudy2.yaml
pools:
  render: 1
sky: {size: 4x2, sun_zenith_deg: [40], target_error: 0.5, preview: false}
luts:
  method: single
  quality: low
  time_mapping: "gt7:3+2"
  skies:
    - {atmosphere: clear, size: 4x8}
    - {atmosphere: hazed, size: 4x8}
    - {atmosphere: cloudy2, size: 2x4}
"""

TEXTURES = ["sky_clear.ktx2", "sky_hazed.ktx2", "sky_cloudy2.ktx2", "transmittance.ktx2", "sun.ktx2", "ambient.ktx2"]


def edges_run(ninja_stdout):
    return [m.group(1) for m in re.finditer(r"^\[\d+/\d+\] (.*)$", ninja_stdout, re.M)]


def lut_render_args(ninja):
    """{sky: the args of its outputs/<sky>/lut_sky.exr edge} of a build.ninja."""
    return {m.group(1): m.group(2) for m in re.finditer(r"build (\w+)/lut_sky\.exr: .*\n  args = (.*)", ninja)}


def ktx2_texels(path):
    """(width, height, depth, layers, level bytes) of a KTX2 file, read with struct (ktxspec
    'File Structure': 12-byte identifier, 9 UInt32 header fields, index, level index at byte 80)."""
    with open(path, "rb") as f:
        data = f.read()
    assert data[:12] == b"\xabKTX 20\xbb\r\n\x1a\n", path
    vk, _, w, h, d, layers = struct.unpack_from("<6I", data, 12)
    assert vk == 122, "not B10G11R11_UFLOAT_PACK32"
    offset, length = struct.unpack_from("<QQ", data, 80)
    return w, h, d, layers, data[offset:offset + length]


def codes(level):
    """The R, G, B codes (11, 11, 10 bits) of every texel."""
    out = []
    for (word,) in struct.iter_unpack("<I", level):
        out.append((word & 0x7FF, (word >> 11) & 0x7FF, word >> 22))
    return out


def check_codes(test, name, level, golden_path):
    """Asserts that a texture's codes are within one step of its golden's and that at most 2 % of
    them differ (the tolerance of a golden reduced bake: last-bit changes of the float
    arithmetic, not a changed method); returns the line for the report."""
    ours = codes(level)
    with open(golden_path, "rb") as f:
        theirs = codes(f.read())
    test.assertEqual(len(ours), len(theirs), name)
    worst = max(abs(x - y) for t, g in zip(ours, theirs) for x, y in zip(t, g))
    differing = sum(1 for t, g in zip(ours, theirs) for x, y in zip(t, g) if x != y)
    test.assertLessEqual(worst, 1, "%s: a code moved by %d steps (SKYBAKE_UPDATE_GOLDENS=1 after a deliberate "
                                   "change)" % (name, worst))
    test.assertLessEqual(differing / (3.0 * len(ours)), 0.02, name)
    return "%s: %d of %d codes differ (worst by %d step%s)" % (name, differing, 3 * len(ours), worst,
                                                              "" if worst == 1 else "s")


# The reason of the skip in update mode: the goldens were just written from this bake, so a
# comparison would compare the bake with itself. ctest reports the test as skipped on it
# (SKIP_REGULAR_EXPRESSION, tests/CMakeLists.txt).
GOLDENS_REWRITTEN = "SKYBAKE_UPDATE_GOLDENS=1: goldens rewritten, not compared"


def write_golden_textures(golden, folder, textures, summary):
    """SKYBAKE_UPDATE_GOLDENS=1: stores the textures' texels under `golden`, says which changed
    (against the manifest's `textures`), and returns the old manifest (empty if none)."""
    os.makedirs(golden, exist_ok=True)
    old = {}
    manifest = os.path.join(golden, "manifest.json")
    if os.path.isfile(manifest):
        with open(manifest) as f:
            old = json.load(f)
    for name in textures:
        with open(os.path.join(golden, name + ".texels"), "wb") as f:
            f.write(ktx2_texels(os.path.join(folder, name))[4])
        state = "unchanged" if old.get("textures", {}).get(name) == summary["textures"][name] else "UPDATED"
        print("golden %s: %s" % (name, state))
    return old


def load_golden_manifest(test, golden):
    """The golden's manifest.json, or a test failure that says how to create it."""
    manifest = os.path.join(golden, "manifest.json")
    test.assertTrue(os.path.isfile(manifest), "no goldens: run with SKYBAKE_UPDATE_GOLDENS=1")
    with open(manifest) as f:
        return json.load(f)


def write_golden_manifest(golden, summary):
    with open(os.path.join(golden, "manifest.json"), "w") as f:
        json.dump(summary, f, indent=2, sort_keys=True)
        f.write("\n")


class LutPipelineTest(PipelineTestCase):
    def setUp(self):
        super().setUp()
        shutil.copytree(os.path.join(SRC, "atmospheres"), self.path("atmospheres"))
        for extra in ("particles", "ocio"):
            shutil.copytree(os.path.join(SRC, extra), self.path(extra))
        self.write("pipeline.yaml", PIPELINE)
        self.write("particles/tiny.yaml", TINY_PARTICLE)
        for atm in ("clear", "hazed", "cloudy2"):
            p = self.path("atmospheres", atm + ".yaml")
            with open(p) as f:
                text = f.read()
            text = re.sub(r"particle: \.\./particles/\w+\.yaml", "particle: ../particles/tiny.yaml", text)
            with open(p, "w") as f:
                f.write(text)
        self.out = self.path("outputs")

    def read_ninja(self):
        with open(os.path.join(self.out, "build.ninja")) as f:
            return f.read()

    def test_fresh_bake_then_no_work_and_an_edit_reruns_only_its_sky(self):
        r = self.bake()
        ran = edges_run(r.stdout)
        for atm in ("clear", "hazed", "cloudy2"):
            self.assertIn("sky-render %s/lut_sky.exr" % atm, ran)
        self.assertIn("lut-pack luts/report.json", ran)
        self.assertEqual(ran.count("lut-pack luts/report.json"), 1)
        for f in TEXTURES + ["sky_clear_array.ktx2", "sky_clear.dds", "sky_clear.exr", "other_luts.exr", "contact_sheet.png",
                             "report.json"]:
            self.assertTrue(os.path.isfile(os.path.join(self.out, "luts", f)), f)
        # The contact sheet is an output of the pack edge (ninja knows who makes it).
        self.assertIn("lut_pack", self.ninja("-t", "query", "luts/contact_sheet.png").stdout)
        self.assertIn("no work to do", self.ninja("-n").stdout)
        self.assertIn("No missing dependencies", self.ninja("-t", "missingdeps").stdout)

        before = self.mtimes()
        self.edit("atmospheres/hazed.yaml", "optical_depth_550nm: 0.5", "optical_depth_550nm: 0.6")
        r = self.ninja()
        self.assertEqual(sorted(edges_run(r.stdout)), sorted(["Regenerating build.ninja", "sky-render hazed/sky.exr",
                                                             "sky-render hazed/lut_sky.exr", "lut-pack luts/report.json"]))
        after = self.mtimes()
        for f in ("sky_clear.ktx2", "sky_clear.dds", "sky_cloudy2.ktx2", "sky_cloudy2_array.ktx2"):
            self.assertEqual(before["luts/" + f], after["luts/" + f], f)
        for f in ("sky_hazed.ktx2", "sky_hazed.dds", "sun.ktx2", "ambient.ktx2", "report.json"):
            self.assertNotEqual(before["luts/" + f], after["luts/" + f], f)
        self.assertEqual(before["clear/lut_sky.exr"], after["clear/lut_sky.exr"])
        self.assertIn("no work to do", self.ninja("-n").stdout)

    def test_unknown_basis_sky_is_an_error_at_its_line(self):
        self.edit("pipeline.yaml", "{atmosphere: cloudy2, size: 2x4}", "{atmosphere: cloudy9, size: 2x4}")
        r = run([tool("skybake"), "generate", "pipeline.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
        self.assertIn("pipeline.yaml:18: luts.skies: 'cloudy9' is not an atmosphere of this pipeline (clear, hazed, cloudy2)",
                      r.stderr)
        self.edit("pipeline.yaml", "{atmosphere: cloudy9, size: 2x4}", "{atmosphere: cloudy2, size: 2x}")
        r = run([tool("skybake"), "generate", "pipeline.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, 1)
        self.assertIn("pipeline.yaml:18: key 'luts.skies[2].size'", r.stderr)

    def test_a_sky_may_name_its_own_quality(self):
        # luts.skies[i].quality overrides the section's preset for that sky's render only (the
        # clear and hazed LUTs at `high`, which meets the LUT accuracy target, the rest at the
        # section's; docs/pipeline.md); a value outside low|medium|high fails at its line.
        self.edit("pipeline.yaml", "{atmosphere: hazed, size: 4x8}", "{atmosphere: hazed, size: 4x8, quality: high}")
        r = run([tool("skybake"), "generate", "pipeline.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        ninja = self.read_ninja()
        edges = lut_render_args(ninja)
        self.assertEqual(sorted(edges), ["clear", "cloudy2", "hazed"], ninja)
        self.assertIn("--quality high", edges["hazed"])
        self.assertIn("--quality low", edges["clear"])
        self.assertIn("--quality low", edges["cloudy2"])
        self.edit("pipeline.yaml", "quality: high}", "quality: best}")
        r = run([tool("skybake"), "generate", "pipeline.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
        self.assertRegex(r.stderr, r"pipeline\.yaml:17: .*quality")

    def test_a_sky_may_name_its_own_spectral_stride(self):
        # luts.skies[i].spectral_stride overrides the section's (1 here: no --spectral-stride) for that
        # sky; with quality: auto the choice sets it, so naming one there is an error at its line.
        self.edit("pipeline.yaml", "{atmosphere: hazed, size: 4x8}", "{atmosphere: hazed, size: 4x8, spectral_stride: 3}")
        r = run([tool("skybake"), "generate", "pipeline.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        ninja = self.read_ninja()
        edges = lut_render_args(ninja)
        self.assertIn("--spectral-stride 3", edges["hazed"])
        self.assertNotIn("--spectral-stride", edges["clear"])
        self.edit("pipeline.yaml", "spectral_stride: 3}", "spectral_stride: 2.5}")
        r = run([tool("skybake"), "generate", "pipeline.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, 1)
        self.assertIn("pipeline.yaml:17: key 'luts.skies[1].spectral_stride': expected a whole number", r.stderr)
        self.edit("pipeline.yaml", "spectral_stride: 2.5}", "spectral_stride: 2, quality: auto}")
        r = run([tool("skybake"), "generate", "pipeline.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, 1)
        self.assertIn("pipeline.yaml:17: key 'luts.skies[1].spectral_stride': not with quality: auto", r.stderr)

    def test_quality_auto_chooses_then_renders_with_the_choice(self):
        # `quality: auto` (docs/sky-methods.md "Automatic quality"): a sky-render choose edge writes
        # hazed/lut_quality.yaml, the render edge reads it, the report carries the choice and its
        # measured error; an edit of the atmosphere re-chooses and re-renders, nothing else does.
        self.edit("pipeline.yaml", "{atmosphere: hazed, size: 4x8}", "{atmosphere: hazed, size: 4x8, quality: auto, tolerance: 2%}")
        r = self.bake()
        ran = edges_run(r.stdout)
        self.assertIn("sky-render hazed/lut_quality.yaml", ran)
        self.assertNotIn("sky-render clear/lut_quality.yaml", ran)
        ninja = self.read_ninja()
        edges = lut_render_args(ninja)
        self.assertIn("--settings hazed/lut_quality.yaml", edges["hazed"])
        self.assertNotIn("--quality", edges["hazed"])
        self.assertIn("--quality low", edges["clear"])
        self.assertRegex(ninja, r"build hazed/lut_quality\.yaml: lut_choose hazed/components/render\.yaml \|.*\n  args = choose "
                                r"--method single .*--tolerance 0\.02 --max-tolerance 0\.02 --twilight-tolerance 0\.03")
        with open(os.path.join(self.out, "hazed", "lut_quality.yaml")) as f:
            choice = yaml.safe_load(f)
        self.assertEqual(choice["method"], "single")
        self.assertLessEqual(choice["chosen"]["daylight_rms"], 0.02)
        self.assertLessEqual(choice["chosen"]["daylight_max"], 0.02)
        self.assertLessEqual(choice["chosen"]["twilight_rms"], 0.03)
        with open(os.path.join(self.out, "luts", "report.json")) as f:
            skies = {s["name"]: s for s in json.load(f)["skies"]}
        q = skies["hazed"]["quality_choice"]
        self.assertEqual((q["quality"], q["spectral_stride"]), (choice["quality"], choice["spectral_stride"]))
        self.assertEqual(q["measured"]["daylight_rms"], choice["chosen"]["daylight_rms"])
        self.assertEqual(q["tolerance"]["daylight_rms"], 0.02)
        self.assertIsNone(skies["clear"]["quality_choice"])
        self.assertIn("no work to do", self.ninja("-n").stdout)
        self.assertIn("No missing dependencies", self.ninja("-t", "missingdeps").stdout)
        self.edit("atmospheres/hazed.yaml", "optical_depth_550nm: 0.5", "optical_depth_550nm: 0.6")
        ran = edges_run(self.ninja().stdout)
        self.assertEqual(sorted(ran), sorted(["Regenerating build.ninja", "sky-render hazed/sky.exr", "sky-render hazed/lut_quality.yaml",
                                              "sky-render hazed/lut_sky.exr", "lut-pack luts/report.json"]))

    def test_quality_auto_errors_are_located(self):
        for old, new, message in [
                ("{atmosphere: hazed, size: 4x8}", "{atmosphere: hazed, size: 4x8, tolerance: 1%}",
                 "pipeline.yaml:17: key 'luts.skies[1].tolerance': applies to quality: auto only"),
                ("{atmosphere: hazed, size: 4x8}", "{atmosphere: hazed, size: 4x8, quality: auto, max_tolerance: lots}",
                 "pipeline.yaml:17: key 'luts.skies[1].max_tolerance': expected a positive relative error"),
                ("  quality: low\n", "  quality: automatic\n", "pipeline.yaml:13: key 'luts.quality': expected one of 'low', 'medium', 'high' or 'auto'")]:
            with open(self.path("pipeline.yaml")) as f:
                original = f.read()
            self.assertIn(old, original)
            self.write("pipeline.yaml", original.replace(old, new, 1))
            r = run([tool("skybake"), "generate", "pipeline.yaml"], cwd=self.tmp)
            self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
            self.assertIn(message, r.stderr)
            self.write("pipeline.yaml", original)

    def test_golden_reduced_bake(self):
        self.bake()
        luts = os.path.join(self.out, "luts")
        with open(os.path.join(luts, "report.json")) as f:
            report = json.load(f)
        summary = {
            "time_mapping": report["time_mapping"]["name"],
            "slice_zenith_deg": [round(z, 9) for z in report["time_mapping"]["slice_zenith_deg"]],
            "skies": [[s["name"], s["size"], s["texel_bytes"]] for s in report["skies"]],
            "budget_bytes": report["budget"]["sky_lut_texel_bytes"],
            "textures": {},
        }
        for name in TEXTURES:
            w, h, d, layers, level = ktx2_texels(os.path.join(luts, name))
            summary["textures"][name] = {"size": [w, h, d, layers], "texels_sha256": hashlib.sha256(level).hexdigest()}
        if os.environ.get("SKYBAKE_UPDATE_GOLDENS") == "1":
            self.update_goldens(luts, summary)
            self.skipTest(GOLDENS_REWRITTEN)  # rewritten from this bake, so not compared with it
        golden = load_golden_manifest(self, GOLDEN)
        for key in ("time_mapping", "skies", "budget_bytes"):
            self.assertEqual(summary[key], golden[key], key)
        for a, b in zip(summary["slice_zenith_deg"], golden["slice_zenith_deg"]):
            self.assertAlmostEqual(a, b, places=7)
        lines = []
        for name in TEXTURES:
            self.assertEqual(summary["textures"][name]["size"], golden["textures"][name]["size"], name)
            lines.append(check_codes(self, name, ktx2_texels(os.path.join(luts, name))[4],
                                     os.path.join(GOLDEN, name + ".texels")))
        print("golden check:\n  " + "\n  ".join(lines))

    def update_goldens(self, luts, summary):
        write_golden_textures(GOLDEN, luts, TEXTURES, summary)
        write_golden_manifest(GOLDEN, summary)


if __name__ == "__main__":
    unittest.main()
