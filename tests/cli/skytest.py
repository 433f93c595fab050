"""Helpers shared by the CLI and pipeline tests (python3 stdlib only).

The tests run the real binaries from SKYBAKE_BIN_DIR (set by CTest) on files under
SKYBAKE_SOURCE_DIR, as OpenEXR's src/test/bin and ninja's misc/output_test.py do.
"""
import os
import shutil
import struct
import subprocess
import tempfile
import unittest
import zlib

BIN = os.environ.get("SKYBAKE_BIN_DIR", os.path.join(os.path.dirname(__file__), "..", "..", "build", "dev", "bin"))
SRC = os.environ.get("SKYBAKE_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))

# A one-mode water particle type small enough for a reduced pipeline's Mie table (seconds).
TINY_PARTICLE = """refractive_index:
  table: ../atmospheres/data/water_refractive_index_segelstein_1981.csv
modes:
  - name: small
    basis: number
    median_radius_um: 0.1
    sigma_g: 1.5
    r_min_um: 0.02
    r_max_um: 0.5
    weight: {relative_number: 1.0}
"""


def tool(name):
    return os.path.join(BIN, name)


def run(args, cwd=None, env=None, timeout=600):
    """Runs a command, returns CompletedProcess with text stdout/stderr."""
    e = dict(os.environ)
    if env:
        e.update(env)
    return subprocess.run(args, cwd=cwd, env=e, capture_output=True, text=True, timeout=timeout)


def read_png(path):
    """Decodes an 8-bit, non-interlaced PNG (grey, RGB or RGBA) with zlib and struct, by the PNG
    specification (ISO/IEC 15948, section 9: the five row filters). Returns (width, height,
    channels, rows) with rows a list of bytes objects, top to bottom."""
    with open(path, "rb") as f:
        data = f.read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, header = 8, b"", None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = header
    assert depth == 8 and interlace == 0, "only 8-bit non-interlaced PNGs"
    channels = {0: 1, 2: 3, 6: 4}[colour]
    raw, stride, rows, prev = zlib.decompress(idat), width * channels, [], bytearray(width * channels)
    for y in range(height):
        kind, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b, c = prev[i], prev[i - channels] if i >= channels else 0
            if kind == 1:
                line[i] = (line[i] + a) & 255
            elif kind == 2:
                line[i] = (line[i] + b) & 255
            elif kind == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line))
        prev = line
    return width, height, channels, rows


def panel_sheet(cols, rows, panel_w, panel_h, title_lines, header_lines):
    """The layout of io/png_label.h RenderPanelSheet with both axes and the value scale (margin
    10, y axis 56, panels 8 apart, a 16 px label above each row, value scale 84, x axis 36; title
    6 + 16 per line, headers 4 + 14 per line): (width, height, origin(row, col) of a panel)."""
    title_h, header_h = 6 + 16 * title_lines, 4 + 14 * header_lines
    width = 2 * 10 + 56 + cols * panel_w + (cols - 1) * 8 + 84
    height = 2 * 10 + title_h + header_h + rows * (16 + panel_h) + (rows - 1) * 8 + 36

    def origin(r, c):
        return 10 + 56 + c * (panel_w + 8), 10 + title_h + header_h + r * (16 + panel_h + 8) + 16

    return width, height, origin


def exr_attributes(path):
    """Reads the string attributes of an OpenEXR header (enough to check provenance) without
    any EXR library: magic, version, then (name, type, size, value) triples until a 0 byte."""
    with open(path, "rb") as f:
        data = f.read()
    assert data[:4] == b"\x76\x2f\x31\x01", "not an OpenEXR file"
    pos = 8
    attrs = {}
    while True:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode()
        pos = end + 1
        if not name:
            break
        end = data.index(b"\0", pos)
        typ = data[pos:end].decode()
        pos = end + 1
        (size,) = struct.unpack_from("<i", data, pos)
        pos += 4
        value = data[pos:pos + size]
        pos += size
        if typ == "string":
            attrs[name] = value.decode()
        elif typ == "int":
            attrs[name] = struct.unpack("<i", value)[0]
        elif typ == "double":
            attrs[name] = struct.unpack("<d", value)[0]
        elif typ == "float":
            attrs[name] = struct.unpack("<f", value)[0]
        else:
            attrs[name] = (typ, value)
    return attrs


class TempDirTestCase(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="skybake_test_")

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def path(self, *parts):
        return os.path.join(self.tmp, *parts)

    def write(self, rel, text):
        p = self.path(rel)
        os.makedirs(os.path.dirname(p), exist_ok=True)
        with open(p, "w") as f:
            f.write(text)
        return p


class PipelineTestCase(TempDirTestCase):
    """A temporary pipeline folder: subclasses write pipeline.yaml and set self.out (the build
    folder); these run skybake and ninja there and look at what changed."""

    def bake(self, expect=0):
        r = run([tool("skybake"), "bake", "pipeline.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, expect, r.stdout + r.stderr)
        return r

    def ninja(self, *args, expect=0):
        r = run(["ninja", "-C", self.out] + list(args))
        self.assertEqual(r.returncode, expect, r.stdout + r.stderr)
        return r

    def edit(self, rel, old, new):
        """Replaces the first `old` in file `rel` (which must contain it) with `new`."""
        p = self.path(rel)
        with open(p) as f:
            text = f.read()
        self.assertIn(old, text)
        with open(p, "w") as f:
            f.write(text.replace(old, new, 1))

    def mtimes(self):
        """Modification times (ns) of every file under the build folder, by relative path."""
        out = {}
        for root, _, files in os.walk(self.out):
            for f in files:
                p = os.path.join(root, f)
                out[os.path.relpath(p, self.out)] = os.stat(p).st_mtime_ns
        return out


class CliContract:
    """Mixin: the CLI contract every tool must satisfy (docs/developing.md). Subclasses set
    TOOL and VALID_ARGS (a list, relative to SRC) and may override as needed."""
    TOOL = None

    def test_help_goes_to_stdout_and_exits_0(self):
        r = run([tool(self.TOOL), "--help"])
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("Usage", r.stdout)
        self.assertEqual(r.stderr, "")

    def test_version(self):
        r = run([tool(self.TOOL), "--version"])
        self.assertEqual(r.returncode, 0)
        self.assertRegex(r.stdout.strip(), r"^%s \(skybake\) \d+\.\d+\.\d+$" % self.TOOL)

    def test_no_arguments_is_a_usage_error(self):
        r = run([tool(self.TOOL)])
        self.assertEqual(r.returncode, 2, r.stdout + r.stderr)
        self.assertTrue(r.stderr.startswith(self.TOOL + ": "), r.stderr)
        self.assertEqual(r.stdout, "")

    def test_unknown_option_is_a_usage_error(self):
        r = run([tool(self.TOOL), "--no-such-option"])
        self.assertEqual(r.returncode, 2)
        self.assertTrue(r.stderr.startswith(self.TOOL + ": "), r.stderr)
        self.assertIn("--help", r.stderr)

    def test_bad_threads_value_is_a_usage_error(self):
        r = run([tool(self.TOOL), "--threads", "-3", "--help"])
        self.assertIn(r.returncode, (0, 2))  # --help wins in CLI11; a lone bad value must be 2
        r = run([tool(self.TOOL), "--threads", "abc"])
        self.assertEqual(r.returncode, 2)
