#!/bin/bash
# before/after on the first 40 steps of the aligned melt: default solver, one thread
for eta in 0.40 0.45; do for margin in 1e-3 0.3; do for seed in 1 2; do for b in br br_new; do
  log=eta${eta}_m${margin}_s${seed}_${b}.log
  timeout 300 /tmp/rodprof/$b --eta $eta --n 400 --u0 0 --dt 5e-4 --melt-dt 5e-4 --equilibrate 0 --average 0.001 --start aligned --melt 0.02 --progress 1 --directions overlap-ends --overlap-ends-angle 0.3 --separation-margin $margin --solver default --seed $seed > /dev/null 2> $log || echo "rc $?" >> $log
done; done; done; done
echo DONE > done.txt
