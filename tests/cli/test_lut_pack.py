"""CLI contract and behaviour of lut-pack (runs the real binaries).

Inputs are sky-render renders of an aerosol-free copy of clear.yaml (no Mie tables needed) on a
reduced GT7 set: 4x8 texels x 5 slices (gt7:3+2), method single at low quality, 7 wavelengths.
The outputs are read by programs that share no code with skybake: the npm package ktx-parse
(KTX2), Python's struct (DDS headers field by field, R11G11B10F texels decoded here from the
format's definition) and OpenImageIO's oiiotool (EXR).
"""
import json
import os
import re
import shutil
import struct
import tempfile
import unittest

from skytest import SRC, CliContract, TempDirTestCase, exr_attributes, read_png, run, tool
from test_noise_gen import ktx_level, ktx_parse

CLEAR = os.path.join(SRC, "atmospheres", "clear.yaml")


def no_aerosol_atmosphere(path):
    """clear.yaml without its aerosol layer, with absolute data paths."""
    with open(CLEAR) as f:
        text = f.read()
    text = re.sub(r"\naerosols:\n(  .*\n|    .*\n)*", "\n", text)
    text = text.replace("file: data/", "file: %s/" % os.path.join(SRC, "atmospheres", "data"))
    text = text.replace("name: clear", "name: plain")
    with open(path, "w") as f:
        f.write(text)
    return path


def ufloat(code, mantissa_bits):
    """R11G11B10F channel value by the format's definition (Vulkan / KDF 1.3 section 10.3)."""
    e, m = code >> mantissa_bits, code & ((1 << mantissa_bits) - 1)
    if e == 0:
        return m * 2.0 ** (-14 - mantissa_bits)
    return (1 + m / 2.0 ** mantissa_bits) * 2.0 ** (e - 15)


def texels(level):
    out = []
    for (w,) in struct.iter_unpack("<I", level):
        out.append((ufloat(w & 0x7FF, 6), ufloat((w >> 11) & 0x7FF, 6), ufloat(w >> 22, 5)))
    return out


def render(atm, out, size="4x8", extra=None):
    args = [tool("sky-render"), "render", atm, "--method", "single", "--quality", "low", "--wavelengths", "400:700:50",
            "--quiet", "-o", out]
    args += extra if extra is not None else ["--mapping", "gt7", "--size", size, "--time-mapping", "gt7:3+2"]
    r = run(args)
    assert r.returncode == 0, r.stderr
    return out


class LutPackCli(CliContract, TempDirTestCase):
    TOOL = "lut-pack"

    @classmethod
    def setUpClass(cls):
        cls.shared = tempfile.mkdtemp(prefix="skybake_lutpack_")
        atm = no_aerosol_atmosphere(os.path.join(cls.shared, "plain.yaml"))
        cls.sky_a = render(atm, os.path.join(cls.shared, "a.exr"))
        cls.sky_b = render(atm, os.path.join(cls.shared, "b.exr"), size="2x4")
        cls.equirect = render(atm, os.path.join(cls.shared, "direct.exr"),
                              extra=["--size", "16x8", "--sun-zenith-deg", "45,89.5"])

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.shared, ignore_errors=True)

    def pack(self, out_dir, *extra, skies=None):
        skies = skies or ["sunny=" + self.sky_a, "cloudy=" + self.sky_b]
        return run([tool("lut-pack"), "pack"] + skies + ["-o", os.path.join(out_dir, "report.json")] + list(extra))

    def test_ktx2_files_read_back_by_ktx_parse(self):
        r = self.pack(self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        info = ktx_parse(self.path("sky_sunny.ktx2"))
        self.assertEqual((info["vkFormat"], info["typeSize"]), (122, 4))  # B10G11R11_UFLOAT_PACK32
        self.assertEqual((info["pixelWidth"], info["pixelHeight"], info["pixelDepth"], info["layerCount"]), (4, 8, 5, 0))
        self.assertEqual((info["faceCount"], info["levelCount"], info["supercompressionScheme"]), (1, 1, 0))
        dfd = info["dfd"]
        self.assertEqual((dfd["colorModel"], dfd["colorPrimaries"], dfd["transferFunction"]), (1, 1, 1))
        self.assertEqual([(s["bitOffset"], s["bitLength"], s["channelType"]) for s in dfd["samples"]],
                         [(0, 10, 0x80), (11, 10, 0x81), (22, 9, 0x82)])
        self.assertEqual(info["keys"], sorted(info["keys"]))
        kv = info["keyValue"]
        self.assertTrue(kv["KTXwriter"].startswith("skybake lut-pack "))
        self.assertEqual(kv["KTXorientation"], "rdi")
        self.assertEqual(kv["skybake.scale"], "1")
        self.assertEqual(kv["skybake.colorspace"], "Linear Rec.2020")
        self.assertEqual(kv["skybake.time_mapping.name"], "gt7:3+2")
        self.assertEqual(kv["skybake.time_interpolation"], "geometric")
        self.assertEqual(len(kv["skybake.slice_zenith_deg"].split()), 5)
        self.assertIn("a.exr xxh3:", kv["skybake.inputs"])
        self.assertNotIn("b.exr", kv["skybake.inputs"])  # a sky's files name only its own render
        self.assertEqual(info["levels"][0]["byteLength"], 4 * 8 * 5 * 4)
        array = ktx_parse(self.path("sky_sunny_array.ktx2"))
        self.assertEqual((array["pixelDepth"], array["layerCount"]), (0, 5))
        self.assertEqual(array["keyValue"]["KTXorientation"], "rd")
        self.assertEqual(ktx_level(self.path("sky_sunny.ktx2"), info), ktx_level(self.path("sky_sunny_array.ktx2"), array))
        # The other LUTs: one row per basis sky, in the command line's order.
        for name, width in (("transmittance", 181), ("sun", 5), ("ambient", 5)):
            t = ktx_parse(self.path(name + ".ktx2"))
            self.assertEqual((t["vkFormat"], t["pixelWidth"], t["pixelHeight"], t["pixelDepth"]), (122, width, 2, 0), name)
            self.assertEqual(t["keyValue"]["skybake.rows"], "sunny cloudy")

    def test_dds_headers_field_by_field(self):
        self.assertEqual(self.pack(self.tmp).returncode, 0)
        with open(self.path("sky_sunny.dds"), "rb") as f:
            dds = f.read()
        self.assertEqual(dds[:4], b"DDS ")
        size, flags, height, width, pitch, depth, mips = struct.unpack_from("<7I", dds, 4)
        self.assertEqual((size, height, width, pitch, depth, mips), (124, 8, 4, 16, 5, 1))
        # DDSD_CAPS | HEIGHT | WIDTH | PITCH | PIXELFORMAT | MIPMAPCOUNT | DEPTH
        self.assertEqual(flags, 0x1 | 0x2 | 0x4 | 0x8 | 0x1000 | 0x20000 | 0x800000)
        self.assertEqual(struct.unpack_from("<11I", dds, 32), (0,) * 11)
        pf_size, pf_flags = struct.unpack_from("<2I", dds, 76)
        self.assertEqual((pf_size, pf_flags, dds[84:88]), (32, 0x4, b"DX10"))
        caps, caps2 = struct.unpack_from("<2I", dds, 108)
        self.assertEqual((caps, caps2), (0x1000, 0x200000))  # DDSCAPS_TEXTURE, DDSCAPS2_VOLUME
        dxgi, dim, misc, array_size, misc2 = struct.unpack_from("<5I", dds, 128)
        self.assertEqual((dxgi, dim, misc, array_size, misc2), (26, 4, 0, 1, 0))  # R11G11B10_FLOAT, TEXTURE3D
        self.assertEqual(len(dds), 148 + 4 * 8 * 5 * 4)
        with open(self.path("sky_sunny.ktx2"), "rb") as f:
            self.assertEqual(dds[148:], ktx_level(self.path("sky_sunny.ktx2"), ktx_parse(self.path("sky_sunny.ktx2"))))
        with open(self.path("sun.dds"), "rb") as f:
            sun = f.read()
        self.assertEqual(struct.unpack_from("<5I", sun, 128), (26, 3, 0, 1, 0))  # a plain 2D texture
        self.assertEqual(struct.unpack_from("<I", sun, 112)[0], 0)

    def test_texels_decode_to_the_inspection_exr_and_the_report(self):
        self.assertEqual(self.pack(self.tmp).returncode, 0)
        ours = texels(ktx_level(self.path("sky_sunny.ktx2"), ktx_parse(self.path("sky_sunny.ktx2"))))
        self.assertTrue(all(v >= 0 for t in ours for v in t))
        self.assertGreater(max(t[1] for t in ours), 100.0)  # a daylight sky, cd/m^2 as is (scale 1)
        dump = run(["oiiotool", "--dumpdata", self.path("sky_sunny.exr")])  # channels R, G, B, then the rest
        self.assertEqual(dump.returncode, 0, dump.stderr)
        values = [tuple(float(x) for x in m.group(1).split()[:3])
                  for m in re.finditer(r"^\s*Pixel \(\d+, \d+\):\s*(.*)$", dump.stdout, re.M)]
        self.assertEqual(len(values), 4 * 8 * 5)
        for (r, g, b), t in zip(values, ours):
            for a, e in zip((r, g, b), t):
                self.assertAlmostEqual(a, e, delta=1e-6 * max(1.0, e))
        with open(self.path("report.json")) as f:
            report = json.load(f)
        self.assertEqual(report["budget"]["sky_lut_texel_bytes"], 4 * 8 * 5 * 4 + 2 * 4 * 5 * 4)
        self.assertTrue(report["budget"]["within"])
        pack = report["skies"][0]["pack"]
        self.assertLessEqual(pack["luminance_relative_error"]["max"], 0.01)
        self.assertLessEqual(pack["channel_relative_error_max"]["G"], 2.0 ** -7)
        self.assertEqual(report["time_mapping"]["name"], "gt7:3+2")
        self.assertEqual(report["files_bytes"]["sky_sunny.dds"], os.path.getsize(self.path("sky_sunny.dds")))

    def test_contact_sheet_shows_each_sky_at_each_sun_elevation(self):
        # Layout (lut/contact_sheet.h): 998 px wide (a label column and 5 cells of 160 px, 16 px
        # apart), 2 x 12 + 84 + 76 + rows x 168 - 8 px high.
        self.assertEqual(self.pack(self.path("two")).returncode, 0)
        three = self.pack(self.path("three"), skies=["sunny=" + self.sky_a, "cloudy=" + self.sky_b, "again=" + self.sky_a])
        self.assertEqual(three.returncode, 0, three.stderr)
        w, h, channels, rows = read_png(self.path("two", "contact_sheet.png"))
        self.assertEqual((w, h, channels), (998, 24 + 84 + 76 + 2 * 168 - 8, 3))
        w3, h3, _, rows3 = read_png(self.path("three", "contact_sheet.png"))
        self.assertEqual((w3, h3), (998, h + 168))  # one more row of cells

        def cell(rows, r, c):
            """The pixels of the inner disc (radius 60 of the 80 px fisheye) of row r, column c."""
            x0, y0 = 12 + 110 + c * 176, 12 + 84 + 76 + r * 168
            out = []
            for y in range(y0 + 20, y0 + 140):
                for x in range(x0 + 20, x0 + 140):
                    if (x - x0 - 80) ** 2 + (y - y0 - 80) ** 2 <= 60 ** 2:
                        out.append(tuple(rows[y][3 * x:3 * x + 3]))
            return out

        for r in range(2):
            day, twilight = cell(rows, r, 0), cell(rows, r, 4)  # sun 60 and -4 deg
            mean = [sum(p[k] for p in day) / len(day) for k in range(3)]
            self.assertGreater(sum(mean) / 3, 40, "the day sky is not dark")
            self.assertGreater(mean[2], mean[0], "the day sky is blue")
            self.assertGreater(len(set(day)), 20, "the day sky is not uniform")
            self.assertGreater(len(set(twilight)), 20, "the twilight sky is not uniform")
            diff = sum(abs(a - b) for p, q in zip(day, twilight) for a, b in zip(p, q)) / (3 * len(day))
            self.assertGreater(diff, 10, "sun 60 and -4 deg look alike")
        # The same sky in a third row is drawn alike: the rows are the skies, nothing else.
        self.assertEqual(cell(rows3, 2, 1), cell(rows3, 0, 1))
        # The exposure is per column, shared by the skies in it: the 4x8 and the 2x4 LUT of the same
        # atmosphere at sun 20 deg are within a few codes of each other on average.
        a, b = cell(rows, 0, 1), cell(rows, 1, 1)
        self.assertLess(abs(sum(map(sum, a)) / len(a) - sum(map(sum, b)) / len(b)), 3 * 40)
        # The title, headers and scales are drawn: text-coloured pixels above the cells.
        header = rows[12:12 + 84 + 76]
        self.assertGreater(sum(1 for row in header for x in range(0, 3 * w, 3) if row[x] > 200), 500)

    def test_missing_font_is_bad_input_and_writes_nothing(self):
        font = self.path("none", "NoSuchFont.ttf")
        r = run([tool("lut-pack"), "pack", "sunny=" + self.sky_a, "-o", self.path("report.json")],
                env={"SKYBAKE_FONT": font})
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertEqual(r.stderr.strip(), "lut-pack: %s: font file not found (the labels of the PNG pictures need a "
                                           "TrueType font: install Debian fonts-dejavu-core, e.g. with scripts/setup, or "
                                           "name one with SKYBAKE_FONT)" % font)
        self.assertEqual(os.listdir(self.tmp), [])

    def test_same_bytes_at_any_thread_count(self):
        outs = {}
        for threads in ("1", "2"):
            d = self.path("t" + threads)
            r = run([tool("lut-pack"), "--threads", threads, "pack", "sunny=" + self.sky_a, "cloudy=" + self.sky_b,
                     "-o", os.path.join(d, "report.json")])
            self.assertEqual(r.returncode, 0, r.stderr)
            outs[threads] = {f: open(os.path.join(d, f), "rb").read() for f in sorted(os.listdir(d))}
        self.assertEqual(outs["1"], outs["2"])
        self.assertGreater(len(outs["1"]), 10)
        self.assertIn("contact_sheet.png", outs["1"])

    def test_a_render_on_another_mapping_is_bad_input_and_writes_nothing(self):
        r = self.pack(self.tmp, skies=["sunny=" + self.sky_a, "flat=" + self.equirect])
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertEqual(r.stderr.strip(), "lut-pack: %s: part 'sky.sza_045.00' is not a slice of the GT7 time mapping: "
                                           "render with sky-render render --mapping gt7 --time-mapping gt7" % self.equirect)
        self.assertEqual(os.listdir(self.tmp), [])

    def test_missing_render_is_bad_input(self):
        r = self.pack(self.tmp, skies=["sunny=" + self.path("nope.exr")])
        self.assertEqual(r.returncode, 1)
        self.assertTrue(r.stderr.startswith("lut-pack: %s:" % self.path("nope.exr")), r.stderr)
        self.assertEqual(os.listdir(self.tmp), [])

    def test_bad_parameters_are_usage_errors(self):
        r = self.pack(self.tmp, skies=[self.sky_a])
        self.assertEqual(r.returncode, 2)
        self.assertIn("expected NAME=SKY.exr", r.stderr)
        r = self.pack(self.tmp, skies=["Sunny=" + self.sky_a])
        self.assertEqual(r.returncode, 2)
        r = self.pack(self.tmp, "--budget-mib", "0.0001")
        self.assertEqual(r.returncode, 2)
        self.assertIn("--budget-mib 0.0001: the 2 sky LUTs take 800 bytes", r.stderr)
        r = self.pack(self.tmp, "--sky-exposure-stops", "0.5")
        self.assertEqual(r.returncode, 2)
        self.assertEqual(os.listdir(self.tmp), [])

    def test_exposure_scale_is_stored_and_undone_by_the_decoder(self):
        self.assertEqual(self.pack(self.path("e0")).returncode, 0)
        self.assertEqual(self.pack(self.path("e4"), "--sky-exposure-stops", "-4").returncode, 0)
        kv = ktx_parse(self.path("e4", "sky_sunny.ktx2"))["keyValue"]
        self.assertEqual(kv["skybake.scale"], "0.0625")
        for d in ("e0", "e4"):
            r = run([tool("lut-pack"), "check", self.path(d, "sky_sunny.ktx2"), "--direct", self.equirect,
                     "-o", self.path(d, "check.json")])
            self.assertEqual(r.returncode, 0, r.stderr)
        with open(self.path("e0", "check.json")) as f:
            a = json.load(f)
        with open(self.path("e4", "check.json")) as f:
            b = json.load(f)
        self.assertEqual([s["sun_zenith_deg"] for s in a["slices"]], [45.0, 89.5])
        for sa, sb in zip(a["slices"], b["slices"]):  # the same sky within the 16x coarser quantisation
            self.assertAlmostEqual(sa["rms_upper"], sb["rms_upper"], delta=0.01)
        self.assertIn("geometric time interpolation", a["luts"])

    def test_check_blends_basis_skies_with_weights(self):
        self.assertEqual(self.pack(self.tmp).returncode, 0)
        one = self.path("one.json")
        half = self.path("half.json")
        lut = self.path("sky_sunny.ktx2")
        self.assertEqual(run([tool("lut-pack"), "check", lut, "--direct", self.equirect, "-o", one]).returncode, 0)
        self.assertEqual(run([tool("lut-pack"), "check", lut + ":0.5", lut + ":0.5", "--direct", self.equirect,
                              "-o", half]).returncode, 0)
        with open(one) as f:
            a = json.load(f)
        with open(half) as f:
            b = json.load(f)
        self.assertAlmostEqual(a["rms_upper_all"], b["rms_upper_all"], places=6)
        r = run([tool("lut-pack"), "check", lut + ":x", "--direct", self.equirect, "-o", half])
        self.assertEqual(r.returncode, 2)

    def dome(self, out, *luts, extra=()):
        r = run([tool("lut-pack"), "decode"] + list(luts) + ["--sun-zenith-deg", "30,89.5,95", "--size", "8x4", "-o", out]
                + list(extra))
        self.assertEqual(r.returncode, 0, r.stderr)
        dump = run(["oiiotool", "--dumpdata", out]).stdout
        return [float(v) for line in dump.splitlines() if line.strip().startswith("Pixel")
                for v in line.split(":")[1].split()[:3]]

    def test_decode_writes_domes_and_blends_linearly(self):
        # The weighted blend is sum_k w_k L_k (lut/decoder.h BlendRadiance): a 0.25 / 0.75 blend
        # of two skies equals the same sum of their single decodes; 3 sun angles stack 3 domes.
        self.assertEqual(self.pack(self.tmp).returncode, 0)
        a, b = self.path("sky_sunny.ktx2"), self.path("sky_cloudy.ktx2")
        da = self.dome(self.path("a.exr"), a)
        db = self.dome(self.path("b.exr"), b)
        mix = self.dome(self.path("mix.exr"), a + ":0.25", b + ":0.75")
        self.assertEqual(len(da), 8 * 4 * 3 * 3)
        self.assertGreater(min(da), 0.0)
        for x, y, m in zip(da, db, mix):
            self.assertAlmostEqual(m, 0.25 * x + 0.75 * y, delta=2e-6 * max(1.0, m))
        kv = exr_attributes(self.path("a.exr"))
        self.assertEqual(kv["skybake.sun_zenith_deg"], "30 89.5 95")
        self.assertIn("dome", kv["skybake.mapping"])
        # The 95 deg dome is below the last slice... of this 5-slice set (100 deg): still decoded, and darker.
        n = 8 * 4 * 3
        self.assertLess(sum(da[2 * n:]), sum(da[n:2 * n]))

    def test_decode_preview_and_bad_arguments(self):
        self.assertEqual(self.pack(self.tmp).returncode, 0)
        lut = self.path("sky_sunny.ktx2")
        png = self.path("dome.png")
        self.dome(self.path("d.exr"), lut, extra=["--preview", png, "--white-cd-m2", "5000"])
        with open(png, "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")
        for bad in (["--sun-zenith-deg", "nan"], ["--sun-zenith-deg", "181"], ["--sun-zenith-deg", "30", "--size", "0x4"],
                    ["--sun-zenith-deg", "30", "--preview", png], ["--sun-zenith-deg", "30", "--preview", png,
                                                                   "--white-cd-m2", "inf"]):
            out = self.path("bad.exr")
            r = run([tool("lut-pack"), "decode", lut, "-o", out] + bad)
            self.assertEqual(r.returncode, 2, (bad, r.stderr))
            self.assertTrue(r.stderr.startswith("lut-pack: "), r.stderr)
            self.assertFalse(os.path.exists(out), bad)
        r = run([tool("lut-pack"), "decode", lut + ":inf", "--sun-zenith-deg", "30", "-o", self.path("bad.exr")])
        self.assertEqual(r.returncode, 2, r.stderr)
        r = run([tool("lut-pack"), "decode", self.path("missing.ktx2"), "--sun-zenith-deg", "30", "-o", self.path("bad.exr")])
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn("missing.ktx2", r.stderr)

    def test_display_json_is_ocio_glsl_and_the_luminance_row(self):
        self.assertEqual(self.pack(self.tmp).returncode, 0)
        with open(self.path("display.json")) as f:
            d = json.load(f)
        self.assertIn("vec4 OCIODisplay(vec4 inPixel)", d["glsl"])
        self.assertEqual(d["input_colorspace"], "Linear Rec.2020")
        # ITU-R BT.2100 / BT.2020 luminance coefficients 0.2627, 0.6780, 0.0593 (Rec. ITU-R BT.2020-2, Table 4).
        for got, want in zip(d["luminance_from_rgb"], (0.2627, 0.6780, 0.0593)):
            self.assertAlmostEqual(got, want, places=4)


if __name__ == "__main__":
    unittest.main()
