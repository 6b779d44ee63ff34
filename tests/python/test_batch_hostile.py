"""wul3d.batch against hostile trees and hostile endings (issue 46: items 1, 2, 8, 12 and 17):
an OUT that is, lies in or holds the input; files in OUT that wul3d did not write; a locked
OUT; symbolic-link loops under ROOT; names that are not UTF-8; SIGINT and SIGTERM. Real Dask
(a LocalCluster of 2 worker processes, or `python3 -m wul3d.batch` in a subprocess), every
test bounded in time and stopping what it started."""

import hashlib
import json
import os
import pathlib
import signal
import subprocess
import sys
import time

import pytest

from conftest import ROOT, SAMPLES

from distributed import Client, LocalCluster  # noqa: E402  (Debian's python3-distributed)

import wul3d  # noqa: E402
from wul3d import batch  # noqa: E402

from test_batch import BUILD  # noqa: E402,F401  (sets PYTHONPATH for the workers)

TABLETOP_FRAMES = sorted(p.name for p in (SAMPLES / "uois_tabletop").iterdir() if p.is_dir())


@pytest.fixture(scope="module")
def client():
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=":0") as cluster, Client(cluster) as c:
        yield c


def batch_cli(root, out, *args, timeout=180):
    """`python3 -m wul3d.batch ROOT --out OUT --workers 2 -q ARGS` (a CompletedProcess)."""
    return subprocess.run([sys.executable, "-m", "wul3d.batch", os.fsencode(root), "--out",
                           os.fsencode(out), "--workers", "2", "--threads-per-worker", "1", "-q",
                           *args], capture_output=True, timeout=timeout, check=False)


def tree_digest(d: pathlib.Path):
    """Every path under `d` (links not followed) with its content's hash: what a test must
    find unchanged."""
    found = {}
    for dirpath, dirnames, filenames in os.walk(d):
        for name in dirnames + filenames:
            p = os.path.join(dirpath, name)
            if os.path.islink(p):
                found[p] = "link:" + os.readlink(p)
            elif os.path.isfile(p):
                with open(p, "rb") as f:
                    found[p] = hashlib.sha256(f.read()).hexdigest()
            else:
                found[p] = "dir"
    return found


def linked_sequence(d: pathlib.Path, frames=TABLETOP_FRAMES):
    """A sequence folder of links to the tabletop frames: a real folder of its own (discovery
    names each folder once), cheap to make."""
    d.mkdir(parents=True)
    for name in frames:
        os.symlink(SAMPLES / "uois_tabletop" / name, d / name)
    return d


def one_line(stderr: bytes) -> str:
    lines = stderr.decode("utf-8", "replace").strip().splitlines()
    assert len(lines) == 1, stderr.decode("utf-8", "replace")
    return lines[0]


# ---- item 1: OUT apart from the input ------------------------------------------------------

def test_out_that_is_in_or_holds_the_input_is_refused_before_anything_is_written(tmp_path):
    data = tmp_path / "data"
    seq = data / "seqA"
    linked_sequence(seq)
    for name in TABLETOP_FRAMES[:2]:  # real frame folders too: these would be replaced
        os.unlink(seq / name)
        (seq / name).mkdir()
        for f in (SAMPLES / "uois_tabletop" / name).iterdir():
            (seq / name / f.name).write_bytes(f.read_bytes())
    outside = tmp_path / "outside"
    linked_sequence(outside / "seqX")
    os.symlink(outside / "seqX", data / "linkX")  # a link out of ROOT: an input too
    os.symlink(data, tmp_path / "data_link")
    before = tree_digest(tmp_path)
    cases = [
        (data, data, "is the input"),                            # --out ROOT
        (data, seq, "lies inside the input"),                    # --out ROOT/seqA
        (seq, data, "contains the input"),                       # ROOT p/seqA, --out p
        (data, tmp_path / "data_link" / "out", "lies inside"),   # through a link
        (data, f"{data}/seqA/../seqA//image_0000", "lies inside"),  # .. and //
        (data, outside, "contains the input"),                   # holds a link's target
        (data, outside / "seqX" / "out", "lies inside the input"),  # in a link's target
    ]
    for root, out, why in cases:
        proc = batch_cli(root, out, timeout=60)
        line = one_line(proc.stderr)
        assert proc.returncode == 2, (root, out, line)
        assert line.startswith("wul3d.batch: --out ") and why in line, line
        assert tree_digest(tmp_path) == before, (root, out)  # nothing created or removed


def test_batch_json_that_is_a_link_or_a_fifo_is_refused(tmp_path):
    root, out = tmp_path / "root", tmp_path / "out"
    seq = root / "seqA"
    seq.mkdir(parents=True)
    frame = seq / "image_0000"
    frame.mkdir()
    for f in (SAMPLES / "uois_tabletop" / "image_0000").iterdir():
        (frame / f.name).write_bytes(f.read_bytes())
    out.mkdir()
    os.symlink(frame / "intrinsics.json", out / "batch.json")
    before = tree_digest(root)
    proc = batch_cli(root, out, timeout=60)
    assert proc.returncode == 2 and "batch.json" in one_line(proc.stderr)
    assert "symbolic link" in one_line(proc.stderr)
    assert tree_digest(root) == before
    os.unlink(out / "batch.json")
    os.mkfifo(out / "batch.json")
    proc = batch_cli(root, out, timeout=60)  # no hang on the FIFO
    assert proc.returncode == 2 and "not a regular file" in one_line(proc.stderr)
    assert sorted(p.name for p in out.iterdir()) == ["batch.json"]


# ---- item 2: never delete what wul3d did not write; the lock --------------------------------

def test_files_wul3d_did_not_write_are_never_removed(client, tmp_path):
    root, out = tmp_path / "root", tmp_path / "out"
    linked_sequence(root / "seqA")
    linked_sequence(root / "seqB")
    notes = out / "seqA" / "image_0000" / "notes.txt"  # a frame folder without summary.json
    notes.parent.mkdir(parents=True)
    notes.write_text("mine\n")
    legacy = out / ".staging" / "keep.txt"  # the name the batch used to remove whole
    legacy.parent.mkdir()
    legacy.write_text("mine too\n")
    stale_foreign = out / f"{batch.STAGING_PREFIX}1-dead" / "0.1.dead" / "notes.txt"
    stale_foreign.parent.mkdir(parents=True)
    stale_foreign.write_text("not wul3d's\n")
    report = batch.run_batch(root, out, client=client, threads_per_worker=1, progress=False,
                             timeout_s=300)
    by_seq = {s["sequence"]: s for s in report["sequences"]}
    assert by_seq["seqB"]["status"] == "ok"  # the others go on
    assert by_seq["seqA"]["status"] == "failed"
    error = by_seq["seqA"]["error"]
    assert "notes.txt" in error and "did not write" in error and "\n" not in error
    assert notes.read_text() == "mine\n"
    assert sorted(p.name for p in notes.parent.iterdir()) == ["notes.txt"]  # untouched
    assert legacy.read_text() == "mine too\n" and stale_foreign.read_text() == "not wul3d's\n"
    assert json.loads((out / "batch.json").read_text())["totals"]["failed"] == 1

    # --overwrite: wul3d's own files are written, the foreign one stays beside them.
    report = batch.run_batch(root, out, client=client, threads_per_worker=1, progress=False,
                             timeout_s=300, overwrite=True)
    assert {s["sequence"]: s["status"] for s in report["sequences"]} == \
        {"seqA": "ok", "seqB": "skipped"}
    assert notes.read_text() == "mine\n"
    assert {"notes.txt", "labels.png", "objects.png", "objects.json"} <= \
        {p.name for p in notes.parent.iterdir()}
    assert (out / "seqA" / "summary.json").is_file()
    # A second try of an unfinished sequence replaces only frame outputs, file by file.
    (out / "seqB" / "summary.json").unlink()
    extra = out / "seqB" / "image_0002" / "cloud.ply"  # an earlier run's --ply output
    extra.write_bytes(b"ply\n")
    report = batch.run_batch(root, out, client=client, threads_per_worker=1, progress=False,
                             timeout_s=300)
    assert {s["sequence"]: s["status"] for s in report["sequences"]} == \
        {"seqA": "skipped", "seqB": "ok"}
    assert not extra.exists()  # wul3d's own, not written this time: removed as `wul3d run` does
    assert legacy.exists() and stale_foreign.exists()
    assert not [p for p in out.iterdir()
                if p.name.startswith(batch.STAGING_PREFIX) and p.name != stale_foreign.parent.parent.name]


def test_a_link_in_place_of_an_output_is_not_followed(client, tmp_path):
    root, out, elsewhere = tmp_path / "root", tmp_path / "out", tmp_path / "elsewhere"
    linked_sequence(root / "seqA")
    elsewhere.mkdir()
    (elsewhere / "precious.txt").write_text("keep\n")
    out.mkdir()
    os.symlink(elsewhere, out / "seqA")
    report = batch.run_batch(root, out, client=client, threads_per_worker=1, progress=False,
                             timeout_s=300, overwrite=True)
    rec = report["sequences"][0]
    assert rec["status"] == "failed" and "not a folder wul3d wrote" in rec["error"], rec
    assert sorted(p.name for p in elsewhere.iterdir()) == ["precious.txt"]


def test_a_second_writer_of_one_out_is_refused(tmp_path):
    root, out = tmp_path / "root", tmp_path / "out"
    linked_sequence(root / "seqA")
    out.mkdir()
    lock = wul3d._wul3d._OutputLock(str(out))  # as a running batch or `wul3d run` holds it
    try:
        proc = batch_cli(root, out, timeout=60)
    finally:
        del lock
    assert proc.returncode == 2
    assert "another wul3d process is writing" in one_line(proc.stderr)
    assert sorted(p.name for p in out.iterdir()) == []
    proc = batch_cli(root, out)  # released: it runs
    assert proc.returncode == 0, proc.stderr
    # While the batch runs, `wul3d run` into the same OUT is refused (the batch holds it).


# ---- item 8: links and loops under ROOT ------------------------------------------------------

def fake_frame(d: pathlib.Path):
    """A folder discovery takes for a frame (it looks for depth.png only)."""
    d.mkdir(parents=True)
    (d / "depth.png").write_bytes(b"")


def test_discovery_over_link_loops_finds_each_sequence_once_and_fast(tmp_path):
    root = tmp_path / "root"
    for seq in ("seqA", "deep/seqB", "deep/seqB/nested"):
        for i in range(2):
            fake_frame(root / seq / f"f{i}")
    os.symlink(root, root / "loop1")  # two links back to ROOT: about 2^40 paths before
    os.symlink(root, root / "deep" / "loop2")
    os.symlink("..", root / "deep" / "seqB" / "nested" / "up")  # nested loops
    os.symlink(root / "deep", root / "deep" / "seqB" / "again")
    os.symlink(root / "seqA", root / "aaa_first_by_name")  # a second name of seqA
    os.symlink("self", root / "self")  # a link to itself (ELOOP)
    os.symlink(tmp_path / "nothing", root / "dangling")
    os.mkfifo(root / "deep" / "fifo")
    outside = tmp_path / "outside"
    for i in range(2):
        fake_frame(outside / "seqC" / f"f{i}")
    os.symlink(outside, root / "ext1")  # followed once, whatever the number of links
    os.symlink(outside, root / "ext2")
    os.symlink(root, outside / "back")
    # Discovery ends (a hang guard, not a speed figure: two links back to ROOT made it walk
    # about 2^40 paths), then its answer in this process.
    subprocess.run([sys.executable, "-c", "import sys; from wul3d import batch; "
                    "batch.discover(sys.argv[1])", str(root)], check=True, timeout=60,
                   env=dict(os.environ, PYTHONPATH=str(BUILD / "python")))
    found = batch.discover_all(root)
    assert found.sequences == ["deep/seqB", "deep/seqB/nested", "ext1/seqC", "seqA"]
    assert found.links == [os.path.realpath(outside)]
    assert found.unread == []
    assert batch.discover(root) == found.sequences


def test_discovery_stops_at_the_depth_bound(tmp_path):
    root = tmp_path / "root"
    deep = root.joinpath(*["d"] * (batch.MAX_DEPTH + 2))
    fake_frame(deep / "f0")
    fake_frame(root / "near" / "f0")
    found = batch.discover_all(root)
    assert found.sequences == ["near"]
    assert [why for _, why in found.unread] == [f"deeper than {batch.MAX_DEPTH} folders"]


def test_out_inside_a_folder_a_link_leads_to_is_refused(tmp_path):
    root, outside = tmp_path / "root", tmp_path / "outside"
    linked_sequence(outside / "seqC")
    root.mkdir()
    os.symlink(outside, root / "ext")
    proc = batch_cli(root, outside / "out", timeout=60)
    assert proc.returncode == 2 and "lies inside the input" in one_line(proc.stderr)
    assert not (outside / "out").exists()


# ---- item 12: names that are not UTF-8 -------------------------------------------------------

def test_names_that_are_not_utf8_do_not_cancel_the_batch(tmp_path):
    root, out = tmp_path / "root", tmp_path / "out"
    linked_sequence(root / "good")
    odd = os.fsdecode(os.fsencode(root) + b"/bad\xff\xfe")
    linked_sequence(pathlib.Path(odd))
    odd_frame = linked_sequence(root / "good2", TABLETOP_FRAMES[:1])
    os.symlink(SAMPLES / "uois_tabletop" / TABLETOP_FRAMES[1],
               os.fsdecode(os.fsencode(odd_frame) + b"/img\xff\xfe"))
    proc = batch_cli(root, out)
    stderr = proc.stderr.decode("utf-8", "replace")
    assert "Traceback" not in stderr and proc.returncode in (0, 1), stderr
    raw = (out / "batch.json").read_bytes()
    report = json.loads(raw.decode("utf-8"))  # strict UTF-8

    def strings(v):
        if isinstance(v, str):
            yield v
        elif isinstance(v, dict):
            for k, x in v.items():
                yield k
                yield from strings(x)
        elif isinstance(v, list):
            for x in v:
                yield from strings(x)
    for s in strings(report):
        s.encode("utf-8")  # no lone surrogates: any JSON reader takes it
    by_seq = {s["sequence"]: s for s in report["sequences"]}
    assert set(by_seq) == {"good", "good2", "bad\\xff\\xfe"}
    assert by_seq["good"]["status"] == "ok"
    assert by_seq["bad\\xff\\xfe"]["sequence_hex"] == b"bad\xff\xfe".hex()
    for rec in by_seq.values():  # each ends on its own: done, or failed with one line
        assert rec["status"] in ("ok", "failed"), rec
        assert rec["status"] == "ok" or (rec["error"] and "\n" not in rec["error"]), rec
    if by_seq["bad\\xff\\xfe"]["status"] == "ok":
        assert os.path.isfile(os.fsencode(out) + b"/bad\xff\xfe/summary.json")


# ---- item 17: signals ------------------------------------------------------------------------

@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_stops_the_batch_at_once_with_one_line(tmp_path, signum):
    root, out = tmp_path / "root", tmp_path / "out"
    for i in range(16):
        linked_sequence(root / f"s{i:02d}")
    # As a terminal's Ctrl-C (or a service manager's stop): to the whole process group.
    proc = subprocess.Popen([sys.executable, "-m", "wul3d.batch", str(root), "--out", str(out),
                             "--workers", "2", "--threads-per-worker", "1", "-q"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            start_new_session=True)
    try:
        for _ in range(12000):  # at most two minutes for the first sequence
            if list(out.glob("s*/summary.json")) or proc.poll() is not None:
                break
            time.sleep(0.01)
        assert proc.poll() is None, "the batch ended before a signal could be sent"
        os.killpg(proc.pid, signum)
        _, stderr = proc.communicate(timeout=20)  # a hang guard; it stops in under a second
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(timeout=10)
    name = signal.Signals(signum).name
    assert proc.returncode == 128 + signum, stderr
    line = one_line(stderr)  # no traceback, from the batch nor from its workers
    assert line.startswith(f"wul3d.batch: interrupted by {name}; ") and "not started" in line
    report = json.loads((out / "batch.json").read_text())
    assert report["interrupted_by"] == name and report["totals"]["sequences"] == 16
    finished = {s["sequence"] for s in report["sequences"] if s["status"] == "ok"}
    assert finished and finished == {p.parent.name for p in out.glob("s*/summary.json")}
    assert {s["status"] for s in report["sequences"]} <= {"ok", "stopped", "not_started"}
    assert not [p for p in out.iterdir() if p.name.startswith(".wul3d.")]  # staging gone
    for d in out.glob("s*"):  # a sequence stopped mid-publish holds only wul3d's files
        assert batch.foreign_entry(d) is None, d
    # The next batch finishes the others.
    proc = batch_cli(root, out)
    assert proc.returncode == 0, proc.stderr
    report = json.loads((out / "batch.json").read_text())
    assert report["totals"]["skipped"] == len(finished)
    assert report["totals"]["succeeded"] == 16 - len(finished)


def test_ended_workers_are_not_restarted():
    """After a signal the batch SIGKILLs its local workers; a nanny that restarted one would
    leave a process that ignores SIGTERM, and Python's exit would wait for it for ever."""
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=":0") as cluster, Client(cluster) as c:
        c.register_worker_plugin(batch.IgnoreStopSignals())
        pids = [n.process.pid for n in cluster.workers.values()]
        batch._end_local_workers(cluster)
        deadline = time.monotonic() + 5  # a restart takes about a second here
        while time.monotonic() < deadline:
            # A worker's pid reads None from its death until its nanny lets go of it; a
            # restarted one has a live pid of its own.
            assert all(n.process is None or n.process.pid in (None, *pids)
                       for n in cluster.workers.values()), "a worker was restarted"
            time.sleep(0.1)
        for pid in pids:  # and the ones it ended are gone
            with pytest.raises(ProcessLookupError):
                os.kill(pid, 0)


# ---- fuzzing: the discovery driver, briefly ----------------------------------------------------

def test_discovery_fuzzer_runs_clean_for_a_few_seconds():
    proc = subprocess.run([sys.executable, str(ROOT / "fuzz" / "fuzz_batch_discovery.py"),
                           "--seconds", "3", "--seed", "1"], capture_output=True, text=True,
                          timeout=120, check=False)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "no finding" in proc.stdout


def test_no_output_is_written_through_a_link_in_out(client, tmp_path):
    root, out, elsewhere = tmp_path / "root", tmp_path / "out", tmp_path / "elsewhere"
    linked_sequence(root / "a" / "b")
    elsewhere.mkdir()
    out.mkdir()
    os.symlink(elsewhere, out / "a")  # OUT/a -> elsewhere: OUT/a/b would land there
    report = batch.run_batch(root, out, client=client, threads_per_worker=1, progress=False,
                             timeout_s=300)
    rec = report["sequences"][0]
    assert rec["sequence"] == "a/b" and rec["status"] == "failed", rec
    assert "symbolic link" in rec["error"]
    assert list(elsewhere.iterdir()) == []


def test_batch_json_is_written_when_the_batch_gives_up(client, tmp_path):
    root, out = tmp_path / "root", tmp_path / "out"
    for i in range(4):
        linked_sequence(root / f"s{i}")
    with pytest.raises(TimeoutError):
        batch.run_batch(root, out, client=client, threads_per_worker=1, progress=False,
                        timeout_s=0.05)
    report = json.loads((out / "batch.json").read_text())
    assert report["totals"]["sequences"] == 4
    assert all(s["status"] == "ok" or s["error"].startswith("not finished: ")
               for s in report["sequences"])
    time.sleep(3)  # the tasks still running find the batch gone and publish nothing
    assert {p.name for p in out.iterdir() if p.name.startswith("s")} == \
        {s["sequence"] for s in report["sequences"] if s["status"] == "ok"}
