#!/usr/bin/env bash
# The headless test of the Blender add-on (docs/BLENDER.md "Test"; not in
# ctest): packs the add-on (scripts/blender-addon-zip.sh), installs Debian's
# blender and python3-numpy when missing (scripts/bootstrap.sh), and runs
# tests/blender/test_addon.py in `blender -b`, which installs the zip into a
# temporary user folder, simulates a cylinder-fold shot through the add-on
# and checks what it imported against crumple's outputs and the error paths.
#   scripts/blender-addon-test.sh
# Exit 0 when every check passes, 1 when one fails, 2 on bad input.
# Environment: CRUMPLE_BIN (default: $CRUMPLE_BUILD_DIR/crumple, else
# build/crumple, else crumple on PATH), BLENDER (default: blender),
# KEEP=1 keeps the work folder.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if [[ "${1:-}" == "-h" || "${1:-}" == "--help" ]]; then
  awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "${BASH_SOURCE[0]}"
  exit 0
fi
source "$root/scripts/crumple-bin.sh"
blender="${BLENDER:-blender}"
if [[ -z "${BLENDER:-}" ]]; then bash "$root/scripts/bootstrap.sh" blender python3-numpy; fi
command -v "$blender" > /dev/null || { echo "blender-addon-test: $blender is not installed" >&2; exit 2; }

work="$(mktemp -d "${TMPDIR:-/tmp}/crumple-addon.XXXXXX")"
[[ -n "${KEEP:-}" ]] && echo "blender-addon-test: work folder $work" >&2 || trap 'rm -rf "$work"' EXIT
bash "$root/scripts/blender-addon-zip.sh" "$work/crumple_blender.zip" > /dev/null
# The add-on is installed into a user folder of the test's own.
export BLENDER_USER_SCRIPTS="$work/user/scripts" BLENDER_USER_CONFIG="$work/user/config"
set +e
"$blender" -b --factory-startup --python-exit-code 1 \
  --python "$root/tests/blender/test_addon.py" -- \
  --zip "$work/crumple_blender.zip" --crumple "$crumple" --work "$work" \
  > "$work/blender.log" 2>&1
status=$?
set -e
grep -E '^(blender |ok  |FAIL|addon test:)' "$work/blender.log" || true
if [[ $status -ne 0 ]] && ! grep -q '^addon test:' "$work/blender.log"; then
  echo "blender-addon-test: Blender failed (status $status):" >&2
  tail -30 "$work/blender.log" >&2
fi
exit $status
