#!/usr/bin/env bash
# `accelviz robustness`: the table and the JSON line parse, the robust variant
# (watertight + padded slab) leaves no hole on a closed scene while the
# counts of every variant add up, and bad arguments are one-line usage errors.
set -euo pipefail
accelviz="$(realpath "$1")"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

scene='builtin:teapot?size=2000'

out=$("$accelviz" --quiet robustness "$scene" --rays 4000 --structure kdtree)
echo "$out"
grep -Eq '^robustness: builtin:teapot\?size=2000 triangles=[0-9]+ rays=4000 \(vertex 1000, edge 1000, axis 1000, grazing 1000\) reference_hits=[0-9]+$' <<<"$out"
for v in 'moller-trumbore \+ plain slab' 'moller-trumbore \+ padded slab' 'watertight \+ plain slab' \
         'watertight \+ padded slab' 'kdtree \(moller-trumbore\)' 'kdtree \(watertight\)'; do
  grep -Eq "^$v +[0-9]+ +[0-9]+ +[0-9]+ +[0-9.]+ +[0-9.]+$" <<<"$out" || { echo "missing row: $v" >&2; exit 1; }
done

"$accelviz" --quiet robustness "$scene" --rays 4000 --json >"$tmp/lab.json"
python3 - "$tmp/lab.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
assert j["rays"] == 4000 and sum(j["rays_by_family"].values()) == 4000, j
names = [v["name"] for v in j["variants"]]
assert names == ["moller-trumbore + plain slab", "moller-trumbore + padded slab",
                 "watertight + plain slab", "watertight + padded slab"], names
for v in j["variants"]:
    assert sum(v["misses_by_family"].values()) == v["misses"], v
    assert sum(v["double_hits_by_family"].values()) == v["double_hits"], v
    assert v["ms"] > 0 and v["mrays_per_s"] > 0, v
robust = j["variants"][3]
assert robust["misses"] == 0 and robust["wrong"] == 0, robust
fast = j["variants"][1]
assert fast["misses"] + fast["double_hits"] > robust["misses"] + robust["double_hits"], (fast, robust)
print("json ok:", {v["name"]: (v["misses"], v["double_hits"], v["wrong"]) for v in j["variants"]})
PY

# -s embree: Embree ignores our triangle test, so its rows are its own two
# modes, named so in the text and the JSON, with no double-hit count.
if [[ "$("$accelviz" render --help)" == *",tlas,embree}"* ]]; then  # a build with Embree
  out=$("$accelviz" --quiet robustness "$scene" --rays 400 -j 1 --structure embree)
  echo "$out"
  for v in 'embree \(default mode\)' 'embree \(robust mode\)'; do
    grep -Eq "^$v +[0-9]+ +n/a +[0-9]+ +[0-9.]+ +[0-9.]+$" <<<"$out" || { echo "missing row: $v" >&2; exit 1; }
  done
  ! grep -q 'embree (watertight)\|embree (moller-trumbore)' <<<"$out" || { echo "Embree rows named after our tests" >&2; exit 1; }
  "$accelviz" --quiet robustness "$scene" --rays 400 -j 1 --structure embree --json | python3 -c '
import json, sys
j = json.load(sys.stdin)
rows = {v["name"]: v for v in j["variants"]}
for mode in ("default", "robust"):
    v = rows["embree (%s mode)" % mode]
    assert v["triangle_test"] == "embree-" + mode and v["embree_mode"] == mode, v
    assert v["double_hits"] is None and v["slab"] == "structure", v
assert rows["watertight + padded slab"]["embree_mode"] is None
print("embree rows ok")'
fi

# Usage errors: exit 2, the first line names the parameter (CLI11 adds a
# "Run with --help" line to range errors).
for args in "--structure voxels" "--structure nope" "--rays 2"; do
  set +e
  err=$("$accelviz" --quiet robustness "$scene" $args 2>&1 >/dev/null)
  rc=$?
  set -e
  [ "$rc" = 2 ] || { echo "robustness $args: exit $rc, expected 2" >&2; exit 1; }
  first=$(head -n 1 <<<"$err")
  param=${args%% *}
  grep -q -- "$param" <<<"$first" || { echo "robustness $args: first line does not name $param: $err" >&2; exit 1; }
done
echo "cli.robustness: OK"
