#!/usr/bin/env bash
# README command 2: install dependencies, build wul3d (Release, build/) and run the test suite:
# the C++ tests (ctest), then the Python module's (tests/python, pytest with Debian's
# /usr/bin/python3 on the module just built). Installs the Python module into Debian's site
# path (scripts/install-python.sh) so that `/usr/bin/python3 -c "import wul3d"` works.
# Extra arguments go to the CMake configure step, e.g. scripts/run-tests.sh -DWUL3D_WERROR=ON.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release "$@"
cmake --build build -j2
ctest --test-dir build --output-on-failure -j2
if [[ -f build/python/wul3d/__init__.py ]]; then
  # As root (the README's set-up) a failed install fails the command; without root the
  # tests below still use build/python and the module is only not installed for other
  # directories (install-python.sh says so).
  scripts/install-python.sh build || [[ $(id -u) -ne 0 ]]
  WUL3D_BUILD_DIR=build timeout 900 /usr/bin/python3 -m pytest -q -p no:cacheprovider tests/python
else
  echo "run-tests: the Python module was not built (pybind11 missing?): tests/python not run" >&2
  exit 1
fi
