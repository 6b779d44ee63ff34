"""bench/scaling.py: Amdahl's serial share fitted from `wul3d bench --threads 1,2`'s
per-stage columns. The fit is checked on times whose share is known; the script end to end
on the shipped frames for its table's shape (not its timings: speed belongs to bench/)."""
import importlib.util
import subprocess
import sys

import pytest

from conftest import ROOT, SAMPLES

spec = importlib.util.spec_from_file_location("scaling", ROOT / "bench" / "scaling.py")
scaling = importlib.util.module_from_spec(spec)
spec.loader.exec_module(scaling)


@pytest.mark.parametrize("share", [0.0, 0.1, 0.35, 1.0])
def test_serial_share_recovers_amdahls_share(share):
    t1 = 8.0
    times = {n: t1 * (share + (1 - share) / n) for n in (1, 2, 4, 8, 16)}
    assert scaling.serial_share(t1, times) == pytest.approx(share, abs=1e-12)


def test_serial_share_above_one_when_more_threads_are_slower():
    assert scaling.serial_share(2.0, {1: 2.0, 2: 3.0}) > 1.0
    assert scaling.serial_share(0.0, {1: 0.0, 2: 0.0}) is None
    assert scaling.serial_share(1.0, {1: 1.0}) is None  # one thread only: nothing to fit


def test_table_per_stage_at_one_and_two_threads(cli, tmp_path):
    rows = tmp_path / "rows.csv"
    proc = subprocess.run(
        [sys.executable, str(ROOT / "bench" / "scaling.py"), str(SAMPLES / "uois_tabletop"),
         "--cli", str(cli), "--threads", "1,2", "--k", "4", "--frames", "1", "--passes", "1",
         "--repeats", "2", "--csv", str(rows)],
        capture_output=True, text=True, timeout=300, check=False)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[1] == "| stage | ms at 1 | ms at 2 | speed-up at 2 | serial share |"
    stages = [line.split("|")[1].strip() for line in lines[3:]]
    # Registered frames skip registration; every other stage of the object pipeline ran.
    assert "registration" not in stages
    for stage in ("decimation", "clustering", "plane", "segmentation", "objects", "frame"):
        assert stage in stages, proc.stdout
    # Two repeats of two thread counts, alternated.
    written = rows.read_text().splitlines()
    assert len(written) == 5
    assert [w.split(",")[2] for w in written[1:]] == ["1", "2", "2", "1"]


def test_a_failing_bench_is_one_line(cli):
    proc = subprocess.run(
        [sys.executable, str(ROOT / "bench" / "scaling.py"), "/nonexistent/frames",
         "--cli", str(cli), "--repeats", "1"],
        capture_output=True, text=True, timeout=120, check=False)
    assert proc.returncode != 0
    assert proc.stderr.strip().count("\n") == 0
    assert "/nonexistent/frames" in proc.stderr
