#!/usr/bin/env bash
# The committed example scenes in assets/ are exactly what assets/generate.sh
# writes with this build (regenerate them after changing a generator or the
# glTF writer), and each loads with the triangle count of its generator.
set -euo pipefail
accelviz="$(realpath "$1")"
src="$2"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

bash "$src/assets/generate.sh" "$accelviz" "$tmp"
n=0
for f in "$tmp"/*.glb; do
  name=$(basename "$f")
  committed="$src/assets/$name"
  [ -f "$committed" ] || { echo "FAIL: $name is generated but not committed in assets/"; exit 1; }
  cmp -s "$f" "$committed" || { echo "FAIL: assets/$name differs from what assets/generate.sh writes (run it)"; exit 1; }
  spec=$(grep "^$name|" "$src/assets/generate.sh" | cut -d'|' -f2)
  want=$("$accelviz" info "$spec" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["triangles"])')
  got=$("$accelviz" info "$committed" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["triangles"])')
  [ "$want" = "$got" ] || { echo "FAIL: $name has $got triangles, its generator $want"; exit 1; }
  n=$((n + 1))
done
for f in "$src"/assets/*.glb; do
  [ -f "$tmp/$(basename "$f")" ] || { echo "FAIL: assets/$(basename "$f") is not made by generate.sh"; exit 1; }
done
[ "$n" -ge 5 ] || { echo "FAIL: only $n assets"; exit 1; }

# export's result line is a result: on stdout under -q too.
out=$("$accelviz" -q export 'builtin:teapot?size=800' "$tmp/small.glb")
grep -q "^wrote $tmp/small.glb: 992 triangles, 1 mesh, 1 instance, 1 light, 1 camera$" <<<"$out" || {
  echo "FAIL: export's line: $out"; exit 1
}
# Animations are not written, and the line says so (they were dropped without a word).
out=$("$accelviz" -q export 'builtin:dynamic?size=2000' "$tmp/dynamic.glb")
grep -q "; not written: 1 animation (the nodes at rest)$" <<<"$out" || { echo "FAIL: export's line: $out"; exit 1; }

# export refuses to overwrite, and names the file.
if "$accelviz" -q export builtin:teapot "$tmp/teapot.glb" 2>"$tmp/err"; then
  echo "FAIL: export overwrote an existing file"; exit 1
fi
grep -q "teapot.glb: exists" "$tmp/err" || { echo "FAIL: message"; cat "$tmp/err"; exit 1; }
if "$accelviz" -q export builtin:teapot "$tmp/teapot.png" 2>"$tmp/err"; then
  echo "FAIL: export accepted .png"; exit 1
fi
echo "assets ok ($n scenes)"
