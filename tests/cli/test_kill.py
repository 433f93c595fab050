"""Kill test: noise-gen's four outputs (KTX2, EXR, PNG, depfile) are one transaction.
SIGKILL at random moments of a run that replaces set A by set B. On disk, a kill after the commit
point and before the last rename leaves a mixed set with its journal (POSIX renames one file at
a time); every skybake tool reads through the journal (io/fileio.h: reading a file first
completes the committed journals of its folder), so the set as a skybake tool sees it is always
A or B, never mixed. After the next run no temporary file or journal is left. A reader that
meets a live commit waits for it to end.

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

    def journals(self):
        return sorted(glob.glob(self.path(".skybake-commit-*")))

    def leftovers(self):
        return sorted(glob.glob(self.path("*.tmp-*")) + self.journals())

    def produce(self, recipe):
        r = run(self.command(recipe), cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(self.leftovers(), [])
        return self.snapshot()

    def read_as_a_skybake_tool(self, name):
        """A skybake tool opens `name` (one file of the set): noise-gen given it as its recipe. The
        loader reads the file (io/fileio.h ReadFileBytes) and rejects it as YAML: exit 1, nothing
        written."""
        r = run([tool("noise-gen"), self.path(name), "-o", "reader/x.ktx2", "--quiet"], cwd=self.tmp)
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn("noise-gen: " + self.path(name), r.stderr)
        self.assertFalse(os.path.exists(self.path("reader")))

    def recipes(self):
        with open(os.path.join(SRC, "clouds", "noise_high.yaml")) as f:
            recipe = f.read()
        self.assertIn("seed: 11", recipe)
        self.write("a.yaml", recipe)
        self.write("b.yaml", recipe.replace("seed: 11", "seed: 12"))
        set_b = self.produce("b.yaml")
        set_a = self.produce("a.yaml")
        for f in OUTPUTS:
            self.assertNotEqual(set_a[f], set_b[f], f)
        return set_a, set_b

    def test_kill_at_random_moments_never_shows_a_skybake_reader_a_mixed_set(self):
        set_a, set_b = self.recipes()
        env = dict(os.environ, **SLOW)
        t0 = time.monotonic()
        subprocess.run(self.command("b.yaml"), cwd=self.tmp, env=env, check=True)
        duration = time.monotonic() - t0
        self.produce("a.yaml")

        trials = int(os.environ.get("SKYBAKE_KILL_TRIALS", "40"))
        rng = random.Random(22)
        on_disk = {"old set": 0, "new set": 0, "mixed set with its journal": 0}
        read = {"old set": 0, "new set": 0}
        for i in range(trials):
            delay = rng.uniform(0.0, 1.1 * duration)
            p = subprocess.Popen(self.command("b.yaml"), cwd=self.tmp, env=env)
            time.sleep(delay)
            p.kill()
            p.wait()
            now = self.snapshot()
            self.assertEqual(sorted(now), sorted(OUTPUTS))
            for f in OUTPUTS:
                self.assertIn(now[f], (set_a[f], set_b[f]), "a partial file: " + f)
            if now == set_a:
                on_disk["old set"] += 1
            elif now == set_b:
                on_disk["new set"] += 1
            else:
                self.assertEqual(self.journals(), [self.path(".skybake-commit-%d" % p.pid)],
                                 "a mixed set without its journal after %.3f s" % delay)
                on_disk["mixed set with its journal"] += 1
            # A skybake tool reads one file of the set (each of the four in turn): it sees, and
            # leaves, a complete set, and no journal.
            self.read_as_a_skybake_tool(OUTPUTS[i % len(OUTPUTS)])
            seen = self.snapshot()
            self.assertIn(seen, (set_a, set_b), "a reader saw a mixed set after a kill at %.3f s" % delay)
            # No committed journal is left; a kill before the commit point may leave a pending
            # one, which the next run removes with the staged files.
            self.assertEqual([j for j in self.journals() if ".tmp-" not in j], [])
            if now != set_a:
                self.assertEqual(seen, set_b)  # a committed journal completes to the new set
            read["old set" if seen == set_a else "new set"] += 1
            # The next run: no stale file is left, and the old set is back for the next trial.
            r = run(self.command("a.yaml"), cwd=self.tmp)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertEqual(self.leftovers(), [])
            self.assertEqual(self.snapshot(), set_a)
        self.assertEqual(sum(read.values()), trials)
        print("\nkill test: %d kills at 0-%.0f ms of a %.0f ms run. On disk right after the kill: %s. "
              "As a skybake tool reads it: %s; never a mixed set, no partial file, no stale file after the "
              "next run" % (trials, 1100 * duration, 1000 * duration,
                            ", ".join("%s %d" % (k, v) for k, v in on_disk.items()),
                            ", ".join("%s %d" % (k, v) for k, v in read.items())), file=sys.stderr)

    def test_a_reader_during_a_live_commit_waits_and_sees_the_new_set(self):
        set_a, set_b = self.recipes()
        # 400 ms after each rename of the commit: the reader starts between two of them.
        env = dict(os.environ, SKYBAKE_TEST_SLOW_COMMIT_MS="400")
        p = subprocess.Popen(self.command("b.yaml"), cwd=self.tmp, env=env)
        self.addCleanup(p.wait)
        self.addCleanup(p.kill)
        journal = self.path(".skybake-commit-%d" % p.pid)  # named: after the commit point
        deadline = time.monotonic() + 60
        while not os.path.exists(journal) and p.poll() is None and time.monotonic() < deadline:
            time.sleep(0.002)
        self.assertEqual(self.journals(), [journal])
        time.sleep(0.15)  # inside the rename loop (4 renames, 400 ms apart): the set on disk is mixed
        self.assertNotIn(self.snapshot(), (set_a, set_b))
        t0 = time.monotonic()
        self.read_as_a_skybake_tool("v.exr")
        waited = time.monotonic() - t0
        self.assertEqual(self.snapshot(), set_b, "the reader returned before the commit ended")
        self.assertGreater(waited, 0.4)  # at least the renames that were still to come
        self.assertEqual(p.wait(), 0)
        self.assertEqual(self.snapshot(), set_b)
        self.assertEqual(self.leftovers(), [])


if __name__ == "__main__":
    unittest.main()
