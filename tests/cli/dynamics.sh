#!/usr/bin/env bash
# Two-level structure, animation and effects by scene from the command line:
# info lists the effects with reasons (and forces), animate prints per-frame
# stats that show rigid motion and the grass refit, render builds 'tlas' from
# the scene's instances (also for an island too large to flatten, which other
# structures refuse), and bad input is a one-line usage error.
set -euo pipefail
accelviz="$(realpath "$1")"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# info: effects and the structure they imply.
"$accelviz" info --json 'builtin:dynamic?size=3000' | python3 -c '
import json, sys
j = json.load(sys.stdin)
fx = {e["name"]: e for e in j["effects"]}
assert set(fx) == {"shadow-rays", "per-frame-updates", "two-level", "textures"}, fx
assert fx["shadow-rays"]["on"] and fx["per-frame-updates"]["on"] and fx["two-level"]["on"], fx
assert not fx["textures"]["on"]
assert all(e["reason"] for e in fx.values())
assert j["structure"] == "tlas"
print("dynamic effects ok")'
"$accelviz" info --json --force-effect two-level 'builtin:duplicates?size=100' | python3 -c '
import json, sys
j = json.load(sys.stdin)
fx = {e["name"]: e for e in j["effects"]}
assert not fx["shadow-rays"]["on"], fx          # the degenerate test scenes have no light
assert not fx["per-frame-updates"]["on"], fx    # nothing animates
assert fx["two-level"]["on"] and fx["two-level"]["forced"], fx
assert j["structure"] == "tlas"
print("forced two-level ok")'
out=$("$accelviz" info 'builtin:teapot?size=500')
grep -Eq '^  shadow-rays +on ' <<<"$out" || { echo "FAIL: teapot has a light: shadow rays on"; echo "$out"; exit 1; }
grep -Eq '^  two-level +off ' <<<"$out" || { echo "FAIL: teapot is not instanced"; echo "$out"; exit 1; }

# animate: every box moves each frame after the first, the grass BLAS is refitted.
"$accelviz" -q animate 'builtin:dynamic?size=3000' --frames 3 --json -j 1 > "$tmp/frames.jsonl"
python3 - "$tmp/frames.jsonl" <<'PY'
import json, sys
head, *rows = [json.loads(l) for l in open(sys.argv[1])]
# The first line is the table's heading: the two-level structure built, and the build that ran.
assert head["scene"] == "builtin:dynamic?size=3000" and head["animates"], head
assert head["instances"] > 0 and head["blas"] >= 1 and head["build_ms"] >= 0, head
assert head["memory_two_level"] > 0 and head["threads"] == 1 and head["frames"] == 3, head
assert head["program"]["line"].startswith("accelviz "), head
assert "frame" not in head, head
assert len(rows) == 3, rows
assert [r["frame"] for r in rows] == [0, 1, 2], rows
boxes = (3000 - 3000 // 4) // 12
for r in rows[1:]:
    assert r["moved_instances"] == boxes, r
    assert r["refits"] == 1 and r["tlas_rebuilt"], r
    assert r["sah_refit"] > 0 and r["sah_rebuilt"] > 0, r
# Instance overlap per frame: measured on each frame's moved instances.
assert all(r["overlap_area"] > 0 and r["overlap_pairs"] > 0 for r in rows), rows
assert len({r["overlap_area"] for r in rows}) > 1, [r["overlap_area"] for r in rows]
print("animate ok")
PY
# A static scene: zero-cost frames and a note; each row still has its time
# and the instance boxes' overlap (it was 0 on every row).
"$accelviz" -q animate 'builtin:forest?size=2000' --frames 3 --dt 0.5 --json 2> "$tmp/err" | python3 -c '
import json, sys
head, *rows = [json.loads(l) for l in sys.stdin]
assert not head["animates"], head
assert [r["frame"] for r in rows] == [0, 1, 2], rows
assert all(r["refits"] == 0 and r["moved_instances"] == 0 and not r["tlas_rebuilt"] for r in rows), rows
assert [r["time"] for r in rows] == [0.0, 0.5, 1.0], rows
assert all(r["overlap_area"] > 0 and r["overlap_pairs"] > 0 for r in rows), rows
assert len({r["overlap_area"] for r in rows}) == 1, rows
print("static animate ok")'
grep -q "nothing animates" "$tmp/err" || { echo "FAIL: no note for a static scene"; exit 1; }

# render: tlas from the scene's instances; an unflattened island is tlas-only.
"$accelviz" -q render 'builtin:forest?size=5000' -s tlas --size 64x48 -o "$tmp/forest.png" > "$tmp/forest.out"
test -s "$tmp/forest.png"
big='builtin:island?size=20000&copies=3000'   # about 54 million instanced triangles: not flattened
"$accelviz" -q render "$big" -s tlas --size 64x48 -o "$tmp/island.png" > "$tmp/island.out" 2>/dev/null
tail -1 "$tmp/island.out" | python3 -c '
import json, sys
j = json.load(sys.stdin)
assert j["triangles"] == 0 and j["hits"] > 0, j
assert j["instanced_triangles"] > 50000000, j   # the world triangles the two levels hold
print("island tlas ok")'
set +e
msg=$("$accelviz" -q render "$big" -s bvh --size 64x48 -o "$tmp/island_bvh.png" 2>&1)
rc=$?
set -e
[ $rc -ne 0 ] || { echo "FAIL: bvh on an unflattened island must fail"; exit 1; }
grep -q "only 'tlas'" <<<"$msg" || { echo "FAIL: message should name tlas: $msg"; exit 1; }
[ "$(wc -l <<<"$msg")" -eq 1 ] || { echo "FAIL: one-line error expected: $msg"; exit 1; }

# Usage errors name the parameter.
for args in "--dt 0" "--rebuild-ratio 0.5"; do
  set +e
  msg=$("$accelviz" animate 'builtin:dynamic?size=300' $args 2>&1)
  rc=$?
  set -e
  [ $rc -eq 2 ] || { echo "FAIL: animate $args: exit $rc, expected 2"; exit 1; }
  grep -q -- "${args%% *}" <<<"$msg" || { echo "FAIL: message should name ${args%% *}: $msg"; exit 1; }
done
set +e
msg=$("$accelviz" info --force-effect motion-blur 'builtin:soup?size=10' 2>&1)
rc=$?
set -e
[ $rc -eq 2 ] || { echo "FAIL: unknown effect: exit $rc"; exit 1; }
grep -q "motion-blur" <<<"$msg" || { echo "FAIL: message should name the effect: $msg"; exit 1; }
# flatten: the what-if traces the same rays through both (same hits); bad ids are a usage error.
"$accelviz" -q flatten 'builtin:forest?size=20000&seed=3' --instances 0,1,2 --size 40x30 --json -j 1 | python3 -c '
import json, sys
j = json.load(sys.stdin)
a, b = j["two_level"], j["flattened"]
assert j["merged_instances"] == 3 and j["merged_triangles"] > 0, j
assert b["instances"] == a["instances"] - 2, j
assert a["rays"] == b["rays"] == 1200 and a["hits"] == b["hits"] > 0, j
assert a["sah_cost"] > 0 and b["sah_cost"] > 0 and a["mean_instances"] > 0, j
print("flatten what-if ok")'
# The ids take the GUI's syntax (core/accel/tlas/instance_ids.h): ranges, and an id listed twice
# counts once; an empty item between commas is a typo, not a list.
"$accelviz" -q flatten 'builtin:forest?size=2000' --instances '0-2,1, 1' --size 8x8 --json -j 1 | python3 -c '
import json, sys
j = json.load(sys.stdin)
assert j["merged_instances"] == 3, j
print("flatten ranges ok")'
for ids in "0,,1" "0," "x" "99999" "2-1"; do
  set +e
  msg=$("$accelviz" flatten 'builtin:forest?size=2000' --instances "$ids" 2>&1)
  rc=$?
  set -e
  [ $rc -eq 2 ] || { echo "FAIL: flatten --instances $ids: exit $rc, expected 2"; exit 1; }
  grep -q -- "--instances" <<<"$msg" || { echo "FAIL: message should name --instances: $msg"; exit 1; }
done
# An id too large for any scene is said as such (it read "not a range LO-HI with LO <= HI").
msg=$("$accelviz" flatten 'builtin:forest?size=2000' --instances 0-99999999999 2>&1) && exit 1
grep -q -- "--instances: '0-99999999999' has an id beyond 4294967295, the largest there can be" <<<"$msg" ||
  { echo "FAIL: a too-large id: $msg"; exit 1; }
# refit's motion is its own: it says so, for a static scene and for an animated one alike.
"$accelviz" -q refit 'builtin:teapot?size=300' --frames 1 --size 16x12 -j 1 --out "$tmp/refit1" > "$tmp/refit1.txt"
grep -q "motion: synthetic explode motion from the rest pose (frame 0; the scene itself is static)" "$tmp/refit1.txt" ||
  { echo "FAIL: refit on a static scene: $(cat "$tmp/refit1.txt")"; exit 1; }
"$accelviz" -q refit 'builtin:dynamic?size=1200' --frames 1 --size 16x12 -j 1 --out "$tmp/refit2" > "$tmp/refit2.txt"
grep -q "the scene's own [0-9]* animations* \(is\|are\) not played here" "$tmp/refit2.txt" ||
  { echo "FAIL: refit on an animated scene: $(cat "$tmp/refit2.txt")"; exit 1; }
# The table's key: what refits, ratio and nodes/ray count; with --rebuild-ratio, what a rebuilt row holds.
grep -q "^refits: of the tree in use since it was built; ratio: SAH refit / SAH fresh; nodes/ray: nodes visited per primary ray$" \
  "$tmp/refit1.txt" || { echo "FAIL: refit's key: $(cat "$tmp/refit1.txt")"; exit 1; }
"$accelviz" -q refit 'builtin:teapot?size=300' --frames 1 --size 16x12 -j 1 --rebuild-ratio 1 --out "$tmp/refit3" |
  grep -q "; rebuilt: the ratio passed --rebuild-ratio, so the fresh tree replaced the refitted one this row measured" ||
  { echo "FAIL: refit's key with --rebuild-ratio"; exit 1; }
python3 -c '
import json, sys
j = json.load(open(sys.argv[1]))
assert j["motion"] == "synthetic" and j["motion_kind"] == "explode" and j["scene_animations"] > 0, j
# frame 0 is the rest pose the first tree was built on: refit and fresh alike
f0 = j["per_frame"][0]
assert f0["frame"] == 0 and f0["ratio"] == 1 and f0["sah_refit"] == f0["sah_fresh"], f0
assert [f["frame"] for f in j["per_frame"]] == [0, 1], j["per_frame"]' "$tmp/refit2/refit.json"
# The level a scene calls for: a note when the structure is of the other level (not with -q).
"$accelviz" render 'builtin:forest?size=2000' --size 16x12 -j 1 --out "$tmp/lv1.png" 2> "$tmp/lv1.err" > /dev/null
grep -q "note: builtin:forest?size=2000: .*\`-s tlas\` builds the two-level structure it calls for; bvh flattens" "$tmp/lv1.err" ||
  { echo "FAIL: no two-level note: $(cat "$tmp/lv1.err")"; exit 1; }
"$accelviz" render 'builtin:forest?size=2000' -s tlas --size 16x12 -j 1 --out "$tmp/lv2.png" 2> "$tmp/lv2.err" > /dev/null
! grep -q "note:" "$tmp/lv2.err" || { echo "FAIL: a note for tlas on an instanced scene: $(cat "$tmp/lv2.err")"; exit 1; }
"$accelviz" render 'builtin:teapot?size=300' -s tlas --size 16x12 -j 1 --out "$tmp/lv3.png" 2> "$tmp/lv3.err" > /dev/null
grep -q "no mesh is instanced twice (two-level off): tlas holds its 1 instance" "$tmp/lv3.err" ||
  { echo "FAIL: no single-level note: $(cat "$tmp/lv3.err")"; exit 1; }
"$accelviz" -q render 'builtin:forest?size=2000' --size 16x12 -j 1 --out "$tmp/lv4.png" 2> "$tmp/lv4.err" > /dev/null
[ ! -s "$tmp/lv4.err" ] || { echo "FAIL: -q printed: $(cat "$tmp/lv4.err")"; exit 1; }
# A frame whose transform flattens an instance stops animate with the file, the frame and its time
# ("tlas: instance 0: ..." alone named neither). A glTF whose node 0's y scale steps to 0 at t = 0.5.
python3 - "$tmp/flat.gltf" <<'PY'
import base64, json, struct, sys
pos = struct.pack('<9f', 0,0,0, 1,0,0, 0,1,0)
times = struct.pack('<3f', 0.0, 0.5, 1.0)
scales = struct.pack('<9f', 1,1,1, 1,0,1, 1,0,1)
buf = pos + times + scales
doc = {
 "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
 "nodes": [{"mesh": 0, "name": "flattened"}, {"mesh": 0, "translation": [3, 0, 0]}],
 "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
 "buffers": [{"byteLength": len(buf), "uri": "data:application/octet-stream;base64," + base64.b64encode(buf).decode()}],
 "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 12},
                 {"buffer": 0, "byteOffset": 48, "byteLength": 36}],
 "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]},
               {"bufferView": 1, "componentType": 5126, "count": 3, "type": "SCALAR", "min": [0], "max": [1]},
               {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC3"}],
 "animations": [{"samplers": [{"input": 1, "output": 2, "interpolation": "STEP"}],
                 "channels": [{"sampler": 0, "target": {"node": 0, "path": "scale"}}]}]}
json.dump(doc, open(sys.argv[1], "w"))
PY
msg=$("$accelviz" -q animate "$tmp/flat.gltf" --frames 4 --dt 0.25 -j 1 2>&1 >/dev/null) && { echo "FAIL: animate went on"; exit 1; }
grep -q "^accelviz: $tmp/flat.gltf: frame 2 (t = 0.5 s): tlas: instance 0: its transform is singular .* (animate plays the two-level structure only)$" <<<"$msg" ||
  { echo "FAIL: animate's singular frame: $msg"; exit 1; }
echo "dynamics cli ok"
