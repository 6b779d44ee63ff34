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

