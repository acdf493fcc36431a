#!/usr/bin/env bash
# Installs whatever Debian 12 packages are missing, then configures and builds pxf (Release) in
# build/ (or $PXF_BUILD_DIR): the pxf executable, or the targets in $PXF_BUILD_TARGETS (test.sh:
# all). Idempotent: with everything installed and built it takes seconds.
#   scripts/setup.sh [extra cmake arguments]
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  cmake g++ make pkg-config ca-certificates
  python3 python3-glad                 # GL loader generated at build time
  libosmesa6-dev libegl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri   # OSMesa and EGL (llvmpipe)
  libglfw3-dev libimgui-dev            # explorer window and UI
  libglm-dev libtinygltf-dev nlohmann-json3-dev libstb-dev
  libopenexr-dev libembree-dev libtbb-dev
  libdraco-dev                         # KHR_draco_mesh_compression: Debian's tinygltf is built without Draco
  libwebp-dev                          # EXT_texture_webp images (stb reads no WebP)
  libmeshoptimizer-dev                 # EXT_meshopt_compression (gltfpack's output): its decoders and filters
  libgtest-dev
  xvfb xauth                           # explorer test under a virtual display
  slurm-wlm munge                      # Slurm.* test: a single-node Slurm on localhost
  clang-14 libfuzzer-14-dev libclang-rt-14-dev   # libFuzzer harnesses (scripts/fuzz.sh)
)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

BUILD_DIR="${PXF_BUILD_DIR:-build}"
JOBS="${PXF_JOBS:-$(nproc)}"
if [ ! -f "$BUILD_DIR/CMakeCache.txt" ]; then
  cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
elif [ $# -gt 0 ]; then
  cmake -S . -B "$BUILD_DIR" "$@" >/dev/null
fi
# The main job needs the pxf executable only; scripts/test.sh asks for every target (the test
# programs and fuzz replays are most of the build: a first run then renders sooner).
cmake --build "$BUILD_DIR" -j "$JOBS" --target ${PXF_BUILD_TARGETS:-pxf}
