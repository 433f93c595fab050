"""Hostile inputs: every number of a file or an option is checked for finiteness and
its physical range before any work, names cannot escape the outputs folder, and a failed
command leaves the previous outputs byte-identical (runs the real binaries)."""
import os
import re
import shutil
import unittest

from skytest import SRC, TempDirTestCase, run, tool

OLD = b"previous output, must survive a failed command\n"
PROGRESS = re.compile(r"^[\w-]+: [a-z ]+ \d+%$")


def messages(stderr):
    """stderr without the progress lines."""
    return [l for l in stderr.splitlines() if not PROGRESS.match(l)]


class HostileInputs(TempDirTestCase):
    def setUp(self):
        super().setUp()
        shutil.copytree(os.path.join(SRC, "atmospheres"), self.path("atmospheres"))
        shutil.copytree(os.path.join(SRC, "particles"), self.path("particles"))
        with open(self.path("atmospheres", "clear.yaml")) as f:
            self.clear = f.read()
        # clear without its aerosol layer: sky-render loads it without Mie tables.
        start, end = self.clear.index("aerosols:"), self.clear.index("ground:")
        self.write(os.path.join("atmospheres", "plain.yaml"), self.clear[:start] + self.clear[end:])
        self.plain = self.path("atmospheres", "plain.yaml")

    def mutant(self, old, new, name="mutant.yaml"):
        """clear.yaml with `old` replaced by `new`; returns (path, 1-based line of the change)."""
        self.assertIn(old, self.clear)
        text = self.clear.replace(old, new, 1)
        line = self.clear[: self.clear.index(old)].count("\n") + 1
        return self.write(os.path.join("atmospheres", name), text), line

    def old_outputs(self, *names):
        """Files holding OLD, as a command's previous outputs."""
        paths = []
        for n in names:
            p = self.path(n)
            with open(p, "wb") as f:
                f.write(OLD)
            paths.append(p)
        return paths

    def assertUntouched(self, paths):
        for p in paths:
            with open(p, "rb") as f:
                self.assertEqual(f.read(), OLD, p)
        leftovers = [f for f in os.listdir(self.tmp) if ".tmp-" in f or f.startswith(".skybake-commit-")]
        self.assertEqual(leftovers, [])

    def assertFails(self, args, code, message):
        outs = self.old_outputs("out.exr", "out.exr.d", "out.png")
        r = run(args + ["--depfile", outs[1]] if "--depfile" not in args else args, cwd=self.tmp)
        self.assertEqual(r.returncode, code, r.stderr)
        self.assertEqual(messages(r.stderr)[0], message)
        self.assertUntouched(outs)

    def sky(self, atmosphere, *extra):
        return [tool("sky-render"), "render", atmosphere, "-o", self.path("out.exr"), "--size", "8x4",
                "--sun-zenith-deg", "60", "--wavelengths", "rgb"] + list(extra)

    # planet: radius_km: 1e20 (or 1e-20)
    def test_planet_radius_outside_its_range(self):
        for value in ("1e20", "1e-20"):
            atm, line = self.mutant("radius_km: 6371.0", "radius_km: " + value)
            msg = "{}: %s:%d: key 'planet.radius_km': expected a number from 100 to 1e+05 in km, got \"%s\"" % (
                atm, line, value)
            self.assertFails([tool("profile-import"), atm, "-o", self.path("out.exr")], 1, msg.format("profile-import"))
            for method in ("single", "orders", "path"):
                self.assertFails(self.sky(atm, "--method", method), 1, msg.format("sky-render"))

    # top_km: 1e9 (a hang) and 1001 (exit 3 from ussa1976.cpp)
    def test_top_of_atmosphere_outside_the_standard(self):
        for value in ("1e9", "1001"):
            atm, line = self.mutant("top_km: 100.0", "top_km: " + value)
            self.assertFails([tool("profile-import"), atm, "-o", self.path("out.exr")], 1,
                             "profile-import: %s:%d: key 'planet.top_km': expected a number from 1 to 1000 in km, "
                             "got \"%s\"" % (atm, line, value))

    # ozone: column_du: 1e300 (an infinite ozone channel, an all-NaN sky)
    def test_ozone_column_outside_its_range(self):
        atm, line = self.mutant("column_du: 300.0", "column_du: 1e300")
        msg = "{}: %s:%d: key 'ozone.column_du': expected a number from 0 to 1000 in Dobson units, got \"1e300\"" % (
            atm, line)
        self.assertFails([tool("profile-import"), atm, "-o", self.path("out.exr")], 1, msg.format("profile-import"))
        self.assertFails(self.sky(atm, "--method", "single"), 1, msg.format("sky-render"))

    # An albedo table value of 2.0
    def test_albedo_above_one_in_its_table(self):
        csv = self.path("atmospheres", "data", "albedo_usgs_splib07_examples.csv")
        with open(csv) as f:
            lines = f.read().split("\n")
        row = next(i for i, l in enumerate(lines) if l.startswith("grass_lawn_green,") and ",0.55" in l)
        cells = lines[row].split(",")
        header = next(l for l in lines if l and not l.startswith("#")).split(",")
        cells[header.index("reflectance")] = "2.0"
        lines[row] = ",".join(cells)
        with open(csv, "w") as f:
            f.write("\n".join(lines))
        self.assertFails(self.sky(self.plain, "--method", "single"), 1,
                         "sky-render: %s:%d: column 'reflectance': expected a value from 0 to 1, got 2.0" % (csv, row + 1))

    # A negative solar spectrum
    def test_negative_solar_spectrum(self):
        csv = self.path("atmospheres", "data", "astm_g173_03_solar_spectrum.csv")
        with open(csv) as f:
            lines = f.read().split("\n")
        header_at = next(i for i, l in enumerate(lines) if l and not l.startswith("#"))
        header = lines[header_at].split(",")
        col = header.index("extraterrestrial_W_m2_nm")
        row = next(i for i in range(header_at + 1, len(lines)) if lines[i].split(",")[0] == "550")
        cells = lines[row].split(",")
        cells[col] = "-" + cells[col]
        lines[row] = ",".join(cells)
        with open(csv, "w") as f:
            f.write("\n".join(lines))
        for grid in ("rgb", "400:700:50"):
            args = self.sky(self.plain, "--method", "single")
            args[args.index("--wavelengths") + 1] = grid
            self.assertFails(args, 1, "sky-render: %s:%d: column 'extraterrestrial_W_m2_nm': expected a value >= 0, "
                             "got %s" % (csv, row + 1, cells[col]))

    # Non-finite options: every floating-point option of every tool
    def test_non_finite_options_are_usage_errors(self):
        clear = self.plain
        cases = [
            ([tool("mie-tables"), "build", self.path("particles", "continental.yaml"), "-o", self.path("out.exr"),
              "--wavelength-step-nm", "nan"], "mie-tables: --wavelength-step-nm nan: expected a finite number"),
            (self.sky(clear, "--method", "path", "--target-error", "nan"),
             "sky-render: --target-error nan: expected a finite number"),
            (self.sky(clear, "--method", "single", "--preview", self.path("out.png"), "--exposure", "nan"),
             "sky-render: --exposure nan: expected a finite number"),
            ([tool("cumulus-map"), os.path.join(SRC, "clouds", "cumulus.yaml"), "-o", self.path("out.exr"),
              "--time-s", "nan"], "cumulus-map: --time-s nan: expected a finite number"),
            ([tool("cumulus-map"), os.path.join(SRC, "clouds", "cumulus.yaml"), "-o", self.path("out.exr"),
              "--time-s", "1e300"], "cumulus-map: --time-s 1e+300: expected a time in [-1e7, 1e7] s"),
            ([tool("lut-pack"), "pack", "clear=" + self.path("sky.exr"), "-o", self.path("out.exr"),
              "--budget-mib", "nan"], "lut-pack: --budget-mib nan: expected a finite number"),
            ([tool("lut-pack"), "check", self.path("sky.ktx2") + ":nan", "--direct", self.path("direct.exr"),
              "-o", self.path("out.exr")],
             "lut-pack: the weight of '%s:nan' must be a finite number" % self.path("sky.ktx2")),
        ]
        for args, message in cases:
            with self.subTest(args=args[:2]):
                outs = self.old_outputs("out.exr", "out.png")
                r = run(args, cwd=self.tmp)
                self.assertEqual(r.returncode, 2, r.stderr)
                self.assertEqual(messages(r.stderr)[0], message)
                self.assertUntouched(outs)

    # mie-tables sphere: a size parameter or index without end ran forever, a tiny one gave NaN
    def test_single_sphere_outside_its_range_is_a_usage_error(self):
        for args in (["--m", "1.33", "--x", "1e300"], ["--m", "1.33", "--x", "1e-300"], ["--m", "1e300", "--x", "1"],
                     ["--m", "1.5+1e300i", "--x", "1"], ["--m", "1.33", "--x", "nan"]):
            with self.subTest(args=args):
                r = run([tool("mie-tables"), "sphere"] + args + ["-o", self.path("out.json")], timeout=20)
                self.assertEqual(r.returncode, 2, r.stderr)
                self.assertTrue(r.stderr.startswith("mie-tables: --"), r.stderr)
                self.assertFalse(os.path.exists(self.path("out.json")))

    # --preview with a bad --display / --white-cd-m2 fails before rendering, the old set intact
    def test_preview_options_are_checked_before_the_render(self):
        clear = self.plain
        for extra, message in (
                (["--display", "CRT"], "sky-render: --display CRT: expected one of the OCIO config's displays: "),
                (["--white-cd-m2", "-5"], "sky-render: --white-cd-m2: expected 'auto' or a luminance in (0, 1e9] cd/m^2, "
                                          "got '-5'")):
            with self.subTest(extra=extra):
                outs = self.old_outputs("out.exr", "out.png", "out.exr.d")
                r = run(self.sky(clear, "--method", "path", "--preview", outs[1], "--depfile", outs[2], *extra),
                        cwd=self.tmp, timeout=60)
                self.assertEqual(r.returncode, 2, r.stderr)
                self.assertTrue(messages(r.stderr)[0].startswith(message), r.stderr)
                # Only the loading reported progress: nothing was rendered.
                self.assertEqual([l for l in r.stderr.splitlines() if PROGRESS.match(l) and " loading " not in l], [])
                self.assertUntouched(outs)

    # name: ../../escaped, ./clear, 'my sky'
    def test_names_are_identifiers(self):
        for value in ("../../escaped", "./clear", "'my sky'", "Clear"):
            with self.subTest(name=value):
                atm, line = self.mutant("name: clear", "name: " + value)
                shown = value.strip("'")
                self.assertFails([tool("profile-import"), atm, "-o", self.path("out.exr")], 1,
                                 "profile-import: %s:%d: key 'name': expected a lowercase identifier (a-z, 0-9, _; "
                                 "starting with a letter), got \"%s\"" % (atm, line, shown))

    def test_generator_writes_nothing_outside_outputs_for_a_bad_name(self):
        atm, line = self.mutant("name: clear", "name: ../../escaped", name="escape.yaml")
        with open(os.path.join(SRC, "pipeline.yaml")) as f:
            text = f.read()
        pipeline = self.path("pipeline.yaml")
        self.assertIn("atmospheres/clear.yaml", text)
        with open(pipeline, "w") as f:
            f.write(text.replace("atmospheres/clear.yaml", "atmospheres/escape.yaml", 1))
        # outputs/../../escaped is the folder beside this test's own: where the components of
        # that name would go (other tests create and remove folders there at the same time, so
        # the check names the one path rather than comparing the whole listing).
        escaped = os.path.join(os.path.dirname(self.tmp), "escaped")
        self.assertFalse(os.path.exists(escaped))
        r = run([tool("skybake"), "generate", "pipeline.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn("%s:%d: key 'name': expected a lowercase identifier" % (atm, line), r.stderr)
        self.assertFalse(os.path.exists(self.path("outputs")))
        self.assertFalse(os.path.exists(escaped))

    # A particle type is named by its file: that name is an identifier too
    def test_particle_file_names_are_identifiers(self):
        shutil.copy(self.path("particles", "continental.yaml"), self.path("particles", "my type.yaml"))
        atm, _ = self.mutant("particle: ../particles/continental.yaml", "particle: '../particles/my type.yaml'")
        line = self.clear[: self.clear.index("particle: ../particles")].count("\n") + 1
        self.assertFails([tool("profile-import"), atm, "-o", self.path("out.exr")], 1,
                         "profile-import: %s:%d: key 'aerosols[0].particle': the particle type's file name 'my type' "
                         "is its name and must be a lowercase identifier (a-z, 0-9, _; starting with a letter) "
                         "with .yaml" % (atm, line))

    # Stale temporary files of a killed run are removed by the next run
    def test_stale_temporary_files_are_removed_by_the_next_run(self):
        out = self.path("p.exr")
        dead = 2 ** 22 + 12345  # above the default pid_max: no such process
        stale = [out + ".tmp-%d" % dead, out + ".d.tmp-%d" % dead]
        for s in stale:
            with open(s, "wb") as f:
                f.write(b"half a file")
        r = run([tool("profile-import"), self.path("atmospheres", "clear.yaml"), "-o", out, "--depfile", out + ".d"])
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(sorted(os.listdir(self.tmp)), ["atmospheres", "p.exr", "p.exr.d", "particles"])

    def test_a_dead_runs_journal_is_completed_by_the_next_run(self):
        # A run killed between its renames: the journal lists the targets, one staged file is
        # still there; the next run renames it over its target and removes the journal.
        dead = 2 ** 22 + 12346
        a, b = self.path("a.bin"), self.path("b.bin")
        with open(a, "wb") as f:
            f.write(b"new a")  # already renamed
        with open(b, "wb") as f:
            f.write(b"old b")
        with open(b + ".tmp-%d" % dead, "wb") as f:
            f.write(b"new b")
        with open(self.path(".skybake-commit-%d" % dead), "w") as f:
            f.write(a + "\n" + b + "\n")
        out = self.path("p.exr")
        r = run([tool("profile-import"), self.path("atmospheres", "clear.yaml"), "-o", out])
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(b, "rb") as f:
            self.assertEqual(f.read(), b"new b")
        self.assertEqual(sorted(os.listdir(self.tmp)), ["a.bin", "atmospheres", "b.bin", "p.exr", "particles"])


if __name__ == "__main__":
    unittest.main()
