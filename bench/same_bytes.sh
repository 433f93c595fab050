#!/usr/bin/env bash
# The same bytes: runs the products of two builds' tools and compares them byte for byte (cmp),
# one line per product. Builds nothing: give it two bin dirs.
#
#   bench/same_bytes.sh --before build/ref/bin --after build/test/bin [--work DIR] [--keep]
#
# A full default bake is too slow for a quick check on a small machine, so this covers the
# products directly: `orders` sky renders (EXR) of a peer's atmosphere (bruneton2017, 10 nm grid)
# and of a Rayleigh-only copy of atmospheres/clear.yaml at low / medium / high quality (high on a
# 50 nm grid), twilight sun angles, a --spectral-stride 2 run, a `points` CSV and a `fog` render
# (view segments); the other methods' renders (the path tracer with a fixed seed and path count,
# single on the GT7 mapping, ms-approx, analytic); and two products of products: lut-pack's
# textures and report of the GT7 render, and fog-fit's products of a fog render (every file each
# writes is compared). About 2.5 min on the 2-core development machine.
#
# Provenance lists every file a tool read, with its hash, a repository file relative to the working
# directory and any other by its absolute path. So that two builds of different checkouts record
# the same paths, each side runs in its own checkout (the bin dir's CMake source directory), the
# atmospheres are copies under the work folder (outside both checkouts), and every product is
# written at one path ($WORK/run) and then moved to the side's folder. Exit status 1 if any
# product differs or fails.
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
WORK="$(mkdir -p "$WORK" && cd "$WORK" && pwd)"
mkdir -p "$WORK/before" "$WORK/after"

# The checkout a bin dir was built from (its CMakeCache's source directory; this one if none).
source_of() {
  local dir
  dir="$(sed -n 's/^CMAKE_HOME_DIRECTORY:INTERNAL=//p' "$1/../CMakeCache.txt" 2>/dev/null)"
  [ -n "$dir" ] && [ -d "$dir" ] && echo "$dir" || echo "$SRC"
}

# The atmospheres (with their data tables) and the Rayleigh-only clear atmosphere
# (tests/cli/test_sky_render.py, rayleigh_atmosphere) beside them.
cp -r "$SRC/atmospheres" "$WORK/atmospheres"
python3 - "$WORK/atmospheres/clear.yaml" "$WORK/atmospheres/rayleigh.yaml" <<'PY'
import sys
text = open(sys.argv[1]).read()
open(sys.argv[2], "w").write(text[:text.index("aerosols:")] + text[text.index("ground:"):])
PY
printf '# source: bench/same_bytes.sh test geometries\nsun_zenith_deg,view_zenith_deg,relative_azimuth_deg\n30,0,0\n30,60,180\n85,89,10\n94,80,0\n70,95,90\n' > "$WORK/geometry.csv"
RAY="$WORK/atmospheres/rayleigh.yaml" PEER="$WORK/atmospheres/peers/bruneton2017.yaml"

# name|tool|arguments: OUT is the output (a file; a folder of its own where the name has no
# extension, every file of which is compared), IN:<name> an earlier product of the same side.
PRODUCTS=(
  "bruneton_low.exr|sky-render|render $PEER --method orders --quality low --wavelengths 360:830:10 --size 16x8 --sun-zenith-deg 30,85,94 -o OUT"
  "rayleigh_medium.exr|sky-render|render $RAY --method orders --quality medium --wavelengths 400:800:20 --size 32x16 --sun-zenith-deg 30,70,90,94 -o OUT"
  "rayleigh_stride2.exr|sky-render|render $RAY --method orders --quality medium --spectral-stride 2 --wavelengths 400:800:20 --size 32x16 --sun-zenith-deg 30,90 -o OUT"
  "rayleigh_high.exr|sky-render|render $RAY --method orders --quality high --wavelengths 400:800:50 --size 16x8 --sun-zenith-deg 30,94 -o OUT"
  "rayleigh_points.csv|sky-render|points $RAY --method orders --quality medium --geometry $WORK/geometry.csv --wavelengths 400:800:20 --wavelengths-out 440,560,680 -o OUT"
  "rayleigh_fog.exr|sky-render|fog $RAY --quality low --wavelengths 400:700:50 --lut-size 4x8 --sun-zenith-deg 40,85,94 --elevations 5 --depths 8 --azimuths-deg 0,90,180 --attenuation-size 8x8 -o OUT"
  "rayleigh_path.exr|sky-render|render $RAY --method path --wavelengths 400:700:50 --size 8x4 --sun-zenith-deg 30,94 --min-paths 64 --max-paths 256 --seed 7 -o OUT"
  "rayleigh_single_gt7.exr|sky-render|render $RAY --method single --quality low --wavelengths 400:700:50 --mapping gt7 --size 4x8 --time-mapping gt7:3+2 -o OUT"
  "rayleigh_ms_approx.exr|sky-render|render $RAY --method ms-approx --quality low --wavelengths 400:700:50 --size 16x8 --sun-zenith-deg 30,94 -o OUT"
  "rayleigh_analytic.exr|sky-render|render $RAY --method analytic --quality low --wavelengths 400:700:50 --size 16x8 --sun-zenith-deg 30,94 -o OUT"
  "rayleigh_fog_gt7.exr|sky-render|fog $RAY --quality low --wavelengths 400:700:50 --lut-size 4x8 --time-mapping gt7:3+2 --sun-zenith-deg 40,85 --elevations 5 --depths 8 --azimuths-deg 0,90,180 --attenuation-size 8x8 -o OUT"
  "lut_pack|lut-pack|pack sky=IN:rayleigh_single_gt7.exr -o OUT/report.json"
  "fog_fit|fog-fit|fit IN:rayleigh_fog_gt7.exr -o OUT/fog_plain.json"
)

fail=0
for p in "${PRODUCTS[@]}"; do
  name="${p%%|*}" rest="${p#*|}"
  tool="${rest%%|*}" args="${rest#*|}"
  for side in before after; do
    bin="$BEFORE"; [ "$side" = after ] && bin="$AFTER"
    rm -rf "$WORK/run" && mkdir -p "$WORK/run"
    out="$WORK/run/$name"
    case "$name" in *.*) ;; *) mkdir -p "$out" ;; esac
    # Earlier products go back to $WORK/run, the path they were written at.
    a="$args"
    while [[ "$a" =~ IN:([^ ]+) ]]; do
      cp -r "$WORK/$side/${BASH_REMATCH[1]}" "$WORK/run/${BASH_REMATCH[1]}"
      a="${a//IN:${BASH_REMATCH[1]}/$WORK/run/${BASH_REMATCH[1]}}"
    done
    # shellcheck disable=SC2086
    if ! (cd "$(source_of "$bin")" && "$bin/$tool" --quiet ${a//OUT/$out}) > "$WORK/$side/$name.log" 2>&1; then
      echo "FAILED   $name ($side: $WORK/$side/$name.log)"; fail=1; continue 2
    fi
    rm -rf "$WORK/$side/$name" && mv "$out" "$WORK/$side/$name"
  done
  if [ -d "$WORK/after/$name" ]; then
    if diff -rq "$WORK/before/$name" "$WORK/after/$name" > /dev/null; then
      echo "same     $name ($(find "$WORK/after/$name" -type f | wc -l) files, $(du -sb "$WORK/after/$name" | cut -f1) bytes)"
    else
      echo "DIFFERS  $name ($(diff -rq "$WORK/before/$name" "$WORK/after/$name" | wc -l) files)"; fail=1
    fi
  elif cmp -s "$WORK/before/$name" "$WORK/after/$name"; then
    echo "same     $name ($(stat -c %s "$WORK/after/$name") bytes)"
  else
    echo "DIFFERS  $name"; fail=1
  fi
done
rm -rf "$WORK/run"
[ "$KEEP" = 1 ] || [ "$fail" = 1 ] || rm -rf "$WORK"
[ "$fail" = 1 ] && echo "outputs kept in $WORK"
exit $fail
