#!/usr/bin/env bash
# accelviz info on built-in scenes: the triangle count the generator promises,
# in text and in JSON with every documented key.
set -euo pipefail
accelviz="$(realpath "$1")"

out=$("$accelviz" info 'builtin:soup?size=1234&seed=3')
echo "$out"
grep -Eq '^triangles +1234$' <<<"$out" || { echo "FAIL: expected 'triangles 1234'"; exit 1; }
grep -Eq '^bounds ' <<<"$out" || { echo "FAIL: no bounds line"; exit 1; }

json=$("$accelviz" info --json 'builtin:duplicates?size=77')
python3 - "$json" <<'PY'
import json, sys
j = json.loads(sys.argv[1])
keys = ["scene", "triangles", "meshes", "instances", "nodes", "lights", "cameras", "animations",
        "has_instancing", "bounds", "dropped_nonfinite", "degenerate", "skipped_primitives", "warnings"]
missing = [k for k in keys if k not in j]
assert not missing, f"missing keys {missing}"
assert j["triangles"] == 77, j["triangles"]
assert isinstance(j["warnings"], list)
assert len(j["bounds"]["min"]) == 3 and len(j["bounds"]["max"]) == 3
print("info --json ok")
PY

# Instancing is reported.
"$accelviz" info --json 'builtin:forest?size=2000' | python3 -c '
import json, sys
j = json.load(sys.stdin)
assert j["has_instancing"] is True, j
print("forest instancing ok")'

# Instanced scenes: the world triangles with the unique ones they come from;
# an island too large to flatten reports its instanced count, not 0.
out=$("$accelviz" info builtin:island)
grep -Eq '^triangles +370530 \(from 100194 unique in 9 meshes\)$' <<<"$out" ||
  { echo "FAIL: island triangle line: $(grep '^triangles' <<<"$out")"; exit 1; }
out=$("$accelviz" info 'builtin:island?size=2000000&copies=560')
grep -Eq '^triangles +1005314592 instanced, not flattened \(1994560 unique in 9 meshes\)$' <<<"$out" ||
  { echo "FAIL: large island triangle line: $(grep '^triangles' <<<"$out")"; exit 1; }
"$accelviz" info --json 'builtin:island?size=2000000&copies=560' | python3 -c '
import json, sys
j = json.load(sys.stdin)
assert j["flattened"] is False and j["triangles"] == 0, j
assert j["instanced_triangles"] == 1005314592 and j["unique_triangles"] == 1994560, j
print("unflattened island counts ok")'
"$accelviz" info --json 'builtin:soup?size=1234' | python3 -c '
import json, sys
j = json.load(sys.stdin)
assert j["flattened"] is True and j["triangles"] == j["instanced_triangles"] == j["unique_triangles"] == 1234, j
print("soup counts ok")'
