#!/usr/bin/env bash
# Installs exactly the Debian 12 packages accelviz needs to build, run and test.
# Idempotent: packages already present are skipped, and nothing is installed
# when all of them are there. Uses sudo when not run as root.
set -euo pipefail

PACKAGES=(
  # toolchain
  build-essential cmake ninja-build pkg-config git
  # core
  libglm-dev libtinygltf-dev nlohmann-json3-dev libstb-dev libtinyobjloader-dev
  # app / command line
  libcli11-dev
  # ui: window, headless GL, loader generator, panels
  libglfw3-dev libosmesa6-dev python3-glad libimgui-dev
  # ui: headless GL on a device (a GPU; Mesa's software device in CI)
  libegl-dev
  # reference backend (Embree 3) and benchmarks / tests
  libembree-dev libbenchmark-dev libgtest-dev libgmock-dev
  # GUI tests in a real window
  xvfb xauth
  # libFuzzer targets (clang's -fsanitize=fuzzer) for the loaders and ray files
  clang libclang-rt-14-dev
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
