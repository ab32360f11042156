#!/usr/bin/env bash
# The simulated mesh against the production look (docs/RENDERING.md
# "Refinement"): simulates the sample (once), renders the frames with the
# path tracer twice, left as simulated and sharp (--refine off --shutter 0),
# right as `render` draws them by default (refined, with the motion blur of
# the sample's [camera] shutter if it has one), and lays them out side by
# side (tests/golden/image_grid.cpp) into docs/images/refine-SAMPLE.png.
#
#   scripts/refine-contact-sheet.sh [SAMPLE] [FRAMES]   (default cylinder-fold "30 42 70 96")
#
# Environment: BUILD_DIR (default $CRUMPLE_BUILD_DIR or build/), OUT (default
# out/refine-contact-sheet), SPP (default 64), CELL (cell width, default 480).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-${CRUMPLE_BUILD_DIR:-$root/build}}"
out="${OUT:-$root/out/refine-contact-sheet}"
sample="${1:-cylinder-fold}"
frames="${2:-30 42 70 96}"
spp="${SPP:-64}"
cell="${CELL:-480}"

ninja -C "$build" crumple image_grid >/dev/null
mkdir -p "$out"
if [ ! -f "$out/$sample/cache.pcache" ]; then
  "$build/crumple" simulate "$root/samples/$sample" --out "$out/$sample" >"$out/$sample.log" 2>&1 ||
    { cat "$out/$sample.log" >&2; exit 1; }
fi
cells=()
for f in $frames; do
  printf -v name '%04d' "$f"
  "$build/crumple" render "$out/$sample/cache.pcache" --frames "$f-$f" --backend embree \
    --spp "$spp" --refine off --shutter 0 --out "$out/$sample/plain" >/dev/null
  "$build/crumple" render "$out/$sample/cache.pcache" --frames "$f-$f" --backend embree \
    --spp "$spp" --out "$out/$sample/look" >/dev/null
  cells+=("$f=$out/$sample/plain/$name.png" "$f=$out/$sample/look/$name.png")
done
"$build/tests/golden/image_grid" "$root/docs/images/refine-$sample.png" 2 "$cell" "${cells[@]}"
echo "docs/images/refine-$sample.png"
