#!/usr/bin/env bash
# accelviz render writes a PNG, prints its path and one JSON line of figures,
# and never overwrites an existing file without --force.
set -euo pipefail
accelviz="$(realpath "$1")"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scene='builtin:teapot?size=2000'

out=$("$accelviz" -q render "$scene" --metric nodes --size 64x48 --out "$tmp/a.png")
echo "$out"
[ "$(sed -n 1p <<<"$out")" = "$tmp/a.png" ] || { echo "FAIL: first line is not the path"; exit 1; }
python3 - "$tmp/a.png" "$(sed -n 2p <<<"$out")" "$("$accelviz" --version)" <<'PY'
import json, struct, sys, zlib
png = open(sys.argv[1], "rb").read()
assert png[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
w, h = struct.unpack(">II", png[16:24])
assert w == 64 and h > 48, (w, h)  # legend and caption below the 64x48 picture
j = json.loads(sys.argv[2])
# The caption is the command that draws the picture (the options not at their default too), its
# words quoted for the shell where they need it: pasted back, it runs.
assert j["caption"] == "accelviz render 'builtin:teapot?size=2000' -s bvh -m nodes --size 64x48", j["caption"]
# The program in the shape bench's machine record has: the facts, and --version's line.
assert j["program"]["line"] == sys.argv[3] and j["program"]["commit"] in sys.argv[3], (j["program"], sys.argv[3])
# The file carries the command and the program (iTXt chunks, each CRC right) beside the pixels.
at, text = 8, {}
while at < len(png):
    n, kind = struct.unpack(">I4s", png[at:at + 8])
    body = png[at + 8:at + 8 + n]
    assert struct.unpack(">I", png[at + 8 + n:at + 12 + n])[0] == zlib.crc32(kind + body), kind
    if kind == b"iTXt":
        key, rest = body.split(b"\0", 1)
        assert rest[:2] == b"\0\0", rest[:2]  # uncompressed
        lang, trans, value = rest[2:].split(b"\0", 2)
        text[key.decode()] = value.decode()
    at += 12 + n
assert kind == b"IEND"
assert text == {"Description": j["caption"], "Software": sys.argv[3]}, text
for k in ["mean", "max", "render_ms", "rays_per_s", "build_ms", "rays", "out"]:
    assert k in j, k
assert j["rays"] == 64 * 48 and j["max"] >= j["mean"] > 0
print("png and figures ok")
PY

# Refuses to overwrite; the file is untouched.
before=$(sha256sum "$tmp/a.png")
if "$accelviz" -q render "$scene" --metric prims --size 32x32 --out "$tmp/a.png" 2>"$tmp/err"; then
  echo "FAIL: overwrote without --force"; exit 1
fi
grep -q "$tmp/a.png: exists (use --force to overwrite)" "$tmp/err" || { echo "FAIL: message"; cat "$tmp/err"; exit 1; }
[ "$before" = "$(sha256sum "$tmp/a.png")" ] || { echo "FAIL: file changed"; exit 1; }

# --force overwrites.
"$accelviz" -q render "$scene" --metric prims --size 32x32 --out "$tmp/a.png" --force >/dev/null
[ "$before" != "$(sha256sum "$tmp/a.png")" ] || { echo "FAIL: --force did not overwrite"; exit 1; }

# Every metric, colour map and legend placement renders.
for m in nodes prims cost shaded depth; do
  "$accelviz" -q render "$scene" --metric "$m" --size 40x30 --out "$tmp/$m.png" --colormap turbo --legend right \
    --structure bvh --threads 2 >/dev/null
done
"$accelviz" -q render "$scene" --size 40x30 --out "$tmp/fixed.png" --max 10 --colormap inferno --legend none \
  --camera 0,5,20,0,0,0,30 --triangle-test fast --splitter median >/dev/null
# --max pNN: the top at a percentile of the image's values, below its maximum (a few outliers do not set it).
"$accelviz" -q render "$scene" --size 80x60 --out "$tmp/p.png" --max p90 | sed -n 2p | python3 -c '
import json, sys
j = json.load(sys.stdin)
assert 0 < j["scale_max"] < j["max"], j
print("--max p90 ok")'
# The caption: every option not at its default, in the picture's own strip; none leaves it out; a text of one's own.
cap=$("$accelviz" -q render "$scene" --size 40x30 --out "$tmp/c1.png" --max 10 --camera 0,5,20,0,0,0,30 \
  --triangle-test fast --splitter median --buckets 8 --order unordered | sed -n 2p |
  python3 -c 'import json, sys; print(json.load(sys.stdin)["caption"])')
[ "$cap" = "accelviz render '$scene' -s bvh -m nodes --size 40x30 --camera 0,5,20,0,0,0,30 --triangle-test fast --order unordered --max 10 --splitter median --buckets 8" ] ||
  { echo "FAIL: caption: $cap"; exit 1; }
# Pasted back into a shell, the caption draws the same file: a scene whose name has spaces, a colour map,
# a legend and a percentile top (the caption used to leave the colours out and the name unquoted).
mkdir -p "$tmp/my scenes"
"$accelviz" -q export "$scene" "$tmp/my scenes/tea pot.glb" >/dev/null
"$accelviz" -q render "$tmp/my scenes/tea pot.glb" --size 40x30 --colormap inferno --legend right --max p95 \
  --out "$tmp/r1.png" >"$tmp/r1.txt"
cap=$(sed -n 2p "$tmp/r1.txt" | python3 -c 'import json, sys; print(json.load(sys.stdin)["caption"])')
case "$cap" in "accelviz render '$tmp/my scenes/tea pot.glb' "*"--colormap inferno --legend right --max p95"*) ;;
  *) echo "FAIL: caption of a spaced name: $cap"; exit 1 ;; esac
(cd "$tmp" && bash -c "'$accelviz' -q ${cap#accelviz } --out r2.png" >/dev/null) || { echo "FAIL: caption did not run: $cap"; exit 1; }
cmp "$tmp/r1.png" "$tmp/r2.png" || { echo "FAIL: the caption's command drew another file"; exit 1; }
echo "caption pasted back ok: $cap"
# A file name starting with '-' (given after --): the caption names it ./-lead.glb, which pastes back.
cp "$tmp/my scenes/tea pot.glb" "$tmp/-lead.glb"
(cd "$tmp" && "$accelviz" -q render --size 40x30 --out r3.png -- -lead.glb >r3.txt)
cap=$(sed -n 2p "$tmp/r3.txt" | python3 -c 'import json, sys; print(json.load(sys.stdin)["caption"])')
[ "$cap" = "accelviz render ./-lead.glb -s bvh -m nodes --size 40x30" ] || { echo "FAIL: caption of -lead.glb: $cap"; exit 1; }
(cd "$tmp" && bash -c "'$accelviz' -q ${cap#accelviz } --out r4.png" >/dev/null) || { echo "FAIL: ./-lead.glb did not run"; exit 1; }
"$accelviz" -q render "$scene" --size 40x30 --out "$tmp/c2.png" --caption none >/dev/null
"$accelviz" -q render "$scene" --size 40x30 --out "$tmp/c3.png" --caption "fig. 3: the teapot" >/dev/null
"$accelviz" -q render "$scene" --size 40x30 --out "$tmp/c4.png" >/dev/null
python3 - "$tmp" <<'PY'
import struct, sys
h = lambda n: struct.unpack(">II", open(f"{sys.argv[1]}/{n}.png", "rb").read()[16:24])[1]
assert h("c2") < h("c3") and h("c2") < h("c4"), (h("c2"), h("c3"), h("c4"))
# A caption of one's own is in the file too (Comment), beside the command (Description).
assert b"iTXtComment\0\0\0\0\0fig. 3: the teapot" in open(f"{sys.argv[1]}/c3.png", "rb").read()
print("caption ok")
PY

# Progress on a pipe or in a log: no carriage returns; a step that runs longer
# than ACCELVIZ_PROGRESS_SECONDS (default 10) prints "LABEL NN%" lines on the way.
ACCELVIZ_PROGRESS_SECONDS=0.000001 "$accelviz" render "$scene" --size 160x120 --out "$tmp/progress.png" \
  >/dev/null 2>"$tmp/progress.err"
cat "$tmp/progress.err"
grep -qE '^rendering nodes [0-9]+%$' "$tmp/progress.err" || { echo "FAIL: no progress line while rendering"; exit 1; }
grep -qE '^rendering nodes: [0-9]+ ms$' "$tmp/progress.err" || { echo "FAIL: no end line"; exit 1; }
if grep -q $'\r' "$tmp/progress.err"; then echo "FAIL: carriage return on a pipe"; exit 1; fi
"$accelviz" render "$scene" --size 32x24 --out "$tmp/quick.png" >/dev/null 2>"$tmp/quick.err"
if grep -qE '[0-9]%$' "$tmp/quick.err"; then echo "FAIL: a quick step printed progress lines"; cat "$tmp/quick.err"; exit 1; fi
echo "progress lines ok"

# Several structures: one image each, OUT-NAME.png, on one colour scale (the largest maximum).
out=$("$accelviz" -q render "$scene" -s bvh,kdtree,grid --size 64x48 --out "$tmp/several.png")
for s in bvh kdtree grid; do [ -f "$tmp/several-$s.png" ] || { echo "FAIL: several-$s.png missing"; exit 1; }; done
python3 - "$(tail -n 1 <<<"$out")" "$(head -n 3 <<<"$out")" <<'PY'
import json, sys
j = json.loads(sys.argv[1])
names = [i["structure"] for i in j["images"]]
assert names == ["bvh", "kdtree", "grid"], names
top = max(i["max"] for i in j["images"])
assert j["scale_max"] == top and all(i["scale_max"] == top for i in j["images"]), j
assert all(i["caption"].endswith("--max %g" % top) for i in j["images"]), [i["caption"] for i in j["images"]]
assert sys.argv[2].split("\n") == [i["out"] for i in j["images"]]
assert j["program"]["line"].startswith("accelviz ") and j["program"]["commit"], j["program"]
print("several structures ok")
PY
# --max pNN: the percentile of every image's values, shared.
"$accelviz" -q render "$scene" -s bvh,octree --size 64x48 --max p90 --out "$tmp/p90.png" | tail -n 1 |
  python3 -c 'import json,sys; j=json.load(sys.stdin); assert 0 < j["scale_max"] < max(i["max"] for i in j["images"]), j'
# A structure that counts nothing (the voxels' prims) is left out of the shared percentile: its zeros
# pulled the top down.
alone=$("$accelviz" -q render "$scene" -s bvh -m prims --size 64x48 --max p90 --out "$tmp/pa.png" | tail -n 1)
both=$("$accelviz" -q render "$scene" -s bvh,voxels -m prims --size 64x48 --max p90 --out "$tmp/pb.png" | tail -n 1)
python3 -c 'import json, sys; a, b = json.loads(sys.argv[1]), json.loads(sys.argv[2]); assert a["scale_max"] == b["scale_max"], (a["scale_max"], b["scale_max"])' "$alone" "$both"
# An existing output stops the run before any is written.
if "$accelviz" -q render "$scene" -s bvh,grid --size 32x24 --out "$tmp/several.png" 2>"$tmp/err"; then
  echo "FAIL: several structures overwrote"; exit 1
fi
grep -q "several-bvh.png: exists" "$tmp/err" || { echo "FAIL: message: $(cat "$tmp/err")"; exit 1; }
echo "render ok"
