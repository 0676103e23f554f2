#!/usr/bin/env bash
# Submits a `fleetmap bench` sweep to Slurm: a job array of SHARDS tasks (bench_array.sbatch, one
# shard each, into OUT_DIR/shard_K) and a job that runs when all of them succeeded and combines the
# shards into OUT_DIR/all (results.csv, summary.csv, summary.md, plots). Logs go to OUT_DIR/logs/.
#
#   bench/slurm/submit.sh [--wait] SHARDS OUT_DIR [fleetmap bench flags...]
#   bench/slurm/submit.sh 16 /scratch/$USER/wave_paper --sweep scenarios/sweeps/wave_paper.yaml
#
# Prints the two job ids. --wait: returns when the combine job has ended, with its exit code (a
# failed shard cancels the combine job). Environment: FLEETMAP, the fleetmap executable (default:
# `fleetmap` on the PATH; it must be reachable from the compute nodes); FLEETMAP_SBATCH_ARGS,
# extra sbatch options for both jobs, e.g. "--partition=short --time=1:00:00 --cpus-per-task=8".
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
wait=()
if [[ ${1:-} == --wait ]]; then
  wait=(--wait)
  shift
fi
usage="usage: submit.sh [--wait] SHARDS OUT_DIR [fleetmap bench flags...]"
shards=${1:?$usage}
out=${2:?$usage}
shift 2
if ! [[ $shards =~ ^[1-9][0-9]*$ ]]; then
  echo "submit.sh: SHARDS must be a whole number >= 1, got '$shards'" >&2
  exit 2
fi
fleetmap=${FLEETMAP:-$(command -v fleetmap || true)}
if [[ -z $fleetmap || ! -x $fleetmap ]]; then
  echo "submit.sh: no fleetmap executable: set FLEETMAP=/path/to/fleetmap or put it on the PATH" >&2
  exit 2
fi
fleetmap=$(cd "$(dirname "$fleetmap")" && pwd)/$(basename "$fleetmap")
mkdir -p "$out/logs"
out=$(cd "$out" && pwd)
read -r -a extra <<<"${FLEETMAP_SBATCH_ARGS:-}"

array=$(FLEETMAP=$fleetmap sbatch --parsable --export=ALL --array="1-$shards" --output="$out/logs/shard_%a.out" \
  "${extra[@]}" "$here/bench_array.sbatch" "$out" "$@")
array=${array%%;*}
echo "shards: job $array"

dirs=()
for ((k = 1; k <= shards; k++)); do dirs+=("'$out/shard_$k'"); done
if ! combine=$(sbatch --parsable "${wait[@]}" --job-name=fleetmap-combine --dependency="afterok:$array" \
  --kill-on-invalid-dep=yes --output="$out/logs/combine.out" "${extra[@]}" \
  --wrap="'$fleetmap' bench --combine ${dirs[*]} --out '$out/all'"); then
  echo "submit.sh: the combine job failed or was cancelled because a shard failed: see $out/logs/" >&2
  exit 1
fi
echo "combine: job ${combine%%;*} -> $out/all"
