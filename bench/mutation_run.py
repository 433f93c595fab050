#!/usr/bin/env python3
"""Mutation run: every number of the shipped atmospheres and particle types replaced,
one at a time, by a huge, tiny, negative, zero, NaN or infinite value, and the tools' loading
paths run on each mutant with a timeout.

  bench/mutation_run.py [--bin-dir build/release/bin] [--jobs 2] [--timeout 120] [--limit N]
                        [--only atmospheres|particles]

Per atmosphere mutant: profile-import, then sky-render render with --method single, orders
(--quality low) and path (a few paths per texel), on 8x4 texels, one sun angle and the
400:700:50 nm grid (the RGB grid for the peers' RGB atmospheres; Mie tables of the shipped
particle types on that grid, built once). The atmospheres are those of atmospheres/,
atmospheres/peers/ and atmospheres/afgl1986/.
Per particle mutant: mie-tables build on the same grid.

Counted per command: crashes (killed by a signal), hangs (past --timeout), internal errors
(exit 3), rejections (exit 1 or 2; those without a `tool: file:line:` or `tool: --option`
message are listed), and exits 0, whose EXR outputs are checked for NaN or infinite values with
bench_exr_finite. Prints the counts and every failure; exit status 1 when any crash, hang,
exit 3 or non-finite output was seen. Uses python3's standard library only.
"""
import argparse
import concurrent.futures
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# The replacements: huge, tiny, negative, zero, NaN and infinite (YAML and plain spellings).
VALUES = ["1e300", "1e20", "1e9", "1e-9", "1e-300", "0", "-1", "-1e300", ".nan", "nan", ".inf", "-.inf"]
# A number in a YAML value position: not part of an identifier, a path or a quoted string.
NUMBER = re.compile(r"(?<![\w.\"'/-])-?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![\w.\"'/])")
GRID = ["--wavelength-min-nm", "400", "--wavelength-max-nm", "700", "--wavelength-step-nm", "50"]
LOCATED = re.compile(r"^[\w-]+: (\S+:\d+: |\S+: |--)", re.M)


def mutants(path):
    """(line number, column, original, replacement, text) for every number of a YAML file."""
    lines = open(path).read().split("\n")
    for i, line in enumerate(lines):
        code = line.split("#", 1)[0]
        if ":" not in code and not code.lstrip().startswith("-"):
            continue
        # Only the value part of "key: value" lines (and list items).
        start = code.index(":") + 1 if ":" in code else 0
        for m in NUMBER.finditer(code, start):
            for v in VALUES:
                new = lines[:]
                new[i] = line[:m.start()] + v + line[m.end():]
                yield i + 1, m.group(0), v, "\n".join(new)


def run(cmd, timeout, cwd):
    t0 = time.monotonic()
    try:
        p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=timeout)
        return p.returncode, p.stderr, time.monotonic() - t0
    except subprocess.TimeoutExpired as e:
        err = e.stderr.decode(errors="replace") if isinstance(e.stderr, bytes) else (e.stderr or "")
        return None, err, time.monotonic() - t0


class Tally:
    def __init__(self):
        self.counts = {}
        self.failures = []

    def add(self, tool, outcome, detail=None):
        key = (tool, outcome)
        self.counts[key] = self.counts.get(key, 0) + 1
        if detail:
            self.failures.append(detail)


def classify(tally, tool, rc, err, outputs, finite_bin, what):
    if rc is None:
        tally.add(tool, "hang", f"HANG {tool} {what}")
    elif rc < 0:
        tally.add(tool, "crash", f"CRASH (signal {-rc}) {tool} {what}: {err.strip()[-300:]}")
    elif rc == 3:
        tally.add(tool, "exit 3", f"EXIT 3 {tool} {what}: {err.strip()[-300:]}")
    elif rc in (1, 2):
        if LOCATED.search(err):
            tally.add(tool, f"exit {rc}")
        else:
            tally.add(tool, f"exit {rc} unlocated", f"UNLOCATED exit {rc} {tool} {what}: {err.strip()[-300:]}")
    elif rc == 0:
        p = subprocess.run([finite_bin] + outputs, capture_output=True, text=True)
        if p.returncode == 0:
            tally.add(tool, "exit 0 finite")
        else:
            tally.add(tool, "exit 0 NON-FINITE", f"NON-FINITE {tool} {what}: {p.stdout.strip()[-300:]}")
    else:
        tally.add(tool, f"exit {rc}", f"EXIT {rc} {tool} {what}: {err.strip()[-300:]}")
    return rc == 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin-dir", default=os.path.join(REPO, "build", "release", "bin"))
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--timeout", type=float, default=120.0,
                    help="seconds per command (water_cloud's Mie table takes ~10 s alone on the 2-core machine)")
    ap.add_argument("--limit", type=int, default=0, help="run every k-th mutant only, so that about N run")
    ap.add_argument("--only", choices=["atmospheres", "particles"], help="mutate only these files")
    ap.add_argument("--keep", action="store_true", help="keep the work folder")
    args = ap.parse_args()
    b = lambda t: os.path.join(os.path.abspath(args.bin_dir), t)
    for t in ("profile-import", "mie-tables", "sky-render", "bench_exr_finite"):
        if not os.path.exists(b(t)):
            sys.exit(f"mutation_run: {b(t)} not found (build it: ninja -C <build> {t})")
    work = tempfile.mkdtemp(prefix="skybake-mutation-")
    shutil.copytree(os.path.join(REPO, "atmospheres"), os.path.join(work, "atmospheres"))
    shutil.copytree(os.path.join(REPO, "particles"), os.path.join(work, "particles"))
    os.makedirs(os.path.join(work, "mie"))
    env_cwd = work
    t_start = time.monotonic()

    # Baseline Mie tables of the shipped particle types on the small grid.
    for f in sorted(os.listdir(os.path.join(work, "particles"))):
        if not f.endswith(".yaml"):
            continue
        rc, err, _ = run([b("mie-tables"), "build", f"particles/{f}", "-o", f"mie/{f[:-5]}.exr", "--quiet"] + GRID,
                         600, env_cwd)
        if rc != 0:
            sys.exit(f"mutation_run: the baseline Mie table of {f} failed: {err}")

    jobs = []
    atmosphere_folders = ["atmospheres", "atmospheres/peers", "atmospheres/afgl1986"]
    for sub in (atmosphere_folders if args.only == "atmospheres" else [args.only]) if args.only else \
            atmosphere_folders + ["particles"]:
        for f in sorted(os.listdir(os.path.join(work, sub))):
            if f.endswith(".yaml"):
                for line, old, new, text in mutants(os.path.join(work, sub, f)):
                    jobs.append((sub, f, line, old, new, text))
    total = len(jobs)
    if args.limit and args.limit < total:
        step = total / args.limit
        jobs = [jobs[int(i * step)] for i in range(args.limit)]
    print(f"mutation_run: {len(jobs)} mutants (of {total}: {len(VALUES)} values x every number of "
          f"atmospheres/*.yaml, atmospheres/{{peers,afgl1986}}/*.yaml and particles/*.yaml), timeout {args.timeout:g} s, {args.jobs} jobs", flush=True)

    tally = Tally()
    sky = [b("sky-render"), "render", None, "--mie-dir", "mie", "--wavelengths", "400:700:50", "--size", "8x4",
           "--sun-zenith-deg", "60", "--threads", "1", "--quiet"]

    def one(idx_job):
        idx, (sub, f, line, old, new, text) = idx_job
        stem = f[:-5]
        d = os.path.join(work, "out", str(idx))
        os.makedirs(d)
        mutant = f"{sub}/{stem}_mutant{idx}.yaml"
        with open(os.path.join(work, mutant), "w") as fh:
            fh.write(text)
        what = f"{sub}/{f}:{line} {old} -> {new}"
        results = []
        if sub == "particles":
            out = f"{d}/mie.exr"
            rc, err, _ = run([b("mie-tables"), "build", mutant, "-o", out, "--threads", "1", "--quiet"] + GRID,
                             args.timeout, env_cwd)
            results.append(("mie-tables", rc, err, [out]))
        else:
            out = f"{d}/profiles.exr"
            rc, err, _ = run([b("profile-import"), mutant, "-o", out, "--threads", "1", "--quiet"], args.timeout, env_cwd)
            results.append(("profile-import", rc, err, [out]))
            for method in (["single"], ["orders", "--quality", "low"],
                           ["path", "--target-error", "0.2", "--min-paths", "16", "--max-paths", "256"]):
                out = f"{d}/sky_{method[0]}.exr"
                cmd = sky[:]
                cmd[2] = mutant
                if "rgb_per_" in text:  # the peers' RGB atmospheres are rendered on the RGB grid
                    cmd[cmd.index("--wavelengths") + 1] = "rgb"
                rc, err, _ = run(cmd + ["-o", out, "--method"] + method, args.timeout, env_cwd)
                results.append((f"sky-render {method[0]}", rc, err, [out]))
        os.remove(os.path.join(work, mutant))
        return what, results

    done = 0
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as ex:
        for what, results in ex.map(one, enumerate(jobs)):
            for tool, rc, err, outputs in results:
                classify(tally, tool, rc, err, outputs, b("bench_exr_finite"), what)
            done += 1
            if done % 100 == 0:
                print(f"mutation_run: {done}/{len(jobs)} mutants, {time.monotonic() - t_start:.0f} s", flush=True)

    print(f"\nmutation_run: {len(jobs)} mutants in {time.monotonic() - t_start:.0f} s")
    tools = sorted({t for t, _ in tally.counts})
    outcomes = sorted({o for _, o in tally.counts})
    print(f"{'command':<22}" + "".join(f"{o:>20}" for o in outcomes))
    for t in tools:
        print(f"{t:<22}" + "".join(f"{tally.counts.get((t, o), 0):>20}" for o in outcomes))
    bad_kinds = ("crash", "hang", "exit 3", "exit 0 NON-FINITE")
    bad = sum(c for (t, o), c in tally.counts.items() if o in bad_kinds)
    print(f"\ncrashes {sum(c for (t, o), c in tally.counts.items() if o == 'crash')}, "
          f"hangs {sum(c for (t, o), c in tally.counts.items() if o == 'hang')}, "
          f"exit 3 {sum(c for (t, o), c in tally.counts.items() if o == 'exit 3')}, "
          f"exit 0 with non-finite outputs {sum(c for (t, o), c in tally.counts.items() if o == 'exit 0 NON-FINITE')}, "
          f"rejections without a location {sum(c for (t, o), c in tally.counts.items() if o.endswith('unlocated'))}")
    for f in tally.failures:
        print(f)
    if args.keep:
        print(f"mutation_run: work folder {work}")
    else:
        shutil.rmtree(work, ignore_errors=True)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
