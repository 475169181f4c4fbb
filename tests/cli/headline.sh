#!/usr/bin/env bash
# bench/headline.sh (docs/performance.md's headline table) on a tiny
# configuration: every run it documents is made, and table.md has one row per
# scene, pairing and thread count with positive ratios in each filled cell.
# Skipped (passes with a note) in a build without Embree.
set -euo pipefail
accelviz="$(realpath "$1")"
src="$2"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# Earlier results are never lost: an OUT_DIR that holds some is refused before the first run unless
# HEADLINE_FORCE=1 (`> "$out/$file"` emptied them as the run began), and a run that fails leaves the earlier
# result as it was (it was left empty). Neither needs Embree: the refusal comes first, the scene fails.
mkdir "$tmp/earlier"
echo mine > "$tmp/earlier/1-robust.json"
echo table > "$tmp/earlier/table.md"
rc=0
HEADLINE_MESHES='builtin:nosuchscene' HEADLINE_SOUP='' HEADLINE_THREADS=1 HEADLINE_REPEAT=1 \
  bash "$src/bench/headline.sh" "$accelviz" "$tmp/earlier" > /dev/null 2> "$tmp/stderr.txt" || rc=$?
[ "$rc" -eq 2 ] || fail "an OUT_DIR holding results: exit $rc, expected 2: $(cat "$tmp/stderr.txt")"
grep -q "already holds results.*HEADLINE_FORCE=1" "$tmp/stderr.txt" || fail "the refusal says: $(cat "$tmp/stderr.txt")"
[ "$(cat "$tmp/earlier/1-robust.json")" = mine ] || fail "a refused run changed an earlier result"
rc=0
HEADLINE_FORCE=1 HEADLINE_MESHES='builtin:nosuchscene' HEADLINE_SOUP='' HEADLINE_THREADS=1 HEADLINE_REPEAT=1 \
  bash "$src/bench/headline.sh" "$accelviz" "$tmp/earlier" > /dev/null 2> "$tmp/stderr.txt" || rc=$?
[ "$rc" -ne 0 ] || fail "a failed bench run did not fail the script"
[ "$(cat "$tmp/earlier/1-robust.json")" = mine ] || fail "a failed run cost the earlier result"
[ "$(cat "$tmp/earlier/table.md")" = table ] || fail "a failed run cost the earlier table"
[ "$(ls -A "$tmp/earlier" | wc -l)" -eq 2 ] || fail "a failed run left files behind: $(ls -A "$tmp/earlier")"

"$accelviz" bench --help > "$tmp/help.txt"
if ! grep -q embree-medium "$tmp/help.txt"; then
  echo "headline: built without Embree, nothing to compare"
  exit 0
fi
HEADLINE_MESHES='builtin:teapot?size=800' HEADLINE_SOUP='builtin:soup?size=2000' HEADLINE_THREADS='1 2' \
  HEADLINE_REPEAT=1 HEADLINE_SIZE=160x120 bash "$src/bench/headline.sh" "$accelviz" "$tmp/out" > "$tmp/stdout.md" \
  2> "$tmp/stderr.txt"
cmp -s "$tmp/stdout.md" "$tmp/out/table.md" || fail "the table printed is not table.md"
[ "$(ls "$tmp/out"/*.json | wc -l)" -eq 10 ] || fail "expected 10 bench runs: $(ls "$tmp/out")"
[ "$(ls -A "$tmp/out" | wc -l)" -eq 11 ] || fail "expected the runs and table.md only: $(ls -A "$tmp/out")"
[ "$(stat -c %a "$tmp/out/table.md")" = "$(printf '%o' $((0666 & ~0$(umask))))" ] ||
  fail "table.md has mode $(stat -c %a "$tmp/out/table.md"), not the umask's"
grep -q -- "--embree-robust" "$tmp/stderr.txt" || fail "the commands are not echoed"
# HEADLINE_SIZE is the meshes' image: 160x120 primary rays (the soup keeps its 64x48).
python3 - "$tmp/out" <<'PY'
import glob, json, os, sys
for f in sorted(glob.glob(os.path.join(sys.argv[1], "*.json"))):
    j = json.load(open(f))
    want = 64 * 48 if j["scene"].startswith("builtin:soup") else 160 * 120
    assert j["ray_sets"]["primary"]["rays"] == want, (f, j["scene"], j["ray_sets"]["primary"])
PY
python3 - "$tmp/out/table.md" <<'PY'
import sys
lines = open(sys.argv[1]).read().splitlines()
assert lines[0].startswith("| scene | mode | threads | build"), lines[0]
rows = [l.strip("|").split("|") for l in lines[2:]]
assert len(rows) == 10, len(rows)
want = {("builtin:teapot?size=800", m, t) for m in ("watertight vs robust", "fast vs default") for t in ("1", "2")}
want |= {("builtin:soup?size=2000", m, t)
         for m in ("watertight vs robust", "fast vs default", "watertight vs default") for t in ("1", "2")}
got = {(r[0].strip(), r[1].strip(), r[2].strip()) for r in rows}
assert got == want, got ^ want
for r in rows:
    cells = [c.strip() for c in r[3:]]
    is_soup = r[0].strip().startswith("builtin:soup")
    assert len(cells) == 6, r
    for i, c in enumerate(cells):
        if is_soup and i >= 4:
            assert c == "", (r, "the soup traces primary rays only")
            continue
        for x in c.split(" / "):
            assert float(x) > 0, (r, c)
PY
echo "headline: ok"
