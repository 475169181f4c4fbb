#!/usr/bin/env bash
# The headline table of docs/performance.md: our BVH beside Embree, in one
# process per cell, on the shared meshes and the 10M-triangle soup.
#
#   bench/headline.sh [ACCELVIZ] [OUT_DIR]
#
# ACCELVIZ: the accelviz binary (default build/release/app/accelviz); OUT_DIR
# (default: a new folder under /tmp) keeps each run's `bench --json` output
# and the table, table.md, which is also printed.
#
# Per mesh and thread count T (1 and 2): `bench MESH -s bvh,embree -n 5
# --warmup 1 -j T --no-epo`, once with our watertight test against Embree's
# robust mode (--embree-robust) and once with our fast test (Moller-Trumbore)
# against Embree's default mode (--triangle-test fast). The soup: `-n 3
# --warmup 1 --rays primary --size 64x48` in those two pairings and in our
# watertight test against Embree's default mode.
#
# Cells are ours / Embree from the same run: build (Embree's time over ours:
# the medians, then the best runs), SAH cost and memory (ours over Embree's:
# lower is better), and Mrays/s of the run's T threads (the `_nt` figures) for
# closest and any hits (higher is better).
#
# Environment (for a quick run; the defaults are the documented headline):
#   HEADLINE_MESHES   space-separated scenes (default: bunny, dragon and
#                     kitchen_partial from $ACCELVIZ_ASSETS, default ../shared/assets)
#   HEADLINE_SOUP     the soup's scene (default builtin:soup?size=10000000; "" skips it)
#   HEADLINE_THREADS  thread counts (default "1 2")
#   HEADLINE_REPEAT   runs per figure of the meshes (default 5); the soup's is 3 unless this is lower
#   HEADLINE_SIZE     the meshes' image size, bench's --size (default: bench's own, 800x600)
#   HEADLINE_FORCE    1: write over the results of an earlier run in OUT_DIR, name by name (the names
#                     this run writes; an earlier run's other N-*.json stay, beside a table.md of this
#                     run only). Without it an OUT_DIR that holds any (N-robust.json, N-fast.json,
#                     N-default.json, table.md) is refused before the first run, and nothing in it
#                     changes.
#
# Each result is written to a temporary in OUT_DIR and takes its name only when its run succeeded: a
# run that fails leaves the earlier result (if any) as it was.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="${1:-$root/build/release/app/accelviz}"
out="${2:-$(mktemp -d /tmp/accelviz-headline-XXXXXX)}"
[ -x "$bin" ] || { echo "headline: $bin: not an executable (build first, or pass the accelviz binary)" >&2; exit 2; }
force="${HEADLINE_FORCE:-0}"
case "$force" in 0 | 1) ;; *) echo "headline: HEADLINE_FORCE=$force: expected 0 or 1" >&2; exit 2 ;; esac
if [ "$force" != 1 ] && [ -d "$out" ]; then
  for f in "$out"/table.md "$out"/[0-9]*-robust.json "$out"/[0-9]*-fast.json "$out"/[0-9]*-default.json; do
    if [ -e "$f" ] || [ -L "$f" ]; then
      echo "headline: $out already holds results ($(basename "$f")); set HEADLINE_FORCE=1 to replace them" >&2
      exit 2
    fi
  done
fi
mkdir -p "$out"
mode="$(printf '%o' $((0666 & ~0$(umask))))"  # what `>` gave a new file (mktemp's are 0600)
pending=""  # the temporary being written, removed when the script stops before it took its name
trap '[ -z "$pending" ] || rm -f -- "$pending"' EXIT

keep() {  # TMP NAME: the finished temporary takes NAME in $out (without HEADLINE_FORCE, only a free name)
  chmod "$mode" -- "$1"
  if [ "$force" = 1 ]; then
    mv -f -- "$1" "$out/$2"
  elif [ -e "$out/$2" ] || [ -L "$out/$2" ]; then  # appeared during the runs
    echo "headline: $out/$2: exists (set HEADLINE_FORCE=1 to replace it)" >&2
    exit 1
  else
    # A hard link takes only a free name; a file system without them: mv's no-clobber.
    ln -- "$1" "$out/$2" 2>/dev/null || mv -n -- "$1" "$out/$2"
    rm -f -- "$1"
  fi
  pending=""
}
assets="${ACCELVIZ_ASSETS:-$root/../shared/assets}"
meshes="${HEADLINE_MESHES-$assets/bunny.glb $assets/dragon.glb $assets/kitchen_partial.glb}"
soup="${HEADLINE_SOUP-builtin:soup?size=10000000}"
threads="${HEADLINE_THREADS:-1 2}"
repeat="${HEADLINE_REPEAT:-5}"
mesh_size=()
if [ -n "${HEADLINE_SIZE:-}" ]; then mesh_size=(--size "$HEADLINE_SIZE"); fi
soup_repeat=$((repeat < 3 ? repeat : 3))

run() {  # FILE ARGS...: one bench run, its JSON kept
  local file="$1"
  shift
  echo "headline: accelviz -q bench $*" >&2
  pending="$(mktemp "$out/.headline-XXXXXX.tmp")"
  "$bin" -q bench "$@" --json > "$pending"
  keep "$pending" "$file"
}

i=0
rows=()
for scene in $meshes; do
  for t in $threads; do
    i=$((i + 1))
    run "$i-robust.json" "$scene" -s bvh,embree -n "$repeat" --warmup 1 -j "$t" --no-epo --embree-robust \
      "${mesh_size[@]}"
    rows+=("$i-robust.json|watertight vs robust")
    run "$i-fast.json" "$scene" -s bvh,embree -n "$repeat" --warmup 1 -j "$t" --no-epo --triangle-test fast \
      "${mesh_size[@]}"
    rows+=("$i-fast.json|fast vs default")
  done
done
if [ -n "$soup" ]; then
  for t in $threads; do
    i=$((i + 1))
    common=(-s bvh,embree -n "$soup_repeat" --warmup 1 -j "$t" --no-epo --rays primary --size 64x48)
    run "$i-robust.json" "$soup" "${common[@]}" --embree-robust
    rows+=("$i-robust.json|watertight vs robust")
    run "$i-fast.json" "$soup" "${common[@]}" --triangle-test fast
    rows+=("$i-fast.json|fast vs default")
    run "$i-default.json" "$soup" "${common[@]}"
    rows+=("$i-default.json|watertight vs default")
  done
fi

pending="$(mktemp "$out/.headline-XXXXXX.tmp")"
python3 - "$out" "${rows[@]}" > "$pending" <<'PY'
import json, os, sys

out, rows = sys.argv[1], sys.argv[2:]

print("| scene | mode | threads | build (median / best) | SAH | memory | primary closest / any "
      "| diffuse closest / any | shadow closest / any |")
print("|---|---|---|---|---|---|---|---|---|")
for row in rows:
    file, mode = row.split("|", 1)
    j = json.load(open(os.path.join(out, file)))
    s = {x["name"]: x for x in j["structures"]}
    ours, emb = s["bvh"], s["embree"]
    ob, eb = ours["build"], emb["build"]
    build = f"{eb['build_ms'] / ob['build_ms']:.2f} / {min(eb['build_ms_runs']) / min(ob['build_ms_runs']):.2f}"
    sah = f"{ours['embree_binary_bvh']['sah_ratio_ours_over_embree']:.4f}"
    mem = f"{ob['memory_bytes'] / eb['memory_bytes']:.2f}"
    cells = []
    for rs in ("primary", "diffuse", "shadow"):
        if rs not in ours["rays"]:
            cells.append("")
            continue
        o, e = ours["rays"][rs], emb["rays"][rs]
        cells.append(f"{o['closest_mrays_nt'] / e['closest_mrays_nt']:.2f} / {o['any_mrays_nt'] / e['any_mrays_nt']:.2f}")
    name = os.path.splitext(os.path.basename(j["scene"]))[0] if not j["scene"].startswith("builtin:") else j["scene"]
    print(f"| {name} | {mode} | {j['threads']} | {build} | {sah} | {mem} | " + " | ".join(cells) + " |")
PY
keep "$pending" table.md
cat "$out/table.md"
echo "headline: the runs' JSON and table.md are in $out" >&2
