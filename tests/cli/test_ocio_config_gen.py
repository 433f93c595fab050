"""CLI contract and behaviour of ocio-config-gen (runs the real binary): it reproduces the
checked-in ocio/config.ocio byte for byte, ociocheck accepts what it writes, bad data tables are
reported with file:line."""
import os
import shutil
import unittest

from skytest import SRC, CliContract, TempDirTestCase, run, tool

DATA = os.path.join(SRC, "atmospheres", "data")
GOLDEN = os.path.join(SRC, "ocio", "config.ocio")


class OcioConfigGenCli(CliContract, TempDirTestCase):
    TOOL = "ocio-config-gen"

    def test_reproduces_the_checked_in_config_and_ociocheck_accepts_it(self):
        out = self.path("config.ocio")
        r = run([tool(self.TOOL), "--data-dir", DATA, "-o", out, "--depfile", out + ".d"])
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(out, "rb") as a, open(GOLDEN, "rb") as b:
            self.assertEqual(a.read(), b.read(), "ocio/config.ocio is stale: regenerate it with ocio-config-gen")
        # A second program reads it: OCIO's own checker (opencolorio-tools, from scripts/setup).
        self.assertIsNotNone(shutil.which("ociocheck"), "ociocheck missing: scripts/setup installs opencolorio-tools")
        check = run(["ociocheck", "--iconfig", out])
        self.assertEqual(check.returncode, 0, check.stdout + check.stderr)
        self.assertIn("(Rec.2100-PQ, Un-tone-mapped)", check.stdout)
        self.assertIn("CIE-XYZ-D65 (cie_xyz_d65_interchange)", check.stdout)
        self.assertIn("ACES2065-1 (aces_interchange)", check.stdout)
        with open(out + ".d") as f:
            dep = f.read()
        self.assertIn("cie2006_2deg_xyz_cmf_1nm.csv", dep)
        self.assertIn("cie_d65_1nm.csv", dep)

    def test_same_bytes_at_any_thread_count_and_unchanged_file_keeps_mtime(self):
        a, b = self.path("a.ocio"), self.path("b.ocio")
        self.assertEqual(run([tool(self.TOOL), "--threads", "1", "--data-dir", DATA, "-o", a]).returncode, 0)
        self.assertEqual(run([tool(self.TOOL), "--threads", "2", "--data-dir", DATA, "-o", b]).returncode, 0)
        with open(a, "rb") as fa, open(b, "rb") as fb:
            self.assertEqual(fa.read(), fb.read())
        os.utime(a, (1000000000, 1000000000))
        self.assertEqual(run([tool(self.TOOL), "--data-dir", DATA, "-o", a]).returncode, 0)
        self.assertEqual(os.stat(a).st_mtime, 1000000000)

    def test_bad_cmf_table_is_reported_with_file_and_line(self):
        data = self.path("data")
        os.makedirs(data)
        shutil.copy(os.path.join(DATA, "cie_d65_1nm.csv"), data)
        bad = os.path.join(data, "cie2006_2deg_xyz_cmf_1nm.csv")
        with open(bad, "w") as f:
            f.write("# source: test\nwavelength_nm,xbar,ybar,zbar\n390,0.1,0.2,0.3\n391,0.1,abc,0.3\n389,0.1,0.2,0.3\n")
        out = self.path("never.ocio")
        r = run([tool(self.TOOL), "--data-dir", data, "-o", out])
        self.assertEqual(r.returncode, 1)
        self.assertEqual(r.stderr.splitlines(), [
            "ocio-config-gen: %s:4: column 'ybar': expected a number, got \"abc\"" % bad,
            "ocio-config-gen: %s:5: column 'wavelength_nm': wavelengths must strictly increase, but 389 follows 391" % bad,
        ])
        self.assertFalse(os.path.exists(out))

    def test_missing_data_folder(self):
        out = self.path("never.ocio")
        missing = self.path("nope")
        r = run([tool(self.TOOL), "--data-dir", missing, "-o", out])
        self.assertEqual(r.returncode, 1)
        self.assertEqual(r.stderr, "ocio-config-gen: %s: cannot open file\n" % os.path.join(missing, "cie2006_2deg_xyz_cmf_1nm.csv"))
        self.assertFalse(os.path.exists(out))


if __name__ == "__main__":
    unittest.main()
