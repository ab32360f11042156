# Sourced by the scripts that run a built crumple: sets $crumple to an
# absolute path: $CRUMPLE_BIN, else $CRUMPLE_BUILD_DIR/crumple (default
# build/crumple), else crumple on PATH; exits 2 naming the calling script
# when there is none. Needs $root (the repository).
crumple="${CRUMPLE_BIN:-}"
if [[ -z "$crumple" ]]; then
  if [[ -x "${CRUMPLE_BUILD_DIR:-$root/build}/crumple" ]]; then
    crumple="${CRUMPLE_BUILD_DIR:-$root/build}/crumple"
  else
    crumple="$(command -v crumple || true)"
  fi
fi
[[ -n "$crumple" && -x "$crumple" ]] ||
  { echo "$(basename "$0" .sh): no crumple binary (build it, or set CRUMPLE_BIN)" >&2; exit 2; }
crumple="$(cd "$(dirname "$crumple")" && pwd)/$(basename "$crumple")"
