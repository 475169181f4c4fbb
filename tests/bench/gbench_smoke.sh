#!/usr/bin/env bash
# accelviz_gbench (bench/bench_accel.cpp) runs its dynamics benchmarks and one
# build and trace pair on a small scene, and reports what they measure: a
# crash or a missing counter fails; the timings are printed, not judged.
set -euo pipefail
bin="$1"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
ACCELVIZ_BENCH_SCENE='builtin:teapot?size=2000' "$bin" \
  --benchmark_filter='^(Refit|InstanceOverlap/[05]|Build/bvh/1|TraceClosest/bvh/0|TraceAny/bvh/2)/real_time$' \
  --benchmark_min_time=0.01 --benchmark_format=json > "$tmp/out.json"
python3 - "$tmp/out.json" <<'PY'
import json, sys
runs = {b["name"]: b for b in json.load(open(sys.argv[1]))["benchmarks"]}
want = ["Refit/real_time", "InstanceOverlap/0/real_time", "InstanceOverlap/5/real_time",
        "Build/bvh/1/real_time", "TraceClosest/bvh/0/real_time", "TraceAny/bvh/2/real_time"]
missing = [w for w in want if w not in runs]
assert not missing, (missing, sorted(runs))
r = runs["Refit/real_time"]
assert r["triangles"] > 1000 and r["build_ms"] > 0 and r["real_time"] > 0, r
o0, o5 = runs["InstanceOverlap/0/real_time"], runs["InstanceOverlap/5/real_time"]
assert o0["instances"] == o5["instances"] > 1000, (o0, o5)
assert 0 < o0["pairs"] < o5["pairs"], "the boxes fly into one another over frames 0-5"
print("gbench: ok", {k: round(runs[k]["real_time"], 3) for k in want})
PY
