#!/usr/bin/env bash
# The full stability suite (issue 9; docs/STABILITY.md): builds `crumple` and
# the suite in Release (into build/ or $CRUMPLE_BUILD_DIR), runs every case
# on its authored frames under both models (every substep count 1-64), each
# under its own time limit, and prints the table case x model: frames, end
# state, worst c_mean, max edge strain, handle error (m), smallest triangle
# area in space over its pattern area, wall time (s).
# Extra arguments go to the test binary (e.g. --gtest_filter='*Twist*').
# Exit status: the suite's (0 when every case passes).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${CRUMPLE_BUILD_DIR:-$root/build}"
bash "$root/scripts/bootstrap.sh"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j "$(nproc 2>/dev/null || echo 2)" --target crumple test_stability
table="$(mktemp)"
log="$build/stability.log"
trap 'rm -f "$table"' EXIT
start=$(date +%s)
status=0
CRUMPLE_STABILITY_FULL=1 CRUMPLE_STABILITY_TABLE="$table" \
  "$build/tests/stability/test_stability" "$@" >"$log" 2>&1 || status=$?
{
  printf 'case\tmodel\tframes\tend\tworst_c_mean\tmax_strain\thandle_error_m\tmin_area\twall_s\n'
  cat "$table"
} | column -t -s $'\t'
grep -E '^\[  (PASSED|FAILED) ' "$log" || true
grep -E '^\[  FAILED  \] Cases' "$log" || true
echo "full suite: $(($(date +%s) - start)) s; log in $log"
exit "$status"
