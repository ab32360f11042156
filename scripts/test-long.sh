#!/usr/bin/env bash
# The long scene-level tests the default suite skips (each several minutes:
# the tear-sound comparison of tear-slow and tear-fast, crumple-ball under
# the strain bound). Installs what is missing and builds like scripts/test.sh.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$root/scripts/build.sh"
build="${CRUMPLE_BUILD_DIR:-$root/build}"
cd "$build"
CRUMPLE_LONG_TESTS=1 ctest --output-on-failure -j "$(nproc 2>/dev/null || echo 2)" \
  -R 'AFasterTearIsLouderAndCracklesMore|CrumpleBallKeepsTheBound' "$@"
