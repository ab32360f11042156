#!/usr/bin/env bash
# Installs the Debian 12 packages crumple builds with (idempotent; silent when
# everything is already there). See ../shared/DEPENDENCIES.md for why each.
# Extra package names given as arguments are installed too (e.g. blender for
# scripts/bench-cycles.sh).
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libsuitesparse-dev libopenblas0
  libassimp-dev libosmesa6-dev libpng-dev zlib1g-dev libembree-dev libopenexr-dev openexr libfcl-dev
  libtomlplusplus-dev libcli11-dev
  libsndfile1-dev libfftw3-dev
  libcgal-dev libgmp-dev libmpfr-dev
  libgtest-dev libbenchmark-dev
  gnuplot-nox python3 ffmpeg
  "$@"
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "bootstrap: need root (or sudo) to install: ${missing[*]}" >&2
    exit 1
  fi
fi
echo "bootstrap: installing ${#missing[@]} Debian packages: ${missing[*]}" >&2
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "bootstrap: done" >&2
