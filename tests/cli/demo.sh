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
# The file says what drew it: the command (as its caption) and the program.
python3 - "$a" "$(sed -n 3p <<<"$first")" "$("$accelviz" --version)" <<'PY'
import json, sys
png, j = open(sys.argv[1], "rb").read(), json.loads(sys.argv[2])
assert j["program"]["line"] == sys.argv[3] and j["program"]["commit"] in sys.argv[3], (j["program"], sys.argv[3])
for key, value in (("Description", j["caption"]), ("Software", sys.argv[3])):
    assert b"iTXt" + key.encode() + b"\0\0\0\0\0" + value.encode() in png, key
PY

# Dangling symbolic links with the names of the next seconds take those names too (the demo
# gave up with "exists (use --force to overwrite)", an option it does not have).
mkdir links && cd links
now=$(date +%s)
for s in $(seq 0 20); do
  ln -s /nonexistent/accelviz-test "accelviz-demo-$(date -d "@$((now + s))" +%Y%m%d-%H%M%S).png"
done
third=$("$accelviz" -q) || { echo "FAIL: demo beside dangling links"; exit 1; }
c=$(sed -n 2p <<<"$third")
[ -f "$c" ] && [ ! -L "$c" ] || { echo "FAIL: $c is not a new file"; exit 1; }
grep -q -- '-1\.png$' <<<"$c" || { echo "FAIL: expected the -1 name beside a link: $c"; exit 1; }
echo "demo ok"
