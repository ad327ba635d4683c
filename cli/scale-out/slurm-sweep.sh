#!/usr/bin/env bash
# A `compensator sweep` as a Slurm job array: one shard per array task,
# merged in shard order into what the single run writes (docs/sweep.md).
#
#   sbatch --array=1-64 cli/scale-out/slurm-sweep.sh OUT_DIR \
#       sweep --params my.toml --vary plunger.diameter=1% --samples 1000000
#   # when the array has finished:
#   cli/scale-out/slurm-sweep.sh --merge OUT_DIR > sweep.csv
#
# Each task runs `compensator ARGS --shard K/N -o OUT_DIR/shard-K-of-N.csv`
# (the CLI writes the file through a `.partial` name, renamed when the
# shard is complete), with K its place in the array (1-based, whatever
# the array's first index) and N the array's size. The array must be a
# contiguous range (`--array=1-64` or `0-63`, a `%limit` allowed; not a
# step or a list). OUT_DIR must be on a filesystem the nodes share.
# Environment: COMPENSATOR (the binary, default `compensator` on PATH);
# the task's threads are SLURM_CPUS_PER_TASK (default 1).
# Exit status: the CLI's (1: some rows could not be computed, the shard is
# still complete), 2 for a misuse of this script.
#
#SBATCH --job-name=compensator-sweep
#SBATCH --cpus-per-task=1
#SBATCH --output=slurm-%x-%A_%a.log
set -euo pipefail

usage() {
    echo "usage: slurm-sweep.sh OUT_DIR sweep ARGS... (as an array task) | slurm-sweep.sh --merge OUT_DIR" >&2
    exit 2
}

# `K N` of this array task, from Slurm's variables.
shard_of_task() {
    local id=${SLURM_ARRAY_TASK_ID:-} min=${SLURM_ARRAY_TASK_MIN:-} max=${SLURM_ARRAY_TASK_MAX:-}
    local count=${SLURM_ARRAY_TASK_COUNT:-}
    if [ -z "$id" ] || [ -z "$min" ] || [ -z "$max" ] || [ -z "$count" ]; then
        echo "slurm-sweep.sh: not a Slurm array task (SLURM_ARRAY_TASK_ID/MIN/MAX/COUNT unset): submit with sbatch --array=1-N" >&2
        exit 2
    fi
    if [ $((max - min + 1)) -ne "$count" ]; then
        echo "slurm-sweep.sh: the array $min-$max has $count tasks: give a contiguous range (--array=1-N), not a step or a list" >&2
        exit 2
    fi
    echo "$((id - min + 1)) $count"
}

if [ "${1:-}" = --merge ]; then
    [ $# -eq 2 ] || usage
    dir=$2
    shopt -s nullglob
    files=("$dir"/shard-*-of-*.csv)
    [ ${#files[@]} -gt 0 ] || { echo "slurm-sweep.sh: no shard-K-of-N.csv in $dir" >&2; exit 2; }
    n=${files[0]##*-of-}
    n=${n%.csv}
    for k in $(seq 1 "$n"); do
        [ -f "$dir/shard-$k-of-$n.csv" ] || { echo "slurm-sweep.sh: $dir/shard-$k-of-$n.csv is missing (task $k not finished?)" >&2; exit 2; }
    done
    [ ${#files[@]} -eq "$n" ] || { echo "slurm-sweep.sh: $dir holds shards of more than one array (of $n and others)" >&2; exit 2; }
    for k in $(seq 1 "$n"); do
        cat "$dir/shard-$k-of-$n.csv"
    done
    exit 0
fi

[ $# -ge 2 ] || usage
dir=$1
shift
shard=$(shard_of_task)
read -r k n <<<"$shard"
mkdir -p "$dir"
export RAYON_NUM_THREADS=${SLURM_CPUS_PER_TASK:-1}
exec "${COMPENSATOR:-compensator}" "$@" --shard "$k/$n" -o "$dir/shard-$k-of-$n.csv"
