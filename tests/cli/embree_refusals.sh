#!/usr/bin/env bash
# Embree refuses scenes with a vertex beyond ±1.844e18 and rays it cannot take
# (origins beyond that bound, directions without a component of 1e-15):
# verify, bench and robustness report the refusal on its own line and still
# check or measure everything else. With the default structures (verify's
# all, bench's bvh,embree) a refusal is no failure (exit 0); a structure named
# in --structure that refuses makes the run exit 1, after its report.
set -uo pipefail
accelviz="$(realpath "$1")"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
fail=0

if [[ "$("$accelviz" render --help)" != *",tlas,embree}"* ]]; then
  echo "cli.embree_refusals: no Embree in this build, skipped"
  exit 0
fi

# A closed cube of 4x4 quads per face, [-S, S]^3.
cube() {
  python3 - "$1" >"$2" <<'PY'
import sys
s = float(sys.argv[1]); n = 4; ids = {}; vs = []; fs = []
def vid(p):
    if p not in ids: ids[p] = len(vs) + 1; vs.append(p)
    return ids[p]
for a in range(3):
    u, w = [k for k in range(3) if k != a]
    for side in (-1, 1):
        for i in range(n):
            for j in range(n):
                q = []
                for di, dj in ((0, 0), (1, 0), (1, 1), (0, 1)):
                    p = [0, 0, 0]; p[a] = side; p[u] = -1 + 2 * (i + di) / n; p[w] = -1 + 2 * (j + dj) / n
                    q.append(vid(tuple(p)))
                fs += [(q[0], q[1], q[2]), (q[0], q[2], q[3])]
print("\n".join("v %r %r %r" % tuple(c * s for c in p) for p in vs))
print("\n".join("f %d %d %d" % f for f in fs))
PY
}
cube 1e-20 "$tmp/tiny.obj"
cube 1e18 "$tmp/big.obj"
cube 2e18 "$tmp/huge.obj"

# check CODE PATTERN -- ARGS: exit CODE, stdout has a line matching the extended regex PATTERN.
check() {
  local code="$1" pattern="$2"
  shift 3
  "$accelviz" -q "$@" >"$tmp/out" 2>"$tmp/err"
  local rc=$?
  if [ "$rc" -ne "$code" ]; then
    echo "FAIL ($*): exit $rc, expected $code"; cat "$tmp/out" "$tmp/err"; fail=1; return
  fi
  if ! grep -Eq -- "$pattern" "$tmp/out"; then
    echo "FAIL ($*): stdout lacks /$pattern/"; cat "$tmp/out" "$tmp/err"; fail=1; return
  fi
  echo "ok ($*): exit $rc"
}

# verify: the other structures are checked and reported; Embree on the rays it
# takes. The tiny cube's rays are made at its scale: Embree takes none of them
# (directions of ~1e-20), so it is not among the structures checked.
check 0 '^verify: .*tiny.obj rays=3000 structures=8 mismatched_prim=0 t_beyond_tolerance=0 anyhit_disagree=0 .* -> OK$' \
  -- verify "$tmp/tiny.obj" --rays 3000 -j 1
grep -Eq '^embree: 3000 of 3000 rays not checked \(the first, ray [0-9]+: cannot trace a ray whose direction .*no component of 1e-15' "$tmp/out" ||
  { echo "FAIL: no line for the rays Embree refused"; cat "$tmp/out"; fail=1; }
check 1 '^embree: [0-9]+ of 3000 rays not checked \(the first, ray [0-9]+: cannot trace a ray whose origin' \
  -- verify "$tmp/big.obj" --rays 3000 -j 1 -s brute,embree
check 0 '^embree: not checked: 192 triangles .* beyond ±1.844e18.*own structures' -- verify "$tmp/huge.obj" --rays 2000 -j 1
grep -Eq '^verify: .* structures=8 mismatched_prim=0 t_beyond_tolerance=0 anyhit_disagree=0 .* -> OK$' "$tmp/out" ||
  { echo "FAIL: the other eight structures are not reported OK"; cat "$tmp/out"; fail=1; }
check 1 '^verify: .* structures=1 .* -> FAIL$' -- verify "$tmp/huge.obj" --rays 500 -j 1 -s brute,embree
"$accelviz" -q verify "$tmp/huge.obj" --rays 500 -j 1 --json >"$tmp/v.json"
python3 - "$tmp/v.json" <<'PY' || fail=1
import json, sys
j = json.load(open(sys.argv[1]))
assert j["ok"] is True and "embree" not in j["structures"], j
n = j["not_checked"]["embree"]
assert n["scene_refused"] is True and n["rays"] == 500 and "1.844e18" in n["reason"], n
assert all(s["rays"] == 500 for s in j["structures"].values()), j["structures"]
print("verify --json: not_checked ok")
PY

# bench: the default structures measure bvh and say what Embree refused.
check 0 '^  not measured: 192 triangles' -- bench "$tmp/huge.obj" -n 1 --size 16x12 -j 1 --rays primary
check 0 '^  primary +not measured: ray [0-9]+: cannot trace a ray whose origin' \
  -- bench "$tmp/big.obj" -n 1 --size 16x12 -j 1 --rays primary
grep -Eq '^  primary +[0-9.]+ +[0-9.]+ ' "$tmp/out" || { echo "FAIL: bvh's primary row is missing"; cat "$tmp/out"; fail=1; }
check 1 '^  primary +not measured' -- bench "$tmp/big.obj" -n 1 --size 16x12 -j 1 --rays primary -s bvh,embree

# robustness -s embree: the lab's variants, then Embree's refusal (exit 1: it was named).
check 1 '^embree: not checked: 192 triangles' -- robustness "$tmp/huge.obj" -n 400 -j 1 -s embree
grep -Eq '^watertight \+ padded slab +0 ' "$tmp/out" || { echo "FAIL: the lab's variants are missing"; cat "$tmp/out"; fail=1; }
check 1 '^embree: [0-9]+ of 400 rays not traced \(the first, ray [0-9]+: cannot trace a ray whose origin' \
  -- robustness "$tmp/big.obj" -n 400 -j 1 -s embree

[ "$fail" = 0 ] && echo "cli.embree_refusals: OK"
exit $fail
