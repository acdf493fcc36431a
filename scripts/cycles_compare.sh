#!/bin/sh
# pxf against Blender Cycles 3.4 on the same glTF (scripts/cycles_compare.py says what is
# compared). Needs a build (scripts/setup.sh) and Debian's blender and python3-numpy:
#   apt-get install blender python3-numpy
# The glass cases are also rendered by a second build, build-cycles-glass (CMake option
# PXF_CYCLES_GLASS_FRESNEL: rough glass with Cycles 3.x's Fresnel split at the macro normal), which
# isolates that one difference of models (docs/materials.md).
# Usage: scripts/cycles_compare.sh [OUT [SPP [CASE...]]]   (defaults: cycles-compare, 1024, every case)
set -eu
cd "$(dirname "$0")/.."
out=${1:-cycles-compare}
spp=${2:-1024}
[ $# -ge 2 ] && shift 2 || shift $#
cases=${*:-glass-0.1 glass-0.3 metal-0.49}
render() {  # BINARY DIR OUT_SUBDIR
  "$1" render --scene "$2/scene.gltf" --env "$2/white.hdr" --size 128x128 --filter none --spp "$spp" \
    --max-vertices 66 --seed 7 --out "$2/$3" > "$2/$3.log" 2>&1
}
case " $cases " in *" glass-"*)
  cmake -S . -B build-cycles-glass -DCMAKE_BUILD_TYPE=Release -DPXF_BUILD_TESTS=OFF -DPXF_CYCLES_GLASS_FRESNEL=ON \
    > /dev/null
  cmake --build build-cycles-glass --target pxf -j "$(nproc)" > /dev/null ;;
esac
for case in $cases; do
  dir="$out/$case"
  python3 scripts/cycles_compare.py scene "$case" "$dir"
  render build/app/pxf "$dir" pxf
  case $case in glass-*) render build-cycles-glass/app/pxf "$dir" pxf-cycles-fresnel ;; esac
  blender -b --python scripts/cycles_compare.py -- render "$case" "$dir" "$spp" > "$dir/cycles.log" 2>&1 ||
    { tail -20 "$dir/cycles.log"; exit 1; }
  grep "CYCLES-COMPARE" "$dir/cycles.log"
done
