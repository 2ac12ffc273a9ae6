#!/usr/bin/env bash
# The contact-solver experiments of docs/results.md (Broms & Tornberg Fig. 4, Table 1, the
# speed-versus-error comparison, contact over the whole step, the rod chains of Fig. 7, the
# biaxial compression of Fig. 8 with Table 2, the random boomerangs of Fig. 9, the contact step
# at scale and on dense networks, the equation of state of Brownian hard spheres). Builds the
# drivers in Release, writes JSON lines to docs/data/ and the printed summaries to
# docs/data/*.txt. About an hour on 2 cores.
# Usage: scripts/run_experiments.sh [fig4|fig4-multiblob|table1|speed|whole-step|fig7|fig8|fig9|fig9-surface-blobs|scale|brownian] ...
#        (default: all but fig9-surface-blobs and brownian; brownian alone takes about 60 minutes)
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --preset release -DSTOKESCONTACT_BUILD_TESTS=OFF -DSTOKESCONTACT_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build --preset release -j "$(nproc 2>/dev/null || echo 2)" --target fig4_spheres speed_vs_error \
  continuous_detection fig7_rod_chains fig8_biaxial fig9_boomerangs contact_step_scaling dense_contact_networks \
  brownian_hard_spheres
bin=build/release/examples
data=docs/data
mkdir -p "$data"
run() {  # name, command...
  local name=$1
  shift
  echo "== $name: $*"
  "$@" --output "$data/$name.jsonl" | tee "$data/$name.txt"
}
parts=("$@")
[ ${#parts[@]} -eq 0 ] && parts=(fig4 fig4-multiblob table1 speed whole-step fig7 fig8 fig9 scale)
for part in "${parts[@]}"; do
  case $part in
    fig4)
      run fig4_rpy_default $bin/fig4_spheres --mobility rpy --pairs
      run fig4_rpy_barrier_slsqp $bin/fig4_spheres --mobility rpy --solver barrier-slsqp --configs 50 --pairs
      run fig4_rpy_barrier_working_set $bin/fig4_spheres --mobility rpy --solver barrier-working-set ;;
    fig4-multiblob)  # the paper's mobility: ~20 s per configuration on one core
      run fig4_multiblob_default $bin/fig4_spheres --mobility multiblob --configs 10 ;;
    table1)
      run table1_rpy_default $bin/fig4_spheres --table1 --mobility rpy --solver default
      run table1_rpy_barrier_slsqp $bin/fig4_spheres --table1 --mobility rpy --solver barrier-slsqp --configs 10
      run table1_rpy_barrier_working_set $bin/fig4_spheres --table1 --mobility rpy --solver barrier-working-set ;;
    fig9)  # 40 boomerangs, 200 configurations per run: about a minute in all
      for solver in default lcp-newton barrier-slsqp; do
        for mobility in free-draining multiblob; do
          run "fig9_${mobility//-/_}_${solver//-/_}" $bin/fig9_boomerangs --mobility $mobility --solver $solver
        done
      done
      /usr/bin/python3 scripts/plot_fig9.py $data/fig9_multiblob_default.jsonl $data/fig9_free_draining_default.jsonl \
        docs/figures/fig9_boomerangs.png
      $bin/fig9_boomerangs --resolution --output $data/fig9_resolution.jsonl | tee $data/fig9_resolution.txt ;;
    fig9-surface-blobs)  # resolved multiblob boomerangs (236 blobs each): ~40 s per configuration
      run fig9_multiblob_surface_default $bin/fig9_boomerangs --mobility multiblob --blob-model surface --configs 10 ;;
    speed)  # every solver on the sphere, rod-chain and boomerang scenes (about 8 minutes)
      run speed_vs_error $bin/speed_vs_error --mobility rpy --configs 10 --jammed-spheres 100
      runs=$(mktemp -d)
      for solver in default lcp-bbpgd lcp-apgd lcp-newton barrier-slsqp barrier-mma barrier-working-set; do
        $bin/fig7_rod_chains --cost matrix-free --solver $solver --output "$runs/fig7_$solver.jsonl" >/dev/null
        $bin/fig9_boomerangs --mobility free-draining --cost matrix-free --solver $solver \
          --output "$runs/fig9_fd_$solver.jsonl" >/dev/null
        $bin/fig9_boomerangs --mobility multiblob --cost matrix-free --solver $solver \
          --output "$runs/fig9_mb_$solver.jsonl" >/dev/null
      done
      /usr/bin/python3 scripts/speed_vs_error_shapes.py $data/speed_vs_error_shapes.jsonl "$runs"/*.jsonl \
        | tee $data/speed_vs_error_shapes.txt
      rm -r "$runs"
      /usr/bin/python3 scripts/plot_speed_vs_error.py $data/speed_vs_error.jsonl $data/speed_vs_error_shapes.jsonl \
        docs/figures/speed_vs_error.png ;;
    whole-step)  # no tunnelling, Galilean invariance, detection cost (~5 minutes)
      run fig4_rpy_end_of_step $bin/fig4_spheres --mobility rpy --end-of-step
      run fig4_rpy_whole_step $bin/fig4_spheres --mobility rpy
      run fig4_rpy_whole_step_relative $bin/fig4_spheres --mobility rpy --d-try-rule relative
      run continuous_detection $bin/continuous_detection ;;
    fig7)  # 700 chains per run, about a second each
      run fig7_free_draining_default_particle $bin/fig7_rod_chains --solver default --directions particle
      run fig7_free_draining_lcp-newton_particle $bin/fig7_rod_chains --solver lcp-newton --directions particle
      run fig7_free_draining_default_line $bin/fig7_rod_chains --solver default --directions line
      /usr/bin/python3 scripts/plot_fig7.py $data/fig7_free_draining_default_particle.jsonl docs/figures/fig7_rod_chains.png ;;
    fig8)  # the six (d_hat, dt) of Table 2 per run, seconds each
      for solver in default lcp-newton; do
        for directions in particle surface line; do
          run fig8_free_draining_${solver}_$directions $bin/fig8_biaxial --solver $solver --directions $directions
        done
      done
      /usr/bin/python3 scripts/plot_fig8.py docs/figures/fig8_biaxial.png $data/fig8_free_draining_*.jsonl ;;
    scale)  # 1e3-1e6 spheres, one process per cost mode (peak memory is per process); ~8 minutes (3 repeats per size)
      mkdir -p $data/scaling
      $bin/contact_step_scaling --sizes 1000,3000,10000,30000,100000,300000,1000000 --cost blocks \
        --output $data/scaling/blocks.jsonl | tee $data/scaling/contact_step_scaling.txt
      $bin/contact_step_scaling --sizes 1000,3000,10000,30000,100000,300000,1000000 --cost matrix-free \
        --output $data/scaling/matrix_free.jsonl | tee -a $data/scaling/contact_step_scaling.txt
      $bin/contact_step_scaling --sizes 1000,3000,10000,30000 --cost formed --formed-max 30000 \
        --output $data/scaling/formed.jsonl | tee -a $data/scaling/contact_step_scaling.txt
      cat $data/scaling/{blocks,matrix_free,formed}.jsonl > $data/scaling/contact_step_scaling.jsonl
      rm $data/scaling/{blocks,matrix_free,formed}.jsonl
      /usr/bin/python3 scripts/plot_contact_step_scaling.py $data/scaling/contact_step_scaling.jsonl \
        docs/figures/contact_step_scaling.png
      run scaling/dense_contact_networks $bin/dense_contact_networks ;;
    brownian)  # hard spheres: 5 packings x 3 step sizes (~45 min), then every solver at dt 1e-4 (~5 min)
      mkdir -p $data/brownian
      run brownian/hard_sphere_eos $bin/brownian_hard_spheres --phi 0.05,0.15,0.25,0.35,0.45 --n 400 \
        --dt 4e-4,1e-4,2.5e-5 --equilibrate 1 --average 3 --seed 2
      /usr/bin/python3 scripts/plot_hard_sphere_eos.py $data/brownian/hard_sphere_eos.jsonl \
        docs/figures/hard_sphere_eos.png
      run brownian/hard_sphere_solver_cost $bin/brownian_hard_spheres --phi 0.05,0.15,0.25,0.35,0.45 --n 400 \
        --dt 1e-4 --equilibrate 0.2 --average 0.3 --seed 3 --solver default,lcp-bbpgd,lcp-apgd,lcp-newton
      # rods, passive and self-propelled (~7 min, Yan Fig. 6)
      run brownian/rods_phi002_dt1e-3 $bin/brownian_rods --n 1000 --phi 0.02 --u0 0,1,2,4 --dt 1e-3 \
        --equilibrate 0.2 --average 2 --seed 1
      run brownian/rods_phi002_dt2.5e-4 $bin/brownian_rods --n 1000 --phi 0.02 --u0 0 --dt 2.5e-4 \
        --equilibrate 0.2 --average 1 --seed 1 ;;
    *) echo "unknown part $part" >&2; exit 2 ;;
  esac
done
