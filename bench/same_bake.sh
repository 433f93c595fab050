#!/usr/bin/env bash
# The same bytes for a whole bake: compares two outputs folders of `scripts/bake` file by file
# (cmp), so a change that must not alter any product (a refactor) can be shown to leave every LUT,
# fog table, sky render, preview, report and component byte-identical.
#
#   bench/same_bake.sh BEFORE_OUTPUTS AFTER_OUTPUTS [-v]
#
# To make the two folders, bake the same pipeline.yaml with both revisions, each in its own clone
# (a clone's outputs/ is its bake):
#   git clone REPO before && git -C before checkout OLD && (cd before && scripts/bake)
#   git clone REPO after && (cd after && scripts/bake)
#   bench/same_bake.sh before/outputs after/outputs
# Ninja's own state (.ninja_log, .ninja_deps) is not compared. Prints one line per file kind
# (extension) with the number of files the same, different and present on one side only, then
# every file that differs or is missing; -v also lists the identical ones. Exit status 1 if any
# file differs or is missing on one side, 2 on a usage error.
set -u
verbose=0
args=()
for a in "$@"; do
  case "$a" in
    -v) verbose=1 ;;
    -h|--help) sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) args+=("$a") ;;
  esac
done
if [ "${#args[@]}" -ne 2 ] || [ ! -d "${args[0]}" ] || [ ! -d "${args[1]}" ]; then
  echo "usage: $0 BEFORE_OUTPUTS AFTER_OUTPUTS [-v]  (two existing folders)" >&2
  exit 2
fi
before="${args[0]}" after="${args[1]}"
list() { (cd "$1" && find . -type f ! -name .ninja_log ! -name .ninja_deps | sed 's|^\./||' | LC_ALL=C sort); }
files="$(mktemp)"
trap 'rm -f "$files"' EXIT
LC_ALL=C sort -u <(list "$before") <(list "$after") > "$files"
python3 - "$before" "$after" "$verbose" "$files" <<'PY'
import filecmp, os, sys
from collections import defaultdict
before, after, verbose = sys.argv[1], sys.argv[2], sys.argv[3] == "1"
kinds = defaultdict(lambda: [0, 0, 0])
bad = []
for rel in (l.rstrip("\n") for l in open(sys.argv[4])):
    ext = os.path.splitext(rel)[1].lstrip(".") or os.path.basename(rel)
    a, b = os.path.join(before, rel), os.path.join(after, rel)
    if not (os.path.isfile(a) and os.path.isfile(b)):
        kinds[ext][2] += 1
        bad.append(f"only in {'before' if os.path.isfile(a) else 'after'}: {rel}")
    elif filecmp.cmp(a, b, shallow=False):
        kinds[ext][0] += 1
        if verbose:
            print(f"same: {rel}")
    else:
        kinds[ext][1] += 1
        bad.append(f"differs: {rel}")
print(f"{'kind':<10} {'same':>6} {'differ':>7} {'one side':>9}")
for ext in sorted(kinds):
    s, d, m = kinds[ext]
    print(f"{ext:<10} {s:>6} {d:>7} {m:>9}")
total = [sum(v[i] for v in kinds.values()) for i in range(3)]
print(f"{'all':<10} {total[0]:>6} {total[1]:>7} {total[2]:>9}")
for line in bad:
    print(line)
sys.exit(1 if bad else 0)
PY
