#!/usr/bin/env bash
# bench: the LBVH builder (--splitter lbvh) and the Embree build-quality rows
# (embree-low, embree-medium, embree-high) answer like the other rows.
set -euo pipefail
accelviz="$(realpath "$1")"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# LBVH: a valid tree whose SAH is above binned SAH's on the same scene, and the same hits.
"$accelviz" -q bench 'builtin:teapot?size=3000' -s bvh --rays primary --size 24x16 --repeat 1 --no-epo --json \
  >"$tmp/binned.json"
"$accelviz" -q bench 'builtin:teapot?size=3000' -s bvh --splitter lbvh --rays primary --size 24x16 --repeat 1 \
  --no-epo --json >"$tmp/lbvh.json"
python3 - "$tmp/binned.json" "$tmp/lbvh.json" <<'PY'
import json, sys
b = json.load(open(sys.argv[1]))["structures"][0]
l = json.load(open(sys.argv[2]))["structures"][0]
assert l["build"]["nodes"] > 0 and l["build"]["leaves"] * 2 - 1 == l["build"]["nodes"], l["build"]
assert l["build"]["sah_cost"] > b["build"]["sah_cost"], (l["build"]["sah_cost"], b["build"]["sah_cost"])
assert l["rays"]["primary"]["hit_fraction"] == b["rays"]["primary"]["hit_fraction"]
print("lbvh ok")
PY

# A bad splitter name is a usage error naming the option.
if "$accelviz" bench 'builtin:teapot?size=300' --splitter morton 2>"$tmp/err.txt"; then
  echo "FAIL: --splitter morton accepted"; exit 1
fi
grep -q -- "--splitter" "$tmp/err.txt" || { echo "FAIL: error does not name --splitter"; cat "$tmp/err.txt"; exit 1; }

# Embree quality rows, when Embree is built in.
"$accelviz" bench --help >"$tmp/help.txt"
if grep -q embree-low "$tmp/help.txt"; then
  "$accelviz" -q bench 'builtin:soup?size=2000' -s embree,embree-low,embree-high --rays primary --size 16x16 \
    --repeat 1 --json >"$tmp/q.json"
  python3 - "$tmp/q.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
names = [s["name"] for s in j["structures"]]
assert names == ["embree", "embree-low", "embree-high"], names
for s in j["structures"]:
    assert s["per_ray_counters"] is False, s["name"]
    assert s["build"]["build_ms"] > 0 and s["build"]["memory_bytes"] > 0, s["name"]
    assert s["rays"]["primary"]["closest_mrays_1t"] > 0, s["name"]
hits = {s["name"]: s["rays"]["primary"]["hit_fraction"] for s in j["structures"]}
assert len(set(hits.values())) == 1, hits  # every quality finds the same hits
r = j["ratios_vs_embree"]
assert set(r) == {"embree-low", "embree-high"}, r
print("embree rows ok")
PY
fi
echo "bench builders ok"
