#!/usr/bin/env bash
# The Blender round trip of `crumple export` (issue 8, docs/EXPORT.md):
#   scripts/blender-roundtrip.sh CACHE [FRAME ...]
# exports CACHE as OBJ, PLY and glTF into a temporary folder, then has
# Blender (headless, `blender -b`) import each chosen frame's files and
# compare their vertex and face counts and bounds with the cache and with
# `crumple inspect --json` (scripts/blender_roundtrip.py says what is
# comparable for each importer), and the shot's .glb (only the frame's node
# shown at each frame). Default frames: the first, middle and last cached
# ones. Exit 0 when everything matches, 1 when not, 2 on bad input.
# Needs: blender (Debian 12: 3.4) and python3-numpy (Blender's glTF importer).
# Environment: CRUMPLE_BIN (default: $CRUMPLE_BUILD_DIR/crumple, else
# build/crumple, else crumple on PATH), BLENDER (default: blender).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if [[ $# -lt 1 || "$1" == "-h" || "$1" == "--help" ]]; then
  awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "${BASH_SOURCE[0]}"
  [[ $# -ge 1 ]] && exit 0 || exit 2
fi
cache="$1"
shift
[[ -f "$cache" ]] || { echo "blender-roundtrip: $cache: no such cache" >&2; exit 2; }

source "$root/scripts/crumple-bin.sh"
blender="${BLENDER:-blender}"
# Blender and the numpy its glTF importer needs (Debian's blender does not pull it in).
if [[ -z "${BLENDER:-}" ]]; then bash "$root/scripts/bootstrap.sh" blender python3-numpy; fi
command -v "$blender" > /dev/null || { echo "blender-roundtrip: $blender is not installed" >&2; exit 2; }

work="$(mktemp -d "${TMPDIR:-/tmp}/crumple-blender.XXXXXX")"
trap 'rm -rf "$work"' EXIT
"$crumple" inspect --json "$cache" > "$work/inspect.json"

frames=("$@")
if [[ ${#frames[@]} -eq 0 ]]; then
  read -r -a frames < <(python3 -c '
import json, sys
f = [x["frame"] for x in json.load(open(sys.argv[1]))["frames"]]
print(*sorted({f[0], f[len(f) // 2], f[-1]}))' "$work/inspect.json")
fi
lo="$(printf '%s\n' "${frames[@]}" | sort -n | head -1)"
hi="$(printf '%s\n' "${frames[@]}" | sort -n | tail -1)"
for format in obj ply gltf; do
  if ! "$crumple" export "$cache" --format "$format" --frames "$lo-$hi" --out "$work/$format" \
    > "$work/export-$format.log" 2>&1; then
    echo "blender-roundtrip: $crumple export --format $format failed:" >&2
    grep -v '^PROGRESS' "$work/export-$format.log" >&2
    exit 2
  fi
done

# Blender prints its own chatter; the comparison's lines are ours.
set +e
"$blender" -b --factory-startup --python-exit-code 1 \
  --python "$root/scripts/blender_roundtrip.py" -- \
  --cache "$cache" --inspect "$work/inspect.json" --export "$work" --frames "${frames[@]}" \
  > "$work/blender.log" 2>&1
status=$?
set -e
grep -E '^(blender |frame |  (obj|ply|gltf) |shot.*glb: |  at frame |round trip:)' "$work/blender.log" || true
if [[ $status -ne 0 ]] && ! grep -q '^round trip:' "$work/blender.log"; then
  echo "blender-roundtrip: Blender failed (status $status):" >&2
  tail -20 "$work/blender.log" >&2
fi
exit $status
