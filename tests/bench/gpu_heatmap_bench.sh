#!/usr/bin/env bash
# accelviz_gpu_bench (bench/gpu_heatmap_bench.cpp): traces a small heatmap in
# an EGL context (here Mesa's software device) a few times, reports one JSON
# object and finds every pixel equal to the CPU's; `gpu` either takes a
# hardware device or says in one line that there is none; bad arguments are
# one-line errors with exit status 2. Timings are printed, not judged.
set -euo pipefail
bench="$(realpath "$1")"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scene='builtin:teapot-stadium?size=3000'

"$bench" "$scene" 64x48 3 >"$tmp/out.json"
cat "$tmp/out.json"
python3 - "$tmp/out.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
assert j["width"] == 64 and j["height"] == 48 and j["rays"] == 64 * 48, j
assert j["triangles"] > 3000, j["triangles"]
assert len(j["trace_ms"]) == 3 and all(t > 0 for t in j["trace_ms"]), j["trace_ms"]
assert j["trace_ms_min"] == min(j["trace_ms"]) and j["trace_ms_median"] == sorted(j["trace_ms"])[1], j
assert j["mismatched_pixels"] == 0, j["mismatched_pixels"]
assert (j["mismatched_counters"], j["mismatched_hit_prim"], j["mismatched_t_only"], j["mismatched_t_max_ulps"]) == (0, 0, 0, 0), j
assert j["gpu_renderer"] and j["gpu_version"].startswith("4."), j
assert j["gpu_software"] == ("llvmpipe" in j["gpu_renderer"]), j
assert j["setup_ms"] > 0 and j["cpu_ms"] > 0 and j["cpu_threads"] >= 1, j
# The whole heatmap (CLI path) and the GUI's frame: each part within its whole.
assert j["heatmap_runs"] == 3 and len(j["heatmap_ms"]) == 3 and len(j["gui_frame_ms"]) == 3, j
assert j["heatmap_ms_median"] >= j["heatmap_trace_ms_median"] > 0, j
assert j["heatmap_metric_ms_median"] >= j["heatmap_readback_ms_median"] > 0, j
assert j["gui_frame_ms_median"] >= j["gui_finish_ms_median"] >= j["gui_readback_ms_median"] > 0, j
assert j["gui_trace_ms_median"] > 0 and len(j["cpu_heatmap_ms"]) == 3, j
print("gpu bench figures ok:", j["gpu_renderer"], j["trace_ms_median"], "ms")
PY

# gpu: a hardware device or one line saying there is none (exit 2).
set +e
"$bench" "$scene" 32x24 1 gpu >"$tmp/gpu.json" 2>"$tmp/gpu.err"
rc=$?
set -e
if [ $rc -eq 0 ]; then
  python3 -c "import json,sys; j=json.load(open(sys.argv[1])); assert not j['gpu_software'], j" "$tmp/gpu.json"
else
  cat "$tmp/gpu.err"
  [ $rc -eq 2 ] && [ "$(wc -l <"$tmp/gpu.err")" -eq 1 ] && grep -q "EGL" "$tmp/gpu.err" ||
    { echo "FAIL: gpu without a GPU: rc $rc"; exit 1; }
fi

# Bad arguments: one line, exit 2, nothing on stdout.
for args in "" "$scene 64x 3" "$scene 64x48 0" "$scene 64x48 3 tpu" "/nonexistent.glb 8x8 1"; do
  set +e
  # shellcheck disable=SC2086
  "$bench" $args >"$tmp/bad.out" 2>"$tmp/bad.err"
  rc=$?
  set -e
  cat "$tmp/bad.err"
  [ $rc -eq 2 ] && [ "$(wc -l <"$tmp/bad.err")" -eq 1 ] && [ ! -s "$tmp/bad.out" ] ||
    { echo "FAIL: '$args': rc $rc"; exit 1; }
done
echo "accelviz_gpu_bench ok"
