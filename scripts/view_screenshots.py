#!/usr/bin/env python3
"""Renders the viewer's presets (viewer/presets.json: noon, sunset, twilight, overcast, fog, clouds)
of a bake in headless Chromium and writes them as OUTPUTS/viewer/<preset>.png.

    python3 scripts/view_screenshots.py [--outputs outputs] [--size 960x540]

scripts/view --screenshots is the front end. Needs scripts/setup's Chromium and puppeteer-core;
the page runs on Chromium's software WebGL2 here (minutes for the cloud preset at 960x540).
Exit 1 when the page reports an error.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--outputs", default=os.path.join(ROOT, "outputs"))
    ap.add_argument("--size", default="960x540")
    a = ap.parse_args()
    try:
        w, h = (int(v) for v in a.size.split("x"))
    except ValueError:
        sys.exit("view_screenshots: --size: expected WxH, got '%s'" % a.size)
    if not os.path.isfile(os.path.join(a.outputs, "luts", "report.json")):
        sys.exit("view_screenshots: %s has no luts/report.json (run scripts/bake first)" % a.outputs)
    with open(os.path.join(ROOT, "viewer", "presets.json")) as f:
        presets = json.load(f)["presets"]
    shots = os.path.join(a.outputs, "viewer")
    os.makedirs(shots, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="skybake_view_") as work:
        plan = os.path.join(work, "plan.json")
        with open(plan, "w") as f:
            json.dump({"width": w, "height": h, "screenshots": presets}, f)
        out = os.path.join(work, "result.json")
        server = subprocess.Popen([sys.executable, os.path.join(ROOT, "scripts", "view_server.py"), "--outputs", a.outputs,
                                   "--port", "0", "--print-port", "--quiet"], stdout=subprocess.PIPE, text=True)
        try:
            port = int(server.stdout.readline().strip())
            subprocess.run(["node", os.path.join(ROOT, "tests", "viewer", "drive.mjs"), "--url", "http://127.0.0.1:%d/" % port,
                            "--plan", plan, "--shots", shots, "--out", out], check=True)
        finally:
            server.terminate()
            server.wait(timeout=10)
        with open(out) as f:
            r = json.load(f)
    if r["errors"]:
        sys.exit("view_screenshots: the page reported: %s" % "; ".join(r["errors"]))
    for p in presets:
        st = r["hdr"][p["name"]]
        print("%s/%s.png  (max luminance %.4g cd/m^2, %d non-finite texels)" % (shots, p["name"], st["max_luminance"],
                                                                          st["non_finite"]))


if __name__ == "__main__":
    main()
