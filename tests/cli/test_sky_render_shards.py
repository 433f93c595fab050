"""sky-render render --shard K/N, sky-render fog --shard K/N and sky-render merge
(transport/sky_shard.h, fog/fog_shard.h, docs/cluster.md): the merged file is the unsharded
render's bytes at any shard count and thread count, for a deterministic method (shards by slices:
`orders`, which repeats its tables in every shard), for the path tracer (shards by slices and
texels, a shard's range crossing slice boundaries), with the preview, and for fog renders (shards
by LUT slices and depth tables, by `orders` and by the path tracer); a merge refuses a missing,
repeated or foreign shard and a shard of the other kind of render, naming the file."""
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

    # The fog pipeline's options reduced: 5 LUT slices of 4x8 texels and 2 depth tables = 7 tasks.
    FOG = ["--method", "orders", "--quality", "low", "--wavelengths", "400:700:50", "--lut-size", "4x8",
           "--time-mapping", "gt7:3+2", "--sun-zenith-deg", "40,85", "--elevations", "5", "--depths", "8",
           "--azimuths-deg", "0,90,180", "--attenuation-size", "8x8"]

    def setUp(self):
        super().setUp()
        self.atm = rayleigh_atmosphere(self.tmp)

    def render(self, out, args, *extra, expect=0, subcommand="render"):
        r = run([tool("sky-render"), subcommand, self.atm, "-o", self.path(out), "--quiet"] + args + list(extra))
        self.assertEqual(r.returncode, expect, r.stderr)
        return r

    def merge(self, out, shards, *extra, expect=0):
        r = run([tool("sky-render"), "merge", "-o", self.path(out), "--quiet"] + [self.path(s) for s in shards] + list(extra))
        self.assertEqual(r.returncode, expect, r.stderr)
        return r

    def sharded(self, args, n, threads, name, subcommand="render"):
        shards = []
        for k in reversed(range(n)):  # the merge takes them in any order
            shards.append("%s.%d-of-%d.exr" % (name, k, n))
            self.render(shards[-1], args, "--shard", "%d/%d" % (k, n), "--threads", str(threads), subcommand=subcommand)
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

    def test_fog_merged_is_the_unsharded_bytes(self):
        self.render("whole.exr", self.FOG, "--threads", "1", subcommand="fog")
        whole = read(self.path("whole.exr"))
        # 7 tasks: 2 shards split the slices (0-2, 3-4 and both tables), 3 shards give the last one
        # a slice and the tables, 7 shards one task each (shard 6: the 85 deg table alone).
        for n, threads in ((2, 2), (3, 1), (7, 2)):
            shards = self.sharded(self.FOG, n, threads, "fog", subcommand="fog")
            self.assertNotEqual(read(self.path(shards[-1])), whole)
            self.merge("merged_%d.exr" % n, shards)
            self.assertEqual(read(self.path("merged_%d.exr" % n)), whole, "%d shards, %d threads" % (n, threads))
        # The path tracer's streams are keyed by the element, not the shard.
        path = ["--method", "path", "--target-error", "0.5", "--max-paths", "256"] + self.FOG[4:]
        self.render("whole_path.exr", path, "--threads", "2", subcommand="fog")
        shards = self.sharded(path, 3, 1, "fog_path", subcommand="fog")
        self.merge("merged_path.exr", shards)
        self.assertEqual(read(self.path("merged_path.exr")), read(self.path("whole_path.exr")))

    def test_a_fog_merge_refuses_missing_repeated_foreign_and_other_kinds_of_shards(self):
        shards = self.sharded(self.FOG, 3, 2, "fog", subcommand="fog")
        r = self.merge("m.exr", shards[:2], expect=1)
        self.assertIn("shard 0/3 of this fog render is missing from the merge's inputs", r.stderr)
        r = self.merge("m.exr", shards + shards[1:2], expect=1)
        self.assertIn("shard 1/3 is given twice", r.stderr)
        self.render("other.1-of-3.exr", self.FOG[:-1] + ["8x4"], "--shard", "1/3", subcommand="fog")
        r = self.merge("m.exr", [shards[0], "other.1-of-3.exr", shards[2]], expect=1)
        self.assertIn("other.1-of-3.exr: a shard of another fog render than", r.stderr)
        sky = self.sharded(self.ORDERS, 2, 2, "orders")
        r = self.merge("m.exr", shards + sky[:1], expect=1)
        self.assertIn("orders.1-of-2.exr: a shard of a sky render, but %s is a shard of a fog render" % self.path(shards[0]),
                      r.stderr)
        r = self.merge("m.exr", shards, "--preview", self.path("m.png"), expect=2)
        self.assertIn("--preview: a fog render has no preview", r.stderr)
        self.render("whole.exr", self.FOG, subcommand="fog")
        r = self.merge("m.exr", [shards[0], "whole.exr"], expect=1)
        self.assertIn("whole.exr: not a shard of a fog render (render it with sky-render fog --shard K/N)", r.stderr)
        self.assertFalse(os.path.exists(self.path("m.exr")))
        # fog-fit reads whole renders only.
        r = run([tool("fog-fit"), "fit", self.path(shards[0]), "--name", "x", "-o", self.path("x.json"), "--quiet"])
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn("a shard of a fog render (sky-render fog --shard): join the shards with sky-render merge", r.stderr)

    def test_bad_fog_shard_options_are_usage_errors(self):
        for bad in ("3/3", "1", "a/4", "0/0"):
            r = self.render("s.exr", self.FOG, "--shard", bad, expect=2, subcommand="fog")
            self.assertIn("sky-render: --shard: expected K/N with 0 <= K < N <= 4096 (e.g. 0/4), got '%s'" % bad, r.stderr)
        r = self.render("s.exr", self.FOG, "--shard", "0/8", expect=2, subcommand="fog")
        self.assertIn("sky-render: --shard 0/8: this fog render has 5 LUT slices and 2 depth tables (7 tasks), fewer than "
                      "8 shards", r.stderr)
        self.assertFalse(os.path.exists(self.path("s.exr")))


if __name__ == "__main__":
    unittest.main()
