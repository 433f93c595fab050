"""Progress lines of a long tool run (io/progress_log.h, io/progress_channel.h): on stderr at the
--progress-interval it is given, and to the bake's progress channel (a FIFO named by
SKYBAKE_PROGRESS) at SKYBAKE_PROGRESS_INTERVAL, naming the tool and its output. The run is a
Mie table of 10 wavelengths (about a second); the intervals are 20 ms, so the counts asserted
hold on a much faster or slower machine."""
import os
import re
import unittest

from skytest import SRC, TempDirTestCase, run, tool

PARTICLE = os.path.join(SRC, "particles", "continental.yaml")
STDERR_LINE = re.compile(r"^mie-tables: mie \d+%$")


class Progress(TempDirTestCase):
    def build(self, *extra, env=None):
        out = self.path("t.exr")
        r = run([tool("mie-tables"), "--threads", "1", "build", PARTICLE, "-o", out, "--wavelength-min-nm", "400",
                 "--wavelength-max-nm", "490", "--wavelength-step-nm", "10"] + list(extra), env=env)
        return r, out

    def fifo(self):
        path = self.path("progress.fifo")
        os.mkfifo(path)
        fd = os.open(path, os.O_RDWR | os.O_NONBLOCK)  # a reader, so that the tool may open it
        self.addCleanup(os.close, fd)
        return path, fd

    @staticmethod
    def drain(fd):
        data = b""
        while True:
            try:
                chunk = os.read(fd, 65536)
            except BlockingIOError:
                break
            if not chunk:
                break
            data += chunk
        return data.decode().splitlines()

    def test_stderr_lines_at_the_given_interval(self):
        r, _ = self.build("--progress-interval", "0.02")
        self.assertEqual(r.returncode, 0, r.stderr)
        lines = [l for l in r.stderr.splitlines() if STDERR_LINE.match(l)]
        self.assertGreaterEqual(len(lines), 5, r.stderr)
        self.assertEqual(lines[0], "mie-tables: mie 0%")
        self.assertEqual(lines[-1], "mie-tables: mie 100%")

    def test_channel_lines_name_the_output_and_quiet_keeps_them(self):
        path, fd = self.fifo()
        r, out = self.build("--quiet", env={"SKYBAKE_PROGRESS": path, "SKYBAKE_PROGRESS_INTERVAL": "0.02"})
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(r.stderr, "")  # --quiet: nothing on stderr
        lines = self.drain(fd)
        self.assertGreaterEqual(len(lines), 3, lines)
        pattern = re.compile(r"^mie-tables %s: (running|mie \d+%%) \(\d+\.\d s\)$" % re.escape(out))
        for l in lines:
            self.assertRegex(l, pattern)
        self.assertTrue(os.path.isfile(out))

    def test_without_a_reader_or_with_a_regular_file_nothing_is_written(self):
        plain = self.write("plain.txt", "")
        for target in (plain, self.path("missing.fifo")):
            r, out = self.build("--quiet", env={"SKYBAKE_PROGRESS": target, "SKYBAKE_PROGRESS_INTERVAL": "0.02"})
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertTrue(os.path.isfile(out))
        with open(plain) as f:
            self.assertEqual(f.read(), "")
        self.assertFalse(os.path.exists(self.path("missing.fifo")))

    def test_bad_intervals_are_usage_errors(self):
        r, out = self.build(env={"SKYBAKE_PROGRESS_INTERVAL": "soon"})
        self.assertEqual(r.returncode, 2)
        self.assertEqual(r.stderr.splitlines()[0],
                         "mie-tables: SKYBAKE_PROGRESS_INTERVAL=soon: expected seconds from 0.01 to 3600")
        self.assertFalse(os.path.exists(out))
        r, out = self.build("--progress-interval", "0")
        self.assertEqual(r.returncode, 2)
        self.assertIn("--progress-interval", r.stderr)
        self.assertFalse(os.path.exists(out))


if __name__ == "__main__":
    unittest.main()
