#!/usr/bin/env bash
# accelviz render --device gpu: the heatmap traced by the compute shader
# in a headless context (--gl: auto, the default, is EGL on a GPU or else
# OSMesa; egl is EGL on a device, here Mesa's software device; osmesa). On
# llvmpipe the PNG's pixels are identical to the CPU's (same counts per pixel,
# same colour map and legend) whichever context traced; the figures say which
# device and context traced; a structure other than bvh, --gl without
# --device gpu and an unknown --gl are one-line usage errors.
set -euo pipefail
accelviz="$(realpath "$1")"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scene='builtin:teapot-stadium?size=3000'
export GALLIUM_DRIVER=llvmpipe
# The same pixels (header and image data): the files' text differs (the command in Description names --device).
same_pixels() {
  python3 - "$1" "$2" <<'PY'
import struct, sys, zlib
def pixels(path):
    png, at, out = open(path, "rb").read(), 8, []
    while at < len(png):
        n, kind = struct.unpack(">I4s", png[at:at + 8])
        if kind in (b"IHDR", b"IDAT"):
            out.append(png[at + 8:at + 8 + n])
        at += 12 + n
    return out[0], zlib.decompress(b"".join(out[1:]))
sys.exit(0 if pixels(sys.argv[1]) == pixels(sys.argv[2]) else 1)
PY
}

for m in nodes prims; do
  "$accelviz" -q render "$scene" --metric "$m" --size 64x48 --out "$tmp/cpu-$m.png" >"$tmp/cpu.out"
  out=$("$accelviz" -q render "$scene" --metric "$m" --size 64x48 --device gpu --out "$tmp/gpu-$m.png")
  echo "$out"
  [ "$(sed -n 1p <<<"$out")" = "$tmp/gpu-$m.png" ] || { echo "FAIL: first line is not the path"; exit 1; }
  same_pixels "$tmp/cpu-$m.png" "$tmp/gpu-$m.png" || { echo "FAIL: $m: GPU picture differs from the CPU's"; exit 1; }
  python3 - "$(sed -n 2p <<<"$out")" "$(sed -n 2p "$tmp/cpu.out")" <<'PY'
import json, sys
g, c = json.loads(sys.argv[1]), json.loads(sys.argv[2])
assert g["device"] == "gpu" and c["device"] == "cpu", (g["device"], c["device"])
assert g["rays"] == 64 * 48 and g["hits"] == c["hits"] > 0, (g["hits"], c["hits"])
assert g["mean"] == c["mean"] and g["max"] == c["max"], (g["mean"], c["mean"])
assert g["render_ms"] > 0 and "gpu_renderer" in g and "gpu_setup_ms" in g
print("gpu figures ok:", g["gpu_renderer"], g["gpu_context"], g["render_ms"], "ms")
PY
done

# Each context by name: the same picture; the figures name the context.
for gl in egl osmesa; do
  out=$("$accelviz" -q render "$scene" --metric nodes --size 64x48 --device gpu --gl $gl --out "$tmp/gpu-$gl.png")
  same_pixels "$tmp/cpu-nodes.png" "$tmp/gpu-$gl.png" || { echo "FAIL: --gl $gl: picture differs from the CPU's"; exit 1; }
  python3 - "$(sed -n 2p <<<"$out")" "$gl" <<'PY'
import json, sys
g, want = json.loads(sys.argv[1]), sys.argv[2]
assert g["gpu_context"] == want, (g["gpu_context"], want)
assert ("gpu_device_file" in g) == (want == "egl"), g
print("--gl", want, "ok:", g["gpu_renderer"], g.get("gpu_device_file", ""))
PY
done
# Without any EGL (libglvnd pointed at no vendor library): --gl egl is a
# one-line error and writes nothing; auto falls back to OSMesa.
if __EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent.json "$accelviz" -q render "$scene" --size 32x24 --device gpu \
  --gl egl --out "$tmp/no-egl.png" 2>"$tmp/err"; then
  echo "FAIL: --gl egl without EGL succeeded"; exit 1
fi
cat "$tmp/err"
grep -q "EGL" "$tmp/err" && [ "$(wc -l <"$tmp/err")" -eq 1 ] && [ ! -e "$tmp/no-egl.png" ] ||
  { echo "FAIL: --gl egl without EGL: not one line naming EGL, or a file"; exit 1; }
out=$(__EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent.json "$accelviz" -q render "$scene" --size 32x24 --device gpu \
  --out "$tmp/auto.png")
python3 -c "import json,sys; g=json.loads(sys.argv[1]); assert g['gpu_context']=='osmesa', g" "$(sed -n 2p <<<"$out")"
if "$accelviz" -q render "$scene" --size 32x24 --gl egl --out "$tmp/cpu-gl.png" 2>"$tmp/err"; then
  echo "FAIL: --gl without --device gpu succeeded"; exit 1
fi
cat "$tmp/err"
grep -q -- "--gl needs --device gpu" "$tmp/err" || { echo "FAIL: --gl message"; exit 1; }
[ "$(wc -l <"$tmp/err")" -eq 1 ] && [ ! -e "$tmp/cpu-gl.png" ] || { echo "FAIL: --gl: not one line, or a file"; exit 1; }
if "$accelviz" -q render "$scene" --size 32x24 --device gpu --gl glx --out "$tmp/glx.png" 2>/dev/null; then
  echo "FAIL: --gl glx accepted"; exit 1
fi

# Only the BVH is traced on the GPU: a usage error naming the option, no file.
if "$accelviz" -q render "$scene" --size 32x24 --device gpu --structure grid --out "$tmp/grid.png" 2>"$tmp/err"; then
  echo "FAIL: --device gpu --structure grid succeeded"; exit 1
fi
cat "$tmp/err"
grep -q -- "--device gpu: only the bvh structure is traced on the GPU" "$tmp/err" || { echo "FAIL: message"; exit 1; }
[ "$(wc -l <"$tmp/err")" -eq 1 ] || { echo "FAIL: not one line"; exit 1; }
[ ! -e "$tmp/grid.png" ] || { echo "FAIL: wrote a file"; exit 1; }
if "$accelviz" -q render "$scene" --size 32x24 --device tpu --out "$tmp/x.png" 2>/dev/null; then
  echo "FAIL: --device tpu accepted"; exit 1
fi
echo "render --device gpu ok"
