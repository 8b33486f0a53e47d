#!/bin/bash
# Submits an RDM bake as a Slurm job array of N shards plus a merge that starts after every
# shard succeeded (docs/deploy.md "Slurm"). Prints what it submitted on stderr and the two
# job ids, "ARRAY_ID MERGE_ID", on stdout.
#
#   deploy/slurm/submit.sh SCENE OUT N [rdm bake options]
#   e.g. RDM=/opt/rdm/bin/rdm RDM_CPUS=8 deploy/slurm/submit.sh scene.json /shared/bake 16 --spp 64
#
# SCENE: a scene JSON every node can read; OUT: a directory on a shared file system (gets
# shard-0 .. shard-N-1, atlas/ and logs/). Environment: RDM the rdm binary as the nodes see
# it (default: rdm on PATH), RDM_CPUS CPUs per shard (default 4), RDM_MEM memory per shard
# (default 4G; about 28 bytes per texel of the shard), RDM_PARTITION, RDM_TIME (time limit
# per shard, default 04:00:00).
set -euo pipefail

die() {
  echo "submit.sh: $*" >&2
  exit 1
}
(($# >= 3)) || die "usage: submit.sh SCENE OUT N [rdm bake options]"
scene=$1 out=$2 count=$3
shift 3
[[ $count =~ ^[1-9][0-9]*$ ]] || die "N must be a positive integer, got '$count'"
[[ -r $scene ]] || die "cannot read the scene $scene"
command -v sbatch > /dev/null || die "sbatch not found: run this on a Slurm submit host"
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
scene=$(realpath "$scene")
mkdir -p "$out/logs" || die "cannot create $out/logs"
out=$(realpath "$out")

common=(--parsable --export=ALL --mem="${RDM_MEM:-4G}")
[[ -n ${RDM_PARTITION:-} ]] && common+=(--partition="$RDM_PARTITION")

array_id=$(sbatch "${common[@]}" --array="0-$((count - 1))" --cpus-per-task="${RDM_CPUS:-4}" \
  --time="${RDM_TIME:-04:00:00}" --output="$out/logs/shard-%a.log" \
  "$here/bake_array.sbatch" "$scene" "$out" "$count" "$@") || die "sbatch of the bake array failed"
array_id=${array_id%%;*}  # --parsable prints "ID" or "ID;CLUSTER"
merge_id=$(sbatch "${common[@]}" --dependency="afterok:$array_id" --kill-on-invalid-dep=yes \
  --output="$out/logs/merge.log" "$here/merge.sbatch" "$out" "$count") ||
  die "sbatch of the merge failed (the bake array $array_id is queued: scancel $array_id)"
merge_id=${merge_id%%;*}
echo "submitted: bake array $array_id ($count shards of $scene), merge $merge_id into $out/atlas" >&2
echo "$array_id $merge_id"
