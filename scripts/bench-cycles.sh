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
# into $OUT/drape (once; reused when already there), or with SHUTTER set into
# $OUT/drape-shutter-$SHUTTER with `simulate --shutter $SHUTTER` (its
# velocities: both renderers blur the frame). Environment:
#   BUILD_DIR    build folder (default $CRUMPLE_BUILD_DIR or build/)
#   OUT          output folder (default out/bench-cycles, out/bench-cycles-shutter-S
#                with SHUTTER=S)
#   FRAME        frame to render (default 48)
#   SPP          samples per pixel, comma-separated (default 16,64)
#   REF_SPP      reference samples per pixel, each renderer (default 1024)
#   THREADS      render threads for both (default 2)
#   RUNS         timed runs per spp, the median is kept (default 3)
#   RESOLUTION   WxH (default 640x480)
#   SHUTTER      motion blur on both: OPEN,CLOSE in frames or S for -S/2,S/2
#                (default: none; e.g. SHUTTER=0.5, a centred 180-degree
#                shutter; with CACHE, passed to bench_render's --shutter)
#   BLENDER      the Blender binary (default blender)
# Installs Blender (the Debian package) when missing, builds the crumple and
# bench_render targets in Release, runs bench_render and prints its table;
# every number is also in $OUT/result.json, the images next to it.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-${CRUMPLE_BUILD_DIR:-$root/build}}"
shutter="${SHUTTER:-}"
out="${OUT:-$root/out/bench-cycles${shutter:+-shutter-$shutter}}"
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
motion=()
if [ -z "$cache" ]; then
  shot="drape"
  simulate=()
  if [ -n "$shutter" ]; then
    shot="drape-shutter-$shutter"
    simulate=(--shutter="$shutter")
  fi
  cache="$out/$shot/cache.pcache"
  if [ ! -f "$cache" ]; then
    echo "bench-cycles: simulating samples/drape into $out/$shot" >&2
    if ! "$build/crumple" simulate "$root/samples/drape" --out "$out/$shot" "${simulate[@]}" \
      >"$out/simulate.log" 2>&1; then
      cat "$out/simulate.log" >&2
      exit 1
    fi
  fi
elif [ -n "$shutter" ]; then
  case "$shutter" in
    *,*) motion=(--shutter "$shutter") ;;
    *) motion=(--shutter "$(python3 -c "import sys; s = float(sys.argv[1]); print(f'{-s / 2!r},{s / 2!r}')" "$shutter")") ;;
  esac
fi

"$build/bench/bench_render" "$cache" --frame "$frame" --spp "$spp" --ref-spp "$ref_spp" \
  --threads "$threads" --runs "$runs" --resolution "$resolution" --blender "$blender" \
  --out "$out" "${motion[@]}"
