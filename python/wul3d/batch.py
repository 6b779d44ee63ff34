"""Many sequences through wul3d on Dask: one machine's cores or a cluster (docs/SCALE.md).

    python3 -m wul3d.batch ROOT --out OUT [--scheduler ADDRESS | --workers N] [run options]

Finds every sequence under ROOT (a TUM sequence, a folder of frame folders, or ROOT itself
when it is one frame), runs each as one Dask task with wul3d.run (the library's run loop, the
same outputs as `wul3d run`), and writes OUT/<sequence path relative to ROOT>/ in the layout
of `wul3d run`, and OUT/batch.json with per-sequence and total figures and, where the
frames carry label.png, the UOIS table.

Nothing half-done: a task runs into a staging folder under OUT/.staging/ and renames it into
place when complete; summary.json, written last, marks a finished sequence. A second run over
the same OUT skips finished sequences and redoes the others. A task whose worker dies is
retried by Dask on another worker; a sequence with bad input is reported with its one-line
reason and the others go on. Exit code: 0 when every sequence succeeded, 1 when some failed,
2 for bad arguments.
"""

import argparse
import json
import os
import pathlib
import shutil
import socket
import sys
import time
import uuid

STAGING = ".staging"
BATCH_JSON = "batch.json"
DONE_MARKER = "summary.json"  # written last by the run loop
# Options of `wul3d run` that pass through (flag name -> wul3d.run keyword).
RUN_OPTIONS = {
    "preset": str, "k": int, "alpha": float, "delta": float, "gamma": float, "psi": float,
    "iters": int, "stride": int, "seed": int, "zmin": float, "zmax": float,
    "normal_radius": int, "segmenter": str, "scope": str, "min_points": int, "object_psi": float,
    "decimate": int, "format": str, "tum_camera": str, "intrinsics": str, "calibration": str,
    "registration": str, "select": str, "frames": int,
}
RUN_FLAGS = {"no_plane", "ply", "overlay"}


# ---- discovery ----------------------------------------------------------------------------

def _is_frame(d: pathlib.Path) -> bool:
    return (d / "depth.png").is_file()


def _is_tum(d: pathlib.Path) -> bool:
    return (d / "rgb.txt").is_file() and (d / "depth.txt").is_file()


def discover(root) -> list:
    """The sequences under `root`, as paths relative to it ("." for root itself), sorted.

    A TUM sequence (rgb.txt and depth.txt) is one sequence; a folder whose sub-folders are
    frames (depth.png) is one sequence of those frames, as `wul3d run FOLDER` reads it; root
    itself being one frame is a sequence of one. Other folders are searched further (a
    folder can hold frames and sequences of its own). Hidden folders are skipped.
    """
    root = pathlib.Path(root)
    if not root.is_dir():
        raise FileNotFoundError(f"{root}: no such folder")
    if _is_tum(root) or _is_frame(root):
        return ["."]
    found = []

    def walk(d: pathlib.Path):
        children = sorted(c for c in d.iterdir() if c.is_dir() and not c.name.startswith("."))
        if _is_tum(d):
            found.append(d)
            return
        if any(_is_frame(c) for c in children):
            found.append(d)
        for c in children:
            if not _is_frame(c):
                walk(c)

    walk(root)
    return [str(p.relative_to(root)) if p != root else "." for p in found]


def output_dir(out, root, rel) -> pathlib.Path:
    """OUT/<rel>, or OUT/<root's name> for root itself."""
    return pathlib.Path(out) / (pathlib.Path(root).resolve().name if rel == "." else rel)


def is_finished(out_dir: pathlib.Path) -> bool:
    return (out_dir / DONE_MARKER).is_file()


# ---- one task -----------------------------------------------------------------------------

def _publish(staging: pathlib.Path, final: pathlib.Path):
    """Moves a complete staging folder to `final`: one rename when `final` does not exist;
    else (it holds a nested sequence's output, or an unfinished earlier try) entry by entry,
    the marker last."""
    final.parent.mkdir(parents=True, exist_ok=True)
    try:
        os.rename(staging, final)
        return
    except OSError:
        if not final.is_dir():
            raise
    (final / DONE_MARKER).unlink(missing_ok=True)
    entries = sorted(staging.iterdir(), key=lambda p: p.name == DONE_MARKER)
    for entry in entries:
        target = final / entry.name
        if target.is_dir() and not target.is_symlink():
            shutil.rmtree(target)
        os.replace(entry, target)
    staging.rmdir()


def _frame_scores(input_dir: pathlib.Path, out_dir: pathlib.Path, names):
    """Per frame with INPUT/<frame>/label.png: the UOIS scores of objects.png against it."""
    import wul3d

    scores = []
    for name in names:
        gt_path = input_dir / name / "label.png"
        if not gt_path.is_file():
            continue
        s = wul3d.evaluate(wul3d.read_label_image(str(out_dir / name / "objects.png")),
                           wul3d.read_label_image(str(gt_path)))
        s.pop("matches")
        s["frame"] = name
        scores.append(s)
    return scores


def run_sequence_task(input_dir: str, out_root: str, rel_out: str, options: dict,
                      threads: int, score: bool = True) -> dict:
    """One Dask task: `wul3d run` of one sequence into OUT/<rel_out>, staged and renamed.

    Returns the sequence's record for batch.json. Bad input is caught and reported (status
    "failed", error = the one-line reason); anything else (a dying worker) is Dask's to retry.
    """
    import wul3d

    record = {"sequence": rel_out, "input": input_dir, "worker": _worker_name(),
              "status": "failed", "error": None, "frames": 0, "fps": 0.0, "wall_s": 0.0}
    # The worker's pid in the name: who is writing it (the fault tests kill that process).
    staging = (pathlib.Path(out_root) / STAGING /
               f"{rel_out.replace('/', '__')}.{os.getpid()}.{uuid.uuid4().hex}")
    final = pathlib.Path(out_root) / rel_out
    start = time.monotonic()
    try:
        if threads > 0:
            wul3d.set_num_threads(threads)
        staging.mkdir(parents=True)
        summary = wul3d.run(input_dir, str(staging), **options)
        names = sorted(p.name for p in staging.iterdir() if p.is_dir())
        record["scores"] = _frame_scores(pathlib.Path(input_dir), staging, names) if score else []
        _publish(staging, final)
        record.update(status="ok", frames=summary["frames"], fps=summary["fps"])
    except (ValueError, OSError, RuntimeError) as e:  # wul3d.InputError is a ValueError
        record["error"] = str(e).splitlines()[0] if str(e) else type(e).__name__
    finally:
        shutil.rmtree(staging, ignore_errors=True)
        record["wall_s"] = time.monotonic() - start
    return record


def _worker_name() -> str:
    try:
        from distributed import get_worker

        return get_worker().address
    except (ImportError, ValueError):
        return f"{socket.gethostname()}:{os.getpid()}"


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
    from . import _wul3d

    scored = [r for r in records if r.get("scores")]
    if not scored:
        return None
    all_scores = [s for r in scored for s in r["scores"]]
    return {"all": _wul3d._summarize(all_scores),
            "per_sequence": {r["sequence"]: _wul3d._summarize(r["scores"]) for r in scored}}


def run_batch(root, out, scheduler=None, workers=None, threads_per_worker=None, options=None,
              retries=1, progress=True, client=None, timeout_s=None, score=True) -> dict:
    """Runs every sequence under `root` (discover) into `out` on Dask; returns batch.json's
    content, also written to OUT/batch.json.

    Args:
        root: the dataset folder.
        out: the output folder (shared by every worker).
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
    """
    from distributed import Client, LocalCluster, wait

    root = pathlib.Path(root).resolve()
    out = pathlib.Path(out).resolve()
    options = dict(options or {})
    from . import _wul3d

    _wul3d._check_run_options(options)  # a bad option fails once, here, not in every task
    sequences = discover(root)
    out.mkdir(parents=True, exist_ok=True)
    shutil.rmtree(out / STAGING, ignore_errors=True)  # tries of an interrupted batch

    cluster = None
    own_client = client is None
    if client is None:
        if scheduler:
            client = Client(scheduler, timeout="30s")
        else:
            cores = os.cpu_count() or 1
            workers = workers or max(1, cores // 2)
            threads_per_worker = threads_per_worker or max(1, cores // workers)
            # One task per worker at a time: a task's own threads use the cores.
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   dashboard_address=":0")
            client = Client(cluster)
    start = time.monotonic()
    records, futures = {}, {}
    try:
        for rel in sequences:
            rel_out = str(output_dir(out, root, rel).relative_to(out))
            if is_finished(out / rel_out):
                records[rel_out] = _finished_record(root / rel, out / rel_out, rel_out, score)
                continue
            fut = client.submit(run_sequence_task, str(root / rel), str(out), rel_out, options,
                                threads_per_worker or 0, score,
                                key=f"wul3d-{rel_out}-{uuid.uuid4().hex}",
                                retries=retries, pure=False)
            futures[fut] = rel_out
        bar = _Progress(len(sequences), progress)
        for _ in records:
            bar.step()
        failed = 0
        pending = set(futures)
        deadline = None if timeout_s is None else time.monotonic() + timeout_s
        while pending:
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                raise TimeoutError(f"wul3d.batch: {len(pending)} sequences unfinished after "
                                   f"{timeout_s} s")
            done, pending = wait(pending, timeout=left, return_when="FIRST_COMPLETED")
            for fut in sorted(done, key=lambda f: futures[f]):
                rel_out = futures[fut]
                try:
                    rec = fut.result()
                except Exception as e:  # noqa: BLE001  (KilledWorker after too many deaths)
                    rec = {"sequence": rel_out, "status": "failed", "worker": None,
                           "frames": 0, "fps": 0.0, "wall_s": 0.0,
                           "error": f"{type(e).__name__}: "
                                    f"{str(e).splitlines()[0] if str(e) else ''}"}
                failed += rec["status"] != "ok"
                records[rel_out] = rec
                bar.step(failed)
        bar.finish()
        # Every task is over: what a killed worker was writing goes (its sequence was redone).
        shutil.rmtree(out / STAGING, ignore_errors=True)
    finally:
        if own_client:
            client.close()
            if cluster is not None:
                cluster.close()
    wall_s = time.monotonic() - start
    ordered = [records[k] for k in sorted(records)]
    frames = sum(r["frames"] for r in ordered if r["status"] in ("ok", "skipped"))
    done_now = sum(r["frames"] for r in ordered if r["status"] == "ok")
    report = {
        "root": str(root),
        "out": str(out),
        "options": options,
        "scheduler": scheduler or ("local" if cluster is not None else "client"),
        "totals": {
            "sequences": len(ordered),
            "succeeded": sum(r["status"] == "ok" for r in ordered),
            "skipped": sum(r["status"] == "skipped" for r in ordered),
            "failed": sum(r["status"] == "failed" for r in ordered),
            "frames": frames,
            "frames_this_run": done_now,
            "wall_s": wall_s,
            "fps": done_now / wall_s if wall_s > 0 else 0.0,
        },
        "sequences": [{k: v for k, v in r.items() if k != "scores"} for r in ordered],
    }
    uois = _uois_table(ordered)
    if uois is not None:
        report["uois"] = uois
    tmp = out / f".{BATCH_JSON}.tmp-{os.getpid()}"
    tmp.write_text(json.dumps(report, indent=2) + "\n", encoding="utf-8")
    os.replace(tmp, out / BATCH_JSON)
    return report


def _finished_record(input_dir, out_dir, rel_out, score):
    """batch.json's record of a sequence a previous run finished (its scores recomputed)."""
    with open(out_dir / DONE_MARKER, encoding="utf-8") as f:
        summary = json.load(f)
    names = sorted(p.name for p in out_dir.iterdir() if p.is_dir() and (out_dir / p.name / "objects.png").is_file())
    return {"sequence": rel_out, "input": str(input_dir), "worker": None, "status": "skipped",
            "error": None, "frames": summary.get("frames", 0), "fps": summary.get("fps", 0.0),
            "wall_s": 0.0,
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
    for name, kind in RUN_OPTIONS.items():
        flag = "--" + name.replace("_", "-")
        run.add_argument(flag, dest=name, type=kind, metavar=kind.__name__.upper(),
                         help=f"as `wul3d run {flag}`")
    run.add_argument("--no-plane", action="store_true", help="as `wul3d run --no-plane`")
    run.add_argument("--ply", action="store_true", help="as `wul3d run --ply`")
    run.add_argument("--overlay", action="store_true", help="as `wul3d run --overlay`")
    return p


def main(argv=None) -> int:
    parser = _parser()
    args = parser.parse_args(argv)
    for name in ("workers", "threads_per_worker"):
        value = getattr(args, name)
        if value is not None and value < 1:
            parser.error(f"--{name.replace('_', '-')} {value}: must be >= 1")
    options = {k: getattr(args, k) for k in RUN_OPTIONS if getattr(args, k) is not None}
    options.update({k: True for k in RUN_FLAGS if getattr(args, k)})
    try:
        report = run_batch(args.root, args.out, scheduler=args.scheduler, workers=args.workers,
                           threads_per_worker=args.threads_per_worker, options=options,
                           retries=args.retries, progress=not args.quiet,
                           score=not args.no_score)
    except (FileNotFoundError, ValueError, OSError) as e:
        print(f"wul3d.batch: {e}", file=sys.stderr)
        return 2
    t = report["totals"]
    for r in report["sequences"]:
        if r["status"] == "failed":
            print(f"wul3d.batch: {r['sequence']}: {r['error']}", file=sys.stderr)
    print(f"wul3d.batch: {t['succeeded']} sequences done, {t['skipped']} already done, "
          f"{t['failed']} failed; {t['frames_this_run']} frames in {t['wall_s']:.1f} s "
          f"({t['fps']:.1f} FPS) -> {report['out']}/{BATCH_JSON}")
    return 0 if t["failed"] == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
