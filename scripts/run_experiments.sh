#!/usr/bin/env bash
# The contact-solver experiments of docs/results.md (Broms & Tornberg Fig. 4, Table 1, Fig. 9 and
# the speed-versus-error comparison). Builds the drivers in Release, writes JSON lines to
# docs/data/ and the printed summaries to docs/data/*.txt. About 45 minutes on 2 cores.
# Usage: scripts/run_experiments.sh [fig4|fig4-multiblob|table1|fig9|fig9-surface-blobs|speed] ... (default: all)
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --preset release -DSTOKESCONTACT_BUILD_TESTS=OFF -DSTOKESCONTACT_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build --preset release -j "$(nproc 2>/dev/null || echo 2)" --target fig4_spheres fig9_boomerangs speed_vs_error
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
[ ${#parts[@]} -eq 0 ] && parts=(fig4 fig4-multiblob table1 fig9 speed)
for part in "${parts[@]}"; do
  case $part in
    fig4)
      run fig4_rpy_default $bin/fig4_spheres --mobility rpy --pairs
      run fig4_rpy_barrier_slsqp $bin/fig4_spheres --mobility rpy --solver barrier-slsqp --configs 50 --pairs ;;
    fig4-multiblob)  # the paper's mobility: ~20 s per configuration on one core
      run fig4_multiblob_default $bin/fig4_spheres --mobility multiblob --configs 10 ;;
    table1)
      run table1_rpy_default $bin/fig4_spheres --table1 --mobility rpy --solver default
      run table1_rpy_barrier_slsqp $bin/fig4_spheres --table1 --mobility rpy --solver barrier-slsqp --configs 10 ;;
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
    speed)
      run speed_vs_error $bin/speed_vs_error --mobility rpy --configs 10 --jammed-spheres 100 ;;
    *) echo "unknown part $part" >&2; exit 2 ;;
  esac
done
