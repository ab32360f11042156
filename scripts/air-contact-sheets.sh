#!/usr/bin/env bash
# Contact sheets and trajectories of the air samples for docs/AIR.md: each
# sample named (default: fall-flat fall-strip fall-flutter desk-draught) is
# simulated at its own settings, its frames rendered with the preview
# renderer at 240 x 180 into a contact sheet
# (docs/images/air-<sample>.png), and its flight drawn side on, the sheet's
# cross-section every few frames (docs/images/air-<sample>-path.png,
# scripts/air_trajectory.py).
# Usage: scripts/air-contact-sheets.sh [SAMPLE...]   (BUILD_DIR, default build)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-$root/build}"
bash "$root/scripts/bootstrap.sh"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" --target crumple
samples=("$@")
[ ${#samples[@]} -gt 0 ] || samples=(fall-flat fall-strip fall-flutter desk-draught)
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$root/docs/images"
for sample in "${samples[@]}"; do
  src="$root/samples/$sample"
  [ -f "$src/scene.toml" ] || { echo "no sample $sample" >&2; exit 2; }
  work="$tmp/$sample"
  cp -r "$src" "$work"
  sed -i 's/^resolution = .*/resolution = [240, 180]/' "$work/scene.toml"
  echo "air contact sheets: simulating $sample" >&2
  "$build/crumple" simulate "$work/scene.toml" --out "$work/out" >"$work/simulate.log" 2>&1 ||
    { cat "$work/simulate.log" >&2; exit 1; }
  "$build/crumple" render "$work/out/cache.pcache" --contact-sheet --out "$work/frames" \
    >"$work/render.log" 2>&1 || { cat "$work/render.log" >&2; exit 1; }
  cp "$work/out/contact_sheet.png" "$root/docs/images/air-$sample.png"
  "$build/crumple" inspect --json "$work/out/cache.pcache" >"$work/inspect.json"
  python3 "$root/scripts/air_trajectory.py" "$work/inspect.json" \
    "$root/docs/images/air-$sample-path.png"
done
ls -l "$root"/docs/images/air-*.png
