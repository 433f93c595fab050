"""sky-render render --shard K/N and sky-render merge (transport/sky_shard.h, docs/cluster.md):
the merged file is the unsharded render's bytes at any shard count and thread count, for a
deterministic method (shards by slices: `orders`, which repeats its tables in every shard) and
for the path tracer (shards by slices and texels, a shard's range crossing slice boundaries),
with the preview; a merge refuses a missing, repeated or foreign shard, naming the file."""
import os
import unittest

from skytest import TempDirTestCase, run, tool
from test_sky_render import rayleigh_atmosphere


def read(path):
    with open(path, "rb") as f:
        return f.read()


class SkyRenderShards(TempDirTestCase):
    ORDERS = ["--method", "orders", "--quality", "low", "--mapping", "gt7", "--size", "4x8", "--time-mapping", "gt7:3+2",
              "--wavelengths", "400:700:50"]
    PATH = ["--method", "path", "--size", "6x4", "--sun-zenith-deg", "40,85,95", "--target-error", "0.3",
            "--wavelengths", "400:700:50"]

    def setUp(self):
        super().setUp()
        self.atm = rayleigh_atmosphere(self.tmp)

    def render(self, out, args, *extra, expect=0):
        r = run([tool("sky-render"), "render", self.atm, "-o", self.path(out), "--quiet"] + args + list(extra))
        self.assertEqual(r.returncode, expect, r.stderr)
        return r

    def merge(self, out, shards, *extra, expect=0):
        r = run([tool("sky-render"), "merge", "-o", self.path(out), "--quiet"] + [self.path(s) for s in shards] + list(extra))
        self.assertEqual(r.returncode, expect, r.stderr)
        return r

    def sharded(self, args, n, threads, name):
        shards = []
        for k in reversed(range(n)):  # the merge takes them in any order
            shards.append("%s.%d-of-%d.exr" % (name, k, n))
            self.render(shards[-1], args, "--shard", "%d/%d" % (k, n), "--threads", str(threads))
        return shards

    def test_orders_merged_is_the_unsharded_bytes(self):
        self.render("whole.exr", self.ORDERS, "--threads", "1")
        whole = read(self.path("whole.exr"))
        for n, threads in ((2, 2), (3, 1), (5, 2)):
            shards = self.sharded(self.ORDERS, n, threads, "orders")
            # A shard holds only its slices: it is not the whole file.
            self.assertNotEqual(read(self.path(shards[0])), whole)
            self.merge("merged_%d.exr" % n, shards)
            self.assertEqual(read(self.path("merged_%d.exr" % n)), whole, "%d shards, %d threads" % (n, threads))

    def test_path_merged_is_the_unsharded_bytes_with_the_preview(self):
        self.render("whole.exr", self.PATH, "--threads", "2", "--preview", self.path("whole.png"))
        whole = read(self.path("whole.exr"))
        # 3 slices x 12 mirror pairs = 36 tasks: 2 shards split by slice midway, 7 and 36 cut texel ranges.
        for n, threads in ((2, 1), (7, 2), (36, 1)):
            shards = self.sharded(self.PATH, n, threads, "path")
            self.merge("merged_%d.exr" % n, shards, "--preview", self.path("merged_%d.png" % n))
            self.assertEqual(read(self.path("merged_%d.exr" % n)), whole, "%d shards, %d threads" % (n, threads))
            self.assertEqual(read(self.path("merged_%d.png" % n)), read(self.path("whole.png")), "preview, %d shards" % n)

    def test_a_merge_refuses_missing_repeated_and_foreign_shards(self):
        shards = self.sharded(self.ORDERS, 3, 2, "orders")
        r = self.merge("m.exr", shards[:2], expect=1)
        self.assertIn("shard 0/3 of this render is missing from the merge's inputs", r.stderr)
        r = self.merge("m.exr", shards + shards[:1], expect=1)
        self.assertIn("shard 2/3 is given twice", r.stderr)
        self.render("other.1-of-3.exr", self.ORDERS[:-1] + ["400:700:25"], "--shard", "1/3")
        r = self.merge("m.exr", [shards[0], "other.1-of-3.exr", shards[2]], expect=1)
        self.assertIn("other.1-of-3.exr: a shard of another render than", r.stderr)
        self.render("whole.exr", self.ORDERS)
        r = self.merge("m.exr", ["whole.exr"], expect=1)
        self.assertIn("whole.exr: not a shard of a render", r.stderr)
        self.assertFalse(os.path.exists(self.path("m.exr")))

    def test_bad_shard_options_are_usage_errors(self):
        for bad in ("3/3", "1", "a/4", "-1/4", "0/0", "1/4x"):
            r = self.render("s.exr", self.ORDERS, "--shard", bad, expect=2)
            self.assertIn("sky-render: --shard: expected K/N with 0 <= K < N <= 4096 (e.g. 0/4), got '%s'" % bad, r.stderr)
        r = self.render("s.exr", self.ORDERS, "--shard", "0/6", expect=2)
        self.assertIn("sky-render: --shard 0/6: this render has 5 slices, fewer than 6 shards", r.stderr)
        r = self.render("s.exr", self.PATH, "--shard", "0/2", "--preview", self.path("s.png"), expect=2)
        self.assertIn("--preview: a shard writes no preview (sky-render merge --preview does)", r.stderr)
        self.assertFalse(os.path.exists(self.path("s.exr")))


if __name__ == "__main__":
    unittest.main()
