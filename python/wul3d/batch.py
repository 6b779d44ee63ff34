"""Many sequences through wul3d on Dask: one machine's cores or a cluster (docs/SCALE.md).

    python3 -m wul3d.batch ROOT --out OUT [--scheduler ADDRESS | --workers N] [run options]

Finds every sequence under ROOT (a TUM sequence, an OCID sequence, an OSD-0.2-depth tree, a
BOP scene, a ROS 1 bag, a folder of frame folders, or ROOT itself when it is one frame or one
bag), runs each as one Dask task with wul3d.run (the library's run loop, the
same outputs as `wul3d run`), and writes OUT/<sequence path relative to ROOT>/ in the layout
of `wul3d run`, and OUT/batch.json with per-sequence and total figures and, where the
frames carry label.png, the UOIS table.

Nothing half-done: a task runs into a staging folder under OUT/.wul3d.staging-<pid>-<id>/
(one per batch) and moves it into place when complete; summary.json, written last, marks a
finished sequence. A second run over the same OUT skips finished sequences and redoes the
others. A task whose worker dies is retried by Dask on another worker; a sequence with bad
input is reported with its one-line reason and the others go on.

Nothing lost: OUT may not be ROOT, lie inside it or hold it (nor any folder a link under
ROOT leads to): the library's guard refuses it before anything is written. The batch removes
only what wul3d wrote: an existing OUT/<sequence> holding anything else fails that sequence
(as `wul3d run` refuses such an OUT), unless --overwrite, which replaces wul3d's own files
only. OUT is locked (flock) for the whole batch: one writer at a time.

Exit code: 0 when every sequence succeeded, 1 when some failed, 2 for bad arguments (and a
refused or locked OUT), 130 after SIGINT, 143 after SIGTERM (batch.json written with what
finished; docs/SCALE.md).
"""

import argparse
import asyncio
import json
import logging
import os
import pathlib
import signal
import socket
import sys
import threading
import time
import uuid

import wul3d

from . import _wul3d

# discover, output_dir, foreign_entry and the names of what the batch writes are wul3d.batch's
# API too (docs/SCALE.md), defined in discovery.py and staging.py.
from .discovery import MAX_DEPTH, discover, discover_all, text  # noqa: F401
from .staging import (DONE_MARKER, FRAME_OUTPUT_FILES, LIVE_MARKER, OWN_PREFIX,  # noqa: F401
                      STAGING_PREFIX, Refused, check_write_target, foreign_entry, is_finished,
                      lstat_or_none, make_staging, no_link_on_the_way, output_dir, publish,
                      remove_run_output, remove_staging)

BATCH_JSON = "batch.json"
EXIT_OK, EXIT_FAILED, EXIT_USAGE = 0, 1, 2
EXIT_SIGNAL_BASE = 128  # 130 after SIGINT, 143 after SIGTERM, as a shell reports them
RUN_FLAGS = {"no_plane", "ply", "overlay"}


def run_options():
    """The options of `wul3d run` that pass through, keyword -> (type, help): the pipeline's
    parameters from the library's table (wul3d.parameters(); its switch, remove_plane, is the
    command's --no-plane flag, in RUN_FLAGS), then the run's own options."""
    types = {"int": int, "float": float, "str": str}
    options = {"preset": (str, 'as `wul3d run --preset`: "default" or "paper"')}
    for p in _wul3d.parameters():
        if p["type"] != "bool":
            options[p["name"]] = (types[p["type"]],
                                  f"{p['help']}, {p['range']} (default {p['default']})")
    for name, kind in (("format", str), ("tum_camera", str), ("intrinsics", str),
                       ("calibration", str), ("registration", str), ("select", str),
                       ("frames", int), ("outputs", str)):
        options[name] = (kind, f"as `wul3d run --{name.replace('_', '-')}`")
    return options


class BatchError(ValueError):
    """A batch refused as a whole (OUT against the input, a locked OUT): one line, exit 2."""


class Interrupted(KeyboardInterrupt):
    """SIGINT or SIGTERM stopped the batch. `report` is batch.json's content (written),
    `signum` the signal, `line` the one line that says so."""

    def __init__(self, signum, report, line):
        super().__init__(line)
        self.signum, self.report, self.line = signum, report, line


def _one_line(e: BaseException) -> str:
    msg = str(e).splitlines()[0] if str(e).strip() else type(e).__name__
    return text(msg)


# ---- one task -----------------------------------------------------------------------------

def _frame_scores(input_dir: pathlib.Path, out_dir: pathlib.Path, names):
    """Per frame with INPUT/<frame>/label.png: the UOIS scores of objects.png against it."""
    scores = []
    for name in names:
        gt_path = input_dir / name / "label.png"
        if not gt_path.is_file() or not (out_dir / name / "objects.png").is_file():
            continue  # no ground truth, or objects.png left out (--outputs)
        s = wul3d.evaluate(wul3d.read_label_image(os.fsencode(out_dir / name / "objects.png")),
                           wul3d.read_label_image(os.fsencode(gt_path)))
        s.pop("matches")
        s["frame"] = text(name)
        scores.append(s)
    return scores


def _run(input_dir: str, out: str, options: dict) -> dict:
    """wul3d.run; with the paths as bytes where they are not UTF-8 (the binding takes bytes,
    and wul3d.run would make "b'...'" of them)."""
    if text(input_dir) == input_dir and text(out) == out:
        return wul3d.run(input_dir, out, **options)
    return _wul3d._run(os.fsencode(input_dir), os.fsencode(out), dict(options))


def run_sequence_task(input_dir, out_root, rel_out, options: dict, threads: int,
                      score: bool = True, staging_root=None, nested=(), overwrite=False,
                      index=0) -> dict:
    """One Dask task: `wul3d run` of one sequence into OUT/<rel_out>, staged and moved.

    Paths may be str or bytes (bytes keep names that are not UTF-8 intact through Dask).
    `staging_root` is the batch's staging folder (a new OUT/.wul3d.staging-* folder of this
    task when None); the task's try runs in `<index>.<pid>.<random>` inside it. `nested`:
    the names of folders in OUT/<rel_out> that hold other sequences' outputs.
    Returns the sequence's record for batch.json. Bad input, or an existing output holding
    what wul3d did not write, is caught and reported (status "failed", error = the one-line
    reason); anything else (a dying worker) is Dask's to retry.
    """
    input_dir, out_root, rel_out = (os.fsdecode(p) for p in (input_dir, out_root, rel_out))
    record = {"sequence": text(rel_out), "input": text(input_dir), "worker": _worker_name(),
              "status": "failed", "error": None, "frames": 0, "fps": 0.0, "wall_s": 0.0}
    own_root = staging_root is None
    staging_root = pathlib.Path(out_root) / (
        f"{STAGING_PREFIX}{os.getpid()}-{uuid.uuid4().hex}" if own_root
        else os.fsdecode(staging_root))
    # The worker's pid in the name: who is writing it (the fault tests kill that process).
    staging = staging_root / f"{index}.{os.getpid()}.{uuid.uuid4().hex}"
    final = pathlib.Path(out_root) / rel_out
    start = time.monotonic()
    ended = False
    batch_fd = None
    try:
        if threads > 0:
            import wul3d

            wul3d.set_num_threads(threads)
        if own_root:
            make_staging(staging_root)
        # The batch renames its folder when it ends or is interrupted: then this try is not
        # wanted (a task on a cluster's worker may outlive its batch). The folder is held
        # open (its inode cannot be reused) and must hold the batch's marker (a folder the
        # run made again at the path, creating its output's parents, does not).
        batch_fd = os.open(staging_root, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
        batch_folder = os.fstat(batch_fd)
        try:
            os.stat(LIVE_MARKER, dir_fd=batch_fd, follow_symlinks=False)
        except FileNotFoundError:
            ended = True
            raise Refused("the batch ended before this sequence started") from None
        staging.mkdir()
        summary = _run(input_dir, str(staging), options)
        names = sorted(p.name for p in staging.iterdir() if p.is_dir())
        record["scores"] = _frame_scores(pathlib.Path(input_dir), staging, names) if score else []
        now = lstat_or_none(staging_root)
        if now is None or (now.st_dev, now.st_ino) != (batch_folder.st_dev, batch_folder.st_ino):
            ended = True
            raise Refused("the batch ended before this sequence was done; not published")
        check_write_target(final, "folder", [input_dir], "output folder")
        no_link_on_the_way(pathlib.Path(out_root), final)
        publish(staging, final, nested, overwrite)
        record.update(status="ok", frames=summary["frames"], fps=summary["fps"])
    except (ValueError, OSError, RuntimeError, TypeError) as e:
        # wul3d.InputError is a ValueError; UnicodeError too
        record["error"] = _one_line(e)
    finally:
        if batch_fd is not None:
            os.close(batch_fd)
        if lstat_or_none(staging) is not None:
            remove_run_output(staging)
        if own_root or ended:
            remove_staging(staging_root)  # an ended batch's folder, made again by the run
        record["wall_s"] = time.monotonic() - start
    return record


def _worker_name() -> str:
    try:
        from distributed import get_worker

        return get_worker().address
    except (ImportError, ValueError):
        return f"{socket.gethostname()}:{os.getpid()}"


def _close_once(extension):
    """Makes a worker extension's close() a no-op the second time. Dask 2022.12 can close a
    worker twice when its batch ends the workers (a SIGINT or SIGTERM to the process group),
    and its shuffle extension asserts on the second close: the worker process then dies with
    a traceback on stderr after the batch's own one line."""
    close = extension.close

    async def close_once():
        if not getattr(extension, "closed", False):
            await close()

    extension.close = close_once


class _QuietWhileClosing(logging.Filter):
    """Drops a worker's log records once it is closing: ending the workers logs Dask's and
    tornado's shutdown races as errors, noise after the batch's own one line."""

    def __init__(self, worker):
        super().__init__()
        self.worker = worker

    def filter(self, record):
        status = getattr(getattr(self.worker, "status", None), "name", "")
        return status not in ("closing", "closing_gracefully", "closed", "failed")


class IgnoreStopSignals:
    """A Dask worker plugin for the batch's local workers: they ignore SIGINT and SIGTERM.
    Ctrl-C (and a service manager's SIGTERM) reach the whole process group; the batch, not
    each worker with a traceback, handles them, and then ends the workers itself; a second close of a
    worker is harmless (_close_once) and a closing worker logs nothing (_QuietWhileClosing). (A plugin, not a preload: it is applied to restarted
    workers too.)"""

    name = "wul3d-ignore-stop-signals"

    def setup(self, worker):
        if threading.current_thread() is threading.main_thread():
            for s in (signal.SIGINT, signal.SIGTERM):
                signal.signal(s, signal.SIG_IGN)
        shuffle = getattr(worker, "extensions", {}).get("shuffle")
        if shuffle is not None and hasattr(shuffle, "close"):
            _close_once(shuffle)
        quiet = _QuietWhileClosing(worker)
        loggers = [logging.getLogger(n) for n in list(logging.root.manager.loggerDict)
                   if n.split(".")[0] in _DASK_LOGGERS] + [logging.getLogger()]
        for handler in {h for lg in loggers for h in lg.handlers}:
            handler.addFilter(quiet)


def _end_local_workers(cluster):
    """SIGKILL to the LocalCluster's worker processes, not restarted: a task running C++
    for minutes would otherwise hold the cluster's close (Dask waits for it, then kills).
    Each nanny is told first that it is closing (close_gracefully): a nanny that saw its
    worker die would start a new one, which ignores SIGTERM (IgnoreStopSignals), and
    Python's exit would wait for it for ever (multiprocessing joins its children)."""
    for nanny in list(getattr(cluster, "workers", {}).values()):
        try:
            nanny.close_gracefully(reason="wul3d.batch interrupted")
            pid = nanny.process.pid if nanny.process is not None else None
            if pid:
                os.kill(pid, signal.SIGKILL)
        except (AttributeError, OSError):
            pass


# ---- the batch ----------------------------------------------------------------------------

class _Progress:
    """A one-line bar on stderr, only when stderr is a terminal."""

    def __init__(self, total, enabled=True):
        self.total, self.done = total, 0
        self.enabled = enabled and sys.stderr.isatty()

    def step(self, failed=0):
        self.done += 1
        if self.enabled:
            width = 30
            filled = width * self.done // max(1, self.total)
            sys.stderr.write(f"\r[{'#' * filled}{' ' * (width - filled)}] {self.done}/{self.total}"
                             f" sequences{f', {failed} failed' if failed else ''}")
            sys.stderr.flush()

    def finish(self):
        if self.enabled:
            sys.stderr.write("\r" + " " * 70 + "\r")
            sys.stderr.flush()


def _uois_table(records):
    """The UOIS summary over all scored frames and per sequence (wul3d eval's figures)."""
    scored = [r for r in records if r.get("scores")]
    if not scored:
        return None
    all_scores = [s for r in scored for s in r["scores"]]
    return {"all": _wul3d._summarize(all_scores),
            "per_sequence": {r["sequence"]: _wul3d._summarize(r["scores"]) for r in scored}}


class _Signals:
    """SIGINT and SIGTERM, while the batch runs (in the main thread only): the first one is
    recorded (the batch stops at its next check, within a fraction of a second) and silences
    Dask's logging of the shutdown; a second one ends the process at once."""

    def __init__(self):
        self.signum = None
        self._old = {}

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            for s in (signal.SIGINT, signal.SIGTERM):
                self._old[s] = signal.signal(s, self._handle)
        return self

    def _handle(self, signum, frame):  # noqa: ARG002
        if self.signum is not None:
            os._exit(EXIT_SIGNAL_BASE + signum)
        self.signum = signum
        _quiet_dask()

    def __exit__(self, *exc):
        for s, old in self._old.items():
            signal.signal(s, old)
        return False


_DASK_LOGGERS = ("distributed", "tornado", "asyncio", "bokeh")


def _quiet_dask():
    """No more log lines from Dask: it reports the workers being closed as errors. Its
    loggers and their children that have a level of their own (tornado.application)."""
    names = [n for n in logging.root.manager.loggerDict if n.split(".")[0] in _DASK_LOGGERS]
    for name in (*_DASK_LOGGERS, *names):
        logging.getLogger(name).setLevel(logging.CRITICAL + 1)


def _write_batch_json(out: pathlib.Path, report: dict, inputs):
    """OUT/batch.json, through the library's guard (a plain file or none there; not an input)
    and a new temporary (O_EXCL, never a link followed) renamed over it. Every string is
    valid Unicode: names that are not UTF-8 are escaped (text)."""
    target = out / BATCH_JSON
    check_write_target(target, "file", inputs, BATCH_JSON)
    tmp = out / f"{OWN_PREFIX}tmp-batch-{os.getpid()}-{uuid.uuid4().hex[:8]}"
    data = (json.dumps(report, indent=2, ensure_ascii=False) + "\n").encode("utf-8")
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC, 0o644)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.replace(tmp, target)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def _clean_strings(value):
    """`value` with every str made valid Unicode (text)."""
    if isinstance(value, str):
        return text(value)
    if isinstance(value, dict):
        return {_clean_strings(k): _clean_strings(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean_strings(v) for v in value]
    return value


def run_batch(root, out, scheduler=None, workers=None, threads_per_worker=None, options=None,
              retries=1, progress=True, client=None, timeout_s=None, score=True,
              overwrite=False) -> dict:
    """Runs every sequence under `root` (discover) into `out` on Dask; returns batch.json's
    content, also written to OUT/batch.json.

    Args:
        root: the dataset folder (or one bag file).
        out: the output folder (shared by every worker). It may not be `root`, lie inside it
            or hold it, nor any folder a link under `root` leads to (BatchError, before
            anything is written); it is locked for the whole batch (BatchError when another
            batch or run holds it).
        scheduler: a Dask scheduler's address ("tcp://host:8786"); None starts a LocalCluster.
        workers: worker processes of the LocalCluster (default: one per 2 cores).
        threads_per_worker: wul3d threads in each task (default: cores // workers locally,
            the worker's own setting on a cluster).
        options: `wul3d run` options as keywords of wul3d.run (k=5, decimate=1, ...).
        retries: extra tries of a task that raised (worker deaths are retried by Dask's
            scheduler regardless, up to distributed.scheduler.allowed-failures).
        client: an existing distributed.Client to use instead of scheduler/workers.
        timeout_s: give up waiting after this many seconds (TimeoutError); None: no limit.
        score: False skips the UOIS table (scoring a 640x480 frame costs more than
            processing it, docs/SCALE.md).
        overwrite: as `wul3d run --overwrite`: an existing OUT/<sequence> holding files
            wul3d did not write is written anyway, replacing only wul3d's own files there
            (without it, that sequence fails and nothing of it is touched).

    Raises BatchError (a ValueError) for a refused or locked OUT, Interrupted (a
    KeyboardInterrupt) after SIGINT or SIGTERM in the main thread, once batch.json is
    written with what finished.
    """
    from distributed import Client, LocalCluster, wait
    from distributed.utils import TimeoutError as DaskTimeoutError

    options = dict(options or {})
    _wul3d._check_run_options(options)  # a bad option fails once, here, not in every task
    out_given = os.fspath(out)
    root = pathlib.Path(os.path.realpath(root))
    try:
        # Before anything is read or written: OUT apart from ROOT (however spelt).
        check_write_target(out_given, "folder", [root], "--out")
        found = discover_all(root)
        inputs = [str(root)] + found.links  # the folders links lead to are inputs too
        check_write_target(out_given, "folder", inputs, "--out")
        if lstat_or_none(pathlib.Path(out_given) / BATCH_JSON) is not None:
            check_write_target(pathlib.Path(out_given) / BATCH_JSON, "file", inputs,
                                BATCH_JSON)
    except _wul3d.InputError as e:
        raise BatchError(_one_line(e)) from None
    out = pathlib.Path(os.path.realpath(out_given))
    out.mkdir(parents=True, exist_ok=True)
    try:
        lock = _wul3d._OutputLock(os.fsencode(out))  # one writer of OUT for the whole batch
    except _wul3d.InputError as e:
        raise BatchError(_one_line(e)) from None
    try:
        with _Signals() as signals:
            return _run_locked(root, out, found, inputs, signals, scheduler, workers,
                               threads_per_worker, options, retries, progress, client,
                               timeout_s, score, overwrite, Client, LocalCluster, wait,
                               DaskTimeoutError)
    finally:
        del lock


def _run_locked(root, out, found, inputs, signals, scheduler, workers, threads_per_worker,
                options, retries, progress, client, timeout_s, score, overwrite, Client,
                LocalCluster, wait, DaskTimeoutError):
    _wul3d._remove_stale_temporaries(os.fsencode(out))  # of a run killed mid-write
    for e in sorted(os.scandir(out), key=lambda e: e.name):  # of a batch killed mid-way
        if e.name.startswith(STAGING_PREFIX) and e.is_dir(follow_symlinks=False):
            remove_staging(pathlib.Path(e.path))
    staging = out / f"{STAGING_PREFIX}{os.getpid()}-{uuid.uuid4().hex[:12]}"
    make_staging(staging)

    sequences = found.sequences
    rel_outs = {rel: str(output_dir(out, root, rel).relative_to(out)) for rel in sequences}
    all_outs = set(rel_outs.values())

    def nested_names(rel_out):
        prefix = rel_out + "/"
        return sorted({o[len(prefix):].split("/")[0] for o in all_outs if o.startswith(prefix)})

    cluster = None
    own_client = client is None
    start = time.monotonic()
    records, futures = {}, {}
    interrupted = error = None
    try:
        if client is None:
            if scheduler:
                client = Client(scheduler, timeout="30s")
            else:
                cores = os.cpu_count() or 1
                workers = workers or max(1, cores // 2)
                threads_per_worker = threads_per_worker or max(1, cores // workers)
                # One task per worker at a time: a task's own threads use the cores. The
                # workers ignore SIGINT and SIGTERM (IgnoreStopSignals): the batch handles
                # them.
                cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                       dashboard_address=":0")
                client = Client(cluster)
                client.register_worker_plugin(IgnoreStopSignals())
        start = time.monotonic()
        for index, rel in enumerate(sequences):
            if signals.signum is not None:
                break
            rel_out = rel_outs[rel]
            final = out / rel_out
            if is_finished(final):
                records[rel_out] = _finished_record(root / rel, final, rel_out, score)
                continue
            what = None if overwrite or lstat_or_none(final) is None else foreign_entry(
                final, nested_names(rel_out))
            if what is not None:
                records[rel_out] = _failed_record(
                    rel_out, root / rel,
                    f"{text(str(final))}: holds what wul3d did not write ({what}); choose "
                    "another --out, or --overwrite to replace only wul3d's own files there")
                continue
            fut = client.submit(run_sequence_task, os.fsencode(root / rel), os.fsencode(out),
                                os.fsencode(rel_out), options, threads_per_worker or 0, score,
                                os.fsencode(staging), nested_names(rel_out), overwrite, index,
                                key=f"wul3d-{index}-{uuid.uuid4().hex}",  # ASCII: Dask's keys
                                retries=retries, pure=False)
            futures[fut] = (rel_out, rel)
        bar = _Progress(len(sequences), progress)
        for _ in records:
            bar.step()
        failed = sum(r["status"] == "failed" for r in records.values())
        pending = set(futures)
        deadline = None if timeout_s is None else time.monotonic() + timeout_s
        while pending and signals.signum is None:
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                raise TimeoutError(f"wul3d.batch: {len(pending)} sequences unfinished after "
                                   f"{timeout_s} s")
            lost = None
            try:  # short waits: a signal is seen within a fraction of a second
                done, pending = wait(pending, timeout=0.2 if left is None else min(0.2, left),
                                     return_when="FIRST_COMPLETED")
            except DaskTimeoutError:
                continue
            except (Exception, asyncio.CancelledError) as e:  # noqa: BLE001
                # The scheduler lost or cancelled some (a connection dropped): those end
                # here as failed, the others are waited for.
                lost = f"{type(e).__name__}: {_one_line(e)}"
                done = {f for f in pending if f.status != "pending"} or set(pending)
                pending = pending - done
            for fut in sorted(done, key=lambda f: futures[f][0]):
                rel_out, rel = futures[fut]
                try:
                    if fut.status == "pending":
                        raise RuntimeError(lost)
                    rec = fut.result(timeout=10)
                except (Exception, asyncio.CancelledError) as e:  # noqa: BLE001  (KilledWorker
                    # after too many deaths, a cancelled or lost task)
                    rec = _failed_record(rel_out, root / rel, f"{type(e).__name__}: {_one_line(e)}")
                rec["sequence"], rec["input"] = text(rel_out), text(str(root / rel))
                failed += rec["status"] != "ok"
                records[rel_out] = rec
                bar.step(failed)
        bar.finish()
        if signals.signum is not None and len(records) < len(sequences):
            interrupted = signals.signum
            started = set()
            for e in os.scandir(staging):  # a task's try folder: "<index>.<pid>.<random>"
                head = e.name.split(".", 1)[0]
                if head.isdigit():
                    started.add(int(head))
            if pending:
                client.cancel(list(pending), force=True)
            for index, rel in enumerate(sequences):
                if rel_outs[rel] not in records:
                    records[rel_outs[rel]] = dict(
                        _failed_record(rel_outs[rel], root / rel, None),
                        status="stopped" if index in started else "not_started")
    except Exception as e:  # a scheduler out of reach, timeout_s: batch.json all the same
        error = e
        for rel in sequences:
            if rel_outs[rel] not in records:
                records[rel_outs[rel]] = _failed_record(
                    rel_outs[rel], root / rel, f"not finished: {_one_line(e)}")
    finally:
        if own_client and client is not None:
            if interrupted is not None or signals.signum is not None:
                _quiet_dask()
                if cluster is not None:
                    _end_local_workers(cluster)
            client.close(timeout=5)
            if cluster is not None:
                cluster.close(timeout=5)
        # Every task is over, or (on a cluster, or a client given) a task still running
        # finds the folder renamed and publishes nothing, and its run fails at its next
        # write. What a killed worker was writing goes (its sequence was redone).
        ended = staging.with_name(staging.name + ".ended")
        try:
            os.rename(staging, ended)
        except OSError:
            ended = staging
        for _ in range(3):
            if remove_staging(ended):
                break
            time.sleep(0.1)
    if interrupted is not None:  # finished, but the result was not collected: OUT says so
        for rel_out, rec in records.items():
            if rec["status"] in ("stopped", "not_started") and is_finished(out / rel_out):
                rel = next(r for r, o in rel_outs.items() if o == rel_out)
                done = _finished_record(root / rel, out / rel_out, rel_out, False)
                records[rel_out] = dict(done, status="ok")
    wall_s = time.monotonic() - start
    names = sorted(records)
    report = _report(root, out, options, scheduler, cluster, names,
                     [records[k] for k in names], found, wall_s)
    if interrupted is not None:
        report["interrupted_by"] = signal.Signals(interrupted).name
    _write_batch_json(out, report, inputs)
    if error is not None:
        raise error
    if interrupted is not None:
        t = report["totals"]
        line = (f"wul3d.batch: interrupted by {signal.Signals(interrupted).name}; "
                f"{t['succeeded'] + t['skipped']} sequences finished, {t['stopped']} stopped, "
                f"{t['not_started']} not started; {t['failed']} failed "
                f"-> {text(str(out / BATCH_JSON))}")
        raise Interrupted(interrupted, report, line)
    return report


def _failed_record(rel_out, input_dir, error):
    return {"sequence": text(rel_out), "input": text(str(input_dir)), "worker": None,
            "status": "failed", "error": error, "frames": 0, "fps": 0.0, "wall_s": 0.0}


def _report(root, out, options, scheduler, cluster, names, ordered, found, wall_s):
    """batch.json's content; `names` are the sequences' output paths (as os.fsdecode gives
    them), `ordered` their records, in that order."""
    frames = sum(r["frames"] for r in ordered if r["status"] in ("ok", "skipped"))
    done_now = sum(r["frames"] for r in ordered if r["status"] == "ok")
    sequences = []
    for name, r in zip(names, ordered):
        rec = _clean_strings({k: v for k, v in r.items() if k != "scores"})
        raw = os.fsencode(name) if text(name) != name else None
        if raw is not None:  # the name's bytes, where it is not UTF-8
            rec["sequence_hex"] = raw.hex()
        sequences.append(rec)
    report = {
        "root": text(str(root)),
        "out": text(str(out)),
        "options": _clean_strings(options),
        "scheduler": scheduler or ("local" if cluster is not None else "client"),
        "totals": {
            "sequences": len(ordered),
            "succeeded": sum(r["status"] == "ok" for r in ordered),
            "skipped": sum(r["status"] == "skipped" for r in ordered),
            "failed": sum(r["status"] == "failed" for r in ordered),
            "stopped": sum(r["status"] == "stopped" for r in ordered),
            "not_started": sum(r["status"] == "not_started" for r in ordered),
            "frames": frames,
            "frames_this_run": done_now,
            "wall_s": wall_s,
            "fps": done_now / wall_s if wall_s > 0 else 0.0,
        },
        "sequences": sequences,
    }
    if found.unread:
        report["not_searched"] = [{"folder": text(p), "reason": text(why)}
                                  for p, why in found.unread]
    uois = _uois_table(ordered)
    if uois is not None:
        report["uois"] = _clean_strings(uois)
    return report


def _finished_record(input_dir, out_dir, rel_out, score):
    """batch.json's record of a sequence a previous run finished (its scores recomputed)."""
    try:
        with open(out_dir / DONE_MARKER, encoding="utf-8", errors="replace") as f:
            summary = json.load(f)
    except (OSError, ValueError) as e:  # skipped all the same: its figures are unknown
        summary = {"error": f"{DONE_MARKER}: {_one_line(e)}"}
    names = sorted(p.name for p in out_dir.iterdir()
                   if p.is_dir() and (out_dir / p.name / "objects.png").is_file())
    return {"sequence": text(rel_out), "input": text(str(input_dir)), "worker": None,
            "status": "skipped", "error": summary.get("error") if "frames" not in summary
            else None, "frames": summary.get("frames", 0),
            "fps": summary.get("fps", 0.0), "wall_s": 0.0,
            "scores": _frame_scores(pathlib.Path(input_dir), out_dir, names) if score else []}


# ---- command line -------------------------------------------------------------------------

def _parser():
    p = argparse.ArgumentParser(
        prog="python3 -m wul3d.batch",
        description="Run wul3d over every sequence under ROOT on Dask (docs/SCALE.md).")
    p.add_argument("root", help="dataset folder: sequences (frame folders, TUM) anywhere below")
    p.add_argument("-o", "--out", required=True, help="output folder, shared by every worker")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--scheduler", help="address of a running Dask scheduler")
    where.add_argument("--workers", type=int, help="local worker processes (default: cores / 2)")
    p.add_argument("--threads-per-worker", "--threads", dest="threads_per_worker", type=int,
                   help="wul3d threads in each task (default: cores / workers)")
    p.add_argument("--retries", type=int, default=1, help="extra tries of a task that raised")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    p.add_argument("--no-score", action="store_true",
                   help="no UOIS table even where frames carry label.png")
    run = p.add_argument_group("run options (as `wul3d run`)")
    for name, (kind, help) in run_options().items():
        run.add_argument("--" + name.replace("_", "-"), dest=name, type=kind,
                         metavar=kind.__name__.upper(), help=help)
    run.add_argument("--no-plane", action="store_true", help="as `wul3d run --no-plane`")
    run.add_argument("--ply", action="store_true", help="as `wul3d run --ply`")
    run.add_argument("--overlay", action="store_true", help="as `wul3d run --overlay`")
    p.add_argument("--overwrite", action="store_true",
                   help="as `wul3d run --overwrite`: write into an OUT/<sequence> that holds "
                        "files wul3d did not write, replacing only wul3d's own files there")
    return p


def main(argv=None) -> int:
    try:
        return _main(argv)
    except Interrupted as e:
        print(e.line, file=sys.stderr)
        return EXIT_SIGNAL_BASE + e.signum
    except KeyboardInterrupt:  # before the batch's own handling began (or after it)
        print("wul3d.batch: interrupted by SIGINT before any sequence started", file=sys.stderr)
        return EXIT_SIGNAL_BASE + signal.SIGINT


def _main(argv) -> int:
    parser = _parser()
    args = parser.parse_args([os.fsdecode(a) for a in argv] if argv is not None else None)
    for name in ("workers", "threads_per_worker"):
        value = getattr(args, name)
        if value is not None and value < 1:
            parser.error(f"--{name.replace('_', '-')} {value}: must be >= 1")
    options = {k: getattr(args, k) for k in run_options() if getattr(args, k) is not None}
    options.update({k: True for k in RUN_FLAGS if getattr(args, k)})
    try:
        report = run_batch(args.root, args.out, scheduler=args.scheduler, workers=args.workers,
                           threads_per_worker=args.threads_per_worker, options=options,
                           retries=args.retries, progress=not args.quiet,
                           score=not args.no_score, overwrite=args.overwrite)
    except (FileNotFoundError, ValueError, OSError) as e:
        print(f"wul3d.batch: {_one_line(e)}", file=sys.stderr)
        return EXIT_USAGE
    t = report["totals"]
    for r in report.get("not_searched", []):
        print(f"wul3d.batch: {r['folder']}: not searched ({r['reason']})", file=sys.stderr)
    for r in report["sequences"]:
        if r["status"] == "failed":
            print(f"wul3d.batch: {r['sequence']}: {r['error']}", file=sys.stderr)
    print(f"wul3d.batch: {t['succeeded']} sequences done, {t['skipped']} already done, "
          f"{t['failed']} failed; {t['frames_this_run']} frames in {t['wall_s']:.1f} s "
          f"({t['fps']:.1f} FPS) -> {report['out']}/{BATCH_JSON}")
    return EXIT_OK if t["failed"] == 0 else EXIT_FAILED


if __name__ == "__main__":
    sys.exit(main())
