#!/usr/bin/env bash
# Speed against error, regenerated in one command (issue 9, docs/BENCH.md):
# installs what the build and the plot need (scripts/bootstrap.sh, gnuplot-nox
# among them), builds the crumple binary in Release, and runs `crumple bench`
# into docs/bench/: report.md, bench.csv, pareto.png (and table3.csv, the
# projection comparison of paper Table III).
#
#   scripts/bench.sh [crumple bench options...]     e.g. --quick, --runs 1
#
# Environment: BUILD_DIR (default $CRUMPLE_BUILD_DIR or build/), OUT (default
# docs/bench). About 30 minutes on one core with the defaults; one thread.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-${CRUMPLE_BUILD_DIR:-$root/build}}"
out="${OUT:-docs/bench}"  # relative to the source tree, as the report quotes it
bash "$root/scripts/bootstrap.sh"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j "$(nproc 2>/dev/null || echo 2)" --target crumple --target crumple-bench
cd "$root"
"$build/crumple" bench --out "$out" "$@"
