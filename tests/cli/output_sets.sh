#!/usr/bin/env bash
# Nothing the user made is lost when a write fails part-way: sweep's and
# refit's DIR, render -s a,b's images and --compare's trio are written all or
# nothing (a write that fails here: a file-size limit, as a full disk would);
# --force replaces only the names the command writes; a replaced file keeps
# its permission bits; a name the file system takes is written, one it does
# not is refused before the work.
set -euo pipefail
bin="$1"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# limited KIB ARGS...: accelviz with writes past KIB KiB in one file failing (EFBIG, not the signal).
limited() {
  local kib="$1"
  shift
  (
    trap '' XFSZ
    ulimit -f "$kib"
    exec "$bin" -q "$@"
  )
}
# listing DIR: every file's name and checksum (the folder's state).
listing() { (cd "$1" && find . -type f -print0 | sort -z | xargs -0 -r sha256sum) }

# ---- sweep: a write fails midway (the charts are larger than the limit) ----
sw=(sweep 'builtin:soup?size=200' --size 8x8 --repeat 1 --threads 1)
out="$tmp/sweep"
"$bin" -q "${sw[@]}" --param buckets=2,4 --out "$out" > /dev/null
echo "my notes" > "$out/sweep-mynotes.png"
before="$(listing "$out")"
limited 8 "${sw[@]}" --param leaf=1,4 --out "$out" --force > "$tmp/stdout" 2> "$tmp/stderr" &&
  fail "sweep wrote past the file-size limit"
[ "$before" = "$(listing "$out")" ] ||
  fail "a failed --force sweep changed DIR: $(diff <(echo "$before") <(listing "$out"))"
[ -z "$(ls -A "$out" | grep -v -e '^sweep' || true)" ] || fail "temporaries left: $(ls -A "$out")"
grep -q "File too large" "$tmp/stderr" || fail "the failure is not said: $(cat "$tmp/stderr")"
# Without --force, into a fresh DIR: nothing is left, not even the folder.
limited 8 "${sw[@]}" --param leaf=1,4 --out "$tmp/fresh/sweep" > /dev/null 2>&1 &&
  fail "sweep wrote past the file-size limit"
[ ! -e "$tmp/fresh" ] || fail "a failed sweep left $(find "$tmp/fresh")"
# --force replaces the names sweep writes, never a user's own sweep-*.png; the earlier run's charts that
# this one does not write (vs-buckets) are removed once the new set is in place.
"$bin" -q "${sw[@]}" --param leaf=1,4 --out "$out" --force > /dev/null
[ "$(cat "$out/sweep-mynotes.png")" = "my notes" ] || fail "--force removed or changed the user's sweep-mynotes.png"
[ -s "$out/sweep-sah_cost-vs-leaf.png" ] || fail "the new charts are missing"
[ ! -e "$out/sweep-sah_cost-vs-buckets.png" ] || fail "the earlier run's stale chart is left"
# A user's own sweep-*.png alone does not make DIR "hold sweep files".
mkdir "$tmp/notes" && echo mine > "$tmp/notes/sweep-mynotes.png"
"$bin" -q "${sw[@]}" --param leaf=1 --out "$tmp/notes" > /dev/null || fail "a user's sweep-mynotes.png refused DIR"

# ---- refit: the same ----
rf=(refit 'builtin:soup?size=200' --frames 3 --size 8x8 --threads 1)
out="$tmp/refit"
"$bin" -q "${rf[@]}" --out "$out" > /dev/null
echo "mine" > "$out/refit-mine.png"
before="$(listing "$out")"
limited 4 "${rf[@]}" --seed 2 --out "$out" --force > /dev/null 2>&1 && fail "refit wrote past the file-size limit"
[ "$before" = "$(listing "$out")" ] || fail "a failed --force refit changed DIR"
[ "$(ls -A "$out" | wc -l)" -eq 6 ] || fail "temporaries left: $(ls -A "$out")"
"$bin" -q "${rf[@]}" --seed 2 --out "$out" --force > /dev/null
[ "$(cat "$out/refit-mine.png")" = mine ] || fail "--force removed the user's refit-mine.png"

# ---- render -s a,b and --compare: all or nothing, paths printed after ----
# A limit between two images' sizes: the first written fits, the next does not. The sizes come from a
# probe run of the same images; where they do not allow it, the check cannot be made here.
# first_fits_kib FIRST OTHERS...: the KiB FIRST needs when one of OTHERS needs more, else 0.
first_fits_kib() {
  local first="$1" kib
  shift
  kib=$((($(stat -c %s "$first") + 1023) / 1024))
  for f in "$@"; do
    [ "$(stat -c %s "$f")" -gt $((kib * 1024)) ] && { echo "$kib"; return; }
  done
  echo 0
}
# failed_set_leaves WHAT DIR N KIB ARGS...: accelviz ARGS -f under a KIB KiB limit fails, and leaves
# DIR's N files as they were, no temporary, and no path printed.
failed_set_leaves() {
  local what="$1" dir="$2" n="$3" kib="$4" before
  shift 4
  before="$(listing "$dir")"
  limited "$kib" "$@" -f > "$tmp/stdout" 2> "$tmp/stderr" && fail "$what wrote past the file-size limit"
  [ "$before" = "$(listing "$dir")" ] || fail "a failed $what left a mixed set"
  [ ! -s "$tmp/stdout" ] || fail "a failed $what printed paths: $(cat "$tmp/stdout")"
  [ "$(ls -A "$dir" | wc -l)" -eq "$n" ] || fail "temporaries left: $(ls -A "$dir")"
}
# Brute force's image is one colour (every ray tests every triangle): a small PNG beside the BVH's.
r=(render 'builtin:teapot?size=150' --size 160x120 -m prims --caption none --threads 1)
mkdir "$tmp/probe" "$tmp/several"
"$bin" -q "${r[@]}" -s brute,bvh --colormap inferno -o "$tmp/probe/T.png" > "$tmp/stdout"
[ "$(wc -l < "$tmp/stdout")" -eq 3 ] || fail "render -s brute,bvh printed: $(cat "$tmp/stdout")"
pair=(brute bvh)
if [ "$(stat -c %s "$tmp/probe/T-brute.png")" -gt "$(stat -c %s "$tmp/probe/T-bvh.png")" ]; then pair=(bvh brute); fi
kib=$(first_fits_kib "$tmp/probe/T-${pair[0]}.png" "$tmp/probe/T-${pair[1]}.png")
if [ "$kib" -gt 0 ]; then
  "$bin" -q "${r[@]}" -s brute,bvh -o "$tmp/several/T.png" > /dev/null
  failed_set_leaves "render -s ${pair[0]},${pair[1]}" "$tmp/several" 2 "$kib" \
    "${r[@]}" -s "${pair[0]},${pair[1]}" --colormap inferno -o "$tmp/several/T.png"
else
  echo "skip: render -s: the two images' sizes round to the same KiB"
fi

mkdir "$tmp/cmp"
"$bin" -q "${r[@]}" -s brute --compare structure=bvh --colormap inferno -o "$tmp/probe/C.png" > /dev/null
kib=$(first_fits_kib "$tmp/probe/C-a.png" "$tmp/probe/C-b.png" "$tmp/probe/C-diff.png")
if [ "$kib" -gt 0 ]; then
  "$bin" -q "${r[@]}" -s brute --compare structure=bvh -o "$tmp/cmp/C.png" > /dev/null
  failed_set_leaves "render --compare" "$tmp/cmp" 3 "$kib" \
    "${r[@]}" -s brute --compare structure=bvh --colormap inferno -o "$tmp/cmp/C.png"
else
  echo "skip: render --compare: image A is not smaller than B or the difference"
fi

# ---- a replaced file keeps its permission bits ----
"$bin" -q "${r[@]}" -o "$tmp/private.png" > /dev/null
chmod 600 "$tmp/private.png"
"$bin" -q "${r[@]}" --colormap inferno -o "$tmp/private.png" -f > /dev/null
[ "$(stat -c %a "$tmp/private.png")" = 600 ] || fail "a 0600 file replaced became $(stat -c %a "$tmp/private.png")"

# ---- names near and past the file system's limit (255 bytes here) ----
long="$(printf 'n%.0s' $(seq 246)).png"  # 250 bytes: the temporary's name was longer than 255
"$bin" -q "${r[@]}" -o "$tmp/$long" > /dev/null 2> "$tmp/stderr" || fail "a 250-byte name failed: $(cat "$tmp/stderr")"
[ -s "$tmp/$long" ] || fail "the 250-byte name was not written"
toolong="$(printf 'n%.0s' $(seq 296)).png"
rc=0
"$bin" -q render 'builtin:soup?size=20' --size 8x8 -o "$tmp/$toolong" > /dev/null 2> "$tmp/stderr" || rc=$?
[ "$rc" -eq 1 ] || fail "a 300-byte name: exit $rc"
grep -q "a name in it is 300 bytes long; the file system takes at most 255" "$tmp/stderr" ||
  fail "a 300-byte name: $(cat "$tmp/stderr")"
rc=0
"$bin" -q sweep 'builtin:soup?size=20' --param leaf=1 --out "$tmp/$toolong" > /dev/null 2> "$tmp/stderr" || rc=$?
[ "$rc" -eq 1 ] && grep -q "the file system takes at most 255" "$tmp/stderr" ||
  fail "sweep into a 300-byte folder name: exit $rc: $(cat "$tmp/stderr")"
echo "output_sets: ok"
