#!/usr/bin/env bash
# Installs the Debian packages StokesContact needs, only those that are missing.
set -euo pipefail
# nlohmann-json3-dev: scene files (stokescontact-run); python3-vtk9 and python3-numpy: the tests
# vtk_readback and scene_output_readback read the VTK output back with VTK's own reader and its
# numpy support (python3-vtk9 does not pull numpy in without its recommended packages);
# python3-matplotlib: the plot scripts of docs/results.md (scripts/plot_*.py).
packages=(g++ cmake make libeigen3-dev libnlopt-cxx-dev libgtest-dev libbenchmark-dev
          nlohmann-json3-dev python3-vtk9 python3-numpy python3-matplotlib)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
"${sudo_cmd[@]}" apt-get update
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y --no-install-recommends "${missing[@]}"
