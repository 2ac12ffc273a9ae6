#!/usr/bin/env bash
# The main job: installs what is missing, builds the scene runner in Release and runs the
# headline scene, Broms & Tornberg Fig. 8 (30 rods in biaxial compression, to T = 9). It prints
# a summary and writes out/biaxial_rods/ (steps.jsonl, summary.json, the VTK series
# bodies.pvd for ParaView). Another scene: scripts/run.sh examples/scenes/NAME.json; extra
# flags (e.g. --max-steps 100) go to stokescontact-run.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
jobs=$(nproc 2>/dev/null || echo 2)
cmake --preset release -DSTOKESCONTACT_BUILD_TESTS=OFF -DSTOKESCONTACT_BUILD_BENCHMARKS=OFF \
  -DSTOKESCONTACT_BUILD_EXAMPLES=OFF
cmake --build --preset release -j "$jobs" --target stokescontact-run
scene=examples/scenes/biaxial_rods.json
if [ $# -gt 0 ] && [[ "$1" == *.json ]]; then
  scene=$1
  shift
fi
mkdir -p out
# --replace: a finished earlier run of the scene is replaced once this one has ended.
./build/release/apps/stokescontact-run "$scene" --replace "$@"
