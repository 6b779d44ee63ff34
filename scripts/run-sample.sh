#!/usr/bin/env bash
# README command 1: install dependencies, build wul3d (Release, build/), and cluster the four
# shipped tabletop frames (data/samples/uois_tabletop) into out/sample/.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j2
scripts/install-python.sh build || true  # the Python module (docs/PYTHON.md); needs root
build/wul3d run data/samples/uois_tabletop --out out/sample

echo
echo "Outputs in $(pwd)/out/sample:"
echo "  <frame>/labels.png   16-bit cluster labels (0 = no point, 1..k)"
echo "  <frame>/colors.png   8-bit RGB, each point coloured by its cluster weights (eq. 9)"
echo "  summary.json         parameters, stage timings, fps, peak memory"
