#!/bin/bash
# Spreads one pxf render over a Slurm cluster: N array tasks, one shard each, then a merge job that
# starts when all of them succeeded. Prints the two job ids.
#   scripts/slurm/submit.sh N OUT SPP --scene cornell --size 1920x1080 [--seed S ...]
# The options after SPP go to every shard and to the merge, so give only options both accept
# (scene, size, seed, path-tracing, filter and tone-map options). OUT must be on a file system
# every node sees.
set -euo pipefail
if [ $# -lt 3 ]; then
  sed -n '2,8p' "$0"
  exit 2
fi
here=$(cd "$(dirname "$0")" && pwd)
n=$1 out=$2 spp=$3
shift 3
mkdir -p "$out"
array=$(sbatch --parsable --array=0-$((n - 1)) --chdir="$out" "$here/render_shards.sbatch" "$(realpath "$out")" "$spp" "$@")
array=${array%%;*}
merge=$(sbatch --parsable --dependency=afterok:"$array" --chdir="$out" "$here/merge.sbatch" "$(realpath "$out")" "$@")
echo "shards: job $array (array 0-$((n - 1))), merge: job ${merge%%;*}; result in $out/merged"
