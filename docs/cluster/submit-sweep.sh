#!/bin/bash
# Submits an array sweep (docs/cluster/sweep.sbatch, TASKS array tasks) and its merge
# (docs/cluster/merge.sbatch), which starts when every task has succeeded.
#
#   TASKS=8 bash docs/cluster/submit-sweep.sh sweeps/bandwidth.toml runs/bandwidth
#
# Build the tables the sweep needs once before (a layered stack not in the cache: run
# `strata sweep SWEEP --list` and `strata solve` one case with the same --cache-dir),
# otherwise every task builds them.
set -euo pipefail
here=$(dirname "$0")
sweep=${1:-sweeps/bandwidth.toml}
runs=${2:-runs/bandwidth}
tasks=${TASKS:-8}
jid=$(sbatch --parsable --array="1-${tasks}" "$here/sweep.sbatch" "$sweep" "$runs" "$tasks")
sbatch --dependency="afterok:${jid}" "$here/merge.sbatch" "$runs"
