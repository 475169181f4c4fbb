#!/usr/bin/env bash
# Quick start command 1: install what is missing, build (Release) and run
# accelviz on the built-in demo scene. Arguments are passed to accelviz.
set -euo pipefail
cd "$(dirname "$0")/.."

./scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release -j "$(nproc)" --target accelviz
exec ./build/release/app/accelviz "$@"
