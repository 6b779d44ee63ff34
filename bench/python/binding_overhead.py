#!/usr/bin/env python3
"""Cost of the Python binding: wul3d.Pipeline.process from Python against the pipeline's
own time on the same frames (docs/PYTHON.md, "Cost of the binding").

    PYTHONPATH=build/python /usr/bin/python3 bench/python/binding_overhead.py \
        [INPUT] [--passes 20] [--threads N] [--cli build/wul3d]

Per call: wall = the time Python spends in process() (perf_counter around the call);
call = result.times["call"], the C++ Pipeline::process call as the binding timed it (the
stages, result.times["total"], plus the library's own untimed work). overhead = wall - call:
argument checks, the copy of the arrays in, the result's arrays and objects out, the GIL
hand-over: what Python adds to C++. Medians over every call
after a first pass (warm-up). With --cli, `wul3d bench` on the same frames as well, for
the C++ side's own median per frame.
"""
import argparse
import pathlib
import statistics
import subprocess
import sys
import time

import wul3d

ROOT = pathlib.Path(__file__).resolve().parents[2]


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("input", nargs="?", default=str(ROOT / "data/samples/uois_tabletop"))
    p.add_argument("--passes", type=int, default=20)
    p.add_argument("--threads", type=int, default=0)
    p.add_argument("--decimate", type=int, default=2)
    p.add_argument("--cli", help="wul3d command: also run `wul3d bench` on the frames")
    args = p.parse_args(argv)
    if args.threads:
        wul3d.set_num_threads(args.threads)
    frames = list(wul3d.read(args.input))
    pipeline = wul3d.Pipeline(decimate=args.decimate)
    walls, totals, calls, overheads = [], [], [], []
    for pass_ in range(args.passes + 1):
        for f in frames:
            t0 = time.perf_counter()
            r = pipeline.process(f.color, f.depth, f.intrinsics, f.depth_scale)
            wall = (time.perf_counter() - t0) * 1e3
            if pass_ == 0:
                continue  # warm-up: first allocations
            walls.append(wall)
            totals.append(r.times["total"])
            calls.append(r.times["call"])
            overheads.append(wall - r.times["call"])
    h, w = frames[0].depth.shape
    print(f"{len(frames)} frames {w}x{h}, {args.passes} passes, decimate {args.decimate}, "
          f"{wul3d.get_num_threads()} threads")
    print(f"python process() wall   median {statistics.median(walls):.3f} ms")
    print(f"C++ process() call      median {statistics.median(calls):.3f} ms")
    print(f"stages (times.total)    median {statistics.median(totals):.3f} ms")
    q = statistics.quantiles(overheads, n=10)
    print(f"binding overhead        median {statistics.median(overheads):.3f} ms "
          f"(p10 {q[0]:.3f}, p90 {q[-1]:.3f})")
    if args.cli:
        cmd = [args.cli, "bench", args.input, "--k", "7", "--frames", str(len(frames)),
               "--passes", str(args.passes), "--decimate", str(args.decimate)]
        if args.threads:
            cmd += ["--threads", str(args.threads)]
        out = subprocess.run(cmd, capture_output=True, text=True, check=True, timeout=600).stdout
        print("wul3d bench (C++):")
        print("\n".join("  " + line for line in out.strip().splitlines()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
