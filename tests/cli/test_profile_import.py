"""CLI contract and behaviour of profile-import (runs the real binary)."""
import os
import unittest

from skytest import SRC, CliContract, TempDirTestCase, exr_attributes, run, tool

CLEAR = os.path.join(SRC, "atmospheres", "clear.yaml")


class ProfileImportCli(CliContract, TempDirTestCase):
    TOOL = "profile-import"

    def test_real_run_is_read_back_by_a_second_program(self):
        out = self.path("p.exr")
        r = run([tool("profile-import"), CLEAR, "-o", out, "--depfile", out + ".d"])
        self.assertEqual(r.returncode, 0, r.stderr)
        # Read back with OpenImageIO (an independent EXR reader): 1001 altitudes x 1 row.
        info = run(["oiiotool", "--info", "-v", out])
        self.assertEqual(info.returncode, 0, info.stderr)
        self.assertIn("1001 x    1", info.stdout)
        self.assertIn("air.number_density", info.stdout)
        stats = run(["oiiotool", "--stats", out])
        self.assertEqual(stats.returncode, 0, stats.stderr)
        self.assertIn("NanCount: 0", stats.stdout.replace("  ", " ").replace("NanCount: 0 0", "NanCount: 0"))
        attrs = exr_attributes(out)
        self.assertEqual(attrs["skybake.tool"], "profile-import")
        self.assertIn("afgl1986_us_standard.csv xxh3:", attrs["skybake.inputs"])
        self.assertAlmostEqual(attrs["skybake.ozone.column_du"], 300.0, places=9)
        with open(out + ".d") as f:
            dep = f.read()
        self.assertIn("afgl1986_us_standard.csv", dep)
        self.assertIn("aerosol_extinction_shettle_fenn_550nm.csv", dep)

    def test_same_bytes_at_any_thread_count(self):
        a, b = self.path("a.exr"), self.path("b.exr")
        self.assertEqual(run([tool("profile-import"), "--threads", "1", CLEAR, "-o", a]).returncode, 0)
        self.assertEqual(run([tool("profile-import"), "--threads", "2", CLEAR, "-o", b]).returncode, 0)
        with open(a, "rb") as fa, open(b, "rb") as fb:
            self.assertEqual(fa.read(), fb.read())

    def test_bad_yaml_value_is_reported_with_file_and_line(self):
        bad = self.write("bad.yaml", "planet:\n  radius_km: abc\n  top_km: 100\nair:\n  profile: ussa1976\n")
        out = self.path("never.exr")
        r = run([tool("profile-import"), bad, "-o", out])
        self.assertEqual(r.returncode, 1)
        self.assertEqual(r.stderr, "profile-import: %s:2: key 'planet.radius_km': expected a number from 100 to 1e+05 in km, got \"abc\"\n" % bad)
        self.assertFalse(os.path.exists(out))

    def test_every_problem_is_reported(self):
        bad = self.write("bad.yaml", "planet:\n  radius_km: -1\n  topp_km: 100\nair:\n  profile: usa1976\n")
        r = run([tool("profile-import"), bad, "-o", self.path("x.exr")])
        self.assertEqual(r.returncode, 1)
        self.assertEqual(r.stderr.splitlines(), [
            "profile-import: %s:2: key 'planet.radius_km': expected a number from 100 to 1e+05 in km, got \"-1\"" % bad,
            "profile-import: %s:2: missing key 'planet.top_km': expected a number from 1 to 1000 in km" % bad,
            "profile-import: %s:3: unknown key 'planet.topp_km' (did you mean 'top_km'?)" % bad,
            "profile-import: %s:5: key 'air.profile': expected one of 'ussa1976', 'exponential' or 'table', got \"usa1976\" (did you mean 'ussa1976'?)" % bad,
        ])

    def test_bad_profile_table_rows_are_located(self):
        self.write("t.csv", "# source: test\naltitude_km,n_cm3\n0,1\n2,-5\n1,3\n3,x\n")
        bad = self.write("a.yaml", "planet: {radius_km: 6371, top_km: 3}\nair: {profile: ussa1976}\n"
                                   "ozone:\n  profile: {table: {file: t.csv, altitude_column: altitude_km, value_column: n_cm3}}\n"
                                   "  column_du: 300\n")
        r = run([tool("profile-import"), bad, "-o", self.path("x.exr")])
        self.assertEqual(r.returncode, 1)
        t = self.path("t.csv")
        self.assertEqual(r.stderr.splitlines(), [
            "profile-import: %s:4: column 'n_cm3': a density cannot be negative, got -5" % t,
            "profile-import: %s:5: column 'altitude_km': altitudes must increase strictly (1 after 2)" % t,
            "profile-import: %s:6: column 'n_cm3': expected a number, got \"x\"" % t,
        ])

    def test_table_that_does_not_cover_the_grid(self):
        self.write("t.csv", "# source: test\naltitude_km,n_cm3\n0,1\n50,1\n")
        bad = self.write("a.yaml", "planet: {radius_km: 6371, top_km: 100}\nair: {profile: ussa1976}\n"
                                   "ozone:\n  profile: {table: {file: t.csv, altitude_column: altitude_km, value_column: n_cm3}}\n"
                                   "  column_du: 300\n")
        r = run([tool("profile-import"), bad, "-o", self.path("x.exr")])
        self.assertEqual(r.returncode, 1)
        self.assertEqual(r.stderr, "profile-import: %s: the table covers altitudes 0 to 50 km but the atmosphere needs 0 to 100 km (extend the table or set 'outside: zero')\n" % self.path("t.csv"))

    def test_missing_input_file(self):
        r = run([tool("profile-import"), self.path("nope.yaml"), "-o", self.path("x.exr")])
        self.assertEqual(r.returncode, 1)
        self.assertEqual(r.stderr, "profile-import: %s: cannot open file\n" % self.path("nope.yaml"))

    def test_unchanged_output_keeps_its_mtime(self):
        out = self.path("p.exr")
        self.assertEqual(run([tool("profile-import"), CLEAR, "-o", out]).returncode, 0)
        os.utime(out, (1000000000, 1000000000))
        self.assertEqual(run([tool("profile-import"), CLEAR, "-o", out]).returncode, 0)
        self.assertEqual(os.stat(out).st_mtime, 1000000000)


if __name__ == "__main__":
    unittest.main()
