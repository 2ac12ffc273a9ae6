run() { # eta margin chord
  E=""; [ $3 != 0 ] && E="CHORD_RODS=$3"
  env $E OMP_NUM_THREADS=1 timeout 200 ./bin/brownian_rods_exp --eta $1 --n 400 --u0 0 --dt 5e-4 --melt-dt 5e-4 --equilibrate 0 --average 0.001 --start aligned --melt 0.02 --progress 1 --directions overlap-ends --overlap-ends-angle 0.3 --separation-margin $2 --solver default --seed 1 > /dev/null 2> rods_exp/eta$1_margin$2_chord$3.log || echo "exit $?" >> rods_exp/eta$1_margin$2_chord$3.log
}
n=0
for eta in 0.31 0.40 0.45; do for m in 1e-3 0.3; do for c in $CS; do
  run $eta $m $c & n=$((n+1)); if [ $n -ge 2 ]; then wait -n; n=$((n-1)); fi
done; done; done; wait
