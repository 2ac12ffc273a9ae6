#!/bin/bash
# BR: the build of 9424944 (before), BR_NEW: the same with exact_turn_derivative.patch applied
# (after); each built as
#   g++ -O2 -g -fno-omit-frame-pointer -DNDEBUG -DNLOPT_DLL -DSTOKESCONTACT_HAS_NLOPT=1 -I examples -I include -isystem /usr/include/eigen3 \
#       -std=gnu++20 examples/brownian_rods.cpp MAIN.cpp -o BINARY -lnlopt
# with MAIN.cpp: namespace brownian_rods { int main(int, char**); } int main(int a, char** v) { return brownian_rods::main(a, v); }
BR=${BR:?the build before}; BR_NEW=${BR_NEW:?the build after}
C=docs/data/brownian/dense_rods/isotropic_nematic; mkdir -p ck
for f in $C/checkpointed/*.checkpoint $C/one_stream/*.checkpoint; do
  name=$(basename $f .checkpoint)
  eta=$(echo $name | grep -o 'eta0\.[0-9]*' | head -1 | cut -c4-)
  case $name in *to_0.46*|compressed_eta0.46*) eta=0.46;; *compressed_eta0.50*) eta=0.50;; *expanded_eta0.42*) eta=0.42;; esac
  for margin in 1e-3 0.3; do for b in br br_new; do bin=$BR; [ $b = br_new ] && bin=$BR_NEW
    timeout 200 $bin --eta $eta --n 400 --u0 0 --dt 5e-4 --melt-dt 5e-4 --equilibrate 0 --average 0.0001 --melt 0.005 --progress 1 --directions overlap-ends --overlap-ends-angle 0.3 --separation-margin $margin --solver default --seed 1 --load-state $f > /dev/null 2> ck/${name}_m${margin}_${b}.log || echo "rc $?" >> ck/${name}_m${margin}_${b}.log
  done; done
done
echo DONE > ck/done.txt
