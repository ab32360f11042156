#!/usr/bin/env bash
# Fuzzing with libFuzzer (docs/FUZZING.md):
#   scripts/fuzz.sh [TARGET|all] [SECONDS]
# TARGET is scene, cache, cache_tools, gltf, fbx or collada (default all); each runs for
# SECONDS (default 600), one after the other. Installs clang and libFuzzer's
# runtime if missing, builds build-fuzz (clang, CRUMPLE_FUZZ=ON: ASan, UBSan,
# coverage), and runs each fuzzer on a working corpus in
# build-fuzz/corpus/<target>, seeded from tests/fuzz/corpus/<target>. Prints
# one summary line per target; a crash input is kept in
# build-fuzz/artifacts/<target>/ and the script says where (exit status 1).
# The log of each run is build-fuzz/logs/<target>.log.
# Environment: CRUMPLE_FUZZ_BUILD (build dir), FUZZ_TIMEOUT (s per input,
# default 10), FUZZ_RSS_MB (default 2048), JOBS (build jobs, default 2).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
all_targets=(scene cache cache_tools gltf fbx collada)
which="${1:-all}"
seconds="${2:-600}"
timeout_s="${FUZZ_TIMEOUT:-10}"
rss_mb="${FUZZ_RSS_MB:-2048}"
build="${CRUMPLE_FUZZ_BUILD:-$root/build-fuzz}"

if [ "$which" = all ]; then
  targets=("${all_targets[@]}")
elif [[ " ${all_targets[*]} " == *" $which "* ]]; then
  targets=("$which")
else
  echo "fuzz.sh: unknown target '$which' (one of: ${all_targets[*]}, all)" >&2
  exit 2
fi
[[ "$seconds" =~ ^[0-9]+$ ]] || { echo "fuzz.sh: SECONDS must be a whole number" >&2; exit 2; }

bash "$root/scripts/bootstrap.sh" clang libclang-rt-14-dev

if [ ! -f "$build/CMakeCache.txt" ]; then
  generator=()
  command -v ninja >/dev/null 2>&1 && generator=(-G Ninja)
  launcher=()
  command -v ccache >/dev/null 2>&1 &&
    launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  CC=clang CXX=clang++ cmake -S "$root" -B "$build" "${generator[@]}" "${launcher[@]}" \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCRUMPLE_FUZZ=ON \
    -DCRUMPLE_BUILD_TESTS=OFF -DCRUMPLE_BUILD_BENCH=OFF >/dev/null
fi
build_targets=()
for t in "${targets[@]}"; do build_targets+=("fuzz_$t"); done
cmake --build "$build" -j "${JOBS:-2}" --target "${build_targets[@]}"

# Leaks inside third-party libraries are not ours (tests/lsan.supp).
export LSAN_OPTIONS="suppressions=$root/tests/lsan.supp:print_suppressions=0"
# A single allocation over the memory limit is an AddressSanitizer error
# (allocation-size-too-big): a crash in our code, while inside the animation
# import's probe child (docs/FUZZING.md) it ends only the child. libFuzzer's
# own malloc limit is set out of the way because its hook would also fire in
# that child and record the input as the parent's crash.
export ASAN_OPTIONS="max_allocation_size_mb=$rss_mb${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
# The animation import's probe child (docs/FUZZING.md) must give up well
# before libFuzzer's per-input timeout: the probe and the real import each
# get a third of it.
export CRUMPLE_IMPORT_TIMEOUT="$(awk -v t="$timeout_s" 'BEGIN { print t / 3 }')"
status=0
summaries=()
for t in "${targets[@]}"; do
  corpus="$build/corpus/$t"
  artifacts="$build/artifacts/$t"
  log="$build/logs/$t.log"
  mkdir -p "$corpus" "$artifacts" "$(dirname "$log")"
  echo "fuzz.sh: fuzz_$t for ${seconds} s (log: $log)" >&2
  rc=0
  "$build/tests/fuzz/fuzz_$t" -max_total_time="$seconds" -timeout="$timeout_s" \
    -rss_limit_mb="$rss_mb" -malloc_limit_mb=$((rss_mb * 1024)) -print_final_stats=1 -artifact_prefix="$artifacts/" \
    "$corpus" "$root/tests/fuzz/corpus/$t" >"$log" 2>&1 || rc=$?
  execs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)"
  rate="$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)"
  files="$(find "$corpus" -type f | wc -l)"
  # Counted from the fuzzer's own log: an input that crashed assimp inside
  # the import probe's child is contained (an InputError), not a crash.
  crashes="$(grep -c 'Test unit written to' "$log" || true)"
  final="$(grep -E '^#[0-9]+[[:space:]]+DONE' "$log" | tail -1 || true)"
  corp="$(sed -n 's/.* corp: \([0-9]*\/[0-9]*[A-Za-z]*\).*/\1/p' <<<"$final")"
  line="fuzz_$t: ${seconds} s, ${execs:-?} executions, ${rate:-?} exec/s, corpus ${corp:-?} (${files} files in $corpus), crashes ${crashes}"
  summaries+=("$line")
  echo "$line"
  [ -n "$final" ] && echo "  libFuzzer: $final"
  if [ "$rc" -ne 0 ] || [ "$crashes" -ne 0 ]; then
    status=1
    echo "  FAILED (exit $rc); see $log" >&2
    grep -E 'ERROR: |SUMMARY: |==[0-9]+== ?ERROR|deadly signal|Test unit written to' "$log" | head -8 >&2 || true
    sed -n 's/.*Test unit written to /  crash input kept: /p' "$log" >&2 || true
    echo "  reproduce: $build/tests/fuzz/fuzz_$t <crash input>" >&2
  fi
done
if [ ${#summaries[@]} -gt 1 ]; then
  echo "summary:"
  printf '  %s\n' "${summaries[@]}"
fi
exit "$status"
