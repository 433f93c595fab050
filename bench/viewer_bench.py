#!/usr/bin/env python3
"""The runtime viewer's cost (docs/runtime.md "Measured"): frame time and texture fetches per pixel in
headless Chromium. Prints a table; writes nothing outside its work folder.

  bench/viewer_bench.py [--outputs outputs] [--size 1280x720] [--frames 3] [--work /tmp/viewer_bench]

Needs a bake (scripts/bake) and scripts/setup's Chromium and puppeteer-core. The page is rendered
by Chromium's software WebGL2 (SwiftShader on the CPU: the renderer string is printed) — the
frame times measure this machine's CPU, not a GPU; the fetch counts are what any GPU would do.
Views (camera level, the sun 25 deg high, 70 deg vertical field of view):
  sky            the sky LUTs alone (clear; the ground without fog)
  sky + fog      the ground under the global fog (hazed)
  sky + clouds   the cumulus layer ray-marched over the sky (cloudiness 0.1)
  weather blend  haziness 0.5 with fog and clouds (three basis skies at once)
The fetches are counted in the shader (SB_COUNT_FETCHES): per pixel of the upper half (the sky,
the clouds) and the lower half (the ground, the fog) of the level view.
"""
import argparse
import json
import os
import subprocess
import sys

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))

VIEWS = [
    ("sky", {"sunElevationDeg": 25, "haziness": 0, "cloudiness": 0, "fog": False, "clouds": False}),
    ("sky + fog", {"sunElevationDeg": 25, "haziness": 1, "cloudiness": 0, "fog": True, "clouds": False}),
    ("sky + clouds", {"sunElevationDeg": 25, "haziness": 0, "cloudiness": 0.1, "fog": False, "clouds": True}),
    ("weather blend", {"sunElevationDeg": 25, "haziness": 0.5, "cloudiness": 0.1, "fog": True, "clouds": True}),
]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--outputs", default=os.path.join(ROOT, "outputs"))
    ap.add_argument("--size", default="1280x720")
    ap.add_argument("--frames", type=int, default=3)
    ap.add_argument("--work", default="/tmp/viewer_bench")
    a = ap.parse_args()
    w, h = (int(v) for v in a.size.split("x"))
    os.makedirs(a.work, exist_ok=True)
    common = {"pitchDeg": 0, "yawDeg": 0, "fovDeg": 70, "ev": 12.5}
    plan = {
        "width": w, "height": h,
        "fetches": [{"name": n, "state": dict(common, **s)} for n, s in VIEWS],
        "frame_times": [{"name": n, "state": dict(common, **s), "frames": a.frames} for n, s in VIEWS],
    }
    plan_path = os.path.join(a.work, "plan.json")
    with open(plan_path, "w") as f:
        json.dump(plan, f)
    out = os.path.join(a.work, "result.json")
    server = subprocess.Popen([sys.executable, os.path.join(ROOT, "scripts", "view_server.py"), "--outputs", a.outputs,
                               "--port", "0", "--print-port", "--quiet"], stdout=subprocess.PIPE, text=True)
    try:
        port = int(server.stdout.readline().strip())
        subprocess.run(["node", os.path.join(ROOT, "tests", "viewer", "drive.mjs"), "--url", "http://127.0.0.1:%d/" % port,
                        "--plan", plan_path, "--out", out], check=True)
    finally:
        server.terminate()
        server.wait(timeout=10)
    with open(out) as f:
        r = json.load(f)
    if r["errors"]:
        sys.exit("viewer errors: %s" % r["errors"])
    print("renderer: %s (%s)" % (r["renderer"]["renderer"], r["renderer"]["version"]))
    print("bake: %s; canvas %dx%d; mean of %d frames, each waited for by a one-pixel readPixels" % (a.outputs, w, h, a.frames))
    print("%-14s %12s %18s %18s" % ("view", "frame (ms)", "fetches/px sky", "fetches/px ground"))
    for n, _ in VIEWS:
        fc = r["fetches"][n]
        print("%-14s %12.1f %18.1f %18.1f" % (n, r["frame_times"][n], fc["sky"], fc["ground"]))


if __name__ == "__main__":
    main()
