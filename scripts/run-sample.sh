#!/usr/bin/env bash
# README command 1: install dependencies, build wul3d (Release, build/), find the objects in the
# four shipped tabletop frames (data/samples/uois_tabletop) into out/sample/ and say what was found.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j2
scripts/install-python.sh build || [[ $(id -u) -ne 0 ]]  # the Python module (docs/PYTHON.md); as root a failure fails
build/wul3d run data/samples/uois_tabletop --out out/sample --overlay

# What was found, from frames.jsonl (one line of statistics per frame): objects per frame.
echo
python3 - out/sample/frames.jsonl <<'PY'
import json, sys
frames = [json.loads(line) for line in open(sys.argv[1])]
total = sum(f["objects"] for f in frames)
print(f"{len(frames)} frames, {total} objects: " +
      ", ".join(f'{f["name"]}: {f["objects"]} objects' for f in frames))
PY

echo
echo "Outputs in $(pwd)/out/sample:"
echo "  <frame>/overlay.png  the objects tinted, outlined and numbered over the colour image"
echo "  <frame>/objects.png  16-bit object labels (0 = none, else the object's track id)"
echo "  <frame>/objects.json each object: id, pixels, centroid, 3D boxes, 2D box, colour"
echo "  <frame>/labels.png   16-bit cluster labels of the paper (0 = no point, 1..k)"
echo "  <frame>/colors.png   8-bit RGB, each point coloured by its cluster weights (eq. 9)"
echo "  summary.json         parameters, how the run ended, stage timings, fps, peak memory"
echo "  frames.jsonl         one line of statistics per frame"
