"""One version everywhere: wul3d.__version__ is CMake's project(VERSION), as `wul3d --version`."""

import re

from conftest import ROOT, run_cli

import wul3d


def project_version():
    """The VERSION of the project() line in the top-level CMakeLists.txt."""
    text = (ROOT / "CMakeLists.txt").read_text()
    match = re.search(r"^project\(\s*wul3d\s+VERSION\s+([0-9.]+)", text, re.MULTILINE)
    assert match, "CMakeLists.txt: no project(wul3d VERSION ...) line"
    return match.group(1)


def test_module_version_is_the_cmake_project_version():
    assert wul3d.__version__ == project_version()


def test_module_and_command_agree(cli):
    result = run_cli(cli, "--version")
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == f"wul3d {wul3d.__version__}"
