#!/usr/bin/env python3
"""`orders` on Bruneton's 2017 atmosphere, on the same work as his CPU reference: 47 wavelengths
(360-820 nm every 10 nm, `reference/model_test.cc`), every order (`orders` sums its orders and
extrapolates the geometric tail), one GT7 sky LUT of 64 sun slices x 32 x 128 texels. Prints the
wall time, CPU time and peak memory at each thread count and quality, the ratio against the CPU
reference's time per sky (REFERENCE_S) and whether the outputs are the same bytes at every thread
count. Writes only into its work folder.

  bench/peer_speed.py [--bin build/release/bin] [--qualities low,medium,high] [--threads 1,2]
                      [--work /tmp/peer_speed]

REFERENCE_S: ~600 s per sky for Bruneton's CPU reference implementation (47 wavelengths, 4 orders)
on a 2-core machine like this project's: the figure of this project's speed issue ("Speed: the
accurate LUT set in 30 s"), for E. Bruneton, precomputed_atmospheric_scattering (2017),
reference/model_test.cc. Its accuracy beside ours: docs/peers.md "Agreement with our path tracer"
(`orders` medium against the path tracer on this atmosphere).
"""
import argparse
import filecmp
import os
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
REFERENCE_S = 600.0  # s per sky, Bruneton 2017's CPU reference on 2 cores (see the docstring)


def render(binary, quality, threads, output):
    """Wall s, CPU s and peak resident MiB of one LUT render."""
    args = [binary, "--quiet", "--threads", str(threads), "render",
            os.path.join(ROOT, "atmospheres/peers/bruneton2017.yaml"), "--wavelengths", "360:820:10",
            "--method", "orders", "--quality", quality, "--size", "32x128", "--time-mapping", "gt7",
            "-o", output]
    t0 = time.perf_counter()
    proc = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    err = proc.stderr.read()
    _, status, usage = os.wait4(proc.pid, 0)  # this child's own rusage
    wall = time.perf_counter() - t0
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit("failed: %s\n%s" % (" ".join(args), err))
    return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024.0  # ru_maxrss: KiB on Linux


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(ROOT, "build/release/bin"))
    ap.add_argument("--qualities", default="low,medium,high")
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--work", default="/tmp/peer_speed")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    binary = os.path.join(os.path.abspath(a.bin), "sky-render")
    threads = [int(t) for t in a.threads.split(",")]
    print("orders on atmospheres/peers/bruneton2017.yaml: 47 wavelengths, 64 slices x 32 x 128, every order")
    print("%-8s %7s %9s %8s %9s %12s %6s" % ("quality", "threads", "wall_s", "cpu_s", "peak_MiB",
                                            "vs_ref_600s", "same"))
    for q in a.qualities.split(","):
        outputs = []
        for t in threads:
            out = os.path.join(a.work, "bruneton_%s_t%d.exr" % (q, t))
            wall, cpu, peak = render(binary, q, t, out)
            outputs.append(out)
            same = all(filecmp.cmp(outputs[0], o, shallow=False) for o in outputs)
            print("%-8s %7d %9.2f %8.2f %9.0f %11.0fx %6s" % (q, t, wall, cpu, peak, REFERENCE_S / wall,
                                                           "yes" if same else "NO"))
            sys.stdout.flush()


if __name__ == "__main__":
    main()
