#!/usr/bin/env bash
# What the commands print reads right: bench's column headers are told apart
# with one thread, counts take their plural only when not 1 ("1 thread",
# "1 instance"), info prints bounds that differ where the box does, and
# render says when Embree counted nothing.
set -uo pipefail
accelviz="$(realpath "$1")"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
fail=0
bad() { echo "FAIL: $*"; fail=1; }

# A closed 2x2x2 cube translated by 1e7 (float spacing 1 there).
python3 - >"$tmp/far.obj" <<'PY'
c = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
print("\n".join("v %r %r %r" % (1e7 + x, 1e7 + y, 1e7 + z) for x, y, z in c))
for f in ((1, 3, 4), (1, 4, 2), (5, 6, 8), (5, 8, 7), (1, 2, 6), (1, 6, 5), (3, 7, 8), (3, 8, 4), (1, 5, 7), (1, 7, 3),
          (2, 4, 8), (2, 8, 6)):
    print("f %d %d %d" % f)
PY

# bench -j 1: the one-thread and the --threads columns are two measurements on one thread; their
# headers differ, in the table and in the ratios; no "1 threads", "1 runs", "1 rays".
out=$("$accelviz" -q bench "$tmp/far.obj" -n 1 --size 1x1 -j 1 --rays primary)
echo "$out"
header=$(grep -E '^  Mrays/s ' <<<"$out" | head -n 1)
python3 - "$header" <<'PY' || fail=1
import re, sys
cols = re.split(r" {2,}", sys.argv[1].strip())[1:]
assert len(cols) == 6 and len(set(cols)) == 6, f"headers not distinct: {cols}"
print("bench headers:", cols)
PY
grep -Eq '^scene .*: 12 triangles; 1 thread; medians of 1 run; ' <<<"$out" || bad "bench's first line: $(head -n 1 <<<"$out")"
grep -Eq '^  primary +1 ray$' <<<"$out" || bad "bench's ray set line"
if grep -Eq '\b1 (threads|runs|rays|triangles)\b' <<<"$out"; then bad "a plural after 1"; fi
out=$("$accelviz" -q bench "$tmp/far.obj" -n 2 --size 2x1 -j 2 -s bvh --rays primary)
grep -Eq '^scene .*: 12 triangles; 2 threads; medians of 2 runs; ' <<<"$out" || bad "bench with 2: $(head -n 1 <<<"$out")"
grep -Eq '^  Mrays/s +closest 1T +closest 2T +any 1T +any 2T ' <<<"$out" || bad "bench's 2-thread headers"

# animate: one instance.
out=$("$accelviz" -q animate "$tmp/far.obj" --frames 1 2>/dev/null)
grep -Eq ': 1 instance, 1 BLAS, ' <<<"$out" || bad "animate: $(head -n 1 <<<"$out")"

# info: a 2-wide box at 1e7 has bounds that differ.
out=$("$accelviz" info "$tmp/far.obj")
grep -Fxq 'bounds         (9999999, 9999999, 9999999) .. (10000001, 10000001, 10000001), extent (2, 2, 2)' <<<"$out" ||
  bad "info bounds: $(grep '^bounds' <<<"$out")"

# render -s embree: Embree keeps no per-ray counters, so nothing was instrumented.
if [[ "$("$accelviz" render --help)" == *",tlas,embree}"* ]]; then
  "$accelviz" render "$tmp/far.obj" -s embree --size 8x6 --out "$tmp/e.png" >"$tmp/e.out" 2>"$tmp/e.err"
  python3 - "$(sed -n 2p "$tmp/e.out")" <<'PY' || fail=1
import json, sys
j = json.loads(sys.argv[1])
assert j["instrumented"] is False and j["per_ray_counters"] is False and j["max"] == 0, j
print("render -s embree: not instrumented")
PY
  grep -q 'embree keeps no per-ray counters' "$tmp/e.err" || bad "render -s embree says nothing about its counters"
  "$accelviz" -q render "$tmp/far.obj" --size 8x6 --out "$tmp/b.png" | sed -n 2p | python3 -c '
import json, sys
j = json.load(sys.stdin)
assert j["instrumented"] is True and j["per_ray_counters"] is True, j' || fail=1
fi

[ "$fail" = 0 ] && echo "cli.wording: OK"
exit $fail
