#!/usr/bin/env bash
# Equal wall time, Sobol against independent sampling: for each scene, ROUNDS rounds of
# four whole jobs back to back (`pxf render --time SECONDS`: sobol/independent x unfiltered/default
# grid filter, seed 101, 102, ... per round; which sampler goes first alternates by round), each
# judged against the scene's reference with
# `pxf diff` (HDR and display NRMSE). Prints every run, then per scene the medians over rounds and
# the Sobol / independent ratios of the medians.
# Usage: scripts/equal_time_samplers.sh REFERENCE_DIR [SECONDS] [ROUNDS] [SCENES...]
#   REFERENCE_DIR holds reference_<scene>_384x216_2048spp.exr for every scene (as `pxf bench
#   --scene S --size 384x216 --reference-spp 2048 --out DIR` writes it: another seed, unfiltered),
#   or <scene>/buffers.exr, a reference render's output (`pxf render --scene S --size 384x216
#   --spp 2048 --seed 7 --filter none --out DIR/S`). With the buffers, each filtered job is also
#   blended again with a perfect filter (`pxf diff --perfect-filter`: L_f = the reference's HV),
#   the least error any filter could leave under the blend.
#   Defaults: 2 s, 3 rounds, cornell atrium kitchen envmap.
#   SECOND_REFS=DIR2 (references like REFERENCE_DIR's, rendered with another seed) judges every job by
#   its noise-corrected error (`pxf diff --second-reference`, docs/metrics.md) instead of its raw
#   error against REFERENCE_DIR; the perfect-filter rows stay raw (they use the reference's HV).
#   FILTER_FLAGS="--sigma-s 2" (say) adds render flags to the filtered jobs only.
set -euo pipefail
cd "$(dirname "$0")/.."
refs=${1:?usage: scripts/equal_time_samplers.sh REFERENCE_DIR [SECONDS] [ROUNDS] [SCENES...]}
seconds=${2:-2}
rounds=${3:-3}
shift $(($# < 3 ? $# : 3))
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(cornell atrium kitchen envmap)
source scripts/equal_time_common.sh
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "scene round sampler filter spp hdr_nrmse display_nrmse" | tee "$tmp/runs"
for scene in "${scenes[@]}"; do
  ref=$(reference_of "$refs" "$scene")
  for round in $(seq "$rounds"); do
    # Alternate which sampler goes first: on a shared machine the first jobs of a round can run
    # at another speed than the last ones.
    order=(sobol independent)
    [ $((round % 2)) -eq 0 ] && order=(independent sobol)
    for sampler in "${order[@]}"; do
      for filter in none grid; do
        out="$tmp/$scene-$round-$sampler-$filter"
        flags=()
        [ "$filter" = grid ] && read -r -a flags <<<"${FILTER_FLAGS:-}"
        "$pxf" render --scene "$scene" --size 384x216 --time "$seconds" --sampler "$sampler" --filter "$filter" \
          --seed $((100 + round)) "${flags[@]}" --out "$out" >/dev/null 2>&1
        spp=$(spp_of "$out")
        errors=$(judge "$out/final.exr" "$refs" "$scene")
        echo "$scene $round $sampler $filter $spp $errors" | tee -a "$tmp/runs"
        if [ "$filter" = grid ] && [ "${ref##*/}" = buffers.exr ]; then
          errors=$(nrmse_pair 'blend with a perfect filter' "$out/buffers.exr" "$ref" --perfect-filter)
          echo "$scene $round $sampler perfect $spp $errors" | tee -a "$tmp/runs"
        fi
      done
    done
  done
done
python3 - "$tmp/runs" <<'PY'
import collections, statistics, sys
rows = [l.split() for l in open(sys.argv[1]).read().splitlines()[1:]]
runs = collections.defaultdict(list)
paired = collections.defaultdict(dict)  # (scene, filter, round) -> sampler -> (hdr, display)
for scene, rnd, sampler, filt, spp, hdr, disp in rows:
    runs[(scene, sampler, filt)].append((float(spp), float(hdr), float(disp)))
    paired[(scene, filt, rnd)][sampler] = (float(hdr), float(disp))
med = {k: [statistics.median(v[i] for v in vals) for i in range(3)] for k, vals in runs.items()}
print("\nmedians over rounds; ratio = sobol / independent of the medians")
print("%-10s %-8s %16s %22s %22s" % ("scene", "filter", "spp sobol/indep", "HDR % (ratio)", "display % (ratio)"))
filters = [f for f in ("none", "grid", "perfect") if any(r[3] == f for r in rows)]
for scene in dict.fromkeys(r[0] for r in rows):
    for filt in filters:
        s, i = med[(scene, "sobol", filt)], med[(scene, "independent", filt)]
        print("%-10s %-8s %7.0f / %-7.0f %7.2f/%-6.2f (%.2f) %7.2f/%-6.2f (%.2f)" %
              (scene, filt, s[0], i[0], s[1], i[1], s[1] / i[1], s[2], i[2], s[2] / i[2]))
# The same rounds paired (one seed, both samplers back to back): how far single rounds spread.
print("\nper-round ratios sobol / independent: median [min - max]")
for scene in dict.fromkeys(r[0] for r in rows):
    for filt in filters:
        pairs = [v for (sc, f, _), v in paired.items() if sc == scene and f == filt and len(v) == 2]
        cells = []
        for k, name in ((0, "HDR"), (1, "display")):
            r = [v["sobol"][k] / v["independent"][k] for v in pairs]
            cells.append("%s %.3f [%.3f - %.3f]" % (name, statistics.median(r), min(r), max(r)))
        print("%-10s %-8s %s   %s" % (scene, filt, cells[0], cells[1]))
PY
