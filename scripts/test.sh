#!/usr/bin/env bash
# Quick start command 2: install what is missing, build, run every test.
#   1. Release build, whole suite (core unit + differential tests, CLI tests,
#      headless GL tests through OSMesa, GUI tests under Xvfb once they exist).
#   1b. libFuzzer targets for the loaders, bounded time (skip with ACCELVIZ_SKIP_FUZZ=1).
#   1c. A build without the renderer on the core's scalar code paths
#      (ACCELVIZ_BUILD_UI=OFF, ACCELVIZ_NO_SIMD: binning, box and triangle
#      tests without SSE2/AVX2): the core tests of the BVH and what runs on
#      it (skip with ACCELVIZ_SKIP_NOSIMD=1).
#   2. Debug + AddressSanitizer + UndefinedBehaviorSanitizer build without the
#      renderer (preset asan): core, app logic and command-line tests again
#      (skip with ACCELVIZ_SKIP_SANITIZERS=1 for a quick local run). With
#      ACCELVIZ_SANITIZE_UI=1 it is preset asan-ui instead: also the renderer,
#      the GL tests and the GUI scripts under the sanitizers (which CI leaves
#      out to stay near its 30-minute budget).
set -euo pipefail
cd "$(dirname "$0")/.."

# Each phase's start time (UTC) and the seconds since the script began, so a
# slow CI run shows where its time went.
t_start=$(date +%s)
phase() { echo "== $(date -u +%H:%M:%S) (+$(($(date +%s) - t_start)) s) $*"; }

phase "install dependencies"
./scripts/install-deps.sh

jobs="$(nproc)"
phase "release build"
cmake --preset release >/dev/null
cmake --build --preset release -j "$jobs"
phase "release tests"
ctest --preset release -j "$jobs"

if [ "${ACCELVIZ_SKIP_FUZZ:-0}" != "1" ]; then
  # libFuzzer on the glTF/GLB, OBJ and ray-file readers (clang, ASan+UBSan),
  # ACCELVIZ_FUZZ_SECONDS (default 30) per target, side by side.
  phase "fuzz (tests/fuzz/run.sh)"
  ./tests/fuzz/run.sh
fi

if [ "${ACCELVIZ_SKIP_NOSIMD:-0}" != "1" ]; then
  phase "no-renderer build on the scalar code paths (preset nosimd): the BVH's core tests"
  cmake --preset nosimd >/dev/null
  cmake --build --preset nosimd -j "$jobs"
  ctest --preset nosimd -j "$jobs"
fi

if [ "${ACCELVIZ_SKIP_SANITIZERS:-0}" != "1" ]; then
  asan=asan
  [ "${ACCELVIZ_SANITIZE_UI:-0}" = "1" ] && asan=asan-ui
  phase "asan+ubsan build (preset $asan)"
  cmake --preset "$asan" >/dev/null
  cmake --build --preset "$asan" -j "$jobs"
  phase "asan+ubsan tests (preset $asan)"
  ctest --preset "$asan" -j "$jobs"
fi
phase "done"
