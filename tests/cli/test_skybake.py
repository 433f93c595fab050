"""CLI contract of the generator `skybake` (runs the real binary)."""
import os
import shutil
import unittest

from skytest import SRC, CliContract, TempDirTestCase, run, tool


class SkybakeCli(CliContract, TempDirTestCase):
    TOOL = "skybake"

    def setUp(self):
        super().setUp()
        shutil.copytree(os.path.join(SRC, "atmospheres"), self.path("atmospheres"))
        shutil.copytree(os.path.join(SRC, "particles"), self.path("particles"))
        self.write("pipeline.yaml", "atmospheres: [atmospheres/clear.yaml]\n")

    def test_generate_output_is_read_by_ninja(self):
        r = run([tool("skybake"), "generate", "pipeline.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        q = run(["ninja", "-C", self.path("outputs"), "-t", "query", "clear/profiles.exr"])
        self.assertEqual(q.returncode, 0, q.stderr)
        self.assertIn("input: profile_import", q.stdout)
        self.assertIn("clear/components/profiles.yaml", q.stdout)

    def test_generate_twice_leaves_build_ninja_untouched(self):
        self.assertEqual(run([tool("skybake"), "generate", "pipeline.yaml"], cwd=self.tmp).returncode, 0)
        p = self.path("outputs", "build.ninja")
        os.utime(p, (1000000000, 1000000000))
        self.assertEqual(run([tool("skybake"), "generate", "pipeline.yaml"], cwd=self.tmp).returncode, 0)
        self.assertEqual(os.stat(p).st_mtime, 1000000000)

    def test_missing_pipeline_file(self):
        r = run([tool("skybake"), "generate", "nope.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, 1)
        self.assertEqual(r.stderr, "skybake: %s: cannot open file\n" % self.path("nope.yaml"))

    def test_bad_pipeline_key(self):
        self.write("pipeline.yaml", "atmospheres: [atmospheres/clear.yaml]\naltitude_stepm: 100\n")
        r = run([tool("skybake"), "generate", "pipeline.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, 1)
        self.assertEqual(r.stderr, "skybake: %s:2: unknown key 'altitude_stepm' (did you mean 'altitude_step_m'?)\n"
                         % self.path("pipeline.yaml"))
        self.assertFalse(os.path.exists(self.path("outputs", "build.ninja")))

    def test_pools_and_launchers_as_lists_are_bad_input(self):
        # Found by the pipeline YAML fuzz target (bench/fuzz): a list where a mapping belongs was
        # iterated as a mapping, and yaml-cpp's InvalidNode ended the generator with exit 3.
        for key, line in (("pools", "pools:\n-  render: 1\n"), ("launchers", "launchers:\n- sky-render: srun\n")):
            self.write("pipeline.yaml", "atmospheres: [atmospheres/clear.yaml]\n" + line)
            r = run([tool("skybake"), "generate", "pipeline.yaml"], cwd=self.tmp)
            self.assertEqual(r.returncode, 1, r.stderr)
            self.assertEqual(r.stderr, "skybake: %s:3: key '%s': expected a mapping, got a list\n" % (self.path("pipeline.yaml"), key))
            self.assertFalse(os.path.exists(self.path("outputs", "build.ninja")))

    def test_unknown_subcommand_is_a_usage_error(self):
        r = run([tool("skybake"), "bak"])
        self.assertEqual(r.returncode, 2)


if __name__ == "__main__":
    unittest.main()
