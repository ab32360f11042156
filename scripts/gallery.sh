#!/usr/bin/env bash
# docs/GALLERY.md: every bundled sample at a glance. Simulates each sample
# (samples/*/scene.toml, once: a cache newer than its scene is reused),
# renders six frames evenly spread over its shot with the preview, shaded
# (top row) and as the crumpling model's structure (bottom row: flat regions
# green, curved magenta with their rulings, singular vertices red; the
# elastic model's samples have no structure and show the shaded row only),
# lays them out with tests/golden/image_grid, writes each as
# docs/images/gallery/SAMPLE.jpg (ffmpeg, quality 4) and the page with the
# sample's own description (the first paragraph of its scene's comments).
#
#   bash scripts/gallery.sh [SAMPLE ...]     (default: every sample)
#
# Environment: BUILD_DIR (default $CRUMPLE_BUILD_DIR or build/), OUT (default
# out/gallery), CELL (cell width, default 200). Takes about 10 minutes on 2
# cores for every sample (the tearing ones take longest).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-${CRUMPLE_BUILD_DIR:-$root/build}}"
out="${OUT:-$root/out/gallery}"
cell="${CELL:-200}"
images="$root/docs/images/gallery"
command -v ffmpeg >/dev/null || bash "$root/scripts/bootstrap.sh" ffmpeg
ninja -C "$build" crumple image_grid >/dev/null
mkdir -p "$out" "$images"
if [ $# -gt 0 ]; then samples=("$@"); else
  samples=()
  for s in "$root"/samples/*/scene.toml; do samples+=("$(basename "$(dirname "$s")")"); done
fi

page="$root/docs/GALLERY.md"
{
  echo "# Gallery"
  echo
  echo "Every bundled sample at a glance: six frames spread over the shot, drawn"
  echo "by the preview (top row) and as the crumpling model's structure (bottom"
  echo "row: flat regions green, curved regions magenta with their rulings,"
  echo "singular vertices red; samples of the elastic model show the top row"
  echo "only). Written by \`bash scripts/gallery.sh\`; \`docs/SCENE.md\` \"Samples\""
  echo "says what each reproduces, and each scene's comments say how."
} > "$page.tmp"

for s in "${samples[@]}"; do
  scene="$root/samples/$s/scene.toml"
  [ -f "$scene" ] || { echo "gallery: no sample '$s'" >&2; exit 2; }
  dir="$out/$s"
  if [ ! -f "$dir/cache.pcache" ] || [ "$scene" -nt "$dir/cache.pcache" ]; then
    echo "gallery: simulating $s" >&2
    "$build/crumple" simulate "$scene" --out "$dir" >"$dir.log" 2>&1 ||
      { cat "$dir.log" >&2; exit 1; }
  fi
  read -r first last < <(sed -n 's/^frames *= *\[ *\([0-9]*\) *, *\([0-9]*\) *\].*/\1 \2/p' "$scene" | head -1)
  cells=() structure=()
  for k in 0 1 2 3 4 5; do
    f=$(( first + (last - first) * k / 5 ))
    printf -v name '%04d' "$f"
    "$build/crumple" render "$dir/cache.pcache" --frames "$f-$f" --out "$dir/shaded" >/dev/null
    cells+=("$f=$dir/shaded/$name.png")
    if "$build/crumple" render "$dir/cache.pcache" --frames "$f-$f" --debug-structure \
      --out "$dir/structure" >/dev/null 2>&1; then
      structure+=("$f=$dir/structure/$name.png")
    fi
  done
  [ ${#structure[@]} -eq 6 ] || structure=()
  "$build/tests/golden/image_grid" "$dir/grid.png" 6 "$cell" "${cells[@]}" "${structure[@]}"
  ffmpeg -loglevel error -y -i "$dir/grid.png" -q:v 4 "$images/$s.jpg"
  about=$(awk '/^#/ && !/^# *$/ { sub(/^# */, ""); printf "%s%s", (n++ ? " " : ""), $0; next } { exit }' "$scene")
  {
    echo
    echo "## $s"
    echo
    echo "$about"
    echo
    echo "![$s: frames $first-$last, shaded${structure:+ and structure}](images/gallery/$s.jpg)"
  } >> "$page.tmp"
  echo "gallery: $s done" >&2
done
mv "$page.tmp" "$page"
echo "$page"
