#!/usr/bin/env bash
# Regenerates the shipped default sound database, assets/sound/default, with
# make_sound_db (docs/SOUND.md "The default database"), after an intended
# change of its model (src/sound/src/database_generator.cpp). The output is
# byte-identical on every run; test_sound_db_generator checks that the
# shipped files are the tool's.
# Usage: scripts/make-sound-db.sh        (BUILD_DIR, default build)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build}
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$BUILD_DIR" --target make_sound_db
mkdir -p assets/sound/default
"$BUILD_DIR/make_sound_db" --force assets/sound/default
du -sh assets/sound/default >&2
git status --short assets/sound/default | head -5
