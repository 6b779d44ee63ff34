"""wul3d.batch on the real engine: Dask's LocalCluster with two worker processes, and
dask-scheduler plus dask-worker as separate processes on 127.0.0.1. Outputs compared byte
for byte with `wul3d run`; resume; a worker killed mid-sequence; a bad sequence among good
ones. Every test is bounded (timeouts) and stops the processes it started."""

import filecmp
import json
import os
import pathlib
import select
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time

import pytest

from conftest import BUILD, SAMPLES, run_cli

from distributed import Client, LocalCluster  # noqa: E402  (Debian's python3-distributed)

from wul3d import batch  # noqa: E402

TIMING_KEYS = {"wall_s", "fps", "fps_end_to_end", "ms_per_frame_median", "stage_ms_median",
               "peak_rss_mb", "per_frame", "input", "threads"}
SAMPLE_SEQUENCES = ["pcl_kinect", "pcl_kinect/pairwise_seq", "uois_tabletop"]
# Workers import the module just built.
os.environ["PYTHONPATH"] = os.pathsep.join(
    [str(BUILD / "python")] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p])


@pytest.fixture(scope="module")
def client():
    """A LocalCluster of 2 worker processes (1 task each at a time), shared by the tests."""
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=":0") as cluster, Client(cluster) as c:
        yield c


@pytest.fixture(scope="module")
def reference(cli, tmp_path_factory):
    """`wul3d run` of each shipped sequence with --threads 1, as the batch runs them."""
    ref = tmp_path_factory.mktemp("reference")
    for seq in SAMPLE_SEQUENCES:
        proc = run_cli(cli, "run", SAMPLES / seq, "--out", ref / seq, "-q", "--threads", 1)
        assert proc.returncode == 0, proc.stderr
    return ref


def frame_dirs(d: pathlib.Path):
    return sorted(p.name for p in d.iterdir() if p.is_dir() and (p / "objects.json").is_file())


def assert_same_as_reference(out: pathlib.Path, ref: pathlib.Path):
    """Every frame folder byte-identical; summary.json equal but for timings and paths."""
    assert frame_dirs(out) == frame_dirs(ref) and frame_dirs(ref)
    for name in frame_dirs(ref):
        files = sorted(p.name for p in (ref / name).iterdir())
        assert sorted(p.name for p in (out / name).iterdir()) == files
        match, mismatch, errors = filecmp.cmpfiles(ref / name, out / name, files, shallow=False)
        assert not mismatch and not errors, (name, mismatch, errors)
    a = json.loads((out / "summary.json").read_text())
    b = json.loads((ref / "summary.json").read_text())
    assert {k: v for k, v in a.items() if k not in TIMING_KEYS} == \
        {k: v for k, v in b.items() if k not in TIMING_KEYS}
    # Per-frame statistics (frames.jsonl): the same frames with the same figures but for time.
    def frame_lines(d):
        lines = [json.loads(line) for line in (d / "frames.jsonl").read_text().splitlines()]
        return [{k: v for k, v in f.items() if k != "ms"} for f in lines]
    assert frame_lines(out) == frame_lines(ref) and frame_lines(ref)


def test_discover_finds_each_sequence():
    assert batch.discover(SAMPLES) == SAMPLE_SEQUENCES
    assert batch.discover(SAMPLES / "uois_tabletop" / "image_0000") == ["."]


def test_local_cluster_outputs_equal_wul3d_run(client, reference, tmp_path):
    report = batch.run_batch(SAMPLES, tmp_path, client=client, threads_per_worker=1,
                             progress=False, timeout_s=300)
    assert [s["sequence"] for s in report["sequences"]] == SAMPLE_SEQUENCES
    assert all(s["status"] == "ok" and s["error"] is None for s in report["sequences"])
    assert report["totals"]["frames"] == 2 + 5 + 4
    assert report["totals"]["sequences"] == 3 and report["totals"]["failed"] == 0
    assert {s["worker"] for s in report["sequences"]} <= set(client.scheduler_info()["workers"])
    for seq in SAMPLE_SEQUENCES:
        assert_same_as_reference(tmp_path / seq, reference / seq)
    assert json.loads((tmp_path / "batch.json").read_text()) == report
    assert not staging_folders(tmp_path)
    assert "uois" not in report  # no label.png in the samples


def test_resume_skips_finished_and_redoes_unfinished(client, reference, tmp_path):
    batch.run_batch(SAMPLES, tmp_path, client=client, threads_per_worker=1, progress=False,
                    timeout_s=300)
    # An interrupted batch: one sequence lost its marker (summary.json, written last) and a
    # frame folder; a killed batch left its staging folder with a try's partial output.
    (tmp_path / "uois_tabletop" / "summary.json").unlink()
    shutil.rmtree(tmp_path / "uois_tabletop" / "image_0005")
    stale = tmp_path / f"{batch.STAGING_PREFIX}1-dead"
    shutil.copytree(tmp_path / "uois_tabletop" / "image_0000", stale / "2.1.dead" / "image_0000")
    finished = tmp_path / "pcl_kinect" / "pairwise_seq" / "capture0003" / "labels.png"
    before = finished.stat().st_mtime_ns
    report = batch.run_batch(SAMPLES, tmp_path, client=client, threads_per_worker=1,
                             progress=False, timeout_s=300)
    status = {s["sequence"]: s["status"] for s in report["sequences"]}
    assert status == {"pcl_kinect": "skipped", "pcl_kinect/pairwise_seq": "skipped",
                      "uois_tabletop": "ok"}
    assert report["totals"]["frames_this_run"] == 4 and report["totals"]["frames"] == 11
    assert finished.stat().st_mtime_ns == before  # not written again
    assert not stale.exists()
    for seq in SAMPLE_SEQUENCES:
        assert_same_as_reference(tmp_path / seq, reference / seq)


def staging_folders(out: pathlib.Path):
    return sorted(p.name for p in out.iterdir() if p.name.startswith(batch.STAGING_PREFIX))


def make_root_with_bad_sequence(root: pathlib.Path):
    """Two good sequences (links to the samples) and one whose second frame's depth.png is
    truncated."""
    (root / "good").mkdir(parents=True)
    os.symlink(SAMPLES / "uois_tabletop", root / "good" / "tabletop")
    os.symlink(SAMPLES / "pcl_kinect" / "pairwise_seq", root / "pairwise")
    bad = root / "bad"
    for name in ("image_0000", "image_0002"):
        shutil.copytree(SAMPLES / "uois_tabletop" / name, bad / name)
    data = (bad / "image_0002" / "depth.png").read_bytes()
    (bad / "image_0002" / "depth.png").write_bytes(data[: len(data) // 3])


def test_bad_sequence_is_reported_and_the_others_finish(cli, tmp_path):
    root, out = tmp_path / "root", tmp_path / "out"
    make_root_with_bad_sequence(root)
    proc = subprocess.run([sys.executable, "-m", "wul3d.batch", str(root), "--out", str(out),
                           "--workers", "2", "--threads-per-worker", "1", "-q"],
                          capture_output=True, text=True, timeout=300, check=False)
    assert proc.returncode == 1, proc.stderr
    report = json.loads((out / "batch.json").read_text())
    by_seq = {s["sequence"]: s for s in report["sequences"]}
    assert set(by_seq) == {"bad", "good/tabletop", "pairwise"}
    assert by_seq["bad"]["status"] == "failed"
    assert "image_0002" in by_seq["bad"]["error"] and "\n" not in by_seq["bad"]["error"]
    assert f"wul3d.batch: bad: {by_seq['bad']['error']}" in proc.stderr
    assert not (out / "bad").exists()  # nothing half-done
    assert by_seq["good/tabletop"]["status"] == by_seq["pairwise"]["status"] == "ok"
    assert report["totals"]["failed"] == 1 and report["totals"]["succeeded"] == 2
    ref = tmp_path / "ref"
    assert run_cli(cli, "run", root / "pairwise", "--out", ref, "-q").returncode == 0
    assert_same_as_reference(out / "pairwise", ref)


def test_bad_arguments_exit_2(tmp_path):
    for args, reason in ((["--k", "0"], "k = 0"), (["--workers", "0"], "--workers 0")):
        proc = subprocess.run([sys.executable, "-m", "wul3d.batch", str(SAMPLES), "--out",
                               str(tmp_path), *args], capture_output=True, text=True,
                              timeout=60, check=False)
        assert proc.returncode == 2, (args, proc.stderr)
        assert reason in proc.stderr.strip().splitlines()[-1], proc.stderr  # one line says why
    assert not (tmp_path / "batch.json").exists()


def test_uois_table_equals_wul3d_eval(cli, client, tmp_path):
    # Ground truth for the tabletop frames: the clusters (labels.png) of a default run, so
    # that the objects are scored against real, different label images.
    ref = tmp_path / "ref"
    assert run_cli(cli, "run", SAMPLES / "uois_tabletop", "--out", ref, "-q").returncode == 0
    root = tmp_path / "root"
    shutil.copytree(SAMPLES / "uois_tabletop", root / "tabletop")
    for name in frame_dirs(ref):
        shutil.copy(ref / name / "labels.png", root / "tabletop" / name / "label.png")
    out = tmp_path / "out"
    report = batch.run_batch(root, out, client=client, threads_per_worker=1, progress=False,
                             timeout_s=300)
    proc = run_cli(cli, "eval", out / "tabletop", root / "tabletop", "--json", tmp_path / "e.json")
    assert proc.returncode == 0, proc.stderr
    theirs = json.loads((tmp_path / "e.json").read_text())
    theirs = theirs.get("summary", theirs)
    for table in (report["uois"]["all"], report["uois"]["per_sequence"]["tabletop"]):
        assert table["images"] == 4 == theirs["images"]
        for key in ("overlap_p", "overlap_r", "overlap_f", "boundary_p", "boundary_r",
                    "boundary_f"):
            assert table[key] == pytest.approx(theirs[key], abs=1e-12), key


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Processes:
    """Processes started by a test; all stopped (TERM, then KILL) when it ends."""

    def __init__(self):
        self.procs = []

    def start(self, *args):
        p = subprocess.Popen([sys.executable, *args], stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL, start_new_session=True)
        self.procs.append(p)
        return p

    def stop(self):
        for p in self.procs:
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGTERM)
        for p in self.procs:
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait(timeout=10)


def test_scheduler_and_workers_as_processes_survive_a_killed_worker(tmp_path):
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    procs = Processes()
    try:
        procs.start("-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port",
                    str(port), "--dashboard-address", ":0", "--no-show")
        for _ in range(2):  # no nanny: a killed worker stays dead, the other must finish
            procs.start("-m", "distributed.cli.dask_worker", address, "--nthreads", "1",
                        "--no-nanny", "--host", "127.0.0.1", "--dashboard-address", ":0")
        with Client(address, timeout="30s") as c:
            c.wait_for_workers(2, timeout=60)
            workers_before = set(c.scheduler_info()["workers"])
        out = tmp_path / "out"
        result, errors = {}, []

        def work():
            try:
                result["report"] = batch.run_batch(SAMPLES, out, scheduler=address,
                                                   threads_per_worker=1, progress=False,
                                                   timeout_s=240, options={"decimate": 1})
            except Exception as e:  # noqa: BLE001  (reported below)
                errors.append(e)

        runner = threading.Thread(target=work)
        runner.start()
        # A staging folder exists only while a task runs its sequence: kill its writer.
        killed = None
        deadline = time.monotonic() + 120
        while killed is None and time.monotonic() < deadline and runner.is_alive():
            for d in (out.glob(batch.STAGING_PREFIX + "*/[0-9]*") if out.is_dir() else []):
                pid = int(d.name.split(".")[-2])
                os.kill(pid, signal.SIGKILL)
                killed = (d.name.split(".")[0], pid)
                break
            time.sleep(0.01)
        runner.join(timeout=260)
        assert not runner.is_alive()
        assert killed is not None, "no task was caught mid-sequence"
        assert not errors, errors
        report = result["report"]
        assert all(s["status"] == "ok" for s in report["sequences"]), report["sequences"]
        assert report["totals"]["frames"] == 11
        # The survivor did every sequence, the killed one's included.
        assert len({s["worker"] for s in report["sequences"]}) == 1
        assert {s["worker"] for s in report["sequences"]} < workers_before
        ref = tmp_path / "ref"
        for seq in SAMPLE_SEQUENCES:
            proc = run_cli(BUILD / "wul3d", "run", SAMPLES / seq, "--out", ref / seq, "-q",
                           "--decimate", 1, "--threads", 1)
            assert proc.returncode == 0, proc.stderr
            assert_same_as_reference(out / seq, ref / seq)
        assert not staging_folders(out)  # the killed try's folder is gone too
    finally:
        procs.stop()


def test_progress_bar_on_a_terminal_only(tmp_path):
    import pty

    root = tmp_path / "root"
    root.mkdir()
    os.symlink(SAMPLES / "uois_tabletop", root / "tabletop")
    os.symlink(SAMPLES / "pcl_kinect" / "pairwise_seq", root / "pairwise")
    leader, follower = pty.openpty()
    try:
        proc = subprocess.Popen([sys.executable, "-m", "wul3d.batch", str(root), "--out",
                                 str(tmp_path / "out"), "--workers", "1",
                                 "--threads-per-worker", "1"],
                                stdout=subprocess.PIPE, stderr=follower, text=True)
        os.close(follower)
        follower = None
        chunks = []
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:  # read the terminal until the process closes it
            ready, _, _ = select.select([leader], [], [], max(0.0, deadline - time.monotonic()))
            if not ready:
                break
            try:
                data = os.read(leader, 4096)
            except OSError:  # EIO: no writer left
                break
            if not data:
                break
            chunks.append(data)
        if proc.poll() is None and time.monotonic() >= deadline:
            proc.kill()
        assert proc.wait(timeout=30) == 0
        proc.stdout.close()
    finally:
        os.close(leader)
        if follower is not None:
            os.close(follower)
    terminal = b"".join(chunks).decode(errors="replace")
    assert "] 2/2 sequences" in terminal and "[" + "#" * 30 + "]" in terminal
    # On a pipe: no bar.
    quiet = subprocess.run([sys.executable, "-m", "wul3d.batch", str(root), "--out",
                            str(tmp_path / "out2"), "--workers", "1"], capture_output=True,
                           text=True, timeout=120, check=False)
    assert quiet.returncode == 0 and "sequences\r" not in quiet.stderr and "[#" not in quiet.stderr
