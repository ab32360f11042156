#!/usr/bin/env bash
# Contact sheets of the crumpling model for docs/CRUMPLING.md ("Contact
# sheets"): each sample named (default: crumple cylinder-fold) is simulated
# at its own settings (seed 1), the way `crumple run` would, and its frames
# are rendered twice with the preview renderer at 240 x 180: shaded, and
# with the model's structure drawn (--debug-structure: flat regions green,
# curved regions purple with their rulings, singular vertices red, handles
# black). Writes docs/images/crumpling-<sample>-shaded.png and
# docs/images/crumpling-<sample>-structure.png (up to 36 frames each,
# evenly spaced, labelled with their numbers). Extra scene lines for [model]
# come from CRUMPLE_MODEL_LINES (e.g. "max_edge_strain = 0"); the images are
# then named crumpling-<sample>-$CRUMPLE_VARIANT-<view>.png (default
# variant name: custom). CRUMPLE_ELASTIC_EDGE=E (cm) runs the same motion on
# the elastic model instead, on a fixed mesh of edge E, shaded only:
# crumpling-<sample>-elastic-<E>cm-shaded.png (a reference to compare by eye).
# Usage: scripts/crumpling-contact-sheets.sh [SAMPLE...]   (BUILD_DIR, default build)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-$root/build}"
bash "$root/scripts/bootstrap.sh"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" --target crumple
samples=("$@")
[ ${#samples[@]} -gt 0 ] || samples=(crumple cylinder-fold)
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$root/docs/images"
suffix=""
[ -n "${CRUMPLE_MODEL_LINES:-}" ] && suffix="-${CRUMPLE_VARIANT:-custom}"
elastic="${CRUMPLE_ELASTIC_EDGE:-}"
views=(shaded structure)
if [ -n "$elastic" ]; then
  suffix="-elastic-${elastic}cm"
  views=(shaded)
fi
for sample in "${samples[@]}"; do
  src="$root/samples/$sample"
  [ -f "$src/scene.toml" ] || { echo "no sample $sample" >&2; exit 2; }
  work="$tmp/$sample"
  cp -r "$src" "$work"
  sed -i 's/^resolution = .*/resolution = [240, 180]/' "$work/scene.toml"
  if [ -n "${CRUMPLE_MODEL_LINES:-}" ]; then
    sed -i "s/^type = \"hybrid\".*/&\n${CRUMPLE_MODEL_LINES}/" "$work/scene.toml"
  fi
  if [ -n "$elastic" ]; then
    sed -i -e 's/^type = "hybrid".*/type = "elastic"/' \
      -e "s/^\[sheet\]\$/[sheet]\nmax_edge = ${elastic}/" "$work/scene.toml"
  fi
  echo "contact sheets: simulating $sample" >&2
  "$build/crumple" simulate "$work/scene.toml" --out "$work/out" >"$work/simulate.log" 2>&1 ||
    { cat "$work/simulate.log" >&2; exit 1; }
  for view in "${views[@]}"; do
    flags=(--contact-sheet --out "$work/frames-$view")
    [ "$view" = structure ] && flags+=(--debug-structure)
    "$build/crumple" render "$work/out/cache.pcache" "${flags[@]}" >"$work/render.log" 2>&1 ||
      { cat "$work/render.log" >&2; exit 1; }
    cp "$work/out/contact_sheet.png" "$root/docs/images/crumpling-$sample$suffix-$view.png"
    rm -f "$work/out/contact_sheet.png"
  done
done
ls -l "$root"/docs/images/crumpling-*.png
