#!/usr/bin/env bash
# The README's first command: install what is missing, build in Release, and
# run the bundled drape sample end to end (simulate, cache, render).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$root/scripts/build.sh"
build="${CRUMPLE_BUILD_DIR:-$root/build}"
out="${1:-$root/out/drape}"
"$build/crumple" run "$root/samples/drape" --out "$out"
