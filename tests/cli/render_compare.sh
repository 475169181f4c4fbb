#!/usr/bin/env bash
# accelviz render --compare writes A, B (one locked colour scale) and B - A
# (diverging colours), prints both totals, refuses to overwrite any of the
# three, and names a bad --compare key or value.
set -euo pipefail
accelviz="$(realpath "$1")"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scene='builtin:teapot?size=2000'

out=$("$accelviz" -q render "$scene" --size 48x36 --out "$tmp/cmp.png" --buckets 16 --compare 'buckets=2 leaf=8')
echo "$out"
[ "$(sed -n 1p <<<"$out")" = "$tmp/cmp-a.png" ] || { echo "FAIL: A path"; exit 1; }
[ "$(sed -n 2p <<<"$out")" = "$tmp/cmp-b.png" ] || { echo "FAIL: B path"; exit 1; }
[ "$(sed -n 3p <<<"$out")" = "$tmp/cmp-diff.png" ] || { echo "FAIL: diff path"; exit 1; }
python3 "$2/tests/support/png_software.py" "$("$accelviz" --version)" "$tmp"/cmp-{a,b,diff}.png || { echo "FAIL: the trio without Software text"; exit 1; }
python3 - "$tmp" "$(sed -n 4p <<<"$out")" <<'PY'
import json, struct, sys
d = sys.argv[1]
for n in ["cmp-a.png", "cmp-b.png", "cmp-diff.png"]:
    png = open(f"{d}/{n}", "rb").read()
    assert png[:8] == b"\x89PNG\r\n\x1a\n", n
    w, h = struct.unpack(">II", png[16:24])
    assert w == 48 and h > 36, (n, w, h)
j = json.loads(sys.argv[2])
assert j["a"]["buckets"] == 16 and j["b"]["buckets"] == 2 and j["b"]["leaf"] == 8, j
assert j["total_a"] > 0 and j["total_b"] > 0
assert abs(j["total_diff"] - (j["total_b"] - j["total_a"])) < 1e-6 * max(1.0, j["total_a"])
assert j["scale_max"] >= max(j["a"]["max"], j["b"]["max"]) - 1e-6  # one locked scale
# Bigger leaves and 2 buckets: fewer nodes per ray is not the point; the totals must differ.
assert j["total_a"] != j["total_b"], "A and B rendered the same"
assert j["program"]["line"].startswith("accelviz ") and j["program"]["commit"], j["program"]
# Each image's caption says which side, what it differs in, the scene, metric and size.
c = j["captions"]
assert c["a"] == "A: bvh buckets=16 leaf=8; builtin:teapot?size=2000, nodes, 48x36".replace("leaf=8", "leaf=4"), c
assert c["b"] == "B: bvh buckets=2 leaf=8; builtin:teapot?size=2000, nodes, 48x36", c
assert c["diff"] == "B - A (buckets 16 -> 2, leaf 4 -> 8); builtin:teapot?size=2000, nodes, 48x36", c
print("compare ok:", j["total_a"], j["total_b"])
PY

# Each side names every option that can differ (here the triangle test) and
# only the options that apply to its structure.
out=$("$accelviz" -q render "$scene" --size 24x18 --out "$tmp/tt.png" --compare 'triangle-test=fast')
python3 - "$(sed -n 4p <<<"$out")" <<'PY'
import json, sys
j = json.loads(sys.argv[1])
a, b = j["a"], j["b"]
assert a["triangle_test"] == "watertight" and b["triangle_test"] == "fast", j
for side in (a, b):
    for k in ("structure", "splitter", "buckets", "leaf", "leaf_cap", "ctrav", "cisect", "order", "xray"):
        assert k in side, (k, side)
    assert "embree_quality" not in side and side["per_ray_counters"] is True, side
assert {k: v for k, v in a.items() if k != "triangle_test"}.keys() == {k: v for k, v in b.items() if k != "triangle_test"}.keys()
# What the choice costs in time and what it changes: each side's timed closest hits, the pixels that differ.
for side in (a, b):
    assert side["trace_ms"] > 0 and side["hits"] > 0, side
assert j["trace_ratio_b_over_a"] > 0 and 0 <= j["pixels_hit_changed"] <= 24 * 18, j
print("descriptions ok")
PY
# Voxels hit voxels, not triangles: every pixel that hits counts as changed.
out=$("$accelviz" -q render "$scene" --size 24x18 --out "$tmp/vx.png" --compare 'structure=voxels')
python3 - "$(sed -n 4p <<<"$out")" <<'PY'
import json, sys
j = json.loads(sys.argv[1])
assert j["pixels_hit_changed"] >= j["b"]["hits"] > 0, j
print("hits changed ok:", j["pixels_hit_changed"])
PY
out=$("$accelviz" -q render "$scene" --size 24x18 --out "$tmp/kd.png" -s kdtree --compare 'leaf-cap=8 structure=bvh')
python3 - "$(sed -n 4p <<<"$out")" <<'PY'
import json, sys
j = json.loads(sys.argv[1])
a, b = j["a"], j["b"]
assert a["structure"] == "kdtree" and not any(k in a for k in ("splitter", "buckets", "leaf_cap", "xray", "ctrav")), a
assert a["order"] == "front-to-back" and a["triangle_test"] == "watertight", a
assert b["structure"] == "bvh" and b["leaf_cap"] == 8, b
print("kdtree side ok")
PY
if [[ "$("$accelviz" render --help)" == *",tlas,embree}"* ]]; then  # a build with Embree
  # Embree: its options only, no counters (every total 0), and no ratio of 0/0.
  out=$("$accelviz" -q render "$scene" --size 24x18 --out "$tmp/em.png" -s embree --compare 'embree-quality=high')
  python3 - "$(sed -n 4p <<<"$out")" <<'PY'
import json, sys
j = json.loads(sys.argv[1])
a, b = j["a"], j["b"]
assert a["embree_quality"] == "medium" and b["embree_quality"] == "high", j
for side in (a, b):
    assert not any(k in side for k in ("splitter", "buckets", "leaf", "leaf_cap", "triangle_test", "order", "xray")), side
    assert side["per_ray_counters"] is False and side["total"] == 0 and side["sah_cost"] is None, side
assert j["total_a"] == 0 and j["ratio_b_over_a"] is None, j
# No counts to compare: not "B cheaper everywhere".
assert j["pixels_b_cheaper"] is None and j["pixels_b_dearer"] is None and j["max_abs_diff"] is None, j
assert j["total_diff"] is None, j
print("embree sides ok")
PY
  # bvh against embree: A's counts are real, B's all 0; no difference compares, and the images say so.
  out=$("$accelviz" -q render "$scene" --size 160x120 --out "$tmp/eb.png" --compare 'structure=embree')
  python3 - "$(sed -n 4p <<<"$out")" "$tmp/eb-diff.png" "$tmp/eb-b.png" "$tmp/eb-a.png" <<'PY'
import json, sys, zlib
j = json.loads(sys.argv[1])
assert j["total_a"] > 0 and j["total_b"] == 0 and j["total_diff"] is None and j["max_abs_diff"] is None, j
def rows(path):  # the pixel rows of an 8-bit RGB PNG, unfiltered
    data = open(path, "rb").read()
    chunks, i = [], 8
    while i < len(data):
        n = int.from_bytes(data[i:i + 4], "big")
        if data[i + 4:i + 8] == b"IDAT":
            chunks.append(data[i + 8:i + 8 + n])
        i += 12 + n
    raw, w = zlib.decompress(b"".join(chunks)), int.from_bytes(data[16:20], "big")
    stride, out, prev = 3 * w, [], bytes(3 * w)
    for r in range(len(raw) // (stride + 1)):
        f, line = raw[r * (stride + 1)], bytearray(raw[r * (stride + 1) + 1:(r + 1) * (stride + 1)])
        for x in range(stride):
            a = line[x - 3] if x >= 3 else 0
            b, c = prev[x], prev[x - 3] if x >= 3 else 0
            if f == 1: line[x] = (line[x] + a) & 255
            elif f == 2: line[x] = (line[x] + b) & 255
            elif f == 3: line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        out.append(bytes(line))
        prev = line
    return out
def has_note(path):  # the dark band (24, 24, 24) across the picture's middle with light text (235) in it
    r = rows(path)[:j["height"]]  # the picture, without the legend and caption strips below it
    return any(row.count(bytes([24, 24, 24])) > 40 for row in r[len(r) // 4:3 * len(r) // 4])
assert has_note(sys.argv[2]) and has_note(sys.argv[3]), "the diff and B images carry the n/a note"
assert not has_note(sys.argv[4]), "A (bvh) has its counts, no note"
print("bvh vs embree ok")
PY
fi

# Child order: back-to-front enters more nodes than front-to-back over the view (a few pixels may
# gain when their closest hit lies in the farther child's box).
out=$("$accelviz" -q render "$scene" --size 40x30 --out "$tmp/order.png" --compare 'order=back-to-front')
python3 - "$(sed -n 4p <<<"$out")" <<'PY'
import json, sys
j = json.loads(sys.argv[1])
assert j["total_b"] > j["total_a"], j
assert j["pixels_b_dearer"] > j["pixels_b_cheaper"], j
print("order ok:", j["total_a"], j["total_b"])
PY

# X-ray: the full traversal is a superset of the traversal that stops at the first hit.
out=$("$accelviz" -q render "$scene" --size 40x30 --metric prims --out "$tmp/xray.png" --compare 'xray=1')
python3 - "$(sed -n 4p <<<"$out")" <<'PY'
import json, sys
j = json.loads(sys.argv[1])
assert j["total_b"] > j["total_a"] and j["pixels_b_cheaper"] == 0, j
PY

# Every splitter the BVH has, LBVH too: B is built with it (a different tree, other totals).
out=$("$accelviz" -q render "$scene" --size 40x30 --out "$tmp/lbvh.png" --compare 'splitter=lbvh')
python3 - "$(sed -n 4p <<<"$out")" <<'PY'
import json, sys
j = json.loads(sys.argv[1])
assert j["a"]["splitter"] == "binned" and j["b"]["splitter"] == "lbvh", j
assert j["a"]["sah_cost"] != j["b"]["sah_cost"], j
PY

# Never overwrites: any existing output stops the run before work, files untouched.
before=$(sha256sum "$tmp/cmp-b.png")
if "$accelviz" -q render "$scene" --size 48x36 --out "$tmp/cmp.png" --compare 'buckets=4' 2>"$tmp/err"; then
  echo "FAIL: overwrote without --force"; exit 1
fi
grep -q "cmp-a.png: exists (use --force to overwrite)" "$tmp/err" || { echo "FAIL: message"; cat "$tmp/err"; exit 1; }
[ "$before" = "$(sha256sum "$tmp/cmp-b.png")" ] || { echo "FAIL: B changed"; exit 1; }
"$accelviz" -q render "$scene" --size 48x36 --out "$tmp/cmp.png" --compare 'buckets=4' --force >/dev/null

# Bad specs: one line naming the key or value, exit 2.
for spec in 'buckets=1' 'bogus=3' 'structure=nope' 'order=sideways' 'leaf' ''; do
  rc=0
  "$accelviz" -q render "$scene" --size 8x8 --out "$tmp/bad.png" --compare "$spec" 2>"$tmp/err" >/dev/null || rc=$?
  [ "$rc" = 2 ] || { echo "FAIL: '$spec' exit $rc"; cat "$tmp/err"; exit 1; }
  [ "$(wc -l <"$tmp/err")" -le 2 ] || { echo "FAIL: '$spec' message too long"; cat "$tmp/err"; exit 1; }
  grep -q -- "--compare" "$tmp/err" || { echo "FAIL: '$spec' message"; cat "$tmp/err"; exit 1; }
done
[ ! -e "$tmp/bad-a.png" ] || { echo "FAIL: wrote on a bad spec"; exit 1; }
echo "ok"
