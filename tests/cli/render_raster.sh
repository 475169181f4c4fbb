#!/usr/bin/env bash
# accelviz render --view raster: the GL overlay view drawn headless through
# OSMesa. Checks the figures it reports (box count at a depth, the picked
# ray's hit equals `trace` on the same pixel ray), the PNG's size and that
# the picture is not blank, and the usage errors.
set -euo pipefail
accelviz="$(realpath "$1")"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scene='builtin:teapot?size=20000'
export GALLIUM_DRIVER=llvmpipe

out=$("$accelviz" -q render "$scene" --view raster --depth 3 --ray-pixel 80,60 --size 160x120 --out "$tmp/r.png")
echo "$out"
json=$(sed -n 2p <<<"$out")
python3 "$2/tests/support/png_software.py" "$("$accelviz" --version)" "$tmp/r.png" || { echo "FAIL: the raster PNG without Software text"; exit 1; }
python3 - "$tmp/r.png" "$json" <<'PY'
import json, struct, sys, zlib
png = open(sys.argv[1], "rb").read()
assert png[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
w, h = struct.unpack(">II", png[16:24])
assert (w, h) == (160, 120), (w, h)
# Decode the IDAT stream (8-bit RGB, filter bytes per row) enough to count distinct colours.
idat = b""
pos = 8
while pos < len(png):
    n = struct.unpack(">I", png[pos:pos + 4])[0]
    kind = png[pos + 4:pos + 8]
    if kind == b"IDAT":
        idat += png[pos + 8:pos + 8 + n]
    pos += 12 + n
raw = zlib.decompress(idat)
assert len(raw) >= h * (1 + 3 * w), len(raw)
j = json.loads(sys.argv[2])
assert j["view"] == "raster" and j["boxes"] == 8, j      # a full binary tree has 8 nodes at depth 3
assert j["ray"]["hit"] is True and j["ray"]["prim"] >= 0, j
assert j["ray"]["nodes_visited"] > 0, j
assert len(set(raw)) > 16, "picture looks blank"
print("raster ok:", j["ray"])
PY

# The picked ray's primitive equals what `trace` reports for the same pixel ray.
"$accelviz" -q rays "$scene" --kind primary --size 160x120 --out "$tmp/p.rays" >/dev/null
"$accelviz" -q trace "$scene" --rays "$tmp/p.rays" --out "$tmp/p.hits" --structure brute >/dev/null
python3 - "$tmp/p.hits" "$json" <<'PY'
import json, struct, sys
data = open(sys.argv[1], "rb").read()
assert data[:4] == b"HITS"
idx = 60 * 160 + 80
prim, t = struct.unpack("<If", data[16 + 8 * idx:16 + 8 * idx + 8])
j = json.loads(sys.argv[2])
assert prim == j["ray"]["prim"], (prim, j["ray"])
print("picked ray agrees with trace:", prim, t)
PY

# Usage errors: raster-only options without --view raster, boxes of a structure without any.
# --ray-camera: the ray of pixel 80,60 of that camera, drawn in --camera's view (the ray from the side,
# not a dot where it leaves the eye): the same ray as that camera's own --ray-pixel.
own=$("$accelviz" -q render "$scene" --view raster --ray-pixel 80,60 --size 160x120 --camera gltf:0 --out "$tmp/own.png" | sed -n 2p)
side=$("$accelviz" -q render "$scene" --view raster --ray-pixel 80,60 --ray-camera gltf:0 --camera 12,5,-2,0,1,0,45 \
  --size 160x120 --out "$tmp/side.png" | sed -n 2p)
moved=$("$accelviz" -q render "$scene" --view raster --ray-pixel 80,60 --camera 12,5,-2,0,1,0,45 --size 160x120 \
  --out "$tmp/moved.png" | sed -n 2p)
python3 - "$own" "$side" "$moved" <<'PY'
import json, sys
own, side, moved = (json.loads(a)["ray"] for a in sys.argv[1:])
assert own["origin"] == side["origin"] and own["direction"] == side["direction"] and own["prim"] == side["prim"], (own, side)
assert moved["origin"] != own["origin"], "without --ray-camera the ray leaves --camera's eye"
print("--ray-camera ok")
PY
if "$accelviz" -q render "$scene" --view raster --ray-camera gltf:0 --out "$tmp/rc.png" 2>"$tmp/err"; then
  echo "FAIL: --ray-camera without --ray-pixel"; exit 1
fi
grep -q -- "--ray-camera needs --ray-pixel" "$tmp/err" || { echo "FAIL: --ray-camera message"; cat "$tmp/err"; exit 1; }
for opt in "--depth 2" "--depth-last 3" "--leaves" "--ray-pixel 1,1" "--ray-camera gltf:0" "--blend 0.5" "--wireframe"; do
  # shellcheck disable=SC2086
  if "$accelviz" -q render "$scene" $opt --out "$tmp/x.png" 2>"$tmp/err"; then echo "FAIL: $opt without raster"; exit 1; fi
  grep -q "need --view raster" "$tmp/err" || { echo "FAIL: $opt message"; cat "$tmp/err"; exit 1; }
  [ ! -e "$tmp/x.png" ] || { echo "FAIL: $opt wrote a picture"; exit 1; }
done
if "$accelviz" -q render "$scene" --view raster --structure grid --depth 2 --out "$tmp/y.png" 2>"$tmp/err"; then
  echo "FAIL: grid has no node boxes"; exit 1
fi
grep -q "grid" "$tmp/err"
# A range needs its first depth, and its last depth must not be below the first.
for opt in "--depth-last 3" "--depth 3 --depth-last 2"; do
  # shellcheck disable=SC2086
  if "$accelviz" -q render "$scene" --view raster $opt --out "$tmp/z.png" 2>"$tmp/err"; then
    echo "FAIL: raster $opt was accepted"; exit 1
  fi
  grep -q -- "--depth" "$tmp/err" || { echo "FAIL: raster $opt message"; cat "$tmp/err"; exit 1; }
  [ ! -e "$tmp/z.png" ] || { echo "FAIL: raster $opt wrote a picture"; exit 1; }
done
echo "render_raster ok"
