#!/usr/bin/env bash
# Every contact solver on the first steps of dense Brownian rods (L/D = 5, 400 rods, aligned
# start, dt D_R = 5e-4, overlap-ends directions at 0.3 rad), at three packings and two
# separation margins: the per-step diagnostics of brownian_rods --progress 1, one log per run
# (OUT/eta<ETA>_margin<M>_<solver>.log), each run under `timeout` (a run the stepper cannot
# continue ends with its message as the log's last line). Two runs at a time, one OpenMP
# thread each (two processes of two spinning OpenMP threads on two cores are 2-4x slower).
#
#   scripts/dense_rod_solver_cost.sh BUILD_DIR OUT [STEPS=40] [TIMEOUT_S=150] [SOLVERS]
# SOLVERS: a space-separated list, default "default lcp-bbpgd lcp-apgd lcp-newton".
#   /usr/bin/python3 scripts/melt_log_table.py --cost OUT/*.log
set -euo pipefail
build=${1:?usage: dense_rod_solver_cost.sh BUILD_DIR OUT [STEPS] [TIMEOUT_S] [SOLVERS]}
out=${2:?usage: dense_rod_solver_cost.sh BUILD_DIR OUT [STEPS] [TIMEOUT_S] [SOLVERS]}
steps=${3:-40}
limit=${4:-150}
solvers=${5:-default lcp-bbpgd lcp-apgd lcp-newton}
mkdir -p "$out"
melt=$(awk -v n="$steps" 'BEGIN { printf "%.6g", n * 5e-4 }')
run() {  # eta margin solver
  local log="$out/eta$1_margin$2_$3.log"
  OMP_NUM_THREADS=1 timeout "$limit" "$build/examples/brownian_rods" --eta "$1" --n 400 --u0 0 --dt 5e-4 \
    --melt-dt 5e-4 --equilibrate 0 --average 0.001 --start aligned --melt "$melt" --progress 1 \
    --directions overlap-ends --overlap-ends-angle 0.3 --separation-margin "$2" --solver "$3" --seed 1 \
    > /dev/null 2> "$log" || { status=$?; [ "$status" -eq 124 ] && echo "stopped by the ${limit} s timeout" >> "$log"; true; }
}
jobs_running=0
for eta in 0.31 0.40 0.45; do
  for margin in 1e-3 0.3; do
    for solver in $solvers; do
      run "$eta" "$margin" "$solver" &
      jobs_running=$((jobs_running + 1))
      if [ "$jobs_running" -ge 2 ]; then wait -n; jobs_running=$((jobs_running - 1)); fi
    done
  done
done
wait
