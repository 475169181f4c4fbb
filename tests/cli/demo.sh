#!/usr/bin/env bash
# accelviz without a subcommand renders the demo heatmap into the current
# directory under a fresh name, never overwriting, and says where.
set -euo pipefail
accelviz="$(realpath "$1")"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"

first=$("$accelviz" -q)
second=$("$accelviz" -q)
echo "$first"
grep -q "^No display: rendered the demo heatmap to $tmp/accelviz-demo-.*\.png$" <<<"$first" \
  || { echo "FAIL: message"; exit 1; }
a=$(sed -n 2p <<<"$first")
b=$(sed -n 2p <<<"$second")
[ -f "$a" ] && [ -f "$b" ] || { echo "FAIL: files missing"; exit 1; }
[ "$a" != "$b" ] || { echo "FAIL: same name twice"; exit 1; }
[ "$(ls "$tmp" | wc -l)" -eq 2 ] || { echo "FAIL: expected two files"; ls "$tmp"; exit 1; }
head -c 8 "$a" | od -An -c | grep -q 'P   N   G' || { echo "FAIL: not a PNG"; exit 1; }
echo "demo ok"
