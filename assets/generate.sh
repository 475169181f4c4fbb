#!/usr/bin/env bash
# Regenerates the repository's own small example scenes from the built-in
# generators (nothing here is copied from elsewhere):
#   assets/generate.sh [path/to/accelviz]   (default build/release/app/accelviz)
# tests/cli/assets.sh checks that the committed files are exactly what this
# script writes, so a change to a generator or to the writer shows up there.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
accelviz="$(realpath "${1:-$here/../build/release/app/accelviz}")"
out="${2:-$here}"

# name | scene spec
while IFS='|' read -r name spec; do
  [ -z "$name" ] && continue
  "$accelviz" -q export "$spec" "$out/$name" --force
done <<'LIST'
teapot.glb|builtin:teapot?size=2000
teapot-stadium.glb|builtin:teapot-stadium?size=4000
walls.glb|builtin:walls?size=400
walls-rotated.glb|builtin:walls-rotated?size=400
forest.glb|builtin:forest?size=5000
grass.glb|builtin:grass?size=3000
LIST
