"""Shared set-up of the Python tests: the module and the `wul3d` command of one build tree.

WUL3D_BUILD_DIR names the build tree (default: build/ at the repository root); its
python/ folder comes first on sys.path, so the tests use the module just built, not an
installed one. Only shipped data (data/samples) is read.
"""

import json
import os
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
BUILD = pathlib.Path(os.environ.get("WUL3D_BUILD_DIR", ROOT / "build")).resolve()
SAMPLES = ROOT / "data" / "samples"
sys.path.insert(0, str(BUILD / "python"))

import wul3d  # noqa: E402


@pytest.fixture(scope="session")
def cli():
    """Path of the `wul3d` command built with the module."""
    exe = BUILD / "wul3d"
    assert exe.is_file(), f"{exe}: build wul3d first"
    return exe


def run_cli(cli, *args, timeout=120):
    """Runs `wul3d ARGS`; returns the CompletedProcess (output captured)."""
    return subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True,
                          timeout=timeout, check=False)


@pytest.fixture(scope="session")
def tabletop_cli_out(cli, tmp_path_factory):
    """`wul3d run` on the four shipped tabletop frames (default parameters)."""
    out = tmp_path_factory.mktemp("cli_tabletop")
    proc = run_cli(cli, "run", SAMPLES / "uois_tabletop", "--out", out, "-q")
    assert proc.returncode == 0, proc.stderr
    return out


def read_objects_json(path):
    with open(path, encoding="utf-8") as f:
        return json.load(f)
