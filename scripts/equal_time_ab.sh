#!/usr/bin/env bash
# Equal wall time, one set of render flags against another: for each scene, ROUNDS rounds of two
# whole jobs back to back (`pxf render --time SECONDS`, default settings plus FLAGS_A or FLAGS_B,
# seed 101, 102, ... per round, both jobs of a round with the same seed; which goes first
# alternates by round), each judged against the scene's reference with `pxf diff` (HDR and display
# NRMSE). Prints every run, then per scene the medians over rounds and the B / A ratios of the
# medians, and the per-round ratios' median and range.
# Usage: scripts/equal_time_ab.sh REFERENCE_DIR SECONDS ROUNDS "FLAGS_A" "FLAGS_B" [SCENES...]
#   REFERENCE_DIR as for scripts/equal_time_samplers.sh: reference_<scene>_384x216_2048spp.exr or
#   <scene>/buffers.exr (`pxf render --scene S --size 384x216 --spp 2048 --seed 7 --filter none
#   --out DIR/S`). Default scenes: cornell atrium kitchen envmap.
# Example: scripts/equal_time_ab.sh REF 2 6 "--bias-guard off" "--bias-guard on"
# SECOND_REFS=DIR2 (references like REFERENCE_DIR's, rendered with another seed) judges every job by
#   its noise-corrected error (`pxf diff --second-reference`, docs/metrics.md) instead of its raw
#   error against REFERENCE_DIR; the perfect-filter rows stay raw (they use the reference's HV).
# Two builds: PXF_A and PXF_B name the binaries of A and B (default build/app/pxf), e.g.
#   PXF_A=OLD/app/pxf scripts/equal_time_ab.sh REF 2 6 --quiet --quiet (the flags may not be empty)
set -euo pipefail
cd "$(dirname "$0")/.."
usage="usage: scripts/equal_time_ab.sh REFERENCE_DIR SECONDS ROUNDS FLAGS_A FLAGS_B [SCENES...]"
refs=${1:?$usage}
seconds=${2:?$usage}
rounds=${3:?$usage}
label_a=${4:?$usage}
label_b=${5:?$usage}
read -r -a flags_a <<<"$label_a"
read -r -a flags_b <<<"$label_b"
shift 5
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(cornell atrium kitchen envmap)
source scripts/equal_time_common.sh
pxf_a=${PXF_A:-$pxf}
pxf_b=${PXF_B:-$pxf}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "scene round variant spp hdr_nrmse display_nrmse" | tee "$tmp/runs"
for scene in "${scenes[@]}"; do
  ref=$(reference_of "$refs" "$scene")
  for round in $(seq "$rounds"); do
    order=(A B)
    [ $((round % 2)) -eq 0 ] && order=(B A)
    for variant in "${order[@]}"; do
      out="$tmp/$scene-$round-$variant"
      if [ "$variant" = A ]; then flags=("${flags_a[@]}") bin=$pxf_a; else flags=("${flags_b[@]}") bin=$pxf_b; fi
      "$bin" render --scene "$scene" --size 384x216 --time "$seconds" --seed $((100 + round)) "${flags[@]}" \
        --out "$out" >/dev/null 2>&1
      spp=$(spp_of "$out")
      errors=$(judge "$out/final.exr" "$refs" "$scene")
      echo "$scene $round $variant $spp $errors" | tee -a "$tmp/runs"
    done
  done
done
python3 - "$tmp/runs" "$label_a [$pxf_a]" "$label_b [$pxf_b]" <<'PY'
import collections, statistics, sys
rows = [l.split() for l in open(sys.argv[1]).read().splitlines()[1:]]
runs = collections.defaultdict(list)   # (scene, variant) -> [(spp, hdr, display)]
paired = collections.defaultdict(dict)  # (scene, round) -> variant -> (hdr, display)
for scene, rnd, variant, spp, hdr, disp in rows:
    runs[(scene, variant)].append((float(spp), float(hdr), float(disp)))
    paired[(scene, rnd)][variant] = (float(hdr), float(disp))
print("\nA: %s   B: %s\nmedians over rounds; ratio = B / A of the medians; per-round ratios: median [min - max]" %
      (sys.argv[2], sys.argv[3]))
print("%-10s %13s %30s %30s" % ("scene", "spp A / B", "HDR % A / B (ratio)", "display % A / B (ratio)"))
for scene in dict.fromkeys(r[0] for r in rows):
    a, b = ([statistics.median(v[i] for v in runs[(scene, x)]) for i in range(3)] for x in "AB")
    cells = []
    for k in range(2):
        per_round = sorted(v["B"][k] / v["A"][k] for (sc, _), v in paired.items() if sc == scene and len(v) == 2)
        cells.append("%6.2f/%-6.2f (%.2f) [%.2f %.2f-%.2f]" % (a[k + 1], b[k + 1], b[k + 1] / a[k + 1],
                     statistics.median(per_round), per_round[0], per_round[-1]))
    print("%-10s %6.0f / %-5.0f %s   %s" % (scene, a[0], b[0], cells[0], cells[1]))
PY
