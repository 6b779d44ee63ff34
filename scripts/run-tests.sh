#!/usr/bin/env bash
# README command 2: install dependencies, build wul3d (Release, build/) and run the test suite.
# Extra arguments go to the CMake configure step, e.g. scripts/run-tests.sh -DWUL3D_WERROR=ON.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release "$@"
cmake --build build -j2
ctest --test-dir build --output-on-failure -j2
