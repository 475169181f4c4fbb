#!/usr/bin/env bash
# accelviz render --device gpu: the heatmap traced by the compute shader
# (headless OSMesa, llvmpipe). The PNG is byte-identical to the CPU's (same
# counts per pixel, same colour map and legend), the figures say which device
# traced, and a structure other than bvh is a one-line usage error.
set -euo pipefail
accelviz="$(realpath "$1")"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scene='builtin:teapot-stadium?size=3000'
export GALLIUM_DRIVER=llvmpipe

for m in nodes prims; do
  "$accelviz" -q render "$scene" --metric "$m" --size 64x48 --out "$tmp/cpu-$m.png" >"$tmp/cpu.out"
  out=$("$accelviz" -q render "$scene" --metric "$m" --size 64x48 --device gpu --out "$tmp/gpu-$m.png")
  echo "$out"
  [ "$(sed -n 1p <<<"$out")" = "$tmp/gpu-$m.png" ] || { echo "FAIL: first line is not the path"; exit 1; }
  cmp "$tmp/cpu-$m.png" "$tmp/gpu-$m.png" || { echo "FAIL: $m: GPU picture differs from the CPU's"; exit 1; }
  python3 - "$(sed -n 2p <<<"$out")" "$(sed -n 2p "$tmp/cpu.out")" <<'PY'
import json, sys
g, c = json.loads(sys.argv[1]), json.loads(sys.argv[2])
assert g["device"] == "gpu" and c["device"] == "cpu", (g["device"], c["device"])
assert g["rays"] == 64 * 48 and g["hits"] == c["hits"] > 0, (g["hits"], c["hits"])
assert g["mean"] == c["mean"] and g["max"] == c["max"], (g["mean"], c["mean"])
assert g["render_ms"] > 0 and "gpu_renderer" in g and "gpu_setup_ms" in g
print("gpu figures ok:", g["gpu_renderer"], g["render_ms"], "ms")
PY
done

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
