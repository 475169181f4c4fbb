#!/usr/bin/env bash
# A build without the renderer (ACCELVIZ_BUILD_UI=OFF; registered only there,
# by tests/CMakeLists.txt): the options that need it are one-line usage
# errors given before any scene is loaded, nothing is written, and the CPU
# heatmap still renders.
set -euo pipefail
accelviz="$(realpath "$1")"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scene='builtin:teapot?size=2000'

for opt in "--device gpu" "--view raster"; do
  rc=0
  # shellcheck disable=SC2086
  "$accelviz" render "$scene" --size 32x24 $opt --out "$tmp/x.png" >"$tmp/out" 2>"$tmp/err" || rc=$?
  cat "$tmp/err"
  [ "$rc" -eq 2 ] || { echo "FAIL: $opt: exit $rc, expected 2"; exit 1; }
  [ "$(wc -l <"$tmp/err")" -eq 1 ] || { echo "FAIL: $opt: not one line (nothing loaded first)"; exit 1; }
  grep -q -- "^accelviz: $opt needs the renderer, and this build has none" "$tmp/err" || { echo "FAIL: $opt: message"; exit 1; }
  [ ! -e "$tmp/x.png" ] || { echo "FAIL: $opt: wrote a file"; exit 1; }
done

out=$("$accelviz" -q render "$scene" --size 32x24 --out "$tmp/cpu.png")
[ "$(sed -n 1p <<<"$out")" = "$tmp/cpu.png" ] && [ -s "$tmp/cpu.png" ] || { echo "FAIL: CPU heatmap"; exit 1; }
echo "ok"
