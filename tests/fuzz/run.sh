#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz/CMakeLists.txt, clang with
# -fsanitize=fuzzer,address,undefined) and runs each one for a bounded time
# from the committed seed corpus. Exits non-zero on any crash, sanitizer
# report, uncaught exception other than the loader's own error, timeout
# (-timeout) or memory blow-up (-rss_limit_mb); the reproducer is left in
# $BUILD/artifacts/<target>/.
#   ACCELVIZ_FUZZ_SECONDS   seconds per target (default 30)
#   ACCELVIZ_FUZZ_BUILD     build directory (default build/fuzz)
#   ACCELVIZ_FUZZ_TARGETS   space-separated subset (default: all three)
set -euo pipefail
cd "$(dirname "$0")/../.."

seconds="${ACCELVIZ_FUZZ_SECONDS:-30}"
build="${ACCELVIZ_FUZZ_BUILD:-build/fuzz}"
targets="${ACCELVIZ_FUZZ_TARGETS:-fuzz_gltf fuzz_obj fuzz_ray_file}"

if ! command -v clang++ >/dev/null; then
  echo "tests/fuzz/run.sh: clang++ not found (scripts/install-deps.sh installs clang and libclang-rt-14-dev)" >&2
  exit 1
fi
if [ ! -f "$build/build.ninja" ]; then
  CC=clang CXX=clang++ cmake -S tests/fuzz -B "$build" -G Ninja >/dev/null
fi
cmake --build "$build" -j "$(nproc)"

# The targets run side by side (each is one process), so the wall time is
# about ACCELVIZ_FUZZ_SECONDS whatever the number of targets.
run_one() {
  local t="$1"
  local corpus_in="tests/fuzz/corpus/${t#fuzz_}"
  local work="$build/corpus/$t"          # grows while fuzzing; the committed seeds stay as they are
  local artifacts="$build/artifacts/$t"
  mkdir -p "$work" "$artifacts"
  ASAN_OPTIONS="detect_leaks=1:allocator_may_return_null=1" UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
    "$build/$t" "$work" "$corpus_in" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -malloc_limit_mb=1024 -max_len=65536 -print_final_stats=1 -artifact_prefix="$artifacts/" \
    >"$build/$t.log" 2>&1
}

# The targets write each input into a private directory under TMPDIR
# (fuzz_common.h); libFuzzer ends without running destructors, so point
# TMPDIR into the build directory and remove it afterwards: nothing is left in /tmp.
fuzz_tmp="$(realpath "$build")/tmp"
rm -rf "$fuzz_tmp"
mkdir -p "$fuzz_tmp"
export TMPDIR="$fuzz_tmp"
trap 'rm -rf "$fuzz_tmp"' EXIT

declare -A pids
for t in $targets; do
  echo "== $t: ${seconds}s from tests/fuzz/corpus/${t#fuzz_}"
  run_one "$t" &
  pids[$t]=$!
done
status=0
for t in $targets; do
  if wait "${pids[$t]}"; then
    echo "$t: $(grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "$build/$t.log" | tr -s ' ' | tr '\n' ' ')-> OK"
  else
    echo "$t: FAILED (log $build/$t.log, reproducer in $build/artifacts/$t/)" >&2
    grep -E "ERROR|SUMMARY|==[0-9]+==|Test unit written" "$build/$t.log" | head -20 >&2 || true
    status=1
  fi
done
exit $status
