#!/usr/bin/env bash
# Peak resident memory against the loader's estimate (docs/robustness.md, "Memory"): writes the
# inputs (scripts/memory_inputs.py, and make_compressed_gltf's Draco and meshopt files when that
# target is built), renders each with `pxf render --spp 1 --size 16x16` under /usr/bin/time, and
# prints input, file bytes, estimated_load_mib, peak MiB and (peak - base) / estimate, where the
# base is the peak of one triangle (the program, its GL context and llvmpipe).
# Usage: scripts/measure_memory.sh [PXF_BINARY] [INPUT ...]   (default build/app/pxf, every input)
# The compressed inputs need: cmake --build build --target make_compressed_gltf
set -euo pipefail
cd "$(dirname "$0")/.."
pxf=$(realpath "${1:-build/app/pxf}")
shift || true
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
python3 scripts/memory_inputs.py "$tmp/in"
make_compressed=build/fuzz/make_compressed_gltf
if [ -x "$make_compressed" ]; then
  mkdir -p "$tmp/meshopt"
  for side in 300 600 1000 1150; do
    mkdir -p "$tmp/draco$side"
    "$make_compressed" draco-pair $side "$tmp/draco$side" >/dev/null
    mv "$tmp/draco$side/grid_draco_quantized.glb" "$tmp/in/draco_quantized_$side.glb"
  done
  mv "$tmp/draco300/grid_draco.glb" "$tmp/in/draco_lossless_300.glb"
  "$make_compressed" meshopt-bombs "$tmp/meshopt" >/dev/null
  mv "$tmp"/meshopt/*.glb "$tmp/in/"
  mkdir -p "$tmp/seeds"
  "$make_compressed" seeds "$tmp/seeds" >/dev/null
  mv "$tmp/seeds/compressed_webp_huge_dimensions.glb" "$tmp/in/webp_huge_dimensions.glb"
fi
measure() {  # prints "peak_mib estimate_mib", or "peak_mib refused"
  local out="$tmp/out" peak
  rm -rf "$out"
  /usr/bin/time -f %M -o "$tmp/peak" "$pxf" render --scene "$1" --spp 1 --size 16x16 --out "$out" >/dev/null 2>&1 || true
  peak=$(tail -1 "$tmp/peak")
  if [ -f "$out/stats.json" ]; then
    python3 -c "import json,sys; print('%.1f %.4f' % (int(sys.argv[1]) / 1024, json.load(open(sys.argv[2]))['estimated_load_mib']))" "$peak" "$out/stats.json"
  else
    python3 -c "import sys; print('%.1f refused' % (int(sys.argv[1]) / 1024))" "$peak"
  fi
}
read -r base _ < <(measure "$tmp/in/tri.gltf")
echo "base (one triangle): $base MiB"
printf '%-28s %10s %12s %10s %8s\n' input bytes estimate_mib peak_mib ratio
inputs=("$@")
if [ ${#inputs[@]} -eq 0 ]; then
  for f in "$tmp"/in/*.gltf "$tmp"/in/*.glb; do if [ -e "$f" ]; then inputs+=("$(basename "$f")"); fi; done
fi
for name in "${inputs[@]}"; do
  f="$tmp/in/$name"
  [ -e "$f" ] || { echo "$name: no such input" >&2; continue; }
  bytes=$( { du -cb "$f" "${f%.*}.bin" "${f%.*}.png" 2>/dev/null || true; } | tail -1 | cut -f1)
  read -r peak estimate < <(measure "$f")
  ratio=$(python3 -c "import sys; e=sys.argv[3]; print('-' if e=='refused' or float(e)==0 else '%.2f' % ((float(sys.argv[1])-float(sys.argv[2]))/float(e)))" "$peak" "$base" "$estimate")
  printf '%-28s %10s %12s %10s %8s\n' "$name" "$bytes" "$estimate" "$peak" "$ratio"
done
