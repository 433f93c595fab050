"""CLI contract and behaviour of cumulus-map (runs the real binary): the cumulus map and the
coverage texture read back by ktx-parse (see test_noise_gen.py) and decoded by Python."""
import math
import os
import struct
import unittest

from skytest import SRC, CliContract, TempDirTestCase, panel_sheet, read_png, run, tool
from test_noise_gen import ktx_level, ktx_parse, png_size, read_bytes

CUMULUS = os.path.join(SRC, "clouds", "cumulus.yaml")
COVERAGE = os.path.join(SRC, "clouds", "coverage.yaml")


class CumulusMapCli(CliContract, TempDirTestCase):
    TOOL = "cumulus-map"

    def test_map_read_back_by_ktx_parse(self):
        out = self.path("map.ktx2")
        r = run([tool("cumulus-map"), CUMULUS, "-o", out, "--time-s", "600", "--exr", self.path("map.exr"),
                 "--preview", self.path("map.png"), "--depfile", out + ".d"])
        self.assertEqual(r.returncode, 0, r.stderr)
        info = ktx_parse(out)
        # A 2D 256 x 256 R8G8_UNORM texture (vkFormat 16): pixelDepth 0, no layers.
        self.assertEqual((info["vkFormat"], info["typeSize"]), (16, 1))
        self.assertEqual((info["pixelWidth"], info["pixelHeight"], info["pixelDepth"], info["layerCount"]), (256, 256, 0, 0))
        self.assertEqual([s["channelType"] for s in info["dfd"]["samples"]], [0, 1])
        self.assertEqual(info["keys"], sorted(info["keys"]))
        kv = info["keyValue"]
        self.assertEqual(kv["KTXorientation"], "ru")
        self.assertEqual(kv["skybake.time_s"], "600")
        self.assertEqual(kv["skybake.wind_m_s"], "8 3")
        # Texel sizes of the sinh mapping: 240 km / 256 texels, edge/centre ratio 4 (docs/clouds.md).
        centre, edge = float(kv["skybake.texel_size_m.centre"]), float(kv["skybake.texel_size_m.edge"])
        a = math.acosh(4.0)
        self.assertAlmostEqual(centre, 2.0 / 256 * 120e3 * a / math.sinh(a), places=6)
        self.assertAlmostEqual(edge / centre, 4.0, places=9)
        level = ktx_level(out, info)
        self.assertEqual(len(level), 256 * 256 * 2)
        density, ctype = level[0::2], level[1::2]
        # Cloud cover 0.45 is a statistic of the whole (infinite) field; a 240 km window holds only
        # ~6 x 6 first-octave cells (40 km), so expect it loosely here (the law is tested in
        # tests/noise on 10^5 cells): some clear and some cloudy texels, both channels used.
        cloudy = sum(1 for d in density if d > 0) / len(density)
        self.assertGreater(cloudy, 0.1)
        self.assertLess(cloudy, 0.9)
        self.assertGreater(max(ctype) - min(ctype), 100)
        # The labelled preview: density and type panels of 256 x 256, north up (row y = texel row 255 - y).
        w, h, origin = panel_sheet(2, 1, 256, 256, 2, 2)
        pw, ph, _, rows = read_png(self.path("map.png"))
        self.assertEqual((pw, ph), (w, h))
        for p in range(2):
            x0, y0 = origin(0, p)
            for j in range(0, 256, 7):
                for i in range(0, 256, 5):
                    self.assertEqual(rows[y0 + 255 - j][3 * (x0 + i)], level[(j * 256 + i) * 2 + p], (p, i, j))
        oiio = run(["oiiotool", "--info", "-v", self.path("map.exr")])
        self.assertEqual(oiio.returncode, 0, oiio.stderr)
        self.assertIn("256 x  256", oiio.stdout)

    def test_maps_at_two_times_are_shifted_copies(self):
        # Wind (8, 3) m/s for 5 000 s moves the weather 40 km east and 15 km north. Near the centre
        # (texels of ~0.5 km) the density at texel p of the later map equals the earlier map's
        # density at p - (40, 15) km, to within UNORM8 and interpolation error.
        a, b = self.path("a.exr"), self.path("b.exr")
        self.assertEqual(run([tool("cumulus-map"), CUMULUS, "-o", self.path("a.ktx2"), "--exr", a, "--time-s", "0"]).returncode, 0)
        self.assertEqual(run([tool("cumulus-map"), CUMULUS, "-o", self.path("b.ktx2"), "--exr", b, "--time-s", "5000"]).returncode, 0)
        la = ktx_level(self.path("a.ktx2"), ktx_parse(self.path("a.ktx2")))
        lb = ktx_level(self.path("b.ktx2"), ktx_parse(self.path("b.ktx2")))
        n, R, ratio = 256, 120e3, 4.0
        k = math.acosh(ratio)

        def world(i):
            return R * math.sinh(k * (2.0 * (i + 0.5) / n - 1.0)) / math.sinh(k)

        def texel(x):
            return (math.asinh(x * math.sinh(k) / R) / k + 1.0) * 0.5 * n - 0.5

        def sample(level, x, y):
            tx, ty = texel(x), texel(y)
            i, j = int(math.floor(tx)), int(math.floor(ty))
            fx, fy = tx - i, ty - j
            v = lambda ii, jj: level[2 * (jj * n + ii)]
            return ((1 - fx) * (1 - fy) * v(i, j) + fx * (1 - fy) * v(i + 1, j) + (1 - fx) * fy * v(i, j + 1) + fx * fy * v(i + 1, j + 1))

        err, change, count = 0.0, 0.0, 0
        for j in range(100, 156, 2):
            for i in range(100, 156, 2):
                x, y = world(i), world(j)
                e = lb[2 * (j * n + i)] - sample(la, x - 40e3, y - 15e3)
                err += e * e
                change += (lb[2 * (j * n + i)] - la[2 * (j * n + i)]) ** 2
                count += 1
        self.assertGreater(change / count, 100.0)  # the pattern really moved (codes differ by > 10 RMS)
        self.assertLess(math.sqrt(err / count), 0.1 * math.sqrt(change / count))

    def test_coverage_texture_read_back_by_ktx_parse(self):
        out = self.path("coverage.ktx2")
        r = run([tool("cumulus-map"), "--product", "coverage", COVERAGE, "-o", out, "--exr", self.path("c.exr"),
                 "--preview", self.path("c.png")])
        self.assertEqual(r.returncode, 0, r.stderr)
        info = ktx_parse(out)
        # A 2D array: 256 x 128, pixelDepth 0, 3 layers (humilis, mediocris, congestus), RGBA8.
        self.assertEqual((info["vkFormat"], info["pixelWidth"], info["pixelHeight"], info["pixelDepth"], info["layerCount"]),
                         (37, 256, 128, 0, 3))
        self.assertEqual(info["keyValue"]["skybake.layers"], "humilis mediocris congestus")
        level = ktx_level(out, info)
        self.assertEqual(len(level), 256 * 128 * 3 * 4)

        def texel(layer, i, j, c):
            return level[((layer * 128 + j) * 256 + i) * 4 + c]

        # Column 0 is density 0: no height modulation and no noise weight at any altitude.
        self.assertTrue(all(texel(l, 0, j, c) == 0 for l in range(3) for j in range(128) for c in range(3)))
        # Congestus at full density reaches 7 km: row of 7 km = (7 - 0.5) / 8 * 127 = 103.2.
        top = max(j for j in range(128) if texel(2, 255, j, 0) > 0)
        self.assertEqual(top, 103)
        # One row of 4 channel panels (256 x 128, altitude up) per cloud type; 1-line headers.
        w, h, origin = panel_sheet(4, 3, 256, 128, 2, 1)
        pw, ph, _, rows = read_png(self.path("c.png"))
        self.assertEqual((pw, ph), (w, h))
        for layer in range(3):
            for c in range(4):
                x0, y0 = origin(layer, c)
                for j in range(0, 128, 9):
                    for i in range(0, 256, 11):
                        self.assertEqual(rows[y0 + 127 - j][3 * (x0 + i)], texel(layer, i, j, c), (layer, c, i, j))

    def test_same_bytes_at_any_thread_count(self):
        for product, src in (("map", CUMULUS), ("coverage", COVERAGE)):
            outs = []
            for threads in ("1", "2"):
                base = self.path(product + threads)
                r = run([tool("cumulus-map"), "--threads", threads, "--product", product, src, "-o", base + ".ktx2",
                         "--exr", base + ".exr", "--preview", base + ".png"])
                self.assertEqual(r.returncode, 0, r.stderr)
                outs.append([read_bytes(base + ext) for ext in (".ktx2", ".exr", ".png")])
            self.assertEqual(outs[0], outs[1], product)

    def test_aliasing_weather_is_reported_word_for_word(self):
        with open(CUMULUS) as f:
            text = f.read()
        bad = self.write("bad.yaml", text.replace("feature_size_km: 40, octaves: 4", "feature_size_km: 40, octaves: 6"))
        out = self.path("never.ktx2")
        r = run([tool("cumulus-map"), bad, "-o", out, "--exr", self.path("never.exr")])
        self.assertEqual(r.returncode, 1)
        line = text[:text.index("density: {")].count("\n") + 1
        self.assertEqual(r.stderr, "cumulus-map: %s:%d: key 'weather.density': the finest density octave has 1.25 km cells, "
                                   "less than two texels at the map edge (2 x 1.998 km): it would alias; use fewer octaves, "
                                   "a larger feature_size_km or a smaller edge_to_centre_texel_ratio\n" % (bad, line))
        self.assertEqual(sorted(os.listdir(self.tmp)), ["bad.yaml"])

    def test_bad_coverage_curve_is_reported_word_for_word(self):
        with open(COVERAGE) as f:
            text = f.read()
        bad = self.write("bad.yaml", text.replace("low_frequency: [[0, 1.0], [1, 0.7]]", "low_frequency: [[0, 1.0], [1, 1.7]]"))
        r = run([tool("cumulus-map"), "--product", "coverage", bad, "-o", self.path("x.ktx2")])
        self.assertEqual(r.returncode, 1)
        line = text[:text.index("low_frequency: [[0, 1.0], [1, 0.7]]")].count("\n") + 1
        self.assertEqual(r.stderr, "cumulus-map: %s:%d: key 'types[0].low_frequency[1][1]': expected a number from 0 to 1, got \"1.7\"\n"
                         % (bad, line))

    def test_bad_parameters_are_usage_errors(self):
        for args, message in (
            (["--product", "coverage", COVERAGE, "-o", self.path("x.ktx2"), "--time-s", "5"],
             "cumulus-map: --time-s applies to --product map only\n"),
            (["--product", "cloud", CUMULUS, "-o", self.path("x.ktx2")], None),
            (["--time-s", "soon", CUMULUS, "-o", self.path("x.ktx2")], None),
        ):
            r = run([tool("cumulus-map")] + args)
            self.assertEqual(r.returncode, 2, r.stderr)
            self.assertTrue(r.stderr.startswith("cumulus-map: "), r.stderr)
            if message:
                self.assertTrue(r.stderr.startswith(message), r.stderr)
        self.assertFalse(os.path.exists(self.path("x.ktx2")))


if __name__ == "__main__":
    unittest.main()
