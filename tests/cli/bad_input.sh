#!/usr/bin/env bash
# Bad files and bad arguments: a one-line message on stderr that names the
# file or the problem, exit 1 (runtime) or 2 (usage), never a crash.
set -uo pipefail
accelviz="$(realpath "$1")"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0

# expect CODE NEEDLE -- ARGS...: runs accelviz, checks exit code, one stderr line containing NEEDLE.
expect() {
  local code="$1" needle="$2"
  shift 3
  "$accelviz" -q "$@" >"$tmp/stdout" 2>"$tmp/stderr"
  local rc=$?
  local lines
  lines=$(wc -l <"$tmp/stderr")
  if [ "$rc" -ne "$code" ]; then
    echo "FAIL ($*): exit $rc, expected $code"; cat "$tmp/stderr"; fail=1; return
  fi
  if [ "$code" -eq 1 ] && [ "$lines" -ne 1 ]; then
    echo "FAIL ($*): $lines stderr lines, expected 1"; cat "$tmp/stderr"; fail=1; return
  fi
  if ! grep -qF -- "$needle" "$tmp/stderr"; then
    echo "FAIL ($*): stderr lacks '$needle'"; cat "$tmp/stderr"; fail=1; return
  fi
  echo "ok ($*): exit $rc: $(head -n 1 "$tmp/stderr")"
}

# Missing, unsupported and malformed scene files.
expect 1 "$tmp/none.glb: no such file" -- info "$tmp/none.glb"
ln -s "$tmp/loop.glb" "$tmp/loop.glb"  # a link to itself: it said "no such file"
expect 1 "$tmp/loop.glb: cannot be read: Too many levels of symbolic links" -- info "$tmp/loop.glb"
# A control byte in a file name is shown as '?', not sent to the terminal (an ESC recoloured it).
expect 1 "bad?[31mname.gltf" -- info "$tmp/bad"$'\x1b'"[31mname.gltf"
if grep -q $'\x1b' "$tmp/stderr"; then echo "FAIL: an ESC reached stderr"; fail=1; fi
echo "hello" >"$tmp/scene.txt"
expect 1 "$tmp/scene.txt" -- info "$tmp/scene.txt"
head -c 100 /dev/urandom >"$tmp/garbage.glb"
expect 1 "$tmp/garbage.glb" -- info "$tmp/garbage.glb"
printf '{"asset": {"version": "2.0"}, "meshes": [{"primitives": [{"attributes": {"POSITION": 5}}]}]}' >"$tmp/bad.gltf"
expect 1 "$tmp/bad.gltf" -- render "$tmp/bad.gltf" --out "$tmp/x.png"
expect 1 "builtin:nosuchscene" -- info builtin:nosuchscene
[ -e "$tmp/x.png" ] && { echo "FAIL: a PNG was written for a bad scene"; fail=1; }

# Malformed ray files name the file.
printf 'RAYS' >"$tmp/short.rays"
expect 1 "$tmp/short.rays" -- trace 'builtin:soup?size=10' --rays "$tmp/short.rays" --out "$tmp/o.hits"
python3 -c "import struct,sys; open(sys.argv[1],'wb').write(b'RAYS'+struct.pack('<IQ',1,1000)+bytes(32))" "$tmp/count.rays"
expect 1 "$tmp/count.rays" -- trace 'builtin:soup?size=10' --rays "$tmp/count.rays" --out "$tmp/o.hits"
python3 -c "import struct,sys; open(sys.argv[1],'wb').write(b'RAYS'+struct.pack('<IQ',1,1)+struct.pack('<8f',0,0,0,0,0,0,0,1))" "$tmp/zero.rays"
expect 1 "zero direction" -- trace 'builtin:soup?size=10' --rays "$tmp/zero.rays" --out "$tmp/o.hits"
python3 -c "import struct,sys; open(sys.argv[1],'wb').write(b'HITS'+struct.pack('<IQ',1,0))" "$tmp/wrong.rays"
expect 1 "$tmp/wrong.rays" -- trace 'builtin:soup?size=10' --rays "$tmp/wrong.rays" --out "$tmp/o.hits"
[ -e "$tmp/o.hits" ] && { echo "FAIL: a HITS file was written for bad rays"; fail=1; }

# Usage errors: exit 2.
expect 2 "--size" -- render 'builtin:soup?size=10' --out "$tmp/y.png" --size 0x10
expect 2 "--size" -- flatten 'builtin:forest?size=200' --instances 0 --size 0x3
expect 2 "--structure" -- render 'builtin:soup?size=10' --out "$tmp/y.png" --structure octopus
expect 2 "--threads: Value 100000 not in range 0 to 1024" -- bench 'builtin:soup?size=10' -s bvh -j 100000
expect 2 "--threads" -- render 'builtin:soup?size=10' --out "$tmp/y.png" -j 4294967295
# Floating-point options: NaN, infinity and overflow are refused, in words
# (CLI11's own checks let nan through and printed 0.000000 to 1797693...).
expect 2 "--ctrav: must be a number from 1e-06 to 1e+06, got nan" -- render 'builtin:soup?size=10' --out "$tmp/y.png" --ctrav nan
expect 2 "--cisect: must be a number from 1e-06 to 1e+06, got 1e308" -- render 'builtin:soup?size=10' --out "$tmp/y.png" --cisect 1e308
# animate --dt: 3e38 overflowed the frames' times (a transform of inf), 1e30 moved nothing.
expect 2 "--dt: must be a number from 1e-06 to 10000, got 3e38" -- animate 'builtin:dynamic?size=2000' --frames 3 --dt 3e38
# At most the GUI's 1e6: 3e38 overflowed the cost metric (a ray's cost read inf).
expect 2 "--ctrav: must be a number from 1e-06 to 1e+06, got 3e38" -- render 'builtin:soup?size=10' --out "$tmp/y.png" --ctrav 3e38 -m cost
expect 2 "--max nan: expected a number from 1.2e-38 to 3.4e38 (float's range), or pNN for a percentile (p99)" -- render 'builtin:soup?size=10' --out "$tmp/y.png" --max nan
expect 2 "--max 1e-300: expected a number from 1.2e-38" -- render 'builtin:soup?size=10' --out "$tmp/y.png" --max 1e-300
# Whole numbers in decimal only: CLI11 read 010 as octal (8) and -1 for a seed as 2^64 - 1.
expect 2 "--buckets: expected a whole number in decimal digits (no leading zero), got '010'" -- \
  render 'builtin:soup?size=10' --out "$tmp/y.png" --buckets 010
expect 2 "--seed: expected a whole number in decimal digits (no sign, no leading zero), got '-1'" -- \
  rays 'builtin:soup?size=10' -k diffuse --seed -1 --out "$tmp/y.rays"
expect 2 "--threads: expected a whole number in decimal digits (no sign, no leading zero), got '0x2'" -- \
  render 'builtin:soup?size=10' --out "$tmp/y.png" -j 0x2
# Beyond 64 bits: CLI11 clamped --seed 10^23 to 2^64 - 1 and ran.
expect 2 "--seed: '99999999999999999999999' is beyond a 64-bit whole number" -- \
  rays 'builtin:soup?size=10' -k diffuse --seed 99999999999999999999999 --out "$tmp/y.rays"
# Checked before the range: "abc" was answered "Value abc not in range".
expect 2 "--threads: expected a whole number in decimal digits (no sign, no leading zero), got 'abc'" -- \
  render 'builtin:soup?size=10' --out "$tmp/y.png" -j abc
expect 2 "--buckets: expected a whole number in decimal digits (no leading zero), got '09'" -- \
  render 'builtin:soup?size=10' --out "$tmp/y.png" --buckets 09
# SAH costs in one range everywhere (a sweep took 3e38 and built the wrong tree; --compare took 2e6).
expect 2 "--ctrav: must be a number from 1e-06 to 1e+06, got 1e-300" -- render 'builtin:soup?size=10' --out "$tmp/y.png" --ctrav 1e-300
expect 2 "--compare: ctrav=2e6: must be a number from 1e-06 to 1e+06" -- \
  render 'builtin:soup?size=10' --out "$tmp/y.png" --compare ctrav=2e6
expect 2 "--compare: buckets given twice" -- render 'builtin:soup?size=10' --out "$tmp/y.png" --compare 'buckets=4 buckets=8'
expect 2 "sweep parameter cisect: bad value '3e38' (must be a number from 1e-06 to 1e+06)" -- sweep 'builtin:soup?size=10' --param cisect=1,3e38 --out "$tmp/sw"
expect 2 "more than the 10000 one sweep takes" -- sweep 'builtin:soup?size=10' --param buckets=2,3,4,5,6,7,8,9,10,11 \
  --param leaf=1,2,3,4,5,6,7,8,9,10 --param ctrav=1,2,3,4,5,6,7,8,9,10 --param cisect=1,2,3,4,5,6,7,8,9,10,11 --out "$tmp/sw"
expect 2 "lambda and res together" -- sweep 'builtin:soup?size=10' -s grid --param lambda=1,2 --param res=4x4x4 --out "$tmp/sw"
[ ! -e "$tmp/sw" ] || { echo "FAIL: a refused sweep made its folder"; fail=1; }
# refit's motion within float's range (3e38 gave NaN SAH figures).
expect 2 "--amplitude must be a number from 0 to 1000" -- refit 'builtin:soup?size=10' --frames 1 --amplitude 3e38 --out "$tmp/rf"
printf 'v -1e37 0 0\nv 1e37 0 0\nv 0 1e37 0\nf 1 2 3\n' >"$tmp/big37.obj"
expect 1 "$tmp/big37.obj: --amplitude 1 would move vertices beyond float's range" -- \
  refit "$tmp/big37.obj" --frames 1 --amplitude 1 --out "$tmp/rf"
expect 2 "--max p0: a percentile is p followed by a number above 0 and at most 100" -- render 'builtin:soup?size=10' --out "$tmp/y.png" --max p0
expect 2 "--max p99: a percentile top is for the heatmap view" -- render 'builtin:soup?size=10' --out "$tmp/y.png" --max p99 --view raster
expect 2 "--blend: must be a number from 0 to 1, got nan" -- render 'builtin:soup?size=10' --out "$tmp/y.png" --view raster --blend nan
expect 2 "--structure: 'bvh' is listed twice" -- bench 'builtin:soup?size=10' -s bvh,bvh -n 1 --size 4x4
expect 2 "--ray-budget: must be a number from 1.2e-38 to 3.4e38 (float's range), got inf" -- sweep 'builtin:soup?size=10' -p leaf=2 --ray-budget inf --out "$tmp/swb"
expect 2 "--scene: an empty scene name" -- calibrate --scene ""
expect 2 "--metric" -- render 'builtin:soup?size=10' --out "$tmp/y.png" --metric colour
expect 2 "camera" -- render 'builtin:soup?size=10' --out "$tmp/y.png" --camera 1,2,3
expect 2 "eye and target lie too far apart" -- render 'builtin:soup?size=10' --out "$tmp/y.png" --camera 3e38,0,0,-3e38,0,0
expect 2 "eye and target are the same point" -- render 'builtin:soup?size=10' --out "$tmp/y.png" --camera 1,2,3,1,2,3
expect 2 "camera" -- render 'builtin:soup?size=10' --out "$tmp/y.png" --camera gltf:4
expect 2 "required" -- trace 'builtin:soup?size=10' --out "$tmp/z.hits"
expect 2 "nosuchcommand" -- nosuchcommand
expect 2 "--repeat" -- bench 'builtin:soup?size=10' --repeat 0
# refit builds BVHs only: Embree's options are not its options.
expect 2 "--embree-quality" -- refit 'builtin:soup?size=10' --embree-quality high --out "$tmp/refit"
expect 2 "--rebuild-ratio" -- refit 'builtin:soup?size=10' --rebuild-ratio 0.5 --out "$tmp/refit"
expect 2 "--frame-step" -- refit 'builtin:soup?size=10' --frame-step nan --out "$tmp/refit"
expect 2 "--amplitude" -- refit 'builtin:soup?size=10' --amplitude inf --out "$tmp/refit"
expect 2 "--rebuild-ratio" -- refit 'builtin:soup?size=10' --rebuild-ratio inf --out "$tmp/refit"
[ ! -e "$tmp/refit" ] || { echo "FAIL: refit wrote $tmp/refit on a usage error"; fail=1; }
expect 2 "--dt" -- animate 'builtin:dynamic?size=100' --frames 1 --dt nan
expect 2 "--rebuild-ratio" -- animate 'builtin:dynamic?size=100' --frames 1 --rebuild-ratio nan
expect 2 "--rebuild-ratio: must be a finite number >= 1 (or 0: always refit), got 0.5" -- animate 'builtin:dynamic?size=100' --frames 1 --rebuild-ratio 0.5
"$accelviz" -q animate 'builtin:dynamic?size=100' --frames 1 --rebuild-ratio 1 >/dev/null ||
  { echo "FAIL: animate --rebuild-ratio 1 refused (refit takes it)"; fail=1; }
# A scene too large to flatten holds no triangle list: the commands that measure one refuse it.
island='builtin:island?size=20000&copies=3000'
expect 1 "only 'tlas' can hold this scene" -- sweep "$island" --param buckets=2 --size 8x6 --repeat 1 --out "$tmp/sw"
expect 1 "only 'tlas' can hold this scene" -- refit "$island" --frames 1 --size 8x6 --out "$tmp/rf"
expect 1 "only 'tlas' can hold this scene" -- calibrate --scene "$island" --repeat 1 --size 8x6
# A run that fails leaves no output folder behind (it is made when the results are written).
[ ! -e "$tmp/sw" ] && [ ! -e "$tmp/rf" ] || { echo "FAIL: a failed run left an output folder"; fail=1; }

# A PNG under another format's name (or none): refused before any work, nothing written.
expect 2 "$tmp/heat.jpg: a PNG file's name must end in .png" -- render 'builtin:soup?size=10' --out "$tmp/heat.jpg"
expect 2 "$tmp/.png: a PNG file needs a name before .png" -- render 'builtin:soup?size=10' --out "$tmp/.png"
expect 2 "$tmp/heat: a PNG file's name must end in .png" -- render 'builtin:soup?size=10' --out "$tmp/heat" \
  --compare 'buckets=4'
for f in heat.jpg heat heat-a heat-b heat-diff; do
  [ ! -e "$tmp/$f" ] || { echo "FAIL: render wrote $tmp/$f under a name that is not .png"; fail=1; }
done

# Rays Embree's kernels cannot take (they abort on them): refused with one
# line, the ray file and the ray named, nothing written; a scene Embree's
# build would silently thin out is refused too.
help="$("$accelviz" render --help)"  # into a variable: `grep -q` on a pipe could end it early (pipefail)
if grep -q embree <<<"$help"; then
  python3 -c "import struct,sys; open(sys.argv[1],'wb').write(b'RAYS'+struct.pack('<IQ',1,2)+struct.pack('<8f',0,0,-5,0,0,0,1,9)+struct.pack('<8f',0,0,-5,-100,0,0,1,9))" "$tmp/negtmin.rays"
  # A negative tmin is refused by the ray file for every structure (they disagreed behind the origin).
  expect 1 "$tmp/negtmin.rays: ray 1: tmin -100 is negative (rays start at their origin" -- \
    trace 'builtin:soup?size=10' -s embree --rays "$tmp/negtmin.rays" --out "$tmp/e.hits"
  expect 1 "$tmp/negtmin.rays: ray 1: tmin -100 is negative" -- \
    trace 'builtin:soup?size=10' -s bvh --any --rays "$tmp/negtmin.rays" --out "$tmp/e.occl"
  [ ! -e "$tmp/e.hits" ] && [ ! -e "$tmp/e.occl" ] || { echo "FAIL: hits written for rays refused"; fail=1; }
  expect 1 "embree: cannot trace a ray whose origin (2e+18, 1, 1)" -- \
    render 'builtin:soup?size=10' -s embree --size 8x6 --camera 2e18,1,1,0,0,0 --out "$tmp/e.png"
  printf 'v 0 0 0\nv 1e19 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\n' >"$tmp/far.obj"
  expect 1 "embree: triangle 0 has a vertex coordinate beyond" -- \
    render "$tmp/far.obj" -s embree --size 8x6 --out "$tmp/f.png"
  [ ! -e "$tmp/e.png" ] && [ ! -e "$tmp/f.png" ] || { echo "FAIL: embree wrote a PNG it could not trace"; fail=1; }
fi

# Outputs never cost what was there (write_output_file): a link or FIFO
# named OUT.part (export's old temporary) is not followed or waited on, and
# a --force write that fails (here a file-size limit) keeps the old file.
echo precious >"$tmp/victim.txt"
ln -s victim.txt "$tmp/p.glb.part"
mkfifo "$tmp/q.glb.part"
for out in p.glb q.glb; do
  timeout 60 "$accelviz" -q export 'builtin:soup?size=20' "$tmp/$out" >/dev/null ||
    { echo "FAIL: export beside $out.part"; fail=1; }
done
[ "$(cat "$tmp/victim.txt")" = precious ] || { echo "FAIL: export wrote through $tmp/p.glb.part"; fail=1; }
"$accelviz" -q rays 'builtin:soup?size=2000' --size 256x192 --out "$tmp/keep.rays" >/dev/null
for kind in png rays hits; do
  old="$tmp/old.$kind"
  echo ORIGINAL >"$old"
  case $kind in
    png) cmd=(render 'builtin:soup?size=2000' --size 256x192 -f -o "$old") ;;
    rays) cmd=(rays 'builtin:soup?size=2000' --size 256x192 -f --out "$old") ;;
    hits) cmd=(trace 'builtin:soup?size=2000' --rays "$tmp/keep.rays" -f --out "$old") ;;
  esac
  (trap '' XFSZ; ulimit -f 1; "$accelviz" -q "${cmd[@]}") >/dev/null 2>"$tmp/stderr" &&
    { echo "FAIL: $kind written past the file-size limit"; fail=1; }
  grep -q "write failed: File too large" "$tmp/stderr" || { echo "FAIL: $kind: $(cat "$tmp/stderr")"; fail=1; }
  [ "$(cat "$old")" = ORIGINAL ] || { echo "FAIL: a failed $kind write lost the old file"; fail=1; }
done
leftovers=$(find "$tmp" -name '.accelviz-*.tmp')
[ -z "$leftovers" ] || { echo "FAIL: temporaries left behind: $leftovers"; fail=1; }
# A newline in an output's name: the path printed stays one line (a '?' for the newline), the
# JSON after it holds the name exactly; it split the line, and a script read half a path.
"$accelviz" -q render 'builtin:soup?size=10' --size 8x8 -o "$tmp/a"$'\n'"b.png" >"$tmp/stdout" ||
  { echo "FAIL: render to a name with a newline"; fail=1; }
[ "$(wc -l <"$tmp/stdout")" -eq 2 ] && [ "$(head -n 1 "$tmp/stdout")" = "$tmp/a?b.png" ] &&
  grep -qF "\"out\":\"$tmp/a\\nb.png\"" "$tmp/stdout" ||
  { echo "FAIL: the path printed for a name with a newline: $(cat "$tmp/stdout")"; fail=1; }
# A knob the structure does not use is said on stderr (it changed nothing, without a word); one
# that a listed structure uses, or --ctrav with the cost metric, is not.
"$accelviz" render 'builtin:soup?size=10' -s grid --leaf 3 --embree-robust --size 8x8 -o "$tmp/unused.png" \
  >/dev/null 2>"$tmp/stderr" && grep -qF "accelviz: note: grid does not use --leaf, --embree-robust" "$tmp/stderr" ||
  { echo "FAIL: no note of the options grid does not use: $(cat "$tmp/stderr")"; fail=1; }
"$accelviz" render 'builtin:soup?size=10' -s bvh,grid --leaf 3 --size 8x8 -o "$tmp/unused2.png" >/dev/null 2>"$tmp/stderr" &&
  "$accelviz" render 'builtin:soup?size=10' -s grid -m cost --ctrav 2 --size 8x8 -o "$tmp/unused3.png" >/dev/null \
    2>>"$tmp/stderr" && ! grep -q "note:" "$tmp/stderr" || { echo "FAIL: a note for used options: $(cat "$tmp/stderr")"; fail=1; }
# The file standard output goes to is not replaced: `-o /dev/stdout -f > out` renamed a new file
# over it, and what was printed there, before and after, went to the old one.
expect 1 "/dev/stdout: is this program's standard output" -- \
  trace 'builtin:soup?size=10' --rays "$tmp/keep.rays" -f --out /dev/stdout

# A scene near the float range cannot be framed: one line naming the scene
# (it was reported as a --camera usage error), nothing written.
printf 'v -3e38 0 0\nv 3e38 0 0\nv 0 3e38 0\nf 1 2 3\n' >"$tmp/huge.obj"
expect 1 "$tmp/huge.obj: cannot frame the scene: a camera that sees its bounds" -- \
  render "$tmp/huge.obj" --size 8x6 --out "$tmp/huge.png"
expect 1 "$tmp/huge.obj: cannot frame the scene" -- verify "$tmp/huge.obj" --rays 100
# refit and calibrate frame the scene themselves: no advice to use an option they do not have.
expect 1 "would stand beyond the float range (this command has no --camera)" -- refit "$tmp/huge.obj" --out "$tmp/rf"
expect 1 "would stand beyond the float range (this command has no --camera)" -- calibrate --scene "$tmp/huge.obj"
# ... and calibrate says so before its seconds of micro-benchmarks (their
# progress line came first).
"$accelviz" calibrate --scene "$tmp/huge.obj" >/dev/null 2>"$tmp/stderr"
if grep -q "micro-benchmarks" "$tmp/stderr"; then echo "FAIL: calibrate measured before framing: $(cat "$tmp/stderr")"; fail=1; fi
[ ! -e "$tmp/huge.png" ] || { echo "FAIL: a PNG of an unframable scene"; fail=1; }

# export: the extension in any case, -f for --force; a name that is only
# an extension, or another extension, is a usage error before any work.
"$accelviz" -q export 'builtin:soup?size=20' "$tmp/UP.GLB" >/dev/null || { echo "FAIL: export to .GLB"; fail=1; }
expect 1 "$tmp/UP.GLB: exists (use --force to overwrite)" -- export 'builtin:soup?size=20' "$tmp/UP.GLB"
"$accelviz" -q export 'builtin:soup?size=20' "$tmp/UP.GLB" -f >/dev/null || { echo "FAIL: export -f"; fail=1; }
expect 2 "$tmp/.glb: a glTF file needs a name before .glb" -- export 'builtin:soup?size=20' "$tmp/.glb"
expect 2 "$tmp/x.obj: the output's name must end in .glb or .gltf" -- export 'builtin:soup?size=20' "$tmp/x.obj"

# Written through a symbolic link (-f) into a folder that does not exist, or into an output folder
# that is a dangling link: said before the work (the writes failed after it, one without a reason).
ln -s "$tmp/no-such-dir/x.png" "$tmp/through.png"
expect 1 "$tmp/through.png: is a symbolic link to $tmp/no-such-dir/x.png, whose directory $tmp/no-such-dir does not exist" \
  -- render 'builtin:soup?size=10' --size 8x8 -o "$tmp/through.png" -f
ln -s "$tmp/no-such-dir" "$tmp/dangling-dir"
expect 1 "$tmp/dangling-dir: is a symbolic link to $tmp/no-such-dir, which does not exist" \
  -- sweep 'builtin:soup?size=10' --param buckets=2,4 --size 8x8 --repeat 1 --out "$tmp/dangling-dir"
[ ! -e "$tmp/.glb" ] && [ ! -e "$tmp/x.obj" ] || { echo "FAIL: export wrote under a refused name"; fail=1; }

# Missing output directory.
expect 1 "$tmp/no/dir/a.png" -- render 'builtin:soup?size=10' --out "$tmp/no/dir/a.png"

# A folder the user cannot write in is refused before the work (it failed after it), as is an empty name.
expect 2 "--out: an empty value (it needs one)" -- sweep 'builtin:soup?size=20' --param buckets=2,4 -o ""
expect 2 "SCENE: an empty value (it needs one)" -- info ""
# An empty value is a usage error, not the default taken in silence (a shell variable that was not set).
expect 2 "--camera: an empty value" -- render 'builtin:soup?size=20' --camera "" -o "$tmp/e.png"
expect 2 "--max: an empty value" -- render 'builtin:soup?size=20' --max "" -o "$tmp/e.png"
expect 2 "--structure: an empty value" -- robustness 'builtin:soup?size=20' -s ""
expect 2 "--structure: an empty item in 'bvh,,kdtree'" -- verify 'builtin:soup?size=20' -s bvh,,kdtree
# A leaf cap below the always-leaf size (it was ignored); not given, it is raised to --leaf.
expect 2 "--leaf-cap 4 is below --leaf 8" -- bench 'builtin:soup?size=20' -s bvh --leaf 8 --leaf-cap 4
expect 2 "--compare: B: --leaf-cap 2 is below --leaf 4" -- render 'builtin:soup?size=20' --size 8x8 -o "$tmp/cap.png" --compare leaf-cap=2
# Several structures in one render: a cost metric, not with --compare, each named once.
expect 2 "several structures: a cost metric" -- render 'builtin:soup?size=20' -s bvh,grid -m depth --size 8x8 -o "$tmp/sev.png"
expect 2 "--compare: one structure for A" -- render 'builtin:soup?size=20' -s bvh,grid --compare buckets=4 --size 8x8 -o "$tmp/sev.png"
expect 2 "--structure: an empty item in 'bvh,,grid'" -- render 'builtin:soup?size=20' -s bvh,,grid --size 8x8 -o "$tmp/sev.png"
expect 2 "--structure: 'bvh' is listed twice" -- render 'builtin:soup?size=20' -s bvh,grid,bvh --size 8x8 -o "$tmp/sev.png"
expect 2 "kdtree: --order back-to-front" -- render 'builtin:soup?size=20' -s bvh,kdtree --order back-to-front --size 8x8 -o "$tmp/sev.png"
# An order or x-ray the structure cannot take (it was ignored and the caption named it).
expect 2 "--order back-to-front: bvh and tlas only (kdtree: front-to-back or unordered)" -- render 'builtin:soup?size=20' -s kdtree --order back-to-front --size 8x8 -o "$tmp/order.png"
expect 2 "--xray: bvh and tlas only" -- render 'builtin:soup?size=20' -s octree --xray --size 8x8 -o "$tmp/order.png"
expect 2 "--compare: B (grid): --order unordered: grid has no child order" -- render 'builtin:soup?size=20' --order unordered --compare structure=grid --size 8x8 -o "$tmp/order.png"
# bench too (CLI11's list splitting dropped the empty item: a typo measured other structures).
expect 2 "--structure: an empty item in 'bvh,,kdtree'" -- bench 'builtin:soup?size=20' -s bvh,,kdtree
expect 2 "--structure: an empty item in 'bvh,'" -- bench 'builtin:soup?size=20' -s bvh,
expect 2 "--structure: bvhx not in {" -- bench 'builtin:soup?size=20' -s bvh,bvhx
mkdir "$tmp/ro" && chmod 555 "$tmp/ro"
as_user=()
runner="$accelviz"
if [ "$(id -u)" -eq 0 ]; then
  # root writes anywhere: run a copy as nobody where the system has setpriv.
  if command -v setpriv >/dev/null; then
    chmod 755 "$tmp" && cp "$accelviz" "$tmp/accelviz-copy" && runner="$tmp/accelviz-copy"
    as_user=(setpriv --reuid=65534 --regid=65534 --clear-groups)
  else runner=""; fi
fi
if [ -n "$runner" ]; then
  for args in "render builtin:soup?size=20 --size 8x8 -o $tmp/ro/x.png" \
    "sweep builtin:soup?size=20 --param buckets=2,4 -o $tmp/ro/sweep" \
    "sweep builtin:soup?size=20 --param buckets=2,4 -o $tmp/ro/new/deeper"; do
    # shellcheck disable=SC2086
    "${as_user[@]}" "$runner" -q $args >/dev/null 2>"$tmp/stderr"
    rc=$?
    if [ "$rc" -ne 1 ] || ! grep -qF ": cannot write in $tmp/ro: Permission denied" "$tmp/stderr"; then
      echo "FAIL: unwritable folder ($args): exit $rc: $(cat "$tmp/stderr")"; fail=1
    else echo "ok: unwritable folder: $(cat "$tmp/stderr")"; fi
  done
fi
chmod 755 "$tmp/ro"

# Out of memory: the command line says which file and options asked for it (it said only "out of memory").
if ldd "$accelviz" 2>/dev/null | grep -q libasan; then
  echo "skip: out of memory under ASan (its shadow memory needs more address space than the limit)"; rc=skip
else
  (ulimit -v 1500000; "$accelviz" -q info 'builtin:soup?size=200000000') 2>"$tmp/stderr"
  rc=$?
fi
if [ "$rc" = skip ]; then :
elif [ "$rc" -ne 1 ] || ! grep -qF "accelviz: out of memory running '-q info builtin:soup?size=200000000'" "$tmp/stderr"; then
  # Under ASan the address-space limit cannot be set this way: its shadow memory needs more.
  if grep -q "AddressSanitizer\|ReserveShadowMemoryRange" "$tmp/stderr"; then echo "skip: out of memory under ASan"
  else echo "FAIL: out of memory: exit $rc: $(cat "$tmp/stderr")"; fail=1; fi
else echo "ok: out of memory: $(cat "$tmp/stderr")"; fi

# Past the file-size limit: the write's error, exit 1, no temporary file left (the signal killed it, 153).
mkdir "$tmp/fsz"
(ulimit -f 100; "$accelviz" -q rays 'builtin:soup?size=200' -o "$tmp/fsz/big.rays" --size 400x400 -j 1) \
  2>"$tmp/stderr"
rc=$?
if [ "$rc" -ne 1 ] || ! grep -qF "$tmp/fsz/big.rays: write failed: File too large" "$tmp/stderr"; then
  echo "FAIL: file-size limit: exit $rc: $(cat "$tmp/stderr")"; fail=1
elif [ -n "$(ls -A "$tmp/fsz")" ]; then
  echo "FAIL: file-size limit left $(ls -A "$tmp/fsz")"; fail=1
else echo "ok: file-size limit: $(cat "$tmp/stderr")"; fi
# What goes to stdout must arrive: a full disk behind stdout is an error, not exit 0.
if [ -w /dev/full ]; then
  # With the reason, also where an earlier flush failed (glibc drops the buffer; a JSON line is flushed).
  for args in "info builtin:soup?size=20" "info builtin:soup?size=20 --json" \
    "bench builtin:soup?size=200 -s bvh --rays primary --size 8x8 -n 1 -j 1 --json" "--version" "--help" \
    "bench builtin:soup?size=200 -s bvh,kdtree,grid --rays all --size 8x8 -n 1 -j 1 --json" \
    "sweep builtin:soup?size=300 --param buckets=$(seq -s, 2 60) --size 8x8 -n 1 -j 1 --out $tmp/sweep-full" \
    "render --help"; do
    # shellcheck disable=SC2086
    "$accelviz" -q $args >/dev/full 2>"$tmp/stderr"
    rc=$?
    if [ "$rc" -ne 1 ] || ! grep -q "^accelviz: stdout: write failed: No space left on device" "$tmp/stderr"; then
      echo "FAIL: stdout to /dev/full ($args): exit $rc: $(cat "$tmp/stderr")"; fail=1
    else echo "ok: stdout to /dev/full ($args): $(cat "$tmp/stderr")"; fi
  done
fi

exit $fail
