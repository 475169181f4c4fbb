#!/usr/bin/env bash
# cmake --install into a temporary prefix: the executable, the example scenes
# and the documentation land where GNUInstallDirs puts them, and the installed
# program works from another folder with neither the source nor the build tree
# (its shaders are built in). Usage: install.sh CMAKE BUILD_DIR renderer|no-renderer
set -u
cmake=$1 build=$2 renderer=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
check() { if eval "$2"; then echo "ok: $1"; else echo "FAIL: $1"; fail=1; fi; }

"$cmake" --install "$build" --prefix "$tmp/prefix" >"$tmp/install.log" 2>&1 || {
  echo "FAIL: cmake --install: $(tail -3 "$tmp/install.log")"; exit 1; }
bin=$tmp/prefix/bin/accelviz
check "the executable is installed" '[ -x "$bin" ]'
check "the example scenes are installed" '[ -f "$tmp/prefix/share/accelviz/assets/teapot.glb" ] && [ -f "$tmp/prefix/share/accelviz/assets/README.md" ]'
check "the shader sources are installed (to edit and reload live)" '[ -f "$tmp/prefix/share/accelviz/shaders/trace_bvh.comp" ]'
check "the documentation is installed" '[ -f "$tmp/prefix/share/doc/accelviz/README.md" ] && [ -f "$tmp/prefix/share/doc/accelviz/docs/cli.md" ]'
check "nothing of the test tree is installed" '! find "$tmp/prefix" -name "*_tests" -o -name "*.sh" | grep -q .'

# Run from an empty folder, the source and build trees out of sight of its working directory.
mkdir -p "$tmp/elsewhere"
cd "$tmp/elsewhere" || exit 1
"$bin" --version >"$tmp/version.txt" 2>&1
check "the installed program runs (--version: $(head -1 "$tmp/version.txt"))" 'grep -q "accelviz" "$tmp/version.txt"'
"$bin" -q info "$tmp/prefix/share/accelviz/assets/teapot.glb" >"$tmp/info.txt" 2>&1
check "it reads an installed scene" 'grep -q "triangles" "$tmp/info.txt"'
"$bin" -q bench 'builtin:teapot?size=2000' -s bvh --rays primary --size 16x12 -n 1 -j 1 >"$tmp/bench.txt" 2>&1
check "it builds and traces" 'grep -qi "mrays" "$tmp/bench.txt"'
ACCELVIZ_NO_SETTINGS=1 "$bin" -q render 'builtin:teapot?size=2000' --size 64x48 --out "$tmp/elsewhere/cpu.png" \
  >"$tmp/render.txt" 2>&1
check "it renders a CPU heatmap" '[ -s "$tmp/elsewhere/cpu.png" ]'
if [ "$renderer" = renderer ]; then
  # The shaders are built into the program: the GPU heatmap (a compute shader) and the raster view
  # (vertex and fragment shaders) render with no shaders/ folder near.
  ACCELVIZ_NO_SETTINGS=1 "$bin" -q render 'builtin:teapot?size=2000' --size 64x48 --device gpu --gl osmesa \
    --out "$tmp/elsewhere/gpu.png" >"$tmp/gpu.txt" 2>&1
  check "it renders a GPU heatmap ($(tail -1 "$tmp/gpu.txt" | cut -c1-120))" '[ -s "$tmp/elsewhere/gpu.png" ]'
  ACCELVIZ_NO_SETTINGS=1 "$bin" -q render 'builtin:teapot?size=2000' --size 64x48 --view raster \
    --out "$tmp/elsewhere/raster.png" >"$tmp/raster.txt" 2>&1
  check "it renders the raster view ($(tail -1 "$tmp/raster.txt" | cut -c1-120))" '[ -s "$tmp/elsewhere/raster.png" ]'
fi
exit $fail
