#!/usr/bin/env bash
# Load time and peak memory of a DamagedHelmet-sized GLB (about 70k triangles, five 2048x2048
# textures) at 320x240: generates it with pxf_helmet_like, renders it ROUNDS times back to back
# (1 spp) and prints load_ms and peak_memory_mib from stats.json, then their medians.
# Usage: scripts/measure_load.sh [PXF_BINARY] [ROUNDS]   (default build/app/pxf, 3)
set -euo pipefail
cd "$(dirname "$0")/.."
pxf=${1:-build/app/pxf}
rounds=${2:-3}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cmake --build build --target pxf_helmet_like >/dev/null
build/assets/pxf_helmet_like "$tmp/helmet.glb" >/dev/null
for i in $(seq "$rounds"); do
  "$pxf" render --scene "$tmp/helmet.glb" --size 320x240 --spp 1 --out "$tmp/out$i" >/dev/null 2>&1
  python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(d['load_ms'], d['peak_memory_mib'])" "$tmp/out$i/stats.json"
done | tee "$tmp/figures" >&2
python3 - "$tmp/figures" <<'PY'
import statistics, sys
rows = [list(map(float, l.split())) for l in open(sys.argv[1])]
print("median load_ms %.0f  peak_memory_mib %.0f" % (statistics.median(r[0] for r in rows), statistics.median(r[1] for r in rows)))
PY
