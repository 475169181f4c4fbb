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
