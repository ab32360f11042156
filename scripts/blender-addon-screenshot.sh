#!/usr/bin/env bash
# Redraws docs/images/blender-panel.png, the add-on's panel in docs/BLENDER.md:
# Blender with a window under Xvfb (xvfb-run, Debian's xvfb) simulates the
# add-on test's shot and takes a screenshot of the Properties editor.
#   scripts/blender-addon-screenshot.sh [OUT.png]
# Environment: CRUMPLE_BIN (as scripts/blender-addon-test.sh), BLENDER.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="${1:-$root/docs/images/blender-panel.png}"
source "$root/scripts/crumple-bin.sh"
blender="${BLENDER:-blender}"
if [[ -z "${BLENDER:-}" ]]; then bash "$root/scripts/bootstrap.sh" blender python3-numpy xvfb; fi
work="$(mktemp -d "${TMPDIR:-/tmp}/crumple-shot.XXXXXX")"
trap 'rm -rf "$work"' EXIT
bash "$root/scripts/blender-addon-zip.sh" "$work/crumple_blender.zip" > /dev/null
export BLENDER_USER_SCRIPTS="$work/user/scripts" BLENDER_USER_CONFIG="$work/user/config"
timeout 300 xvfb-run -a -s "-screen 0 1500x1350x24" "$blender" --factory-startup \
  --python-exit-code 1 --python "$root/tests/blender/panel_screenshot.py" -- \
  --zip "$work/crumple_blender.zip" --crumple "$crumple" --work "$work" --out "$out" \
  > "$work/blender.log" 2>&1 || { tail -30 "$work/blender.log" >&2; exit 1; }
grep '^panel screenshot:' "$work/blender.log"
