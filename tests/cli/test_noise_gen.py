"""CLI contract and behaviour of noise-gen (runs the real binary).

The KTX2 output is read back by two programs that share no code with skybake: the npm package
ktx-parse (pinned, installed by scripts/setup into .tools/; its absence is a failure, not a skip)
and a few lines of Python below that decode the level with struct (half floats via format 'e').
The EXR is read by OpenImageIO's oiiotool.
"""
import hashlib
import json
import os
import struct
import subprocess
import unittest

from skytest import SRC, CliContract, TempDirTestCase, panel_sheet, read_png, run, tool

KTX_PARSE_DIR = os.path.join(SRC, ".tools", "node_modules", "ktx-parse")
LOW = os.path.join(SRC, "clouds", "noise_low.yaml")
HIGH = os.path.join(SRC, "clouds", "noise_high.yaml")

# Reads a KTX2 file with ktx-parse and prints what it found as JSON: header, DFD, key/value data
# (keys in file order, values as text), and each level's offset, length and SHA-256.
NODE_READER = r"""
import { readFileSync } from 'node:fs';
import { createHash } from 'node:crypto';
import { join } from 'node:path';
import { pathToFileURL } from 'node:url';
const [dir, file] = process.argv.slice(1);
const pkg = JSON.parse(readFileSync(join(dir, 'package.json'), 'utf8'));
const entry = (pkg.exports && pkg.exports['.'] && (pkg.exports['.'].default || pkg.exports['.'].import)) || pkg.module || pkg.main;
const { read } = await import(pathToFileURL(join(dir, entry)).href);
const bytes = new Uint8Array(readFileSync(file));
const c = read(bytes);
const text = (v) => typeof v === 'string' ? v : new TextDecoder().decode(v).replace(/\0$/, '');
const keyValue = {};
for (const k of Object.keys(c.keyValue)) keyValue[k] = text(c.keyValue[k]);
console.log(JSON.stringify({
  version: pkg.version,
  vkFormat: c.vkFormat, typeSize: c.typeSize, pixelWidth: c.pixelWidth, pixelHeight: c.pixelHeight,
  pixelDepth: c.pixelDepth, layerCount: c.layerCount, faceCount: c.faceCount, levelCount: c.levelCount,
  supercompressionScheme: c.supercompressionScheme,
  dfd: c.dataFormatDescriptor[0],
  keys: Object.keys(c.keyValue), keyValue,
  levels: c.levels.map(l => ({ byteOffset: l.levelData.byteOffset, byteLength: l.levelData.byteLength,
    uncompressedByteLength: Number(l.uncompressedByteLength),
    sha256: createHash('sha256').update(l.levelData).digest('hex') })),
}));
"""


def ktx_parse(path):
    """The file as ktx-parse reads it. Fails (never skips) when node or the package is missing:
    scripts/setup installs both."""
    if not os.path.isfile(os.path.join(KTX_PARSE_DIR, "package.json")):
        raise AssertionError("ktx-parse is not installed in %s: run scripts/setup" % KTX_PARSE_DIR)
    try:
        r = subprocess.run(["node", "--input-type=module", "-e", NODE_READER, KTX_PARSE_DIR, path],
                           capture_output=True, text=True, timeout=120)
    except FileNotFoundError:
        raise AssertionError("node is not installed: run scripts/setup")
    if r.returncode != 0:
        raise AssertionError("ktx-parse failed on %s: %s" % (path, r.stderr))
    return json.loads(r.stdout)


def ktx_level(path, info):
    """Level 0's bytes as sliced by Python at the offset ktx-parse reported, checked by hash."""
    data = read_bytes(path)
    lvl = info["levels"][0]
    level = data[lvl["byteOffset"]:lvl["byteOffset"] + lvl["byteLength"]]
    assert hashlib.sha256(level).hexdigest() == lvl["sha256"], "ktx-parse and Python disagree on the level bytes"
    assert len(data) == lvl["byteOffset"] + lvl["byteLength"], "bytes after the last level"
    return level


def read_bytes(path):
    with open(path, "rb") as f:
        return f.read()


def f32_bits_as_int32(x):
    return struct.unpack("<i", struct.pack("<f", x))[0]


def png_size(path):
    with open(path, "rb") as f:
        head = f.read(24)
    assert head[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    return struct.unpack(">II", head[16:24])


class NoiseGenCli(CliContract, TempDirTestCase):
    TOOL = "noise-gen"

    def test_low_frequency_volume_read_back_by_ktx_parse(self):
        out = self.path("low.ktx2")
        r = run([tool("noise-gen"), LOW, "-o", out, "--exr", self.path("low.exr"), "--preview",
                 self.path("low.png"), "--depfile", out + ".d"])
        self.assertEqual(r.returncode, 0, r.stderr)
        info = ktx_parse(out)
        self.assertEqual(info["version"], "2.0.0")
        # Header: VK_FORMAT_R16_SFLOAT (76), typeSize 2, a 128^3 3D texture, one level, no supercompression.
        self.assertEqual((info["vkFormat"], info["typeSize"]), (76, 2))
        self.assertEqual((info["pixelWidth"], info["pixelHeight"], info["pixelDepth"]), (128, 128, 128))
        self.assertEqual((info["layerCount"], info["faceCount"], info["levelCount"], info["supercompressionScheme"]), (0, 1, 1, 0))
        # DFD: RGBSDA, BT.709, linear; one 16-bit RED sample, FLOAT|SIGNED, -1.0 .. 1.0.
        dfd = info["dfd"]
        self.assertEqual((dfd["colorModel"], dfd["colorPrimaries"], dfd["transferFunction"]), (1, 1, 1))
        self.assertEqual(dfd["bytesPlane"][:1], [2])
        self.assertEqual(len(dfd["samples"]), 1)
        s = dfd["samples"][0]
        self.assertEqual((s["bitOffset"], s["bitLength"], s["channelType"]), (0, 15, 0xC0))
        self.assertEqual((s["sampleLower"], s["sampleUpper"]), (f32_bits_as_int32(-1.0), f32_bits_as_int32(1.0)))
        # Key/value data sorted by code point, with KTXwriter and the provenance.
        self.assertEqual(info["keys"], sorted(info["keys"]))
        self.assertTrue(info["keyValue"]["KTXwriter"].startswith("skybake noise-gen "))
        self.assertEqual(info["keyValue"]["skybake.tool"], "noise-gen")
        self.assertEqual(info["keyValue"]["skybake.channel.R.range"], "-1 1")
        self.assertIn("noise_low.yaml xxh3:", info["keyValue"]["skybake.inputs"])
        self.assertIn("normalize: zero_mean", info["keyValue"]["skybake.parameters"])
        # The level: 128^3 halves; its mean is 0 (GT7: normalised to zero mean) within 1e-3 and its
        # range [-1, 1] with an extreme at exactly +-1 - decoded here by Python's own binary16.
        self.assertEqual(info["levels"][0]["byteLength"], 128 ** 3 * 2)
        self.assertEqual(info["levels"][0]["byteOffset"] % 4, 0)
        values = struct.unpack("<%de" % (128 ** 3), ktx_level(out, info))
        mean = sum(values) / len(values)
        self.assertLess(abs(mean), 1e-3)
        self.assertGreaterEqual(min(values), -1.0)
        self.assertLessEqual(max(values), 1.0)
        self.assertEqual(max(-min(values), max(values)), 1.0)
        # The EXR (OpenImageIO) and the labelled PNG montage: 4 slices of 2 x 128 pixels, 3 title lines,
        # 2-line column headers.
        oiio = run(["oiiotool", "--info", "-v", self.path("low.exr")])
        self.assertEqual(oiio.returncode, 0, oiio.stderr)
        self.assertIn("128 x 16384", oiio.stdout)
        w, h, _ = panel_sheet(4, 1, 256, 256, 3, 2)
        self.assertEqual(png_size(self.path("low.png")), (w, h))
        with open(out + ".d") as f:
            self.assertIn("noise_low.yaml", f.read())

    def test_high_frequency_and_rgba_formats(self):
        out = self.path("high.ktx2")
        self.assertEqual(run([tool("noise-gen"), HIGH, "-o", out]).returncode, 0)
        info = ktx_parse(out)
        self.assertEqual((info["vkFormat"], info["typeSize"], info["pixelDepth"]), (9, 1, 32))  # R8_UNORM
        self.assertEqual(info["dfd"]["samples"][0]["sampleUpper"], 255)
        level = ktx_level(out, info)
        self.assertEqual((min(level), max(level)), (0, 255))  # min_max normalisation spans the codes
        rgba = self.write("rgba.yaml", "resolution: 16\ntile_size_km: 5\nseed: 3\nformat: rgba8_unorm\nnormalize: min_max\n"
                                       "channels:\n  - perlin_worley: {perlin: {frequency: 2}, worley: {frequency: 2}}\n"
                                       "  - worley: {frequency: 2}\n  - worley: {frequency: 4}\n  - perlin: {frequency: 8}\n")
        out = self.path("rgba.ktx2")
        r = run([tool("noise-gen"), rgba, "-o", out, "--preview", self.path("rgba.png")])
        self.assertEqual(r.returncode, 0, r.stderr)
        info = ktx_parse(out)
        self.assertEqual((info["vkFormat"], info["typeSize"]), (37, 1))  # R8G8B8A8_UNORM
        self.assertEqual([s["channelType"] for s in info["dfd"]["samples"]], [0, 1, 2, 15])
        self.assertEqual([s["bitOffset"] for s in info["dfd"]["samples"]], [0, 8, 16, 24])
        self.assertEqual(info["levels"][0]["byteLength"], 16 ** 3 * 4)
        level = ktx_level(out, info)
        # 4 channels x 4 slices of 2 x 16 texels, drawn 2 x 2 pixels per texel (N < 64).
        # The 3 title lines wrap to the 440 px width: the height grows by 16 px per extra line.
        pw, ph, channels, rows = read_png(self.path("rgba.png"))
        w, h, _ = panel_sheet(4, 4, 64, 64, 3, 2)
        self.assertEqual((pw, channels), (w, 3))
        self.assertEqual((ph - h) % 16, 0)
        self.assertGreater(ph, h)
        w, h, origin = panel_sheet(4, 4, 64, 64, 3 + (ph - h) // 16, 2)
        # Each panel is its slice's texels (min_max: value = code / 255), tiled 2 x 2; slice k = N/4 = 4.
        for c in range(4):
            x0, y0 = origin(c, 1)
            for j in range(32):
                for i in range(32):
                    code = level[((4 * 16 + j % 16) * 16 + i % 16) * 4 + c]
                    grey = rows[y0 + 2 * j][3 * (x0 + 2 * i)]
                    self.assertLessEqual(abs(grey - code), 1, (c, i, j))
        # Labels: text-coloured pixels in the title and headers, and left of the panels (y axis).
        self.assertGreater(sum(1 for row in rows[:origin(0, 0)[1]] for x in range(0, 3 * w, 3) if row[x] > 200), 100)
        self.assertGreater(sum(1 for row in rows for x in range(0, 3 * (origin(0, 0)[0] - 2), 3) if row[x] > 150), 50)

    def test_the_preview_needs_the_font_and_nothing_else_does(self):
        font = self.path("none", "NoSuchFont.ttf")
        out = self.path("high.ktx2")
        r = run([tool("noise-gen"), HIGH, "-o", out, "--preview", self.path("high.png")], env={"SKYBAKE_FONT": font})
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertTrue(r.stderr.startswith("noise-gen: %s: font file not found" % font), r.stderr)
        self.assertEqual(os.listdir(self.tmp), [])
        r = run([tool("noise-gen"), HIGH, "-o", out], env={"SKYBAKE_FONT": font})
        self.assertEqual(r.returncode, 0, r.stderr)

    def test_same_bytes_at_any_thread_count(self):
        outs = {}
        for threads in ("1", "2"):
            base = self.path("t" + threads)
            r = run([tool("noise-gen"), "--threads", threads, LOW, "-o", base + ".ktx2", "--exr", base + ".exr",
                     "--preview", base + ".png"])
            self.assertEqual(r.returncode, 0, r.stderr)
            outs[threads] = [read_bytes(base + ext) for ext in (".ktx2", ".exr", ".png")]
        self.assertEqual(outs["1"], outs["2"])

    def test_different_seed_gives_different_bytes(self):
        with open(HIGH) as f:
            text = f.read()
        other = self.write("other.yaml", text.replace("seed: 11", "seed: 12"))
        a, b = self.path("a.ktx2"), self.path("b.ktx2")
        self.assertEqual(run([tool("noise-gen"), HIGH, "-o", a]).returncode, 0)
        self.assertEqual(run([tool("noise-gen"), other, "-o", b]).returncode, 0)
        la, lb = ktx_level(a, ktx_parse(a)), ktx_level(b, ktx_parse(b))
        self.assertGreater(sum(x != y for x, y in zip(la, lb)), len(la) // 2)

    def test_bad_yaml_is_reported_with_file_and_line_and_writes_nothing(self):
        bad = self.write("bad.yaml", "resolution: 32\ntile_size_km: 1\nseed: 1\nformat: r8_unorm\nnormalize: zero_mean\n"
                                     "channels:\n  - worley: {frequency: 4, octaves: 3}\n")
        out = self.path("never.ktx2")
        r = run([tool("noise-gen"), bad, "-o", out, "--exr", self.path("never.exr"), "--preview", self.path("never.png")])
        self.assertEqual(r.returncode, 1)
        self.assertEqual(r.stderr, "noise-gen: %s:5: key 'normalize': r8_unorm stores values in [0, 1]: use min_max, "
                                   "or format r16_sfloat for zero_mean\n" % bad)
        self.assertEqual(os.listdir(self.tmp), ["bad.yaml"])

    def test_every_problem_is_reported(self):
        bad = self.write("bad.yaml", "resolution: 3\ntile_size_km: -1\nseed: 1\nformat: r16_sfloat\nnormalise: none\n"
                                     "channels:\n  - perlin: {frequency: 1, gain: 2}\n")
        r = run([tool("noise-gen"), bad, "-o", self.path("x.ktx2")])
        self.assertEqual(r.returncode, 1)
        self.assertEqual(r.stderr.splitlines(), [
            "noise-gen: %s:1: key 'resolution': expected an integer from 4 to 256 (texels per side), got \"3\"" % bad,
            "noise-gen: %s:1: missing key 'normalize': expected one of 'zero_mean', 'min_max' or 'none'" % bad,
            "noise-gen: %s:2: key 'tile_size_km': expected a positive number in km, got \"-1\"" % bad,
            "noise-gen: %s:5: unknown key 'normalise' (did you mean 'normalize'?)" % bad,
            "noise-gen: %s:7: key 'channels[0].perlin.gain': expected a number in (0, 1] (amplitude ratio between octaves), got \"2\"" % bad,
        ])

    def test_bad_parameter_is_a_usage_error(self):
        r = run([tool("noise-gen"), LOW])  # no -o
        self.assertEqual(r.returncode, 2)
        self.assertTrue(r.stderr.startswith("noise-gen: "), r.stderr)
        self.assertIn("--output is required", r.stderr)

    def test_missing_input_file(self):
        r = run([tool("noise-gen"), self.path("nope.yaml"), "-o", self.path("x.ktx2")])
        self.assertEqual(r.returncode, 1)
        self.assertEqual(r.stderr, "noise-gen: %s: cannot open file\n" % self.path("nope.yaml"))

    def test_unchanged_output_keeps_its_mtime(self):
        out = self.path("h.ktx2")
        self.assertEqual(run([tool("noise-gen"), HIGH, "-o", out]).returncode, 0)
        os.utime(out, (1000000000, 1000000000))
        self.assertEqual(run([tool("noise-gen"), HIGH, "-o", out]).returncode, 0)
        self.assertEqual(os.stat(out).st_mtime, 1000000000)


if __name__ == "__main__":
    unittest.main()
