#!/usr/bin/env bash
# The main job: installs what is missing, builds in Release and runs the headline example.
# Its outputs go to out/ (JSON lines) and a readable summary to the terminal.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
jobs=$(nproc 2>/dev/null || echo 2)
cmake --preset release -DSTOKESCONTACT_BUILD_TESTS=OFF -DSTOKESCONTACT_BUILD_BENCHMARKS=OFF
cmake --build --preset release -j "$jobs" --target geometry_demo
mkdir -p out
./build/release/examples/geometry_demo --output out/geometry_demo.jsonl "$@"
