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

