"""The Python module under the attacks of issue 46: threads sharing a reader, thread counts,
Ctrl-C in wul3d.run, out-of-range and wrong-typed options, outputs against the input, image
sizes. Whatever could crash or hang runs in a subprocess with a timeout, so that a failure
fails its test instead of killing or stalling pytest."""

import json
import os
import pathlib
import shutil
import signal
import struct
import subprocess
import sys
import time
import zlib

import numpy as np
import pytest

import wul3d
from conftest import BUILD, SAMPLES, run_cli

TABLETOP = SAMPLES / "uois_tabletop"


def python(script, *args, timeout=120):
    """Runs `script` in a fresh interpreter on this build's module; the CompletedProcess."""
    env = dict(os.environ, PYTHONPATH=str(BUILD / "python"))
    return subprocess.run([sys.executable, "-c", script, *map(str, args)], capture_output=True,
                          text=True, timeout=timeout, env=env, check=False)


def start_python(script, *args):
    env = dict(os.environ, PYTHONPATH=str(BUILD / "python"))
    return subprocess.Popen([sys.executable, "-c", script, *map(str, args)], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def tree_digest(root):
    """Every path and byte under root: equal digests, an untouched tree."""
    out = []
    for p in sorted(pathlib.Path(root).rglob("*")):
        out.append((str(p.relative_to(root)), p.is_symlink(),
                    p.read_bytes() if p.is_file() and not p.is_symlink() else None))
    return out


# ---- item 5: one reader shared by threads -----------------------------------------------

READER_THREADS = """
import sys, threading
import wul3d
reader = wul3d.read(sys.argv[1])
reference = [(f.name, f.depth.tobytes(), f.color.tobytes()) for f in reader]
errors, mismatches = [], []

def work(t):
    for j in range(40):
        i = (j + t) % len(reader)
        try:
            f = reader[i]
            if (f.name, f.depth.tobytes(), f.color.tobytes()) != reference[i]:
                mismatches.append(i)
        except Exception as e:
            errors.append(repr(e))

threads = [threading.Thread(target=work, args=(t,)) for t in range(8)]
for t in threads:
    t.start()
for t in threads:
    t.join()
print("errors", len(errors), "mismatches", len(mismatches), errors[:2])
"""


def test_one_reader_shared_by_eight_threads():
    # main: a segfault or "malloc(): unaligned tcache chunk" (rc -11, -6), else false
    # "cannot decode PNG (CRC error ...)" on the shipped frames.
    proc = python(READER_THREADS, TABLETOP)
    assert proc.returncode == 0, (proc.returncode, proc.stderr[-2000:])
    assert proc.stdout.startswith("errors 0 mismatches 0 "), proc.stdout


# ---- item 6: thread counts --------------------------------------------------------------

@pytest.mark.parametrize("n", [0, -1, 1025, 65536, 40000, 2**40, -2**70])
def test_thread_counts_out_of_range(n):
    before = wul3d.get_num_threads()
    with pytest.raises(ValueError, match=r"threads = .*must be in \[1, 1024\]"):
        wul3d.set_num_threads(n)
    assert wul3d.get_num_threads() == before


@pytest.mark.parametrize("n", ["4", 4.0, True, None])
def test_thread_counts_of_the_wrong_type(n):
    before = wul3d.get_num_threads()
    with pytest.raises(TypeError, match="threads: expected an int"):
        wul3d.set_num_threads(n)
    assert wul3d.get_num_threads() == before


def test_huge_thread_count_then_process_does_not_crash():
    # main before 8afdf67: set_num_threads(65536) then process() died on signal 11.
    script = """
import sys, wul3d
f = wul3d.read(sys.argv[1])[0]
for n in (65536, 40000, 1025):
    try:
        wul3d.set_num_threads(n)
    except ValueError:
        pass
r = wul3d.Pipeline().process(f.color, f.depth, f.intrinsics, f.depth_scale)
print("objects", len(r.instances), "threads", wul3d.get_num_threads())
"""
    proc = python(script, TABLETOP / "image_0000")
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.startswith("objects ")


def test_run_refers_threads_to_set_num_threads(tmp_path):
    with pytest.raises(TypeError, match="threads: wul3d.set_num_threads"):
        wul3d.run(TABLETOP, tmp_path / "o", threads=65536)


# ---- item 9: Ctrl-C in wul3d.run ----------------------------------------------------------

def png(path, array, bit_depth, colour_type):
    """A minimal PNG writer (no dependency): 8-bit RGB or 16-bit grey."""
    rows = b"".join(b"\0" + row.tobytes() for row in array)
    h, w = array.shape[:2]

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data +
                struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))

    path.write_bytes(b"\x89PNG\r\n\x1a\n" +
                     chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, bit_depth, colour_type, 0, 0, 0)) +
                     chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


def tiny_tum(root, n):
    """A TUM sequence of n 8 x 8 frames (a tilted surface with a box on it, as
    tests/run/robust_test.cpp), one pair of images listed n times under distinct stamps."""
    (root / "rgb").mkdir(parents=True)
    (root / "depth").mkdir()
    v, u = np.mgrid[0:8, 0:8]
    box = (u >= 3) & (u <= 5) & (v >= 2) & (v <= 4)
    depth = np.where(box, 900, 1000 + 60 * v).astype(">u2")
    color = np.where(box[..., None], np.array([40, 120, 200]), 180).astype(np.uint8)
    png(root / "depth" / "d.png", depth, 16, 0)
    png(root / "rgb" / "c.png", color, 8, 2)
    stamps = [f"{1000 + i}.000000" for i in range(n)]
    (root / "rgb.txt").write_text("".join(f"{s} rgb/c.png\n" for s in stamps))
    (root / "depth.txt").write_text("".join(f"{s} depth/d.png\n" for s in stamps))
    return root


TINY = dict(intrinsics="8,8,3.5,3.5", decimate=1, k=3, min_points=2)

RUN_LONG = """
import signal, sys, wul3d
if sys.argv[3] == "own-handler":
    class Mine(Exception):
        pass
    def handler(sig, frame):
        raise Mine("the caller's own SIGINT handler")
    signal.signal(signal.SIGINT, handler)
wul3d.set_num_threads(1)
print("start", flush=True)
wul3d.run(sys.argv[1], sys.argv[2], format="tum", intrinsics="8,8,3.5,3.5", decimate=1, k=3,
          min_points=2)
print("returned", flush=True)
"""


def lines(path):
    try:
        return path.read_text().count("\n")
    except FileNotFoundError:
        return 0


def interrupt_when(proc, ready, after_s=0.0, within_s=10, signal_number=signal.SIGINT):
    """SIGINT (or `signal_number`) `after_s` after ready() holds; (stdout, stderr). A process
    that does not end within `within_s` fails the test (a hang guard, not a speed figure)."""
    for _ in range(1200):  # at most a minute for the run to start
        assert proc.poll() is None, proc.communicate()
        if ready():
            break
        time.sleep(0.05)
    else:
        pytest.fail("the run did not start")
    time.sleep(after_s)
    proc.send_signal(signal_number)
    try:
        return proc.communicate(timeout=within_s)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.communicate()
        pytest.fail(f"wul3d.run ran on for {within_s} s after signal {signal_number}")


def assert_out_as_the_command_leaves_it(out, n_frames):
    summary = json.loads((out / "summary.json").read_text())
    assert summary["stopped_by"] == "signal"
    folders = [p for p in out.iterdir() if p.is_dir()]
    assert summary["frames"] == len(folders) == lines(out / "frames.jsonl")
    assert 0 < len(folders) < n_frames
    for f in folders:  # every frame written is whole
        assert (f / "objects.json").is_file() and (f / "labels.png").is_file(), f
    return summary


@pytest.mark.parametrize("handler", ["default", "own-handler"])
def test_sigint_stops_a_long_run(tmp_path, handler):
    # main: all 3000 frames, then KeyboardInterrupt (72 s on the machine of the report).
    seq, out = tiny_tum(tmp_path / "seq", 3000), tmp_path / "out"
    proc = start_python(RUN_LONG, seq, out, handler)
    stdout, stderr = interrupt_when(proc, lambda: lines(out / "frames.jsonl") >= 20)
    assert "returned" not in stdout
    expected = "KeyboardInterrupt" if handler == "default" else "Mine: the caller's own SIGINT"
    assert expected in stderr, stderr
    assert stderr.count("Traceback") == 1, stderr
    assert_out_as_the_command_leaves_it(out, 3000)


def test_sigterm_stops_a_long_run_then_ends_the_process(tmp_path):
    # SIGTERM's default action ended the interpreter at once: no summary.json, frames.jsonl
    # cut wherever it was. Now the run stops as the command does, then the process ends
    # as SIGTERM's default action would (killed by signal 15), with OUT final.
    seq, out = tiny_tum(tmp_path / "seq", 3000), tmp_path / "out"
    proc = start_python(RUN_LONG, seq, out, "default")
    stdout, stderr = interrupt_when(proc, lambda: lines(out / "frames.jsonl") >= 20,
                                    signal_number=signal.SIGTERM)
    assert proc.returncode == -signal.SIGTERM, (proc.returncode, stderr)
    assert "returned" not in stdout and "Traceback" not in stderr, stderr
    assert_out_as_the_command_leaves_it(out, 3000)


RUN_SLOW_FRAME = """
import sys, wul3d
print("start", flush=True)
try:
    wul3d.run(sys.argv[1], sys.argv[2], k=65535, decimate=1)
except KeyboardInterrupt:
    print("interrupted", flush=True)
# The stop request is withdrawn: the next run goes to its end.
s = wul3d.run(sys.argv[3], sys.argv[4], format="tum", frames=3, intrinsics="8,8,3.5,3.5",
              decimate=1, k=3, min_points=2)
print("next run:", s["stopped_by"], s["frames"], flush=True)
"""


def test_sigint_stops_a_frame_of_minutes(tmp_path):
    # k = 65535 on a 640x480 frame: main ran on for over 97 s after SIGINT (rc 124 at 100 s).
    out, seq = tmp_path / "out", tiny_tum(tmp_path / "seq", 5)
    proc = start_python(RUN_SLOW_FRAME, TABLETOP / "image_0000", out, seq, tmp_path / "next")
    # OUT prepared: the frame is under way.
    stdout, stderr = interrupt_when(proc, (out / "frames.jsonl").exists, after_s=0.5,
                                    within_s=20)
    assert proc.returncode == 0, stderr
    assert stdout.startswith("start\ninterrupted\n"), (stdout, stderr)
    assert "next run: frames 3" in stdout
    summary = json.loads((out / "summary.json").read_text())
    assert summary["stopped_by"] == "signal" and summary["frames"] == 0


def test_a_run_on_another_thread_stops_on_the_stop_request(tmp_path):
    # SIGINT reaches the main thread only: a caller with runs on other threads (the batch)
    # stops them with the library's stop request.
    import threading
    seq, out = tiny_tum(tmp_path / "seq", 3000), tmp_path / "out"
    result = {}
    worker = threading.Thread(target=lambda: result.update(wul3d.run(seq, out, format="tum", **TINY)))
    worker.start()
    try:
        for _ in range(1200):  # at most a minute for 20 frames
            if lines(out / "frames.jsonl") >= 20 or not worker.is_alive():
                break
            time.sleep(0.05)
        wul3d._wul3d._request_stop()
        worker.join(timeout=10)
    finally:
        wul3d._wul3d._clear_stop_request()
    assert not worker.is_alive()
    assert result["stopped_by"] == "signal"
    assert_out_as_the_command_leaves_it(out, 3000)
    assert wul3d.run(seq, tmp_path / "again", format="tum", frames=2, **TINY)["stopped_by"] == "frames"


# ---- item 14: select out of range ---------------------------------------------------------

@pytest.mark.parametrize("select", ["1e20,1", "nan,1", "inf,2", "1,-inf", "-1,5", "70000,1",
                                    (2**40, 1), (float("nan"), 1), (1, float("inf"))])
def test_select_out_of_range_is_a_value_error(tmp_path, select):
    # main: "1e20,1" became -2147483648 (an InputError after OUT was made).
    with pytest.raises(ValueError, match=r"--select .*must be pixels in \[0, 65536\)") as err:
        wul3d.run(TABLETOP, tmp_path / "o", select=select)
    assert not isinstance(err.value, wul3d.InputError)
    assert not (tmp_path / "o").exists()  # refused before anything is written


def test_select_gives_the_commands_message(cli, tmp_path):
    for text in ("1e20,1", "3abc,1", "1,2,3"):
        with pytest.raises(ValueError) as err:
            wul3d.run(TABLETOP, tmp_path / "o", select=text)
        proc = run_cli(cli, "run", TABLETOP, "--out", tmp_path / "cli", "--select", text)
        assert proc.returncode == 2 and str(err.value) in proc.stderr, (str(err.value), proc.stderr)


@pytest.mark.parametrize("select", [(1,), [1, 2, 3], 5, ("a", 1), (True, 1), {"u": 1}])
def test_select_of_the_wrong_type_is_a_type_error(tmp_path, select):
    with pytest.raises(TypeError, match="select"):
        wul3d.run(TABLETOP, tmp_path / "o", select=select)


# ---- item 17: wrong types name the argument -----------------------------------------------

@pytest.fixture(scope="module")
def frame():
    return wul3d.read(TABLETOP / "image_0005")[0]


def intrinsics_with(frame, **changes):
    d = frame.intrinsics.to_dict()
    d.update(changes)
    return d


WRONG = [
    # (what, call(frame, tmp_path), exception, message)
    ("fx '525'", lambda f, t: wul3d.Pipeline().process(
        f.color, f.depth, intrinsics_with(f, fx="525")), TypeError, r"intrinsics\['fx'\]: expected a number, got str"),
    ("cy None", lambda f, t: wul3d.Pipeline().process(
        f.color, f.depth, intrinsics_with(f, cy=None)), TypeError, r"intrinsics\['cy'\]"),
    ("width '640'", lambda f, t: wul3d.Pipeline().process(
        f.color, f.depth, intrinsics_with(f, width="640")), TypeError, r"intrinsics\['width'\]: expected an int"),
    ("width 2**40", lambda f, t: wul3d.Pipeline().process(
        f.color, f.depth, intrinsics_with(f, width=2**40)), ValueError, r"intrinsics\['width'\] = 1099511627776"),
    ("depth_scale '0.001'", lambda f, t: wul3d.Pipeline().process(
        f.color, f.depth, f.intrinsics, depth_scale="0.001"), TypeError, "depth_scale: expected a number"),
    ("Intrinsics('525', ...)", lambda f, t: wul3d.Intrinsics("525", 525, 320, 240),
     TypeError, "fx: expected a number"),
    ("Pipeline k '7'", lambda f, t: wul3d.Pipeline(k="7"), TypeError, "k: expected an int, got str"),
    ("Pipeline k 7.5", lambda f, t: wul3d.Pipeline(k=7.5), TypeError, "k: expected an int, got float"),
    ("Pipeline k 2**40", lambda f, t: wul3d.Pipeline(k=2**40), ValueError, "k = 1099511627776"),
    ("Pipeline alpha '0.01'", lambda f, t: wul3d.Pipeline(alpha="0.01"), TypeError, "alpha: expected a number"),
    ("Pipeline seed -1", lambda f, t: wul3d.Pipeline(seed=-1), ValueError, r"seed = -1: must be in \[0, 2\^64\)"),
    ("Pipeline preset 3", lambda f, t: wul3d.Pipeline(preset=3), TypeError, "preset: expected a str"),
    ("Pipeline remove_plane 'no'", lambda f, t: wul3d.Pipeline(remove_plane="no"),
     TypeError, "remove_plane: expected True or False"),
    ("Pipeline decimate True", lambda f, t: wul3d.Pipeline(decimate=True), TypeError, "decimate: expected an int, got bool"),
    ("run k '7'", lambda f, t: wul3d.run(TABLETOP, t / "o", k="7"), TypeError, "k: expected an int"),
    ("run frames 2**70", lambda f, t: wul3d.run(TABLETOP, t / "o", frames=2**70), ValueError, "frames = "),
    ("run frames '3'", lambda f, t: wul3d.run(TABLETOP, t / "o", frames="3"), TypeError, "frames: expected an int"),
    ("run ply 'yes'", lambda f, t: wul3d.run(TABLETOP, t / "o", ply="yes"), TypeError, "ply: expected True or False"),
    ("run overwrite 2", lambda f, t: wul3d.run(TABLETOP, t / "o", overwrite=2), TypeError, "overwrite"),
    ("run fx '525'", lambda f, t: wul3d.run(TABLETOP, t / "o", intrinsics={"fx": "525", "fy": 525, "cx": 1, "cy": 1}),
     TypeError, r"intrinsics\['fx'\]"),
    ("run intrinsics '1,2,3,4x'", lambda f, t: wul3d.run(TABLETOP, t / "o", intrinsics="525,525,3,4x"),
     ValueError, "--intrinsics '525,525,3,4x': '4x' is not a number"),
    ("run format 3", lambda f, t: wul3d.run(TABLETOP, t / "o", format=3), TypeError, "format: expected a str"),
    ("run input 5", lambda f, t: wul3d.run(5, t / "o"), TypeError, "input: expected a path"),
    ("run out None", lambda f, t: wul3d.run(TABLETOP, None), TypeError, "out: expected a path"),
    ("run calibration 7", lambda f, t: wul3d.run(TABLETOP, t / "o", calibration=7), TypeError, "calibration"),
    ("read format 3", lambda f, t: wul3d.read(TABLETOP, format=3), TypeError, "format: expected a str"),
    ("read tum_camera 5", lambda f, t: wul3d.read(TABLETOP, tum_camera=5), TypeError, "tum_camera"),
    ("read path 5", lambda f, t: wul3d.read(5), TypeError, "path: expected a path"),
    ("read fx '525'", lambda f, t: wul3d.read(TABLETOP, intrinsics={"fx": "525", "fy": 1, "cx": 1, "cy": 1}),
     TypeError, r"intrinsics\['fx'\]"),
    ("reader['a']", lambda f, t: wul3d.read(TABLETOP)["a"], TypeError, "integer"),
    ("reader[2**70]", lambda f, t: wul3d.read(TABLETOP)[2**70], IndexError, "out of range"),
    ("evaluate fraction 'x'", lambda f, t: wul3d.evaluate(f.depth, f.depth, boundary_fraction="x"),
     TypeError, "boundary_fraction: expected a number"),
    ("evaluate tolerance 2**40", lambda f, t: wul3d.evaluate(f.depth, f.depth, boundary_tolerance_px=2**40),
     ValueError, "boundary_tolerance_px = "),
    ("read_label_image 5", lambda f, t: wul3d.read_label_image(5), TypeError, "path: expected a path"),
]


@pytest.mark.parametrize("call, exception, message", [w[1:] for w in WRONG],
                         ids=[w[0] for w in WRONG])
def test_wrong_types_and_values_name_the_argument(frame, tmp_path, monkeypatch, call, exception,
                                                 message):
    # main: "fx": "525" raised RuntimeError "Unable to cast Python instance to C++ type";
    # the keyword arguments raised a TypeError listing the whole signature, naming none;
    # wul3d.run(INPUT, None) wrote into ./None (str(None)): run where that is harmless.
    monkeypatch.chdir(tmp_path)
    with pytest.raises(exception, match=message) as err:
        call(frame, tmp_path)
    assert type(err.value) is not RuntimeError and "\n" not in str(err.value)


def test_numpy_scalars_and_path_objects_are_accepted(frame, tmp_path):
    K = {"fx": np.float32(frame.intrinsics.fx), "fy": np.float64(frame.intrinsics.fy),
         "cx": frame.intrinsics.cx, "cy": frame.intrinsics.cy, "width": np.int64(640),
         "height": np.uint16(480)}
    p = wul3d.Pipeline(k=np.int32(7), alpha=np.float32(0.0033), remove_plane=np.bool_(True))
    assert p.process(frame.color, frame.depth, K, depth_scale=np.float64(0.001)).instances
    s = wul3d.run(TABLETOP, tmp_path / "o", frames=np.int64(1), select=(np.int64(320), 300.0))
    assert s["frames"] == 1
    assert len(wul3d.read(os.fsencode(TABLETOP))) == len(wul3d.read(str(TABLETOP))) == 4


# ---- outputs against the input -------------------------------------------------------------

@pytest.fixture()
def own_input(tmp_path):
    """A copy of the tabletop frames to attack, and its digest."""
    src = tmp_path / "in"
    shutil.copytree(TABLETOP, src)
    return src, tree_digest(src)


@pytest.mark.parametrize("where", ["same", "inside", "holding", "same-through-link",
                                   "same-through-dotdot"])
def test_out_against_the_input_is_refused(tmp_path, own_input, where):
    src, digest = own_input
    out = {"same": src, "inside": src / "image_0000" / "o", "holding": tmp_path,
           "same-through-link": tmp_path / "link",
           "same-through-dotdot": src / "image_0000" / ".."}[where]
    if where == "same-through-link":
        out.symlink_to(src)
    for overwrite in (False, True):
        with pytest.raises(wul3d.InputError, match="input"):
            wul3d.run(src, out, overwrite=overwrite, frames=1)
        assert tree_digest(src) == digest


@pytest.mark.parametrize("overwrite", [False, True])
def test_frames_jsonl_as_a_symlink_is_refused(tmp_path, own_input, overwrite):
    src, digest = own_input
    out = tmp_path / "out"
    out.mkdir()
    (out / "frames.jsonl").symlink_to(src / "image_0000" / "intrinsics.json")
    with pytest.raises(wul3d.InputError, match="frames.jsonl"):
        wul3d.run(src, out, overwrite=overwrite, frames=1)
    assert tree_digest(src) == digest
    assert (out / "frames.jsonl").is_symlink()


def test_an_out_being_written_is_refused_at_once(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    lock = wul3d._wul3d._OutputLock(str(out))  # what a run writing OUT holds
    with pytest.raises(wul3d.InputError, match="out"):
        wul3d.run(TABLETOP, out, frames=1)
    del lock
    assert wul3d.run(TABLETOP, out, frames=1)["frames"] == 1


@pytest.mark.parametrize("overwrite", ["False", "True"])
def test_frames_jsonl_as_a_fifo_is_refused_without_blocking(tmp_path, overwrite):
    out = tmp_path / "out"
    out.mkdir()
    os.mkfifo(out / "frames.jsonl")
    script = """
import sys, wul3d
try:
    wul3d.run(sys.argv[1], sys.argv[2], frames=1, overwrite=sys.argv[3] == "True")
except wul3d.InputError as e:
    print("InputError:", e)
"""
    proc = python(script, TABLETOP, out, overwrite, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith("InputError:") and "frames.jsonl" in proc.stdout, proc.stdout


# ---- image sizes -----------------------------------------------------------------------------

@pytest.fixture()
def max_pixels():
    before = wul3d.get_max_pixels()
    yield before
    wul3d.set_max_pixels(before)


@pytest.mark.parametrize("n", [0, -1, 2**30 + 1, 2**64])
def test_max_pixels_out_of_range(max_pixels, n):
    with pytest.raises(ValueError, match="pixels"):
        wul3d.set_max_pixels(n)
    assert wul3d.get_max_pixels() == max_pixels == 2**24


def test_process_refuses_an_image_past_the_limit_before_running(max_pixels):
    # 4097 x 4097 > 2^24: main ran the pipeline on it (an InputError after the work).
    depth = np.zeros((4097, 4097), np.uint16)
    K = {"fx": 4000.0, "fy": 4000.0, "cx": 2048.0, "cy": 2048.0}
    with pytest.raises(ValueError, match=r"larger than the limit of 16777216 pixels") as err:
        wul3d.Pipeline().process(None, depth, K)
    assert not isinstance(err.value, wul3d.InputError)
    with pytest.raises(ValueError, match="65536 a side"):
        wul3d.Pipeline().process(None, np.zeros((1, 65537), np.uint16), K)
    wul3d.set_max_pixels(2**25)  # then it is read, and found to have no depth
    with pytest.raises(wul3d.InputError, match="no valid pixel"):
        wul3d.Pipeline().process(None, depth, K)


def test_read_and_run_honour_max_pixels(max_pixels, tmp_path):
    wul3d.set_max_pixels(640 * 480 - 1)
    with pytest.raises(wul3d.InputError, match="pixels"):
        wul3d.read(TABLETOP)[0]
    with pytest.raises(wul3d.InputError, match="pixels"):
        wul3d.run(TABLETOP, tmp_path / "o", frames=1)
    wul3d.set_max_pixels(640 * 480)
    assert wul3d.read(TABLETOP)[0].depth.shape == (480, 640)


def test_frame_names_that_are_not_utf8_read_back_as_fsdecode_gives_them(tmp_path):
    # Frame.name raised UnicodeDecodeError for a frame folder named with bytes b"\xff\xfe".
    name = os.fsdecode(b"img\xff\xfe")
    shutil.copytree(TABLETOP / "image_0000", tmp_path / "seq" / name)
    frame = wul3d.read(str(tmp_path / "seq"))[0]
    assert frame.name == name
    assert os.fsencode(frame.name) == b"img\xff\xfe"
    assert "Frame(" in repr(frame)
