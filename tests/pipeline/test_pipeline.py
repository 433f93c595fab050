"""The generated Ninja pipeline on a temporary copy of the repo's atmospheres.

Checks: a fresh bake builds; a second run has no work; an edit to one atmosphere re-runs only
that atmosphere's edges; comment/whitespace edits re-run nothing downstream; missingdeps is
clean; removing an atmosphere + cleandead removes its outputs; a malformed atmosphere fails
with file:line and leaves every output intact; deleting generator inputs/components regenerates.
"""
import os
import re
import shutil
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "cli"))
from skytest import SRC, PipelineTestCase, TINY_PARTICLE, TempDirTestCase, run, tool  # noqa: E402

PIPELINE = """outputs: outputs
altitude_step_m: 100
wavelengths: {min_nm: 400, max_nm: 700, step_nm: 50}
atmospheres:
  - atmospheres/clear.yaml
  - atmospheres/hazed.yaml
pools:
  render: 1
sky: {size: 4x2, sun_zenith_deg: [40], target_error: 0.5, preview: false}
"""

# A cheap particle type for the pipeline tests (small droplets: few Mie terms), replacing the
# atmospheres' real types so that a bake takes seconds. Both atmospheres share it: one Mie edge.

def edges_run(ninja_stdout):
    """The descriptions of the edges ninja ran ("[1/2] profile-import x" -> "profile-import x")."""
    return [m.group(1) for m in re.finditer(r"^\[\d+/\d+\] (.*)$", ninja_stdout, re.M)]


class PipelineTest(PipelineTestCase):
    def setUp(self):
        super().setUp()
        shutil.copytree(os.path.join(SRC, "atmospheres"), self.path("atmospheres"))
        for extra in ("particles", "clouds", "ocio"):
            if os.path.isdir(os.path.join(SRC, extra)):
                shutil.copytree(os.path.join(SRC, extra), self.path(extra))
        self.write("pipeline.yaml", PIPELINE)
        self.write("particles/tiny.yaml", TINY_PARTICLE)
        for atm in ("clear", "hazed"):
            p = self.path("atmospheres", atm + ".yaml")
            with open(p) as f:
                text = f.read()
            text = re.sub(r"particle: \.\./particles/\w+\.yaml", "particle: ../particles/tiny.yaml", text)
            with open(p, "w") as f:
                f.write(text)
        self.out = self.path("outputs")

    def test_fresh_bake_then_no_work(self):
        r = self.bake()
        self.assertEqual(sorted(edges_run(r.stdout)),
                         ["mie-tables mie/tiny.exr",  # the particle type both atmospheres share here
                          "profile-import clear/profiles.exr", "profile-import hazed/profiles.exr",
                          "sky-render clear/sky.exr", "sky-render hazed/sky.exr"])
        for atm in ("clear", "hazed"):
            self.assertTrue(os.path.isfile(os.path.join(self.out, atm, "profiles.exr")))
        self.assertIn("no work to do", self.ninja("-n").stdout)
        self.assertIn("no work to do", self.ninja().stdout)

    def test_missingdeps_is_clean(self):
        self.bake()
        r = self.ninja("-t", "missingdeps")
        self.assertIn("No missing dependencies", r.stdout)

    def test_editing_one_atmosphere_profile_reruns_only_its_edge(self):
        self.bake()
        before = self.mtimes()
        self.edit("atmospheres/hazed.yaml", "extinction_550nm_per_km_vis5", "extinction_550nm_per_km_vis10")
        r = self.ninja("-d", "explain")
        # hazed's profiles change, so its sky is re-rendered; nothing of clear, no Mie table.
        self.assertEqual(edges_run(r.stdout), ["Regenerating build.ninja", "profile-import hazed/profiles.exr",
                                               "sky-render hazed/sky.exr"])
        after = self.mtimes()
        self.assertEqual(before["clear/profiles.exr"], after["clear/profiles.exr"])
        self.assertEqual(before["clear/components/profiles.yaml"], after["clear/components/profiles.yaml"])
        self.assertNotEqual(before["hazed/profiles.exr"], after["hazed/profiles.exr"])
        self.assertIn("no work to do", self.ninja("-n").stdout)

    def test_editing_a_value_in_a_private_profile_table_reruns_only_its_edge(self):
        shutil.copy(self.path("atmospheres/data/aerosol_extinction_shettle_fenn_550nm.csv"),
                    self.path("atmospheres/data/hazed_private.csv"))
        self.edit("atmospheres/hazed.yaml", "aerosol_extinction_shettle_fenn_550nm.csv", "hazed_private.csv")
        self.bake()
        self.edit("atmospheres/data/hazed_private.csv", "\n1,4.150e-02,9.910e-02,3.790e-01,7.700e-01\n",
                  "\n1,4.150e-02,9.910e-02,3.790e-01,6.500e-01\n")
        r = self.ninja()
        self.assertEqual(edges_run(r.stdout), ["profile-import hazed/profiles.exr", "sky-render hazed/sky.exr"])

    def test_editing_render_only_settings_reruns_only_the_sky(self):
        self.bake()
        before = self.mtimes()
        self.edit("atmospheres/hazed.yaml", "optical_depth_550nm: 0.5", "optical_depth_550nm: 0.6")
        r = self.ninja()
        self.assertEqual(edges_run(r.stdout), ["Regenerating build.ninja", "sky-render hazed/sky.exr"])
        after = self.mtimes()
        self.assertEqual(before["hazed/profiles.exr"], after["hazed/profiles.exr"])
        self.assertEqual(before["mie/tiny.exr"], after["mie/tiny.exr"])
        self.assertEqual(before["clear/sky.exr"], after["clear/sky.exr"])

    def test_editing_a_particle_type_reruns_its_mie_table_and_the_skies_using_it(self):
        self.bake()
        self.edit("particles/tiny.yaml", "sigma_g: 1.5", "sigma_g: 1.6")
        r = self.ninja()
        self.assertEqual(sorted(edges_run(r.stdout)), ["Regenerating build.ninja", "mie-tables mie/tiny.exr",
                                                       "sky-render clear/sky.exr", "sky-render hazed/sky.exr"])

    def test_comment_and_whitespace_edits_rerun_nothing_downstream(self):
        self.bake()
        before = self.mtimes()
        self.edit("atmospheres/clear.yaml", "name: clear\n", "name: clear   # a new comment\n\n")
        r = self.ninja()
        self.assertEqual(edges_run(r.stdout), ["Regenerating build.ninja"])
        self.edit("pipeline.yaml", "pools:", "# comment\npools:")
        r = self.ninja()
        self.assertEqual(edges_run(r.stdout), ["Regenerating build.ninja"])
        after = self.mtimes()
        for k in before:
            if not k.startswith(".ninja"):
                self.assertEqual(before[k], after[k], k)

    def test_removing_an_atmosphere_and_cleandead(self):
        self.bake()
        self.edit("pipeline.yaml", "  - atmospheres/hazed.yaml\n", "")
        os.remove(self.path("atmospheres/hazed.yaml"))  # a deleted generator input regenerates, not fails
        r = self.ninja()
        self.assertEqual(edges_run(r.stdout), ["Regenerating build.ninja"])
        r = self.ninja("-t", "cleandead")
        self.assertFalse(os.path.exists(os.path.join(self.out, "hazed", "profiles.exr")))
        self.assertFalse(os.path.exists(os.path.join(self.out, "hazed", "sky.exr")))
        self.assertFalse(os.path.exists(os.path.join(self.out, "hazed", "components", "profiles.yaml")))
        self.assertTrue(os.path.exists(os.path.join(self.out, "clear", "profiles.exr")))
        self.assertIn("no work to do", self.ninja("-n").stdout)

    def test_deleted_component_is_regenerated(self):
        self.bake()
        before = self.mtimes()
        os.remove(os.path.join(self.out, "clear", "components", "profiles.yaml"))
        r = self.ninja()
        # The component comes back (new mtime), its tool re-runs, writes identical bytes and
        # restat stops there: the product keeps its mtime.
        self.assertEqual(edges_run(r.stdout), ["Regenerating build.ninja", "profile-import clear/profiles.exr"])
        self.assertTrue(os.path.exists(os.path.join(self.out, "clear", "components", "profiles.yaml")))
        self.assertEqual(before["clear/profiles.exr"], self.mtimes()["clear/profiles.exr"])
        self.assertIn("no work to do", self.ninja("-n").stdout)

    def test_malformed_atmosphere_fails_with_file_line_and_keeps_outputs(self):
        self.bake()
        before = self.mtimes()
        with open(os.path.join(self.out, "build.ninja")) as f:
            ninja_before = f.read()
        self.edit("atmospheres/hazed.yaml", "column_du: 300.0", "column_du: lots")
        r = self.ninja(expect=1)
        self.assertIn("skybake: %s:18: key 'ozone.column_du': expected a number from 0 to 1000 in Dobson units, got \"lots\""
                      % os.path.join(self.tmp, "atmospheres", "hazed.yaml"), r.stdout + r.stderr)
        after = self.mtimes()
        for k in before:
            if not k.startswith(".ninja"):
                self.assertEqual(before[k], after[k], k)
        with open(os.path.join(self.out, "build.ninja")) as f:
            self.assertEqual(f.read(), ninja_before)
        # Fixing the file recovers; the fix restores the old content so nothing reruns.
        self.edit("atmospheres/hazed.yaml", "column_du: lots", "column_du: 300.0")
        r = self.ninja()
        self.assertEqual(edges_run(r.stdout), ["Regenerating build.ninja"])

    def test_atmosphere_without_ground_or_sun_is_reported_at_generate_time(self):
        # A sky render needs the whole atmosphere; the generator names the atmosphere file rather
        # than letting sky-render fail later on the generated component.
        p = self.path("atmospheres", "clear.yaml")
        with open(p) as f:
            text = f.read()
        with open(p, "w") as f:
            f.write(re.sub(r"^ground:\n(?:[ #].*\n)*", "", text, flags=re.M))
        self.assert_generate_fails("skybake: %s: missing section 'ground'" % p)
        self.assertFalse(os.path.exists(os.path.join(self.out, "build.ninja")))

    def test_graph_prints_the_plan_without_writing(self):
        r = run([tool("skybake"), "graph", "pipeline.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("profile-import: clear/profiles.exr", r.stdout)
        self.assertIn("<- clear/components/profiles.yaml", r.stdout)
        self.assertFalse(os.path.exists(self.out))

    def test_launcher_prefix_and_pools_reach_build_ninja(self):
        self.edit("pipeline.yaml", "pools:", "launchers:\n  profile-import: \"env SKYBAKE_LAUNCHED=1\"\npools:")
        self.bake()
        with open(os.path.join(self.out, "build.ninja")) as f:
            text = f.read()
        self.assertRegex(text, r"command = env SKYBAKE_LAUNCHED=1 \S*profile-import ")
        self.assertIn("pool render\n  depth = 1\n", text)

    def assert_generate_fails(self, message):
        """`skybake generate` exits 1 with `message` on stderr."""
        r = run([tool("skybake"), "generate", "pipeline.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
        self.assertIn(message, r.stderr)

    def test_unknown_launcher_tool_is_an_error(self):
        self.edit("pipeline.yaml", "pools:", "launchers:\n  profile-imprt: srun\npools:")
        self.assert_generate_fails("pipeline.yaml:8: unknown key 'launchers.profile-imprt' (did you mean 'profile-import'?)")

    def test_references_can_leave_the_default_bake_for_validate(self):
        # sky.target: validate - the default bake builds everything but the path-traced
        # references; `skybake validate` builds them (and what they need), a second time nothing.
        self.edit("pipeline.yaml", "preview: false}", "preview: false, target: validate}")
        r = self.bake()
        self.assertEqual(sorted(edges_run(r.stdout)), ["mie-tables mie/tiny.exr", "profile-import clear/profiles.exr",
                                                       "profile-import hazed/profiles.exr"])
        self.assertFalse(os.path.exists(os.path.join(self.out, "clear", "sky.exr")))
        self.assertIn("no work to do", self.ninja().stdout)
        r = run([tool("skybake"), "validate", "pipeline.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertEqual(sorted(edges_run(r.stdout)), ["sky-render clear/sky.exr", "sky-render hazed/sky.exr"])
        self.assertIn("no work to do", self.ninja("validate").stdout)
        # With the default target the references are in the bake, and `validate` names them too.
        self.edit("pipeline.yaml", "target: validate", "target: default")
        self.assertIn("no work to do", self.ninja().stdout.splitlines()[-1])
        with open(os.path.join(self.out, "build.ninja")) as f:
            self.assertIn("build validate: phony clear/sky.exr hazed/sky.exr\n", f.read())

    def test_unknown_sky_target_is_an_error(self):
        self.edit("pipeline.yaml", "preview: false}", "preview: false, target: later}")
        self.assert_generate_fails("pipeline.yaml:9: key 'sky.target'")

    def test_bake_relays_the_progress_of_running_tools(self):
        # Ninja holds a command's output until it ends; `skybake bake` relays the tools' progress
        # channel instead (io/progress_channel.h). At 10 ms every edge of this bake writes lines.
        r = run([tool("skybake"), "bake", "pipeline.yaml", "--progress-interval", "0.01"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        relayed = [l for l in r.stdout.splitlines() if re.match(r"^sky-render clear/sky\.exr: .* \(\d+\.\d s\)$", l)]
        self.assertTrue(relayed, r.stdout)
        self.assertEqual([n for n in os.listdir(self.out) if "progress" in n], [])


class KillMidWriteTest(TempDirTestCase):
    """A tool killed (SIGKILL) while writing leaves the previous output intact."""

    def test_sigkill_during_a_large_write_keeps_the_old_file(self):
        import signal
        import subprocess
        import time
        small = self.write("a.yaml", "planet: {radius_km: 6371, top_km: 100}\ngrid: {altitude_step_m: 100}\nair: {profile: ussa1976}\n")
        big = self.write("b.yaml", "planet: {radius_km: 6371, top_km: 100}\ngrid: {altitude_step_m: 1}\nair: {profile: ussa1976}\n")
        out = self.path("p.exr")
        self.assertEqual(run([tool("profile-import"), small, "-o", out]).returncode, 0)
        with open(out, "rb") as f:
            old = f.read()
        env = dict(os.environ, SKYBAKE_TEST_SLOW_WRITE_MS="20")
        p = subprocess.Popen([tool("profile-import"), big, "-o", out], env=env,
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        tmp = out + ".tmp-%d" % p.pid
        deadline = time.time() + 60
        while time.time() < deadline and not (os.path.exists(tmp) and os.path.getsize(tmp) > 16384):
            time.sleep(0.01)
        self.assertTrue(os.path.exists(tmp), "the tool never started writing")
        p.send_signal(signal.SIGKILL)
        p.wait()
        with open(out, "rb") as f:
            self.assertEqual(f.read(), old)
        # The next successful run replaces it completely.
        self.assertEqual(run([tool("profile-import"), small, "-o", out]).returncode, 0)


if __name__ == "__main__":
    unittest.main()
