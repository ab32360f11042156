#!/usr/bin/env bash
# Opens a crumple AOV EXR in Blender's compositor, headless, and checks every
# pass and two pixels of each against what crumple wrote
# (tests/blender/aov_compositor.py; expectations from tests/blender/exr_probe).
#
#   scripts/blender-aov-check.sh
#
# Installs Blender (the Debian package) when missing, builds crumple and
# exr_probe in Release, simulates samples/cylinder-fold into
# $OUT/cylinder-fold, renders frame $FRAME with every AOV and runs Blender.
# Environment: BUILD_DIR (default $CRUMPLE_BUILD_DIR or build/), OUT (default
# out/blender-aov), FRAME (default 70), BLENDER (default blender).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-${CRUMPLE_BUILD_DIR:-$root/build}}"
out="${OUT:-$root/out/blender-aov}"
frame="${FRAME:-70}"
blender="${BLENDER:-blender}"

bash "$root/scripts/bootstrap.sh"
if ! command -v "$blender" >/dev/null 2>&1; then
  echo "Blender not found: installing the Debian package" >&2
  bash "$root/scripts/bootstrap.sh" blender
  blender=blender
fi
"$blender" --version 2>/dev/null | head -1 >&2
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
ninja -C "$build" crumple exr_probe >/dev/null

mkdir -p "$out"
if [ ! -f "$out/cylinder-fold/cache.pcache" ]; then
  "$build/crumple" simulate "$root/samples/cylinder-fold" --out "$out/cylinder-fold" \
    >"$out/simulate.log" 2>&1 || { cat "$out/simulate.log" >&2; exit 1; }
fi
printf -v name '%04d' "$frame"
"$build/crumple" render "$out/cylinder-fold/cache.pcache" --frames "$frame-$frame" \
  --backend embree --spp 16 --no-png \
  --aov depth,normal,albedo,position,region,handle-id,object-id --out "$out/frames" \
  >"$out/render.log" 2>&1 || { cat "$out/render.log" >&2; exit 1; }
"$build/tests/blender/exr_probe" "$out/frames/$name.exr" >"$out/expect.txt"
"$blender" -b --factory-startup -noaudio --python-exit-code 1 \
  --python "$root/tests/blender/aov_compositor.py" -- "$out/frames/$name.exr" "$out/expect.txt" "$out"
