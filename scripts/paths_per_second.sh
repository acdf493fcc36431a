#!/usr/bin/env bash
# Paths/s of several pxf builds or settings, back to back: ROUNDS rounds, each running every
# variant once in the order given (`pxf bench pathtracer --size 128x128`, FRAMES timed frames,
# default 150), then per variant the median over rounds and its ratio to the first variant's.
# A shared machine drifts between minutes, so only ratios from one run of this script compare.
# Usage: scripts/paths_per_second.sh ROUNDS SCENE LABEL=BINARY[:EXTRA FLAGS] ...
#   FRAMES=60 scripts/paths_per_second.sh 9 kitchen old=../old/build/app/pxf \
#     new=build/app/pxf "new_independent=build/app/pxf:--sampler independent"
set -euo pipefail
usage="usage: [FRAMES=N] scripts/paths_per_second.sh ROUNDS SCENE LABEL=BINARY[:EXTRA FLAGS] ..."
rounds=${1:?$usage}
scene=${2:?$usage}
shift 2
[ $# -gt 0 ] || { echo "$usage" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for round in $(seq "$rounds"); do
  for spec in "$@"; do
    label=${spec%%=*}
    rest=${spec#*=}
    binary=${rest%%:*}
    extra=""
    [[ $rest == *:* ]] && extra=${rest#*:}
    # shellcheck disable=SC2086  # the extra flags are meant to split into words
    line=$("$binary" bench pathtracer --scene "$scene" --size 128x128 --timed-frames "${FRAMES:-150}" $extra \
      --out "$tmp/bench" 2>&1 | grep -o '[0-9.]* M paths/s' | head -1) || { echo "$label: no paths/s from $binary" >&2; exit 1; }
    echo "$label ${line%% *}" | tee -a "$tmp/runs"
  done
done
python3 - "$tmp/runs" <<'PY'
import statistics, sys
runs = {}
for line in open(sys.argv[1]):
    label, value = line.split()
    runs.setdefault(label, []).append(float(value))
first = None
print("\nmedian M paths/s over rounds, ratio to the first variant")
for label, values in runs.items():
    median = statistics.median(values)
    first = first or median
    print("%-20s %6.3f  %.3f  [%s]" % (label, median, median / first, " ".join("%.2f" % v for v in values)))
PY
