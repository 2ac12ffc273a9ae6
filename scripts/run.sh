#!/usr/bin/env bash
# The main job: installs what is missing, builds in Release and runs the headline example.
# Its outputs go to out/ (JSON lines) and a readable summary to the terminal.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
jobs=$(nproc 2>/dev/null || echo 2)
cmake --preset release -DSTOKESCONTACT_BUILD_TESTS=OFF -DSTOKESCONTACT_BUILD_BENCHMARKS=OFF
cmake --build --preset release -j "$jobs" --target fig4_spheres
mkdir -p out
# Broms & Tornberg Fig. 4 with RPY mobility, 20 configurations per density; extra flags
# (e.g. --mobility multiblob --configs 200) go to the driver.
./build/release/examples/fig4_spheres --mobility rpy --configs 20 --output out/fig4_spheres.jsonl "$@"
