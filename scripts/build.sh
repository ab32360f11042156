#!/usr/bin/env bash
# Configures and builds crumple in Release into build/ (or $CRUMPLE_BUILD_DIR).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${CRUMPLE_BUILD_DIR:-$root/build}"
bash "$root/scripts/bootstrap.sh"
jobs="$(nproc 2>/dev/null || echo 2)"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
cmake --build "$build" -j "$jobs"
