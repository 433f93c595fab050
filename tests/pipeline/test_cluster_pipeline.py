"""Sharded bakes (docs/cluster.md): the generator's shard edges, and a bake through a real Slurm.

ShardedGraphTest (no scheduler): `shards: N` splits each render (sky references, LUT renders,
fog renders) into N `--shard k/N` edges and a merge edge; bad shard counts and a launcher that is not installed fail at generate time with
pipeline.yaml:line.

ClusterBakeTest: scripts/cluster-up starts a one-node Slurm on loopback (munged, slurmctld,
slurmd in a temporary folder); a reduced pipeline (2 atmospheres, LUT renders by `orders` at low
quality on 5 slices, path references of 4x2 texels on 2 sun angles) is baked locally without
shards and through Slurm (`srun` as sky-render's launcher, 4 shards per render, ninja -j 4):
every product has the same bytes; the job completion log (jobcomp/filetxt) shows each shard and
merge as a completed Slurm job; a second bake does no work; an edit to one atmosphere re-runs only
its shards; a shard cancelled with scancel leaves no partial file, fails the bake naming the
shard, and the next bake runs only that shard (and the merges after it). Skipped, saying so, when
slurm-wlm or munge is not installed (scripts/setup installs both).
"""
import filecmp
import os
import re
import shutil
import subprocess
import sys
import time
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "cli"))
from skytest import SRC, PipelineTestCase, TINY_PARTICLE, run, tool  # noqa: E402

PIPELINE = """outputs: {outputs}
altitude_step_m: 200
wavelengths: {{min_nm: 400, max_nm: 700, step_nm: 50}}
atmospheres:
  - atmospheres/clear.yaml
  - atmospheres/hazed.yaml
{launchers}sky: {{size: 4x2, sun_zenith_deg: [40, 85], target_error: 0.5, preview: true, shards: {shards}}}
luts:
  method: orders
  quality: low
  time_mapping: "gt7:3+2"
  shards: {shards}
  skies:
    - {{atmosphere: clear, size: 4x8}}
    - {{atmosphere: hazed, size: 4x8}}
"""

# The fog section of the reduced pipeline (lines 16-23 after PIPELINE): 5 LUT slices + 2 depth tables.
FOG = """fog:
  quality: low
  time_mapping: "gt7:3+2"
  lut_size: 4x8
  attenuation_size: 8x8
  depth_tables: {{sun_zenith_deg: [40, 85], elevations: 5, azimuths_deg: [0, 90, 180], depths: 8}}
  shards: {shards}
  skies: [clear, hazed]
"""

SLURM_BINARIES = ("munged", "slurmctld", "slurmd", "srun", "sinfo", "squeue", "scancel")
LAUNCHER = 'launchers: {sky-render: "srun --quiet -n1 -c1 -J $out"}\n'


def edges_run(ninja_stdout):
    return [m.group(1) for m in re.finditer(r"^\[\d+/\d+\] (.*)$", ninja_stdout, re.M)]


def products(folder):
    """Every file a tool wrote under `folder`, by relative path: the graph's products, not
    the generator's files, Ninja's logs or the shards."""
    out = []
    for root, dirs, files in os.walk(folder):
        rel = os.path.relpath(root, folder)
        parts = rel.split(os.sep)
        if "components" in parts or "shards" in parts or ".skybake" in parts:
            continue
        for f in files:
            if f.startswith(".ninja") or f == "build.ninja" or f.endswith(".d"):
                continue
            out.append(os.path.normpath(os.path.join(rel, f)))
    return sorted(out)


class ReducedPipeline(PipelineTestCase):
    def setUp(self):
        super().setUp()
        shutil.copytree(os.path.join(SRC, "atmospheres"), self.path("atmospheres"))
        for extra in ("particles", "ocio"):
            shutil.copytree(os.path.join(SRC, extra), self.path(extra))
        self.write("particles/tiny.yaml", TINY_PARTICLE)
        for atm in ("clear", "hazed"):
            p = self.path("atmospheres", atm + ".yaml")
            with open(p) as f:
                text = f.read()
            with open(p, "w") as f:
                f.write(re.sub(r"particle: \.\./particles/\w+\.yaml", "particle: ../particles/tiny.yaml", text))

    def pipeline(self, name, outputs, shards, launchers=""):
        self.write(name, PIPELINE.format(outputs=outputs, shards=shards, launchers=launchers))


class ShardedGraphTest(ReducedPipeline):
    def test_shards_become_shard_edges_and_a_merge(self):
        self.pipeline("pipeline.yaml", "outputs", 4)
        r = run([tool("skybake"), "graph", "pipeline.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        for atm in ("clear", "hazed"):
            for k in range(4):
                self.assertIn("sky-render: %s/shards/lut_sky.%d-of-4.exr" % (atm, k), r.stdout)
                self.assertIn("sky-render: %s/shards/sky.%d-of-4.exr" % (atm, k), r.stdout)
            self.assertIn("<- %s/shards/lut_sky.3-of-4.exr" % atm, r.stdout)
        self.generate_ok()
        with open(self.path("outputs", "build.ninja")) as f:
            text = f.read()
        self.assertIn("--shard 2/4", text)
        self.assertRegex(text, r"build clear/sky.exr \| clear/sky.png: sky_merge clear/shards/sky.0-of-4.exr")
        self.assertIn("args = merge --preview clear/sky.png", text)

    def test_fog_shards_become_shard_edges_and_a_merge(self):
        self.pipeline("pipeline.yaml", "outputs", 1)
        with open(self.path("pipeline.yaml"), "a") as f:
            f.write(FOG.format(shards=3))
        self.generate_ok()
        with open(self.path("outputs", "build.ninja")) as f:
            text = f.read()
        for atm in ("clear", "hazed"):
            shard_edges = re.findall(r"^build %s/shards/fog\.(\d)-of-3\.exr: fog_render %s/components/render\.yaml" % (atm, atm),
                                     text, re.M)
            self.assertEqual(shard_edges, ["0", "1", "2"])
            for k in range(3):
                self.assertRegex(text, r"build %s/shards/fog\.%d-of-3\.exr: [^\n]*\n(  [^\n]*\n)*  args = fog [^\n]* --shard %d/3\n"
                                 % (atm, k, k))
            self.assertIn("build %s/fog.exr: fog_merge %s/shards/fog.0-of-3.exr %s/shards/fog.1-of-3.exr "
                          "%s/shards/fog.2-of-3.exr" % (atm, atm, atm, atm), text)
            # The fit reads the merged render.
            self.assertRegex(text, r"build fog/fog_%s\.json[^:]*: fog_fit %s/fog\.exr" % (atm, atm))
        # One shard: one render edge, no merge.
        self.pipeline("pipeline.yaml", "outputs", 1)
        with open(self.path("pipeline.yaml"), "a") as f:
            f.write(FOG.format(shards=1))
        self.generate_ok()
        with open(self.path("outputs", "build.ninja")) as f:
            text = f.read()
        self.assertNotIn("fog_merge", text)
        self.assertNotIn("--shard", text)
        self.assertRegex(text, r"build clear/fog\.exr: fog_render clear/components/render\.yaml")
        # 8 shards for 7 tasks: refused at the key's line, no build.ninja written.
        shutil.rmtree(self.path("outputs"))
        self.pipeline("pipeline.yaml", "outputs", 1)
        with open(self.path("pipeline.yaml"), "a") as f:
            f.write(FOG.format(shards=8))
        self.generate_fails("pipeline.yaml:22: key 'fog.shards': 8 shards for the 5 LUT slices of time mapping gt7:3+2 "
                            "and 2 depth tables: at most one shard per slice or table")

    def generate_ok(self):
        r = run([tool("skybake"), "generate", "pipeline.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)

    def generate_fails(self, message):
        r = run([tool("skybake"), "generate", "pipeline.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
        self.assertTrue(r.stderr.startswith("skybake: "), r.stderr)
        self.assertIn(message, r.stderr)
        self.assertFalse(os.path.exists(self.path("outputs", "build.ninja")))

    def test_bad_shard_counts_fail_at_their_line(self):
        self.pipeline("pipeline.yaml", "outputs", 0)
        self.generate_fails("pipeline.yaml:7: key 'sky.shards': expected a whole number of shards from 1 to 4096, got \"0\"")
        self.pipeline("pipeline.yaml", "outputs", 6)  # 5 slices of gt7:3+2
        self.generate_fails("pipeline.yaml:14: key 'luts.skies[0]': 6 shards for the 5 slices of time mapping gt7:3+2: at most one shard "
                            "per slice")
        self.pipeline("pipeline.yaml", "outputs", 1)
        self.edit("pipeline.yaml", "preview: true, shards: 1", "preview: true, shards: 9")  # 2 slices x 4 texel tasks
        self.generate_fails("pipeline.yaml:7: key 'sky.shards': 9 shards for 8 texel tasks of the render: at most one shard per task")

    def test_no_shards_key_and_bad_sun_angles_report_the_angles(self):
        # Without a `shards` key nothing is said of shards, even when the sun angles that count the
        # tasks are themselves in error (tests/fuzz/regressions/pipeline_yaml/).
        self.pipeline("pipeline.yaml", "outputs", 1)
        self.edit("pipeline.yaml", "preview: true, shards: 1", "preview: true")
        self.edit("pipeline.yaml", "sun_zenith_deg: [40, 85], target_error", "sun_zenith_deg: [40, gg85], target_error")
        self.generate_fails("pipeline.yaml:7: key 'sky.sun_zenith_deg[1]'")

    def test_a_missing_launcher_fails_at_generate_time(self):
        self.pipeline("pipeline.yaml", "outputs", 2, 'launchers: {sky-render: "no-such-srun --quiet -n1"}\n')
        self.generate_fails("pipeline.yaml:7: key 'launchers.sky-render': 'no-such-srun' is not on PATH")
        self.pipeline("pipeline.yaml", "outputs", 2, 'launchers: {sky-render: "./bin/srun -n1"}\n')
        self.generate_fails("pipeline.yaml:7: key 'launchers.sky-render': './bin/srun' is not an executable file")


def slurm_missing():
    path = os.environ.get("PATH", "") + ":/usr/sbin"
    return [b for b in SLURM_BINARIES if not shutil.which(b, path=path)]


@unittest.skipIf(slurm_missing(), "Slurm is not installed (missing %s): scripts/setup installs slurm-wlm and munge"
                 % ", ".join(slurm_missing()))
class ClusterBakeTest(ReducedPipeline):
    def setUp(self):
        super().setUp()
        self.cluster = self.path("slurm")
        r = run([os.path.join(SRC, "scripts", "cluster-up"), self.cluster], timeout=120)
        if r.returncode != 0:  # tearDown does not run after a failed setUp: stop what did start
            run([os.path.join(SRC, "scripts", "cluster-down"), self.cluster])
            super().tearDown()
            self.fail("scripts/cluster-up failed:\n" + r.stdout + r.stderr)
        self.cluster_started = True
        self.env = dict(os.environ)
        for m in re.finditer(r"^export (\w+)=(.*)$", r.stdout, re.M):
            self.env[m.group(1)] = m.group(2).replace("$PATH", os.environ.get("PATH", ""))
        self.out = self.path("outputs_slurm")

    def tearDown(self):
        # Before the temporary folder (with the daemons' pid files) is removed.
        if getattr(self, "cluster_started", False):
            r = run([os.path.join(SRC, "scripts", "cluster-down"), self.cluster])
            self.assertEqual(r.returncode, 0, r.stderr)
        super().tearDown()

    def slurm(self, *args, expect=0, check=True):
        r = run(["ninja", "-C", self.out, "-j", "4"] + list(args), env=self.env)
        if check:
            self.assertEqual(r.returncode, expect, r.stdout + r.stderr)
        return r

    @staticmethod
    def tool_running(needle):
        """Whether a sky-render process (not its srun) has `needle` in its command line."""
        for pid in os.listdir("/proc"):
            try:
                with open("/proc/%s/cmdline" % pid, "rb") as f:
                    cmd = f.read().replace(b"\0", b" ").decode(errors="replace")
            except OSError:
                continue
            if needle in cmd and "sky-render" in cmd.split(" ")[0]:
                return True
        return False

    def jobs(self):
        """Completed Slurm jobs by name (jobcomp/filetxt: one line per finished job)."""
        path = os.path.join(self.cluster, "jobcomp.log")
        if not os.path.exists(path):
            return []
        with open(path) as f:
            return [(m.group(1), m.group(2)) for m in re.finditer(r"Name=(\S+) JobState=(\S+)", f.read())]

    def test_slurm_bake_is_the_local_bake_and_faults_rerun_one_shard(self):
        # The local, unsharded reference bake.
        self.pipeline("local.yaml", "outputs_local", 1)
        r = run([tool("skybake"), "bake", "local.yaml"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        # Through Slurm, 4 shards per render.
        self.pipeline("pipeline.yaml", "outputs_slurm", 4, LAUNCHER)
        r = run([tool("skybake"), "generate", "pipeline.yaml"], cwd=self.tmp, env=self.env)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.slurm()
        local, slurm = products(self.path("outputs_local")), products(self.out)
        self.assertEqual(local, slurm)
        for f in ("clear/lut_sky.exr", "hazed/sky.exr", "hazed/sky.png", "luts/sky_hazed.ktx2", "luts/report.json"):
            self.assertIn(f, local)
        differ = [f for f in local if not filecmp.cmp(os.path.join(self.path("outputs_local"), f), os.path.join(self.out, f),
                                                      shallow=False)]
        self.assertEqual(differ, [], "sharded Slurm bake differs from the local bake")
        # Each shard and each merge ran as a Slurm job, named by its output ($out in the launcher).
        jobs = self.jobs()
        expected = ["%s/shards/%s.%d-of-4.exr" % (a, p, k) for a in ("clear", "hazed") for p in ("lut_sky", "sky")
                    for k in range(4)] + ["%s/%s.exr" % (a, p) for a in ("clear", "hazed") for p in ("lut_sky", "sky")]
        self.assertEqual(sorted(n for n, s in jobs if s == "COMPLETED"), sorted(expected), jobs)
        # Nothing to do the second time: no job is submitted.
        self.assertIn("no work to do", self.slurm().stdout)
        self.assertEqual(len(self.jobs()), len(jobs))

        # An edit to hazed re-runs hazed's shards and merges only (and the pack).
        self.edit("atmospheres/hazed.yaml", "optical_depth_550nm: 0.5", "optical_depth_550nm: 0.6")
        ran = edges_run(self.slurm().stdout)
        renders = [e for e in ran if e.startswith("sky-render")]
        self.assertEqual(len(renders), 10, ran)
        self.assertTrue(all("hazed/" in e for e in renders), ran)
        self.assertIn("lut-pack luts/report.json", ran)

        # A shard cancelled mid-run: no partial file, a failed bake naming the shard, and the
        # next bake runs that shard only.
        self.edit("atmospheres/hazed.yaml", "optical_depth_550nm: 0.6", "optical_depth_550nm: 0.7")
        victim = "hazed/shards/lut_sky.1-of-4.exr"
        with open(os.path.join(self.out, victim), "rb") as f:
            old = f.read()
        bake = subprocess.Popen(["ninja", "-C", self.out, "-j", "4", "-k", "0"], env=self.env, stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True)
        # Cancelled once the tool itself runs on the node (its process exists), not while the
        # job waits or its step launches.
        cancelled = None
        deadline = time.time() + 120
        while cancelled is None and time.time() < deadline and bake.poll() is None:
            if self.tool_running("-o " + victim):
                q = run(["squeue", "-h", "-o", "%i %j"], env=self.env)
                for line in q.stdout.split("\n"):
                    if line.endswith(" " + victim):
                        cancelled = line.split()[0]
                        run(["scancel", cancelled], env=self.env)
            time.sleep(0.02)
        out, _ = bake.communicate(timeout=300)
        self.assertIsNotNone(cancelled, "the shard's job was never seen running:\n" + out)
        self.assertNotEqual(bake.returncode, 0, out)
        print("\n--- the bake with a cancelled shard ---\n" + out)
        self.assertIn("FAILED: " + victim, out)
        self.assertIn("CANCELLED", out)
        # The shard's file is its previous complete version (the tool writes by rename).
        with open(os.path.join(self.out, victim), "rb") as f:
            self.assertEqual(f.read(), old)
        plan = self.slurm("-n").stdout
        shards_planned = [e for e in edges_run(plan) if "/shards/" in e]
        self.assertEqual(shards_planned, ["sky-render " + victim], plan)
        ran = edges_run(self.slurm().stdout)
        self.assertEqual([e for e in ran if "/shards/" in e], ["sky-render " + victim], ran)
        self.assertIn("sky-render merge hazed/lut_sky.exr", ran)
        self.assertIn("no work to do", self.slurm().stdout)


if __name__ == "__main__":
    unittest.main()
