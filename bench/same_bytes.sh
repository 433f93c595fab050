#!/usr/bin/env bash
# The same bytes: runs the `orders` products with two builds' tools and compares them byte for
# byte (cmp), one line per product. Builds nothing: give it two bin dirs.
#
#   bench/same_bytes.sh --before build/ref/bin --after build/test/bin [--work DIR] [--keep]
#
# A full default bake is too slow for a quick check on a small machine, so this covers the orders
# method's products directly: sky renders (EXR) of a peer's atmosphere (bruneton2017, 10 nm grid)
# and of a Rayleigh-only copy of atmospheres/clear.yaml at low / medium / high quality (high on a
# 50 nm grid), twilight
# sun angles, a --spectral-stride 2 run, a `points` CSV and a `fog` render (view segments). The
# EXR provenance holds no timestamp or build path (checked by cmp of two runs), so cmp compares
# the whole files. Exit status 1 if any product differs or fails.
set -u
SRC="$(cd "$(dirname "$0")/.." && pwd)"
BEFORE="" AFTER="" WORK="" KEEP=0
while [ $# -gt 0 ]; do
  case "$1" in
    --before) BEFORE="$(cd "$2" && pwd)"; shift 2 ;;
    --after) AFTER="$(cd "$2" && pwd)"; shift 2 ;;
    --work) WORK="$2"; shift 2 ;;
    --keep) KEEP=1; shift ;;
    *) echo "usage: $0 --before BIN_DIR --after BIN_DIR [--work DIR] [--keep]" >&2; exit 2 ;;
  esac
done
[ -n "$BEFORE" ] && [ -n "$AFTER" ] || { echo "usage: $0 --before BIN_DIR --after BIN_DIR [--work DIR] [--keep]" >&2; exit 2; }
[ -n "$WORK" ] || WORK="$(mktemp -d)"
mkdir -p "$WORK/before" "$WORK/after"

# The Rayleigh-only clear atmosphere (tests/cli/test_sky_render.py, rayleigh_atmosphere).
python3 - "$SRC" "$WORK/rayleigh.yaml" <<'PY'
import sys
src, out = sys.argv[1], sys.argv[2]
text = open(src + "/atmospheres/clear.yaml").read()
text = text[:text.index("aerosols:")] + text[text.index("ground:"):]
text = text.replace("file: data/", "file: %s/atmospheres/data/" % src)
open(out, "w").write(text)
PY
printf '# source: bench/same_bytes.sh test geometries\nsun_zenith_deg,view_zenith_deg,relative_azimuth_deg\n30,0,0\n30,60,180\n85,89,10\n94,80,0\n70,95,90\n' > "$WORK/geometry.csv"
RAY="$WORK/rayleigh.yaml" PEER="$SRC/atmospheres/peers/bruneton2017.yaml"

# name|tool arguments (OUT is replaced by the output path)
PRODUCTS=(
  "bruneton_low.exr|render $PEER --method orders --quality low --wavelengths 360:830:10 --size 16x8 --sun-zenith-deg 30,85,94 -o OUT"
  "rayleigh_medium.exr|render $RAY --method orders --quality medium --wavelengths 400:800:20 --size 32x16 --sun-zenith-deg 30,70,90,94 -o OUT"
  "rayleigh_stride2.exr|render $RAY --method orders --quality medium --spectral-stride 2 --wavelengths 400:800:20 --size 32x16 --sun-zenith-deg 30,90 -o OUT"
  "rayleigh_high.exr|render $RAY --method orders --quality high --wavelengths 400:800:50 --size 16x8 --sun-zenith-deg 30,94 -o OUT"
  "rayleigh_points.csv|points $RAY --method orders --quality medium --geometry $WORK/geometry.csv --wavelengths 400:800:20 --wavelengths-out 440,560,680 -o OUT"
  "rayleigh_fog.exr|fog $RAY --quality low --wavelengths 400:700:50 --lut-size 4x8 --sun-zenith-deg 40,85,94 --elevations 5 --depths 8 --azimuths-deg 0,90,180 --attenuation-size 8x8 -o OUT"
)

fail=0
for p in "${PRODUCTS[@]}"; do
  name="${p%%|*}" args="${p#*|}"
  for side in before after; do
    bin="$BEFORE"; [ "$side" = after ] && bin="$AFTER"
    out="$WORK/$side/$name"
    # shellcheck disable=SC2086
    if ! "$bin/sky-render" ${args//OUT/$out} --quiet > "$WORK/$side/$name.log" 2>&1; then
      echo "FAILED   $name ($side: $WORK/$side/$name.log)"; fail=1; continue 2
    fi
  done
  if cmp -s "$WORK/before/$name" "$WORK/after/$name"; then
    echo "same     $name ($(stat -c %s "$WORK/after/$name") bytes)"
  else
    echo "DIFFERS  $name"; fail=1
  fi
done
[ "$KEEP" = 1 ] || [ "$fail" = 1 ] || rm -rf "$WORK"
[ "$fail" = 1 ] && echo "outputs kept in $WORK"
exit $fail
