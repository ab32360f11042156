#!/usr/bin/env bash
# The README's first command: install what is missing (Debian packages,
# ffmpeg among them), build in Release, and run the headline sample end to
# end: samples/slide-on-table, a sheet of office paper on a table slid into
# an arch whose back edge then stands up into a folded wall (the crumpling
# model with contacts and friction), with its soundtrack. Writes into OUT
# (default out/slide-on-table): the cache, the preview frames, a contact
# sheet, sound.wav and preview.mp4 (the frames with the sound), then says
# where to look.
#   bash scripts/run-sample.sh [OUT]
# Environment: CRUMPLE_BUILD_DIR (default build/), CRUMPLE_SAMPLE (another
# folder of samples/ to run the same way).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if [[ "${1:-}" == "-h" || "${1:-}" == "--help" ]]; then
  awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "${BASH_SOURCE[0]}"
  exit 0
fi
bash "$root/scripts/build.sh"
build="${CRUMPLE_BUILD_DIR:-$root/build}"
sample="${CRUMPLE_SAMPLE:-slide-on-table}"
[[ -f "$root/samples/$sample/scene.toml" ]] || { echo "run-sample: no sample '$sample' in samples/" >&2; exit 2; }
out="${1:-$root/out/$sample}"
started=$SECONDS
"$build/crumple" run "$root/samples/$sample" --out "$out" --contact-sheet --movie
cat <<DONE

run-sample: $sample in $((SECONDS - started)) s (after the build). Look at:
  $out/contact_sheet.png   the shot at a glance
  $out/preview.mp4         the preview frames with the soundtrack
  $out/sound.wav           the soundtrack alone
  $out/frames/             every frame (PNG)
Next: docs/SCENE.md to write a scene, \`crumple init DIR\` for a starter one,
docs/RENDERING.md for the path tracer (crumple render CACHE --backend embree).
DONE
