#!/usr/bin/env bash
# Differential test at scale: `accelviz verify` over several small procedural
# scenes on every structure, at least 1,000,000 rays in all (Release). Each
# scene must print "-> OK". ACCELVIZ_VERIFY_SCALE (default 1) scales the ray
# counts down for slow builds (the AddressSanitizer run uses 0.05).
set -euo pipefail
accelviz="$(realpath "$1")"
scale="${ACCELVIZ_VERIFY_SCALE:-1}"

scenes=(
  'builtin:soup?size=1000&seed=1'
  'builtin:teapot?size=1500'
  'builtin:teapot-stadium?size=1500&seed=2'
  'builtin:walls-rotated?size=1000&seed=3'
  'builtin:grass?size=1500&seed=4'
  'builtin:same-centroid?size=500'
  'builtin:flat-wall?size=800'
)
per_scene=143000   # 7 x 143,000 = 1,001,000 rays
n=$(python3 -c "import sys; print(max(1000, int($per_scene * float(sys.argv[1]))))" "$scale")

total=0
fail=0
for s in "${scenes[@]}"; do
  start=$(date +%s.%N)
  out=$("$accelviz" --quiet verify "$s" --rays "$n" --structure all --seed 11 2>&1) || true
  end=$(date +%s.%N)
  echo "$out"
  printf '  (%.1f s)\n' "$(echo "$end - $start" | bc)"
  if ! grep -Eq "^verify: .* rays=$n structures=[0-9]+ .* -> OK$" <<<"$out"; then
    echo "FAIL: $s"
    fail=1
  fi
  total=$((total + n))
done
echo "total rays per structure: $total"
if [ "$scale" = "1" ] && [ "$total" -lt 1000000 ]; then echo "FAIL: fewer than 1,000,000 rays"; exit 1; fi
exit $fail
