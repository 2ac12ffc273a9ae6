#!/bin/bash
# BR: the build of 9424944 (before), BR_NEW: the same with exact_turn_derivative.patch applied
# (after); each built as
#   g++ -O2 -g -fno-omit-frame-pointer -DNDEBUG -DNLOPT_DLL -DSTOKESCONTACT_HAS_NLOPT=1 -I examples -I include -isystem /usr/include/eigen3 \
#       -std=gnu++20 examples/brownian_rods.cpp MAIN.cpp -o BINARY -lnlopt
# with MAIN.cpp: namespace brownian_rods { int main(int, char**); } int main(int a, char** v) { return brownian_rods::main(a, v); }
BR=${BR:?the build before}; BR_NEW=${BR_NEW:?the build after}
# before/after on the first 40 steps of the aligned melt: default solver, one thread
for eta in 0.40 0.45; do for margin in 1e-3 0.3; do for seed in 1 2; do for b in br br_new; do bin=$BR; [ $b = br_new ] && bin=$BR_NEW
  log=eta${eta}_m${margin}_s${seed}_${b}.log
  timeout 300 $bin --eta $eta --n 400 --u0 0 --dt 5e-4 --melt-dt 5e-4 --equilibrate 0 --average 0.001 --start aligned --melt 0.02 --progress 1 --directions overlap-ends --overlap-ends-angle 0.3 --separation-margin $margin --solver default --seed $seed > /dev/null 2> $log || echo "rc $?" >> $log
done; done; done; done
echo DONE > done.txt
