#!/usr/bin/env bash
# Packs the Blender add-on (integrations/blender/crumple_blender, docs/BLENDER.md)
# into a zip that Blender installs (Edit > Preferences > Add-ons > Install):
#   scripts/blender-addon-zip.sh [OUT.zip]        default: build/crumple_blender.zip
# The same sources give the same zip, byte for byte (sorted, fixed dates).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if [[ "${1:-}" == "-h" || "${1:-}" == "--help" ]]; then
  awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "${BASH_SOURCE[0]}"
  exit 0
fi
out="${1:-$root/build/crumple_blender.zip}"
mkdir -p "$(dirname "$out")"
python3 - "$root/integrations/blender" "$out" <<'PY'
import os, sys, zipfile
src, out = sys.argv[1], sys.argv[2]
package = os.path.join(src, "crumple_blender")
tmp = out + ".%d.tmp" % os.getpid()
with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
    for name in sorted(os.listdir(package)):
        if name.endswith(".py"):
            info = zipfile.ZipInfo("crumple_blender/" + name, date_time=(1980, 1, 1, 0, 0, 0))
            info.external_attr = 0o644 << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            with open(os.path.join(package, name), "rb") as f:
                z.writestr(info, f.read())
os.replace(tmp, out)
print(out)
PY
