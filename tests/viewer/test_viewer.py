"""The runtime viewer (viewer/) in a real browser: Debian's Chromium, headless, with
software WebGL2 (SwiftShader), driven by puppeteer-core (tests/viewer/drive.mjs) against a
reduced bake served on 127.0.0.1 by scripts/view_server.py.

The reduced bake (a temporary copy of the repo): clear, hazed, cloudy1 and cloudy2; sky LUTs by
`single` at low quality on 7 wavelengths, 8x16 (4x8 cloudy) x 5 slices (gt7:3+2); fog of clear,
hazed, cloudy1 and cloudy2 by `orders` low (4x8 fog LUT, 8x8 attenuation LUT, two depth tables); 16^3 noise
volumes, the shipped cumulus map and coverage texture.

Checks (docs/runtime.md "Checks"):
- the page loads the bake, compiles every program and renders with no WebGL error, no console
  error and no page error;
- numbers: the page's float32 dome views (linear radiance read back from an RGBA32F target) of
  clear, hazed, haziness 0.5 and a cloudiness blend at sun elevations 60, 20, 5, 0, -4 deg agree
  with `lut-pack decode` (the C++ reference decoder, double) within 0.5 % RMS and 2 % max of the
  relative luminance outside 3 deg of the sun; the page's weather weights equal the documented
  ladder's; fog at fixed (direction, distance, sun, occlusion) points agrees with `fog-fit eval`
  within 0.5 % RMS / 2 % max (in-scattered luminance) and 2e-3 absolute (transmittance);
- screenshots (noon, sunset, twilight, overcast, fog, clouds) under outputs/viewer/: PNGs that are
  not black, not uniform and carry no NaN (the HDR targets are checked for NaN and infinity).
"""
import json
import math
import os
import re
import shutil
import subprocess
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "cli"))
sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "pipeline"))
from skytest import SRC, TempDirTestCase, read_png, run, tool  # noqa: E402
from test_lut_pipeline import TINY_PARTICLE  # noqa: E402

PIPELINE = """outputs: outputs
altitude_step_m: 100
wavelengths: {min_nm: 400, max_nm: 700, step_nm: 50}
atmospheres:
  - atmospheres/clear.yaml
  - atmospheres/hazed.yaml
  - atmospheres/cloudy1.yaml
  - atmospheres/cloudy2.yaml
pools:
  render: 1
sky: {atmospheres: []}
luts:
  method: single
  quality: low
  time_mapping: "gt7:3+2"
  skies:
    - {atmosphere: clear, size: 8x16}
    - {atmosphere: hazed, size: 8x16}
    - {atmosphere: cloudy1, size: 4x8}
    - {atmosphere: cloudy2, size: 4x8}
fog:
  method: orders
  quality: low
  cut_altitude_km: 1
  time_mapping: "gt7:3+2"
  lut_size: 4x8
  attenuation_size: 8x8
  depth_tables: {sun_zenith_deg: [40, 85], elevations: 3, azimuths_deg: [0, 180], depths: 4}
  skies: [clear, hazed, cloudy1, cloudy2]
clouds:
  noise: [clouds/noise_low.yaml, clouds/noise_high.yaml]
  cumulus: clouds/cumulus.yaml
  cumulus_times_s: [0]
  coverage: clouds/coverage.yaml
"""

# 16^3 noise volumes (the shipped 128^3 and 32^3 ones are tested at full size by tests/noise, tests/cli).
from test_clouds_pipeline import SMALL_HIGH, SMALL_LOW  # noqa: E402

SKIES = ("clear", "hazed", "cloudy1", "cloudy2")
SUN_ELEVATIONS_DEG = (60, 20, 5, 0, -4)
DOME = (64, 32)
SUN_CONE_DEG = 3.0        # the checks leave out the sun's neighbourhood (the aureole's steepest part)
RMS_TOLERANCE = 0.005     # relative luminance, the target
MAX_TOLERANCE = 0.02


def weather_weights(h, c, cloudy):
    """The basis-sky weights of docs/runtime.md decision 1, written independently of the page's."""
    m = len(cloudy)
    s = c * m
    sunny = max(0.0, 1.0 - s)
    pos = max(s - 1.0, 0.0)
    j = min(math.floor(pos), max(m - 2, 0))
    f = min(1.0, max(0.0, pos - j)) if m > 1 else 0.0
    w = {"clear": sunny * (1 - h), "hazed": sunny * h}
    w[cloudy[j]] = w.get(cloudy[j], 0.0) + (1 - sunny) * (1 - f)
    if m > 1:
        w[cloudy[j + 1]] = w.get(cloudy[j + 1], 0.0) + (1 - sunny) * f
    return {k: v for k, v in w.items() if v > 0}


# The display check: (name, haziness, cloudiness, sun elevation (deg), white (cd/m^2)); whites that
# clip part of the sky and leave the rest in the curve's steep and flat parts.
DISPLAY_VIEWS = [("noon", 0.0, 0.0, 60, 6000.0), ("dusk", 0.5, 0.0, 0, 600.0), ("twilight", 0.0, 0.75, -4, 8.0)]

# The dome views: (name, haziness, cloudiness).
VIEWS = [("clear", 0.0, 0.0), ("hazed", 1.0, 0.0), ("haziness_0.5", 0.5, 0.0), ("cloudiness_0.75", 0.3, 0.75)]


def dump_exr(path):
    """Pixels of an RGB EXR as a list of floats (R, G, B interleaved), read by OpenImageIO's oiiotool."""
    r = run(["oiiotool", "--dumpdata", path])
    assert r.returncode == 0, r.stderr
    values = []
    for m in re.finditer(r"^\s*Pixel \((\d+), (\d+)\):\s*(.*)$", r.stdout, re.M):
        values.extend(float(v) for v in m.group(3).split()[:3])
    return values


def png_pixels(path):
    """(width, height, channels, bytes) of an 8-bit PNG (skytest.read_png, zlib + struct)."""
    w, h, ch, rows = read_png(path)
    return w, h, ch, b"".join(rows)


def dome_direction(x, y, w, h):
    phi = 2 * math.pi * (x + 0.5) / w - math.pi
    theta = 0.5 * math.pi * (y + 0.5) / h
    return (math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta))


class ViewerTest(TempDirTestCase):
    @classmethod
    def setUpClass(cls):
        cls.case = TempDirTestCase("setUp")
        cls.case.setUp()
        c = cls.case
        shutil.copytree(os.path.join(SRC, "atmospheres"), c.path("atmospheres"))
        for extra in ("particles", "ocio", "clouds"):
            shutil.copytree(os.path.join(SRC, extra), c.path(extra))
        c.write("pipeline.yaml", PIPELINE)
        c.write("particles/tiny.yaml", TINY_PARTICLE)
        c.write("clouds/noise_low.yaml", SMALL_LOW)
        c.write("clouds/noise_high.yaml", SMALL_HIGH)
        for atm in SKIES:
            p = c.path("atmospheres", atm + ".yaml")
            with open(p) as f:
                text = f.read()
            text = re.sub(r"particle: \.\./particles/\w+\.yaml", "particle: ../particles/tiny.yaml", text)
            with open(p, "w") as f:
                f.write(text)
        r = run([tool("skybake"), "bake", "pipeline.yaml"], cwd=c.tmp, timeout=1200)
        assert r.returncode == 0, r.stdout + r.stderr
        cls.out = c.path("outputs")
        cls.luts = os.path.join(cls.out, "luts")
        cls.cloudy = ["cloudy1", "cloudy2"]

        # The C++ references: lut-pack decode per view, fog-fit eval per fog sky.
        sza = ",".join(str(90 - e) for e in SUN_ELEVATIONS_DEG)
        cls.reference = {}
        for name, h, cl in VIEWS:
            weights = weather_weights(h, cl, cls.cloudy)
            args = ["%s:%r" % (os.path.join(cls.luts, "sky_%s.ktx2" % k), w) for k, w in weights.items()]
            exr = c.path("dome_%s.exr" % name)
            r = run([tool("lut-pack"), "decode"] + args + ["--sun-zenith-deg", sza, "--size", "%dx%d" % DOME, "-o", exr])
            assert r.returncode == 0, r.stderr
            cls.reference[name] = dump_exr(exr)
        # The display check: one dome through OCIO's CPU path (lut-pack decode --preview).
        cls.display_png = {}
        for name, h, cl, e, white in DISPLAY_VIEWS:
            weights = weather_weights(h, cl, cls.cloudy)
            args = ["%s:%r" % (os.path.join(cls.luts, "sky_%s.ktx2" % k), w) for k, w in weights.items()]
            png = c.path("display_%s.png" % name)
            r = run([tool("lut-pack"), "decode"] + args + ["--sun-zenith-deg", str(90 - e), "--size", "%dx%d" % DOME,
                                                          "-o", c.path("display_%s.exr" % name), "--preview", png,
                                                          "--white-cd-m2", repr(white)])
            assert r.returncode == 0, r.stderr
            cls.display_png[name] = png_pixels(png)
        cls.fog_points = []
        for sza_deg in (0, 30, 60, 75.5, 84, 89, 91, 96):
            for vza in (0, 30, 60, 80, 88, 89.5, 95):
                for raz in (0, 60, 180):
                    for depth in (50, 700, 4000, 30000, 200000):
                        occlusion = 0.5 if (vza + raz) % 60 == 30 else 0.0
                        cls.fog_points.append((sza_deg, vza, raz, depth, occlusion))
        csv = "# source: tests/viewer/test_viewer.py, fog check points\n" \
              "sun_zenith_deg,view_zenith_deg,relative_azimuth_deg,depth_m,occlusion\n" + \
              "".join("%r,%r,%r,%r,%r\n" % p for p in cls.fog_points)
        points_csv = c.write("fog_points.csv", csv)
        cls.fog_reference = {}
        for sky in ("clear", "hazed"):
            out_csv = c.path("fog_%s.csv" % sky)
            r = run([tool("fog-fit"), "eval", os.path.join(cls.out, "fog", "fog_%s.json" % sky), "--points", points_csv,
                     "-o", out_csv])
            assert r.returncode == 0, r.stderr
            with open(out_csv) as f:
                rows = [l.strip().split(",") for l in f if l.strip() and not l.startswith("#")]
            head = rows[0]
            cls.fog_reference[sky] = [dict(zip(head, map(float, row))) for row in rows[1:]]

        # The browser run: one page load, every measurement (tests/viewer/drive.mjs).
        plan = {
            "domes": [{"name": n, "haziness": h, "cloudiness": cl, "sun_zenith_deg": [90 - e for e in SUN_ELEVATIONS_DEG],
                       "width": DOME[0], "height": DOME[1]} for n, h, cl in VIEWS],
            "display": [{"name": n, "haziness": h, "cloudiness": cl, "sun_zenith_deg": 90 - e, "width": DOME[0], "height": DOME[1],
                         "white_cd_m2": white} for n, h, cl, e, white in DISPLAY_VIEWS],
            "weights": [[h, cl] for _, h, cl in VIEWS] + [[0.0, 0.1], [0.0, 0.4], [1.0, 1.0]],
            "fog": [{"sky": s, "points": [dict(zip(["sun_zenith_deg", "view_zenith_deg", "relative_azimuth_deg", "depth_m",
                                                    "occlusion"], p)) for p in cls.fog_points]} for s in ("clear", "hazed")],
            "screenshots": SCREENSHOTS,
            "width": 480, "height": 270,
        }
        cls.shots = os.path.join(cls.out, "viewer")
        cls.result = drive(cls.out, plan, cls.shots, c.path("drive"))

    @classmethod
    def tearDownClass(cls):
        cls.case.tearDown()

    def test_page_loads_compiles_and_renders_without_errors(self):
        r = self.result
        self.assertEqual(r["errors"], [], r["errors"])
        self.assertEqual(r["gl_error"], 0)
        self.assertEqual(sorted(r["names"]), sorted(SKIES))
        self.assertEqual(sorted(r["fog_skies"]), sorted(SKIES))
        self.assertTrue(r["has_clouds"])
        print("\nrenderer:", r["renderer"])

    def test_weather_weights_are_the_documented_ladder(self):
        for (h, c), got in zip(self.result["plan_weights"], self.result["weights"]):
            want = weather_weights(h, c, self.cloudy)
            got = {k: v for k, v in got.items() if v > 0}
            self.assertEqual(sorted(got), sorted(want), (h, c))
            for k in want:
                self.assertAlmostEqual(got[k], want[k], places=12, msg=(h, c, k))
        self.assertAlmostEqual(sum(weather_weights(0.3, 0.05, self.cloudy).values()), 1.0, places=12)

    def test_dome_views_match_the_reference_decoder(self):
        k = self.result["luminance_from_rgb"]
        w, h = DOME
        lines = []
        for view in self.result["domes"]:
            ref = self.reference[view["name"]]
            for i, e in enumerate(SUN_ELEVATIONS_DEG):
                page = view["views"][i]
                zs = math.radians(90 - e)
                sun = (math.sin(zs), 0.0, math.cos(zs))
                errs = []
                for y in range(h):
                    for x in range(w):
                        d = dome_direction(x, y, w, h)
                        if math.degrees(math.acos(max(-1, min(1, sum(a * b for a, b in zip(d, sun)))))) < SUN_CONE_DEG:
                            continue
                        p = ((y + i * h) * w + x) * 3
                        q = (y * w + x) * 3
                        yr = k[0] * ref[p] + k[1] * ref[p + 1] + k[2] * ref[p + 2]
                        yp = k[0] * page[q] + k[1] * page[q + 1] + k[2] * page[q + 2]
                        self.assertTrue(math.isfinite(yp), (view["name"], e, x, y))
                        self.assertGreater(yr, 0.0)
                        errs.append(yp / yr - 1)
                rms = math.sqrt(sum(x * x for x in errs) / len(errs))
                mx = max(abs(x) for x in errs)
                lines.append("%-16s sun %+3d deg: RMS %.4f %%, max %.4f %% (%d directions)" % (view["name"], e, 100 * rms, 100 * mx,
                                                                                              len(errs)))
                self.assertLessEqual(rms, RMS_TOLERANCE, lines[-1])
                self.assertLessEqual(mx, MAX_TOLERANCE, lines[-1])
        print("\n" + "\n".join(lines))

    def test_display_view_matches_the_ocio_cpu_preview(self):
        # OCIO's GLSL (luts/display.json) on the GPU against OCIO's CPU processor (the PNG previews'
        # path) on the same decoded radiance: every 8-bit code within one step (the radiance
        # differs by the float32 decode, ~1e-6, and a value can fall either side of a rounding
        # boundary), and almost all equal.
        for res in self.result["display"]:
            w, h, ch, px = self.display_png[res["name"]]
            self.assertEqual((w, h, ch), (DOME[0], DOME[1], 3))
            diff = [abs(a - b) for a, b in zip(res["codes"], px)]
            self.assertEqual(len(diff), w * h * 3)
            same = sum(1 for d in diff if d == 0) / len(diff)
            print("\ndisplay %-9s max |code difference| %d, %.2f %% equal" % (res["name"], max(diff), 100 * same))
            self.assertLessEqual(max(diff), 1, res["name"])
            self.assertGreater(same, 0.98, res["name"])
            self.assertGreater(len(set(px)), 20, "the %s preview is not a picture" % res["name"])

    def test_fog_points_match_the_reference_evaluator(self):
        k = self.result["luminance_from_rgb"]
        for res in self.result["fog"]:
            ref = self.fog_reference[res["sky"]]
            errs, tmax = [], 0.0
            for p, got, want in zip(self.fog_points, res["values"], ref):
                yr = k[0] * want["fog_R_cd_m2"] + k[1] * want["fog_G_cd_m2"] + k[2] * want["fog_B_cd_m2"]
                yp = k[0] * got["inscattered"][0] + k[1] * got["inscattered"][1] + k[2] * got["inscattered"][2]
                if yr > 1e-3:
                    errs.append(yp / yr - 1)
                else:
                    self.assertLess(abs(yp - yr), 1e-3, p)
                for c, ch in enumerate("RGB"):
                    tmax = max(tmax, abs(got["transmittance"][c] - want["transmittance_" + ch]))
            rms = math.sqrt(sum(x * x for x in errs) / len(errs))
            mx = max(abs(x) for x in errs)
            msg = "fog %s: in-scattered RMS %.4f %%, max %.4f %% (%d points); transmittance max |diff| %.2e" % (
                res["sky"], 100 * rms, 100 * mx, len(errs), tmax)
            print("\n" + msg)
            self.assertLessEqual(rms, RMS_TOLERANCE, msg)
            self.assertLessEqual(mx, MAX_TOLERANCE, msg)
            self.assertLessEqual(tmax, 2e-3, msg)

    def test_screenshots_are_real_pictures(self):
        for shot in SCREENSHOTS:
            path = os.path.join(self.shots, shot["name"] + ".png")
            self.assertTrue(os.path.isfile(path), path)
            w, h, ch, px = png_pixels(path)
            self.assertEqual((w, h), (480, 270), path)
            lum = [sum(px[i:i + 3]) / 3 for i in range(0, len(px), ch)]
            mean = sum(lum) / len(lum)
            sd = math.sqrt(sum((v - mean) ** 2 for v in lum) / len(lum))
            self.assertGreater(mean, 3, "%s is black (mean %.1f)" % (path, mean))
            self.assertGreater(sd, 2, "%s is uniform (sd %.2f)" % (path, sd))
            stats = self.result["hdr"][shot["name"]]
            self.assertEqual(stats["non_finite"], 0, path)
            self.assertGreater(stats["max_luminance"], 0, path)


with open(os.path.join(SRC, "viewer", "presets.json")) as _f:
    SCREENSHOTS = json.load(_f)["presets"]  # noon, sunset, twilight, overcast, fog, clouds


def drive(outputs, plan, shots_dir, work):
    """Serves `outputs` and runs tests/viewer/drive.mjs with `plan`; returns its JSON result."""
    os.makedirs(work, exist_ok=True)
    os.makedirs(shots_dir, exist_ok=True)
    plan_path = os.path.join(work, "plan.json")
    with open(plan_path, "w") as f:
        json.dump(plan, f)
    result_path = os.path.join(work, "result.json")
    server = subprocess.Popen([sys.executable, os.path.join(SRC, "scripts", "view_server.py"), "--outputs", outputs,
                               "--port", "0", "--print-port", "--quiet"], stdout=subprocess.PIPE, text=True)
    try:
        port = int(server.stdout.readline().strip())
        r = run(["node", os.path.join(SRC, "tests", "viewer", "drive.mjs"), "--url", "http://127.0.0.1:%d/" % port,
                 "--plan", plan_path, "--shots", shots_dir, "--out", result_path], timeout=1500)
        assert r.returncode == 0, r.stdout + r.stderr
    finally:
        server.terminate()
        server.wait(timeout=10)
    with open(result_path) as f:
        return json.load(f)


if __name__ == "__main__":
    unittest.main()
