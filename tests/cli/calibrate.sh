#!/usr/bin/env bash
# accelviz calibrate end to end: the micro-benchmarks' constants, and with
# --scene both BVHs measured the same way (medians of --repeat builds and
# passes): the default tree built with (1, 1), the calibrated one with (1,
# C_isect of the chosen test), both judged under the calibrated constants
# (the calibrated tree's own SAH cost is that figure); the text table names
# both; a missing scene is a one-line error naming it.
set -euo pipefail
bin="$1"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

for test in watertight fast; do
  "$bin" -q calibrate --scene 'builtin:teapot?size=800' --repeat 2 --size 32x24 --threads 1 \
    --triangle-test "$test" --json > "$tmp/$test.json"
  python3 - "$tmp/$test.json" "$test" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
test = sys.argv[2]
c = j["c_isect_" + test]
assert c > 0 and j["c_trav"] == 1.0, j
s = j["scene"]
assert s["rays"] == 32 * 24 and s["threads"] == 1 and s["triangle_test"] == test and s["triangles"] > 0, s
assert j["machine"]["threads_used"] == 1 and "calibrate" in j["machine"]["command_line"], j["machine"]
assert j["machine"]["program"]["commit"], j["machine"]
d, k = s["default"], s["calibrated"]
assert d["c_trav"] == 1.0 and d["c_isect"] == 1.0, d
assert k["c_trav"] == 1.0 and abs(k["c_isect"] - c) <= 1e-6 * c, (k, c)
for f in (d, k):
    for key in ("build_ms", "rays_per_s", "nodes_per_ray", "prims_per_ray", "sah_cost_own_constants",
                "sah_cost_calibrated_constants"):
        assert f[key] > 0, (key, f)
# The calibrated tree is built with the constants it is judged by.
own, judged = k["sah_cost_own_constants"], k["sah_cost_calibrated_constants"]
assert abs(own - judged) <= 1e-4 * judged, (own, judged)
PY
done

"$bin" -q calibrate --scene 'builtin:teapot?size=800' --repeat 1 --size 16x12 > "$tmp/text.txt"
grep -q "^  default (1, 1) " "$tmp/text.txt" || fail "no default row: $(cat "$tmp/text.txt")"
grep -q "^  calibrated (1, [0-9.]*) " "$tmp/text.txt" || fail "no calibrated row: $(cat "$tmp/text.txt")"

set +e
"$bin" -q calibrate --scene "$tmp/missing.glb" --repeat 1 > "$tmp/out.txt" 2> "$tmp/err.txt"
rc=$?
set -e
[ "$rc" -ne 0 ] || fail "a missing scene exited 0"
[ "$(wc -l < "$tmp/err.txt")" -eq 1 ] || fail "not one line: $(cat "$tmp/err.txt")"
grep -q "missing.glb" "$tmp/err.txt" || fail "the error does not name the file: $(cat "$tmp/err.txt")"
echo "calibrate: ok"
