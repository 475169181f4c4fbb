#!/usr/bin/env bash
# accelviz sweep end to end: a tiny sweep writes CSV, JSON and PNG charts that
# parse; every requested setting is there; a DIR with sweep files is refused
# without --force; unknown parameters and values are usage errors naming them.
set -euo pipefail
bin="$1"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

out="$tmp/s1"
"$bin" -q sweep 'builtin:teapot?size=800' --param buckets=2,8,exact --param triangle=watertight,fast \
  --size 32x24 --repeat 1 --threads 1 --edge-probes 300 --out "$out" > "$tmp/stdout.txt"
grep -q "Pareto-optimal" "$tmp/stdout.txt" || fail "no Pareto list on stdout"
grep -q "best for 1e+06 rays" "$tmp/stdout.txt" || fail "no best setting for 1e6 rays"
grep -q "best for 1e+09 rays" "$tmp/stdout.txt" || fail "no best setting for 1e9 rays"
for f in sweep.csv sweep.json sweep-pareto.png sweep-sah_cost-vs-buckets.png sweep-rays_per_s-vs-buckets.png \
         sweep-nodes_per_ray-vs-triangle.png sweep-build_ms-vs-buckets.png sweep-total_ms-vs-triangle.png; do
  [ -s "$out/$f" ] || fail "missing $f"
done
# The charts name the build that drew them (Software), as render's PNGs do.
python3 "$2/tests/support/png_software.py" "$("$bin" --version)" "$out"/sweep-*.png || fail "a chart without the program's Software text"

python3 - "$out" <<'PY'
import csv, json, struct, sys, zlib, glob, os
out = sys.argv[1]
rows = list(csv.DictReader(open(os.path.join(out, "sweep.csv"))))
assert len(rows) == 6, len(rows)
want = {(b, t) for b in ("2", "8", "exact") for t in ("watertight", "fast")}
assert {(r["buckets"], r["triangle"]) for r in rows} == want, rows
for r in rows:
    assert float(r["build_ms"]) > 0 and float(r["rays_per_s"]) > 0 and float(r["sah_cost"]) > 0, r
    assert int(r["edge_probes"]) == 300, r
    assert int(r["edge_misses"]) <= int(r["edge_probes"]), r
# The triangle test is a query option: one tree per bucket count, built and timed once.
by = {(r["buckets"], r["triangle"]): r for r in rows}
for b in ("2", "8", "exact"):
    w, f = by[(b, "watertight")], by[(b, "fast")]
    assert w["build_of"] == "" and f["build_of"] == w["label"], (w, f)
    assert f["build_ms"] == w["build_ms"] and f["memory_bytes"] == w["memory_bytes"], (w, f)
j = json.load(open(os.path.join(out, "sweep.json")))
for k in ("cpu_model", "hardware_threads", "threads_used", "date", "command_line"):
    assert k in j["machine"], k
assert j["machine"]["threads_used"] == 1
assert j["warmup"] == 1 and j["repeat"] == 1, (j["warmup"], j["repeat"])
assert "sweep" in j["machine"]["command_line"]
assert j["machine"]["program"]["version"] and j["machine"]["program"]["commit"], j["machine"]
assert len(j["results"]) == 6 and len(j["pareto_front"]) >= 1
assert {b["rays"] for b in j["best_for_budget"]} >= {1e6, 1e9}, j["best_for_budget"]
assert len(j["best_for_budget"]) == 2, j["best_for_budget"]  # the default budget 1e6 is listed once
for b in j["best_for_budget"]:
    assert "edge_leaks" in b and "best_without_leaks" in b, b  # edges were probed
# One repeat: no setting has two runs to lie apart.
assert j["timing_scatter"] == {"rays_per_s": 0.0, "build_ms": 0.0}, j["timing_scatter"]
for png in glob.glob(os.path.join(out, "*.png")):
    data = open(png, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", png
    w, h = struct.unpack(">II", data[16:24])
    assert w > 100 and h > 100, (png, w, h)
    # Decompress the IDAT stream to be sure the file is whole.
    pos, idat = 8, b""
    while pos < len(data):
        n = struct.unpack(">I", data[pos:pos + 4])[0]
        if data[pos + 4:pos + 8] == b"IDAT":
            idat += data[pos + 8:pos + 8 + n]
        pos += 12 + n
    assert len(zlib.decompress(idat)) == h * (1 + 3 * w), png
PY

# Grids report no SAH cost: n/a in the table, null in the JSON, empty in the CSV.
"$bin" -q sweep 'builtin:soup?size=200' -s grid --param lambda=1,2 --size 8x8 --repeat 1 --threads 1 \
  --out "$tmp/g" > "$tmp/g.txt"
grep -q " n/a " "$tmp/g.txt" || fail "grid SAH not n/a: $(cat "$tmp/g.txt")"
python3 - "$tmp/g" <<'PY'
import csv, json, os, sys
j = json.load(open(os.path.join(sys.argv[1], "sweep.json")))
assert all(r["sah_cost"] is None for r in j["results"]), j["results"]
assert all(r["sah_cost"] == "" for r in csv.DictReader(open(os.path.join(sys.argv[1], "sweep.csv"))))
PY

# Shadow rays in a scene without lights aim at the synthetic light, and stdout says where.
printf 'v -1 -1 0\nv 1 -1 0\nv 0 1 0\nv 0 0 -1\nf 1 2 3\nf 1 2 4\nf 2 3 4\nf 3 1 4\n' > "$tmp/unlit.obj"
"$bin" -q sweep "$tmp/unlit.obj" --rays shadow --param leaf=1 --size 16x12 --repeat 1 --threads 1 \
  --out "$tmp/sh" > "$tmp/sh.txt"
grep -q "no lights: shadow rays aim at a synthetic point light at (" "$tmp/sh.txt" ||
  fail "synthetic light not said: $(cat "$tmp/sh.txt")"

# A directory that holds sweep files is refused without --force, accepted with it.
if "$bin" -q sweep 'builtin:soup?size=200' --param leaf=1,4 --size 8x8 --repeat 1 --out "$out" 2> "$tmp/err.txt"; then
  fail "overwrote a sweep directory without --force"
fi
grep -q "force" "$tmp/err.txt" || fail "refusal does not mention --force: $(cat "$tmp/err.txt")"
"$bin" -q sweep 'builtin:soup?size=200' --param leaf=1,4 --size 8x8 --repeat 1 --out "$out" --force > /dev/null
[ "$(wc -l < "$out/sweep.csv")" -eq 3 ] || fail "--force run did not replace sweep.csv"
[ ! -e "$out/sweep-sah_cost-vs-buckets.png" ] || fail "stale chart of the first sweep left behind"
# --force on a run that fails (a missing scene) keeps the results that were there.
before=$(sha256sum "$out/sweep.csv")
"$bin" -q sweep "$tmp/missing.glb" --param leaf=1 --out "$out" --force 2> /dev/null && fail "a missing scene swept"
[ "$before" = "$(sha256sum "$out/sweep.csv")" ] || fail "a failed --force run removed or changed sweep.csv"

# Usage errors (exit 2) name the parameter or value, before any work: no output directory.
# usage_error WHAT NEEDLE -- SWEEP-ARGS...
usage_error() {
  local what="$1" needle="$2" rc=0
  shift 3
  "$bin" -q sweep "$@" --out "$tmp/bad" 2> "$tmp/err.txt" || rc=$?
  [ "$rc" -eq 2 ] || fail "$what: exit $rc"
  grep -qF -- "$needle" "$tmp/err.txt" || fail "$what not said: $(cat "$tmp/err.txt")"
  [ ! -e "$tmp/bad" ] || fail "$what: a usage error created the output directory"
}
usage_error "unknown parameter" "bukets" -- 'builtin:soup?size=200' --param bukets=2
usage_error "bad value" "4x4" -- 'builtin:soup?size=200' --structure grid --param res=4x4
# Each side in range, the product not.
usage_error "too many cells" "more than 2^26 cells" -- 'builtin:soup?size=200' --structure grid --param res=4096x4096x8
echo "sweep: ok"
