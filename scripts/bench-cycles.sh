#!/usr/bin/env bash
# Render benchmark: crumple's Embree path tracer against Blender's Cycles (CPU,
# headless) on one frame of a simulated shot, at equal samples per pixel and
# on the same thread count (bench/bench_render.cpp; the Blender side is
# bench/cycles/render_cycles.py, its light units measured by
# bench/cycles/calibrate.py).
#
#   scripts/bench-cycles.sh [CACHE]
#
# CACHE: a .pcache to render a frame of; default: samples/drape simulated
# into $OUT/drape (once; reused when already there). Environment:
#   BUILD_DIR    build folder (default $CRUMPLE_BUILD_DIR or build/)
#   OUT          output folder (default out/bench-cycles)
#   FRAME        frame to render (default 48)
#   SPP          samples per pixel, comma-separated (default 16,64)
#   REF_SPP      reference samples per pixel, each renderer (default 1024)
#   THREADS      render threads for both (default 2)
#   RUNS         timed runs per spp, the median is kept (default 3)
#   RESOLUTION   WxH (default 640x480)
#   BLENDER      the Blender binary (default blender)
# Installs Blender (the Debian package) when missing, builds the crumple and
# bench_render targets in Release, runs bench_render and prints its table;
# every number is also in $OUT/result.json, the images next to it.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-${CRUMPLE_BUILD_DIR:-$root/build}}"
out="${OUT:-$root/out/bench-cycles}"
frame="${FRAME:-48}"
spp="${SPP:-16,64}"
ref_spp="${REF_SPP:-1024}"
threads="${THREADS:-2}"
runs="${RUNS:-3}"
resolution="${RESOLUTION:-640x480}"
blender="${BLENDER:-blender}"

# Build dependencies, and Blender (the Debian package) when no binary is given
# or found.
if command -v "$blender" >/dev/null 2>&1; then
  bash "$root/scripts/bootstrap.sh"
else
  bash "$root/scripts/bootstrap.sh" blender
  blender=blender
fi
"$blender" --version 2>/dev/null | head -1 >&2

jobs="$(nproc 2>/dev/null || echo 2)"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" --target crumple bench_render -j "$jobs"

mkdir -p "$out"
cache="${1:-}"
if [ -z "$cache" ]; then
  cache="$out/drape/cache.pcache"
  if [ ! -f "$cache" ]; then
    echo "bench-cycles: simulating samples/drape into $out/drape" >&2
    if ! "$build/crumple" simulate "$root/samples/drape" --out "$out/drape" \
      >"$out/simulate.log" 2>&1; then
      cat "$out/simulate.log" >&2
      exit 1
    fi
  fi
fi

"$build/bench/bench_render" "$cache" --frame "$frame" --spp "$spp" --ref-spp "$ref_spp" \
  --threads "$threads" --runs "$runs" --resolution "$resolution" --blender "$blender" \
  --out "$out"
