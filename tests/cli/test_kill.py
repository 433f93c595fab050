"""Kill test: noise-gen's four outputs (KTX2, EXR, PNG, depfile) are one transaction.
SIGKILL at random moments of a run that replaces set A by set B leaves set A, set B, or (killed
between the renames of the commit) a mixed set with its journal, which the next run completes
to set B; after the next run no temporary file or journal is left.

SKYBAKE_KILL_TRIALS sets the number of kills (default 40); the figures are printed on stderr.
  cd tests/cli && SKYBAKE_BIN_DIR=... python3 -m unittest -v test_kill
"""
import glob
import os
import random
import subprocess
import sys
import time
import unittest

from skytest import SRC, TempDirTestCase, run, tool

OUTPUTS = ["v.ktx2", "v.exr", "v.png", "v.ktx2.d"]
# Slow writes (1 ms per 4 KiB) and a 20 ms pause after each rename of the commit, so that
# random kills land in the staging, in the commit and after it.
SLOW = {"SKYBAKE_TEST_SLOW_WRITE_MS": "1", "SKYBAKE_TEST_SLOW_COMMIT_MS": "20"}


class KillTest(TempDirTestCase):
    def command(self, recipe):
        return [tool("noise-gen"), self.path(recipe), "-o", "v.ktx2", "--exr", "v.exr", "--preview", "v.png",
                "--depfile", "v.ktx2.d", "--quiet"]

    def snapshot(self):
        out = {}
        for f in OUTPUTS:
            p = self.path(f)
            if os.path.exists(p):
                with open(p, "rb") as fh:
                    out[f] = fh.read()
        return out

    def leftovers(self):
        return sorted(glob.glob(self.path("*.tmp-*")) + glob.glob(self.path(".skybake-commit-*")))

    def produce(self, recipe):
        r = run(self.command(recipe), cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(self.leftovers(), [])
        return self.snapshot()

    def test_kill_at_random_moments_leaves_the_old_or_the_new_set(self):
        with open(os.path.join(SRC, "clouds", "noise_high.yaml")) as f:
            recipe = f.read()
        self.assertIn("seed: 11", recipe)
        self.write("a.yaml", recipe)
        self.write("b.yaml", recipe.replace("seed: 11", "seed: 12"))
        set_b = self.produce("b.yaml")
        set_a = self.produce("a.yaml")
        for f in OUTPUTS:
            self.assertNotEqual(set_a[f], set_b[f], f)
        env = dict(os.environ, **SLOW)
        t0 = time.monotonic()
        subprocess.run(self.command("b.yaml"), cwd=self.tmp, env=env, check=True)
        duration = time.monotonic() - t0
        self.produce("a.yaml")

        trials = int(os.environ.get("SKYBAKE_KILL_TRIALS", "40"))
        rng = random.Random(22)
        tally = {"old set": 0, "new set": 0, "mixed set with its journal": 0}
        for i in range(trials):
            delay = rng.uniform(0.0, 1.1 * duration)
            p = subprocess.Popen(self.command("b.yaml"), cwd=self.tmp, env=env)
            time.sleep(delay)
            p.kill()
            p.wait()
            now = self.snapshot()
            self.assertEqual(sorted(now), sorted(OUTPUTS))
            if now == set_a:
                tally["old set"] += 1
            elif now == set_b:
                tally["new set"] += 1
            else:
                for f in OUTPUTS:
                    self.assertIn(now[f], (set_a[f], set_b[f]), "a partial file: " + f)
                journals = glob.glob(self.path(".skybake-commit-%d" % p.pid))
                self.assertEqual(len(journals), 1, "a mixed set without a journal after %.3f s" % delay)
                tally["mixed set with its journal"] += 1
                # The next run completes the journal: the new set.
                r = run(self.command("b.yaml"), cwd=self.tmp)
                self.assertEqual(r.returncode, 0, r.stderr)
                self.assertEqual(self.snapshot(), set_b)
            # The next run: no stale file is left, and the old set is back for the next trial.
            r = run(self.command("a.yaml"), cwd=self.tmp)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertEqual(self.leftovers(), [])
            self.assertEqual(self.snapshot(), set_a)
        print("\nkill test: %d kills at 0-%.0f ms of a %.0f ms run: %s; no partial file, no stale file after the "
              "next run" % (trials, 1100 * duration, 1000 * duration,
                            ", ".join("%s %d" % (k, v) for k, v in tally.items())), file=sys.stderr)


if __name__ == "__main__":
    unittest.main()
