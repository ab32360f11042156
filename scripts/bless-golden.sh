#!/usr/bin/env bash
# Re-blesses the golden images (tests/golden/) after an intended change of the
# renderers or of the samples:
#   1. simulates each sample up to its golden frame and keeps that one frame as
#      tests/golden/inputs/<sample>.pcache (only with --inputs: the inputs pin
#      the renderers' input, so a simulator change does not move the images);
#   2. rewrites tests/golden/osmesa/*.png and tests/golden/embree/*.png, and
#      the render unit tests' golden images (tests/render/golden/*.png).
# Usage: scripts/bless-golden.sh [--inputs]     (BUILD_DIR, default build)
# Then look at the images (git diff shows which changed) and commit them.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build}
bash scripts/bootstrap.sh
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$BUILD_DIR" --target crumple golden_tool test_golden test_render

# sample:frame (the frame shown in the golden image)
FRAMES="backlit-cutout:40 crumple:108 cylinder-fold:70 drape:48 first-singularity:96 moebius:80 unload:102"
if [ "${1:-}" = "--inputs" ]; then
  tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' EXIT
  for entry in $FRAMES; do
    sample=${entry%%:*}
    frame=${entry##*:}
    echo "bless-golden: simulating $sample to frame $frame" >&2
    if ! "$BUILD_DIR/crumple" simulate "samples/$sample" --frames "$frame-$frame" \
      --out "$tmp/$sample" >"$tmp/$sample.log" 2>&1; then
      cat "$tmp/$sample.log" >&2
      exit 1
    fi
    "$BUILD_DIR/tests/golden/golden_tool" extract "$tmp/$sample/cache.pcache" "$frame" "tests/golden/inputs/$sample.pcache"
  done
fi
CRUMPLE_BLESS=1 "$BUILD_DIR/tests/golden/test_golden" --gtest_filter='*Osmesa*:*Embree*' >/dev/null
CRUMPLE_BLESS=1 "$BUILD_DIR/tests/render/test_render" --gtest_filter='*Golden*' >/dev/null
echo "bless-golden: rewrote tests/golden/{osmesa,embree}/*.png and tests/render/golden/*.png" >&2
git status --short tests/golden tests/render/golden
