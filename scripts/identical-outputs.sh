#!/usr/bin/env bash
# Byte-identical outputs before and after a change that must not change
# behaviour (a restructuring). Every bundled scene (samples/*/scene.toml and
# samples/paper-types/*.toml) is run end to end with one crumple binary:
#   run        the cache, the preview frames (osmesa PNG) and sound.wav + its
#              spectrogram for a scene with [sound], --checkpoint-every 20
#   render     three frames with the path tracer (embree, 4 spp, PNG + EXR)
#              and one frame of the structure view (--debug-structure)
#   export     the middle frame as obj, ply, gltf and usda
#   inspect    --json of the cache
# and every file written is hashed (SHA-256) into a manifest; summary.json
# and checkpoint.bin (both hold wall-clock timings) and the lock file are
# left out (test_resume checks that a resumed run's cache is byte-identical).
#
# Usage:
#   scripts/identical-outputs.sh record BUILD_DIR|BINARY MANIFEST [SCENE_NAME...]
#       hash the outputs of BUILD_DIR/crumple (or of the crumple BINARY given)
#       into MANIFEST
#   scripts/identical-outputs.sh compare BASE_REV [SCENE_NAME...]
#       build BASE_REV (a git revision) in build-baseline/ (a worktree under
#       build-baseline/src, reused while the revision is the same), build the
#       working tree in build/, record both manifests and diff them; exit 0
#       when every output is byte-identical, 1 with the differing files listed
# SCENE_NAME is a sample folder's name (crumple, drape, ...) or
# paper-types/eps-0.5; default: all of them. A run that fails is a line
# "FAILED scene: its last message" in the manifest (and compared too). Takes
# about an hour for all scenes on 2 cores (per binary). The scenes are copied
# to $CRUMPLE_IDENTICAL_STAGE (default /tmp/crumple-identical-scenes).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

all_scenes() {
  for d in "$root"/samples/*/; do
    [ -f "$d/scene.toml" ] && basename "$d"
  done
  for f in "$root"/samples/paper-types/*.toml; do
    echo "paper-types/$(basename "$f" .toml)"
  done
}

# A copy of each scene at a fixed path (its path is in the cache's header,
# so both binaries must read it from the same place) with the cost guard off
# ([scene] frame_budget_s = 0): the guard stops a run by its CPU time, which
# differs between machines and builds; it never changes what a finished run
# writes.
# Every sample folder is staged, whichever scenes run: a scene may read
# another's files (backlit-cutout animates drape's glTF).
stage_scenes() {
  local stage="$1"
  rm -rf "$stage"
  mkdir -p "$stage"
  cp -r "$root/samples/." "$stage/"
  find "$stage" -name '*.toml' -print0 | while IFS= read -r -d '' f; do
    grep -q 'frame_budget_s' "$f" || sed -i '/^\[scene\]/a frame_budget_s = 0' "$f"
  done
}

# record BUILD_DIR|BINARY MANIFEST [SCENE...]
record() {
  local build="$1" manifest="$2"
  shift 2
  local bin="$build"
  [ -d "$build" ] && bin="$build/crumple"
  [ -x "$bin" ] || { echo "no crumple binary at $build" >&2; exit 2; }
  local scenes=("$@")
  [ ${#scenes[@]} -gt 0 ] || mapfile -t scenes < <(all_scenes)
  local stage="${CRUMPLE_IDENTICAL_STAGE:-/tmp/crumple-identical-scenes}"
  stage_scenes "$stage"
  local work
  work="$(mktemp -d)"
  : >"$manifest"
  for s in "${scenes[@]}"; do
    local name="${s//\//_}"
    local out="$work/$name"
    local scene="$stage/$s"
    [ -d "$scene" ] || scene="$scene.toml"
    echo "== $s" >&2
    if ! "$bin" run "$scene" --out "$out" --threads 2 --checkpoint-every 20 >"$out.log" 2>&1; then
      echo "FAILED $name: $(tail -1 "$out.log")" >>"$manifest"
      echo "run failed for $s: $(tail -1 "$out.log")" >&2
    else
      local frames first last mid
      frames="$("$bin" inspect --json "$out/cache.pcache" | python3 -c \
        'import json,sys; f=json.load(sys.stdin)["frames"]; print(f[0]["frame"], f[-1]["frame"])')"
      first="${frames% *}"
      last="${frames#* }"
      mid=$(((first + last) / 2))
      for f in "$first" "$mid" "$last"; do
        "$bin" render "$out/cache.pcache" --backend embree --spp 4 --threads 2 \
          --frames "$f-$f" --exr --out "$out/embree" >>"$out.log" 2>&1
      done
      "$bin" render "$out/cache.pcache" --debug-structure --frames "$mid-$mid" \
        --out "$out/structure" >>"$out.log" 2>&1
      for fmt in obj ply gltf usda; do
        "$bin" export "$out/cache.pcache" --format "$fmt" --frames "$mid-$mid" \
          --out "$out/export-$fmt" >>"$out.log" 2>&1
      done
      "$bin" inspect --json "$out/cache.pcache" >"$out/inspect.json"
    fi
    (cd "$work" && find "./$name" -type f ! -name summary.json ! -name checkpoint.bin \
      ! -name .crumple.lock -print0 | sort -z | xargs -0 -r sha256sum) >>"$manifest"
    rm -rf "$out" "$out.log"
  done
  rm -rf "$work"
  echo "$(grep -vc '^FAILED' "$manifest") files hashed into $manifest" >&2
}

compare() {
  local rev="$1"
  shift
  local base="$root/build-baseline"
  local sha
  sha="$(git -C "$root" rev-parse "$rev^{commit}")"
  if [ ! -d "$base/src" ] || [ "$(git -C "$base/src" rev-parse HEAD)" != "$sha" ]; then
    git -C "$root" worktree remove --force "$base/src" 2>/dev/null || rm -rf "$base/src"
    git -C "$root" worktree prune
    mkdir -p "$base"
    git -C "$root" worktree add --detach "$base/src" "$sha" >/dev/null
  fi
  cmake -S "$base/src" -B "$base/build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$base/build" --target crumple >/dev/null
  cmake -S "$root" -B "$root/build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$root/build" --target crumple >/dev/null
  # The baseline's manifest of every scene is kept per revision.
  if [ $# -eq 0 ] && [ -f "$base/manifest-$sha.txt" ]; then
    cp "$base/manifest-$sha.txt" "$base/manifest-before.txt"
  else
    record "$base/build" "$base/manifest-before.txt" "$@"
    [ $# -gt 0 ] || cp "$base/manifest-before.txt" "$base/manifest-$sha.txt"
  fi
  record "$root/build" "$base/manifest-after.txt" "$@"
  if diff "$base/manifest-before.txt" "$base/manifest-after.txt" >"$base/manifest.diff"; then
    echo "identical: $(wc -l <"$base/manifest-after.txt") files, $rev against the working tree"
  else
    echo "DIFFERENT ($rev against the working tree):"
    cat "$base/manifest.diff"
    exit 1
  fi
}

case "${1:-}" in
record)
  [ $# -ge 3 ] || { sed -n '15,28p' "$0" >&2; exit 2; }
  shift
  record "$@"
  ;;
compare)
  [ $# -ge 2 ] || { sed -n '15,28p' "$0" >&2; exit 2; }
  shift
  compare "$@"
  ;;
*)
  sed -n '2,28p' "$0" >&2
  exit 2
  ;;
esac
