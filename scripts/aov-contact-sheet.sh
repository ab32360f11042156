#!/usr/bin/env bash
# The AOV layers of one frame of a crumpling sample as a contact sheet, for
# docs/RENDERING.md "AOVs": simulates the sample (once), renders the frame
# with the path tracer and every AOV, and lays the layers out
# (tests/golden/aov_sheet.cpp) into docs/images/aov-SAMPLE.png.
#
#   scripts/aov-contact-sheet.sh [SAMPLE] [FRAME]   (default cylinder-fold 70)
#
# Environment: BUILD_DIR (default $CRUMPLE_BUILD_DIR or build/), OUT (default
# out/aov-contact-sheet), SPP (default 64).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-${CRUMPLE_BUILD_DIR:-$root/build}}"
out="${OUT:-$root/out/aov-contact-sheet}"
sample="${1:-cylinder-fold}"
frame="${2:-70}"
spp="${SPP:-64}"

ninja -C "$build" crumple aov_sheet >/dev/null
mkdir -p "$out"
if [ ! -f "$out/$sample/cache.pcache" ]; then
  "$build/crumple" simulate "$root/samples/$sample" --out "$out/$sample" >"$out/$sample.log" 2>&1 ||
    { cat "$out/$sample.log" >&2; exit 1; }
fi
printf -v name '%04d' "$frame"
"$build/crumple" render "$out/$sample/cache.pcache" --frames "$frame-$frame" --backend embree \
  --spp "$spp" --no-png --aov depth,normal,albedo,position,region,handle-id,object-id \
  --out "$out/$sample/frames" >/dev/null
"$build/tests/golden/aov_sheet" "$out/$sample/frames/$name.exr" "$root/docs/images/aov-$sample.png" 320
echo "docs/images/aov-$sample.png"
