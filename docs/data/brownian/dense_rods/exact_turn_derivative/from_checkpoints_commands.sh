#!/bin/bash
C=/work/main/docs/data/brownian/dense_rods/isotropic_nematic
for f in $C/checkpointed/*.checkpoint $C/one_stream/*.checkpoint; do
  name=$(basename $f .checkpoint)
  eta=$(echo $name | grep -o 'eta0\.[0-9]*' | head -1 | cut -c4-)
  case $name in *to_0.46*|compressed_eta0.46*) eta=0.46;; *compressed_eta0.50*) eta=0.50;; *expanded_eta0.42*) eta=0.42;; esac
  for margin in 1e-3 0.3; do for b in br br_new; do
    timeout 200 /tmp/rodprof/$b --eta $eta --n 400 --u0 0 --dt 5e-4 --melt-dt 5e-4 --equilibrate 0 --average 0.0001 --melt 0.005 --progress 1 --directions overlap-ends --overlap-ends-angle 0.3 --separation-margin $margin --solver default --seed 1 --load-state $f > /dev/null 2> ck/${name}_m${margin}_${b}.log || echo "rc $?" >> ck/${name}_m${margin}_${b}.log
  done; done
done
echo DONE > ck/done.txt
