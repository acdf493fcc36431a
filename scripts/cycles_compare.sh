#!/bin/sh
# pxf against Blender Cycles 3.4 on the same glTF (issue 35; scripts/cycles_compare.py says what is
# compared). Needs a build (scripts/setup.sh) and Debian's blender and python3-numpy:
#   apt-get install blender python3-numpy
# Usage: scripts/cycles_compare.sh [OUT [SPP [CASE...]]]   (defaults: cycles-compare, 1024, every case)
set -eu
cd "$(dirname "$0")/.."
out=${1:-cycles-compare}
spp=${2:-1024}
[ $# -ge 2 ] && shift 2 || shift $#
cases=${*:-glass-0.1 glass-0.3 metal-0.49}
for case in $cases; do
  dir="$out/$case"
  python3 scripts/cycles_compare.py scene "$case" "$dir"
  build/app/pxf render --scene "$dir/scene.gltf" --env "$dir/white.hdr" --size 128x128 --filter none \
    --spp "$spp" --max-vertices 66 --seed 7 --out "$dir/pxf" > "$dir/pxf.log"
  blender -b --python scripts/cycles_compare.py -- render "$case" "$dir" "$spp" > "$dir/cycles.log" 2>&1 ||
    { tail -20 "$dir/cycles.log"; exit 1; }
  grep "CYCLES-COMPARE" "$dir/cycles.log"
done
