#!/usr/bin/env python3
"""Throughput of wul3d.batch on this machine: sequences and frames per second with 1 and 2
local worker processes (docs/SCALE.md).

    PYTHONPATH=build/python /usr/bin/python3 bench/python/batch_throughput.py \
        [ROOT] [--copies 4] [--workers 1,2] [--threads-per-worker 1] [--decimate 2]

ROOT (default data/samples) is copied --copies times under a temporary root (files hard-linked
where the filesystem allows: discovery reads a folder reached twice through links once), so
that there are enough sequences to keep the workers busy; each configuration runs into a fresh output
folder. The wall time is the batch's own (batch.json "wall_s"): from the first task submitted
to the last result, the cluster's start-up excluded (it is reported apart).
"""
import argparse
import json
import os
import pathlib
import shutil
import sys
import tempfile
import time

from wul3d import batch

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _link_or_copy(src, dst):
    try:
        os.link(src, dst)
    except OSError:
        shutil.copy2(src, dst)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("root", nargs="?", default=str(ROOT / "data/samples"))
    p.add_argument("--copies", type=int, default=4)
    p.add_argument("--workers", default="1,2")
    p.add_argument("--threads-per-worker", type=int, default=1)
    p.add_argument("--decimate", type=int, default=2)
    p.add_argument("--score", action="store_true", help="also the UOIS table (label.png)")
    args = p.parse_args(argv)
    from distributed import Client, LocalCluster

    with tempfile.TemporaryDirectory() as tmp:
        root = pathlib.Path(tmp) / "root"
        root.mkdir()
        for i in range(args.copies):
            shutil.copytree(pathlib.Path(args.root).resolve(), root / f"copy{i}",
                            copy_function=_link_or_copy)
        n_seq = len(batch.discover(root))
        for workers in (int(w) for w in args.workers.split(",")):
            t0 = time.monotonic()
            with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                              dashboard_address=":0") as cluster, Client(cluster) as client:
                startup = time.monotonic() - t0
                out = pathlib.Path(tmp) / f"out{workers}"
                report = batch.run_batch(root, out, client=client,
                                         threads_per_worker=args.threads_per_worker,
                                         options={"decimate": args.decimate}, progress=False,
                                         score=args.score)
            t = report["totals"]
            seq_fps = [s["fps"] for s in report["sequences"]]
            print(json.dumps({
                "workers": workers, "threads_per_worker": args.threads_per_worker,
                "score": args.score,
                "sequences": n_seq, "frames": t["frames"], "failed": t["failed"],
                "wall_s": round(t["wall_s"], 2),
                "sequences_per_s": round(n_seq / t["wall_s"], 3),
                "frames_per_s": round(t["frames"] / t["wall_s"], 2),
                "pipeline_fps_median_of_sequences": round(sorted(seq_fps)[len(seq_fps) // 2], 1),
                "cluster_startup_s": round(startup, 2)}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
