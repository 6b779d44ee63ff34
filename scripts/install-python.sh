#!/usr/bin/env bash
# Installs the Python module `wul3d` from a build tree (default build/) into Debian's site
# path: /usr/local/lib/python3.<minor>/dist-packages/wul3d (docs/PYTHON.md). Another prefix:
# WUL3D_PYTHON_PREFIX=DIR (then add DIR/lib/python3.<minor>/dist-packages to PYTHONPATH).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
build=${1:-build}
prefix=${WUL3D_PYTHON_PREFIX:-/usr/local}
if ! cmake --install "$build" --component python --prefix "$prefix" >/dev/null; then
  echo "install-python: cannot install into $prefix (run as root, or set WUL3D_PYTHON_PREFIX)" >&2
  exit 1
fi
echo "install-python: wul3d installed under $prefix for $(/usr/bin/python3 --version)"
