#!/usr/bin/env bash
# The test command: installs what is missing, builds with warnings as errors and runs the
# default test suite. `scripts/test.sh sanitize` does the same in the address+undefined
# sanitizer build; `scripts/test.sh release -L geometry` passes extra arguments to ctest.
# The full-size experiments (label long) run with `ctest --preset long` after a release build.
set -euo pipefail
cd "$(dirname "$0")/.."
preset=${1:-release}
shift || true
scripts/install-deps.sh
jobs=$(nproc 2>/dev/null || echo 2)
cmake --preset "$preset"
cmake --build --preset "$preset" -j "$jobs"
ctest --preset "$preset" -j "$jobs" "$@"
