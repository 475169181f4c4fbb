#!/usr/bin/env bash
# accelviz bench --json prints one JSON document with the documented keys.
set -euo pipefail
accelviz="$(realpath "$1")"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

"$accelviz" bench 'builtin:soup?size=2000' --structure bvh,brute-bbox --size 24x16 --repeat 2 --json \
  >"$tmp/bench.json" 2>"$tmp/progress.txt"
python3 -m json.tool "$tmp/bench.json" >/dev/null
[ -s "$tmp/progress.txt" ] || { echo "FAIL: no progress on stderr"; exit 1; }
# The rounds build the structures in turn (A, B, A, B), not A's repeats then B's.
builds=$(grep -o '^building [a-z-]* ([0-9]/2)' "$tmp/progress.txt" | tr '\n' ';')
[ "$builds" = "building bvh (1/2);building brute-bbox (1/2);building bvh (2/2);building brute-bbox (2/2);" ] ||
  { echo "FAIL: builds not in turns: $builds"; exit 1; }
# --warmup N: N untimed build rounds first (in turns too), then the timed ones; only those are reported.
"$accelviz" bench 'builtin:soup?size=2000' --structure bvh,brute-bbox --rays primary --size 8x8 --repeat 2 \
  --warmup 1 --json >"$tmp/warm.json" 2>"$tmp/warm.txt"
builds=$(grep -o '^building [a-z-]* ([a-z -]*[0-9]/[0-9])' "$tmp/warm.txt" | tr '\n' ';')
[ "$builds" = "building bvh (warm-up 1/1);building brute-bbox (warm-up 1/1);building bvh (1/2);building brute-bbox (1/2);building bvh (2/2);building brute-bbox (2/2);" ] ||
  { echo "FAIL: warm-up builds: $builds"; exit 1; }
python3 -c '
import json, sys
j = json.load(open(sys.argv[1]))
assert j["warmup"] == 1 and j["repeat"] == 2, (j["warmup"], j["repeat"])
for s in j["structures"]:
    assert len(s["build"]["build_ms_runs"]) == 2, s["build"]["build_ms_runs"]
print("bench warmup ok")' "$tmp/warm.json"
"$accelviz" bench 'builtin:soup?size=2000' --structure bvh --rays primary --size 8x8 --warmup -1 2>/dev/null &&
  { echo "FAIL: --warmup -1 accepted"; exit 1; }
# A file name that is not UTF-8 (a Latin-1 e-acute): the JSON has U+FFFD for that byte. The JSON
# writer threw on it and bench failed after all its work; a render's PNG text (UTF-8) the same.
lat="$tmp/lat$(printf '\xe9').glb"
"$accelviz" -q export 'builtin:soup?size=200' "$lat" >/dev/null
"$accelviz" -q bench "$lat" -s bvh --rays primary --size 8x8 -n 1 -j 1 --json >"$tmp/lat.json"
"$accelviz" -q render "$lat" --size 16x12 -j 1 --out "$tmp/lat.png" >"$tmp/lat-render.txt"
python3 - "$tmp/lat.json" "$tmp/lat-render.txt" "$tmp/lat.png" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
assert j["scene"].endswith("lat\ufffd.glb"), j["scene"]
assert "lat\ufffd.glb" in j["machine"]["command_line"], j["machine"]["command_line"]
r = json.loads(open(sys.argv[2], "rb").read().split(b"\n")[1])
assert "lat\ufffd.glb" in r["caption"], r["caption"]
png = open(sys.argv[3], "rb").read()
assert "lat\ufffd.glb".encode() in png, "iTXt Description not UTF-8"
print("not-UTF-8 name ok")
PY
# Where and with what it ran: the machine, and the program as --version names it (its commit).
"$accelviz" --version >"$tmp/version.txt"
python3 - "$tmp/bench.json" "$tmp/version.txt" <<'PY'
import json, re, sys
j = json.load(open(sys.argv[1]))
version = open(sys.argv[2]).read().strip()
m = re.fullmatch(r"accelviz (\d+\.\d+\.\d+) \(commit ([0-9a-f]{7,}(-dirty)?|unknown), (\w+) build(, Embree [\d.]+)?\)", version)
assert m, version
machine = j["machine"]
for k in ["cpu_model", "hardware_threads", "threads_used", "load_average_1min", "date", "command_line", "program"]:
    assert k in machine, k
assert machine["threads_used"] == j["threads"], (machine["threads_used"], j["threads"])
# Each word quoted for the shell where it needs it ('?'), so that the line pastes back as it ran.
assert "bench 'builtin:soup?size=2000' --structure bvh,brute-bbox" in machine["command_line"], machine["command_line"]
assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", machine["date"]), machine["date"]
p = machine["program"]
assert (p["version"], p["commit"], p["build_type"]) == (m.group(1), m.group(2), m.group(4)), (p, version)
assert ("embree" in p) == (m.group(5) is not None), (p, version)
assert p["line"] == version, (p, version)
print("bench machine ok:", version)
for k in ["scene", "triangles", "threads", "repeat", "warmup", "ray_sets", "structures"]:
    assert k in j, k
assert j["warmup"] == 0
assert set(j["ray_sets"]) == {"primary", "diffuse", "shadow"}, j["ray_sets"]
assert j["ray_sets"]["primary"]["rays"] == 24 * 16
names = [s["name"] for s in j["structures"]]
assert names == ["bvh", "brute-bbox"], names
for s in j["structures"]:
    for k in ["build_ms", "build_ms_runs", "nodes", "leaves", "max_depth", "memory_bytes", "sah_cost"]:
        assert k in s["build"], (s["name"], k)
    assert len(s["build"]["build_ms_runs"]) == 2
    for rs in ["primary", "diffuse", "shadow"]:
        q = s["rays"][rs]
        for k in ["closest_mrays_1t", "closest_mrays_nt", "any_mrays_1t", "any_mrays_nt",
                  "closest_nodes_per_ray", "closest_prims_per_ray", "any_nodes_per_ray", "any_prims_per_ray"]:
            assert k in q, (s["name"], rs, k)
        assert q["closest_mrays_1t"] > 0
bvh = j["structures"][0]
assert bvh["build"]["nodes"] > 0 and bvh["build"]["sah_cost"] > 0
assert bvh["rays"]["primary"]["closest_nodes_per_ray"] > 0
print("bench json ok")
PY
# The other outputs with timings name the same build: trace, robustness, flatten and refit.json.
"$accelviz" -q rays 'builtin:soup?size=200' --size 8x8 --out "$tmp/p.rays" >/dev/null
"$accelviz" -q trace 'builtin:soup?size=200' --rays "$tmp/p.rays" --out "$tmp/p.hits" -j 1 >"$tmp/trace.json"
"$accelviz" -q robustness 'builtin:soup?size=200' --rays 200 -j 1 --json >"$tmp/lab.json"
"$accelviz" -q flatten 'builtin:forest?size=2000' --instances 0 --size 8x8 -j 1 --json >"$tmp/flatten.json"
"$accelviz" -q refit 'builtin:soup?size=200' --frames 2 --size 8x8 -j 1 --out "$tmp/refit" >/dev/null
python3 - "$tmp/version.txt" "$tmp/trace.json" "$tmp/lab.json" "$tmp/flatten.json" "$tmp/refit/refit.json" <<'PY'
import json, sys
version = open(sys.argv[1]).read().strip()
for path in sys.argv[2:]:
    text = open(path).read().strip().splitlines()[-1] if not path.endswith("refit.json") else open(path).read()
    p = json.loads(text)["program"]
    assert p["line"] == version and p["commit"] in version, (path, p, version)
print("program named by trace, robustness, flatten, refit: ok")
PY

# With Embree: ratios and Embree's binary-BVH SAH beside ours.
# (The help goes to a file first: with pipefail, `grep -q` closing the pipe
# early could fail the pipeline and skip this part silently.)
"$accelviz" render --help >"$tmp/help.txt"
if grep -q embree "$tmp/help.txt"; then
  "$accelviz" -q bench 'builtin:soup?size=2000' --structure bvh,embree --rays primary --size 16x16 --repeat 1 --json \
    | python3 -c '
import json, sys
j = json.load(sys.stdin)
assert "ratios_vs_embree" in j and "bvh" in j["ratios_vs_embree"], j.keys()
r = j["ratios_vs_embree"]["bvh"]
assert "build_ms" in r and "closest_mrays_1t" in r["primary"]
e = j["structures"][0]["embree_binary_bvh"]
assert e["sah_cost"] > 0 and e["sah_ratio_ours_over_embree"] > 0
assert j["structures"][1]["per_ray_counters"] is False
# Figures Embree does not have are null, not 0 (a script picking the lowest took the 0).
em = j["structures"][1]
assert em["build"]["nodes"] is None and em["build"]["sah_cost"] is None, em["build"]
assert em["rays"]["primary"]["closest_nodes_per_ray"] is None, em["rays"]["primary"]
assert em["rays"]["primary"]["closest_mrays_1t"] > 0
assert j["embree_robust"] is False
print("embree ratios ok")'
  # --embree-robust: Embree's watertight counterpart, said so in the JSON and the text.
  "$accelviz" -q bench 'builtin:soup?size=2000' --structure bvh,embree --embree-robust --rays shadow --size 16x16 \
    --repeat 1 --json | python3 -c '
import json, sys
j = json.load(sys.stdin)
assert j["embree_robust"] is True, j.get("embree_robust")
assert j["ratios_vs_embree"]["bvh"]["shadow"]["any_mrays_1t"] > 0
print("embree robust ok")'
  "$accelviz" -q bench 'builtin:soup?size=2000' --structure embree --embree-robust --rays primary --size 8x8 \
    --repeat 1 >"$tmp/robust.txt"
  grep -q "Embree robust" "$tmp/robust.txt" || { echo "FAIL: text output does not say Embree robust"; exit 1; }
  # --embree-isa: Embree pinned to one instruction set (SSE2: every x86-64 CPU has it), said so in the
  # JSON and the text (tests/core/test_embree.cpp checks its hits).
  "$accelviz" -q bench 'builtin:soup?size=2000' --structure bvh,embree --embree-isa sse2 --rays primary \
    --size 8x8 --repeat 1 --json | python3 -c '
import json, sys
j = json.load(sys.stdin)
assert j["embree_isa"] == "sse2", j.get("embree_isa")
assert j["ratios_vs_embree"]["bvh"]["primary"]["closest_mrays_1t"] > 0
print("embree isa ok")'
  "$accelviz" -q bench 'builtin:soup?size=2000' --structure embree --embree-isa sse2 --rays primary --size 8x8 \
    --repeat 1 >"$tmp/isa.txt"
  grep -q "its sse2 kernels" "$tmp/isa.txt" || { echo "FAIL: text output does not name the ISA"; exit 1; }
  "$accelviz" -q bench 'builtin:soup?size=2000' --structure embree --rays primary --size 8x8 --repeat 1 --json |
    python3 -c 'import json, sys; assert json.load(sys.stdin)["embree_isa"] == "auto"'
  if "$accelviz" -q bench 'builtin:soup?size=2000' --structure embree --embree-isa avx3 --rays primary \
    --size 8x8 --repeat 1 2>"$tmp/isa_err.txt"; then
    echo "FAIL: --embree-isa avx3 accepted"; exit 1
  fi
  [ "$(wc -l <"$tmp/isa_err.txt")" -le 2 ] && grep -q "embree-isa" "$tmp/isa_err.txt" ||
    { echo "FAIL: --embree-isa avx3: $(cat "$tmp/isa_err.txt")"; exit 1; }
fi
# Each SAH cost says the constants it is under (the K-D tree's C_isect is 1.5 by default); none for the grid.
"$accelviz" -q bench 'builtin:soup?size=2000' --structure bvh,kdtree,octree,grid --rays primary --size 8x8 \
  --repeat 1 --json >"$tmp/sah.json"
python3 -c '
import json, sys
s = {x["name"]: x["build"] for x in json.load(open(sys.argv[1]))["structures"]}
assert s["bvh"]["sah_constants"] == {"c_trav": 1, "c_isect": 1}, s["bvh"]
assert s["kdtree"]["sah_constants"] == {"c_trav": 1, "c_isect": 1.5}, s["kdtree"]
assert s["octree"]["sah_constants"] == {"c_trav": 1, "c_isect": 1}, s["octree"]
assert "sah_constants" not in s["grid"] and s["grid"]["sah_cost"] is None, s["grid"]
print("bench sah constants ok")' "$tmp/sah.json"
"$accelviz" -q bench 'builtin:soup?size=2000' --structure kdtree --rays primary --size 8x8 --repeat 1 |
  grep -q ', SAH [0-9.]* (C_trav 1, C_isect 1.5),' || { echo "FAIL: no SAH constants in the text"; exit 1; }
# A slow structure's rate keeps its digits (a grid on the stadium read "0.00" Mrays/s).
row=$("$accelviz" -q bench 'builtin:teapot-stadium?size=30000&ratio=1000' -s grid --rays primary --size 8x6 \
  --repeat 1 -j 1 | grep '^  primary  *0')
python3 -c '
import sys
tokens = sys.argv[1].split()[1:5]
assert all(float(x) > 0 for x in tokens), sys.argv[1]
assert all(float(x) >= 0.1 or len(x.replace(".", "").lstrip("0")) >= 2 for x in tokens), sys.argv[1]
print("bench slow rates ok")' "$row"

# A scene whose only light gives no light (intensity 0): no shadow ray aims at it; the shadow set aims
# at the synthetic stand-in and says so, as for a scene without lights.
python3 - "$tmp/dark.gltf" <<'PY'
import base64, json, struct, sys
pos = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
doc = {"asset": {"version": "2.0"}, "extensionsUsed": ["KHR_lights_punctual"],
       "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 0}]}},
       "buffers": [{"byteLength": len(pos), "uri": "data:application/octet-stream;base64," + base64.b64encode(pos).decode()}],
       "bufferViews": [{"buffer": 0, "byteLength": len(pos)}],
       "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}],
       "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
       "nodes": [{"mesh": 0}, {"translation": [0.2, 0.2, 3], "extensions": {"KHR_lights_punctual": {"light": 0}}}],
       "scenes": [{"nodes": [0, 1]}], "scene": 0}
open(sys.argv[1], "w").write(json.dumps(doc))
PY
"$accelviz" bench "$tmp/dark.gltf" -s bvh --rays shadow --size 8x8 --repeat 1 --json 2>"$tmp/dark.err" |
  python3 -c 'import json, sys; s = json.load(sys.stdin)["ray_sets"]["shadow"]; assert s["synthetic_light"] is True, s'
grep -q "has no lights that give light (intensity or colour 0): shadow rays aim at a synthetic point light" "$tmp/dark.err" ||
  { echo "FAIL: the stand-in light is not said: $(cat "$tmp/dark.err")"; exit 1; }
"$accelviz" -q info "$tmp/dark.gltf" | grep -q "shadow-rays *off .*none gives light" ||
  { echo "FAIL: info: $("$accelviz" -q info "$tmp/dark.gltf" | grep shadow)"; exit 1; }
echo "dark light ok"
# The voxels test no triangles: their prims per ray are null, their nodes counted.
"$accelviz" -q bench 'builtin:teapot?size=300' -s voxels --rays primary --size 8x8 --repeat 1 --json |
  python3 -c 'import json, sys; q = json.load(sys.stdin)["structures"][0]["rays"]["primary"]; assert q["closest_prims_per_ray"] is None and q["any_prims_per_ray"] is None and q["closest_nodes_per_ray"] > 0, q'
echo "voxels prims null ok"
