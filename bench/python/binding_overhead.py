#!/usr/bin/env python3
"""Cost of the Python binding: wul3d.Pipeline.process from Python against the C++ call inside
it, on the same frames in the same run (docs/PYTHON.md, "Cost of the binding").

    PYTHONPATH=build/python /usr/bin/python3 bench/python/binding_overhead.py \
        [INPUT] [--passes 40] [--threads N] [--decimate 2] [--outputs all,objects,none] \
        [--cli build/wul3d]

Every call is timed twice: `wall`, perf_counter around process() in Python, and `call`,
result.times["call"], steady_clock around the C++ Pipeline::process inside the binding (the
stages, result.times["total"], plus the library's own untimed work; nothing of the binding's).
overhead = wall - call, call by call: what Python adds to the same C++ work on the same frame
(argument checks, the GIL hand-over, the images handed over or copied out, the instances
and dicts, and the previous result freed, which a `r = pipeline.process(...)` loop does
inside the call's statement). The frames are read and decoded before the timing. `reads`: the first read of
r.instances, r.plane, r.times and r.stats after the call, timed apart: the binding makes
those Python objects on first read, so a loop that reads them pays this too.

--outputs: the selections measured, comma separated: `all` (process() as called by default,
the three images), `none` (outputs=()), or image names joined by "+" ("objects",
"labels+objects"). One pipeline a selection, each fed the same frames, the selections
alternated call by call; medians over every call after a warm-up pass. With --cli, `wul3d
bench` on the same frames as well, for the C++ side's own median per frame.
"""
import argparse
import pathlib
import statistics
import subprocess
import sys
import time

import wul3d

ROOT = pathlib.Path(__file__).resolve().parents[2]
IMAGES = ("labels", "objects", "colors")


def selection(text):
    """`all` -> None (process()'s default), `none` -> (), else the "+"-joined image names."""
    if text == "all":
        return None
    if text == "none":
        return ()
    names = tuple(text.split("+"))
    for n in names:
        if n not in IMAGES:
            raise argparse.ArgumentTypeError(f"--outputs: {n!r} is not all, none or one of {IMAGES}")
    return names


def measure(frames, pipelines, passes):
    """Per selection: (walls, calls, overheads, reads) in ms over passes x frames calls,
    alternated."""
    timings = {name: ([], [], [], []) for name in pipelines}
    last = dict.fromkeys(pipelines)  # each selection's previous result, freed in its next call
    for pass_ in range(passes + 1):
        for f in frames:
            for name, (pipeline, outputs) in pipelines.items():
                kwargs = {} if outputs is None else {"outputs": outputs}
                t0 = time.perf_counter()
                last[name] = pipeline.process(f.color, f.depth, f.intrinsics, f.depth_scale,
                                              **kwargs)
                wall = (time.perf_counter() - t0) * 1e3
                r = last[name]
                t0 = time.perf_counter()
                r.instances, r.plane, r.times, r.stats  # noqa: B018 (made on first read)
                read = (time.perf_counter() - t0) * 1e3
                if pass_ == 0:
                    continue  # warm-up: first allocations
                walls, calls, overheads, reads = timings[name]
                reads.append(read)
                walls.append(wall)
                calls.append(r.times["call"])
                overheads.append(wall - r.times["call"])
    return timings


def report(timings):
    print(f"{'outputs':<16} {'python wall':>11} {'C++ call':>9} {'difference':>10}   "
          f"{'overhead per call: median (p10, p90)':<37} {'reads':>6}   [ms, medians]")
    for name, (walls, calls, overheads, reads) in timings.items():
        q = statistics.quantiles(overheads, n=10)
        wall, call = statistics.median(walls), statistics.median(calls)
        overhead = f"{statistics.median(overheads):.3f} ({q[0]:.3f}, {q[-1]:.3f})"
        print(f"{name:<16} {wall:>11.3f} {call:>9.3f} {wall - call:>10.3f}   "
              f"{overhead:<37} {statistics.median(reads):>6.3f}")


def run_cli(args, n_frames):
    cmd = [args.cli, "bench", args.input, "--k", "7", "--frames", str(n_frames),
           "--passes", str(args.passes), "--decimate", str(args.decimate)]
    if args.threads:
        cmd += ["--threads", str(args.threads)]
    out = subprocess.run(cmd, capture_output=True, text=True, check=True, timeout=600).stdout
    print("wul3d bench (C++):")
    print("\n".join("  " + line for line in out.strip().splitlines()))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("input", nargs="?", default=str(ROOT / "data/samples/uois_tabletop"))
    p.add_argument("--passes", type=int, default=20)
    p.add_argument("--threads", type=int, default=0)
    p.add_argument("--decimate", type=int, default=2)
    p.add_argument("--outputs", default="all,objects,none",
                   help="selections compared, comma separated (default all,objects,none)")
    p.add_argument("--cli", help="wul3d command: also run `wul3d bench` on the frames")
    args = p.parse_args(argv)
    try:
        chosen = {name: selection(name) for name in args.outputs.split(",")}
    except argparse.ArgumentTypeError as e:
        p.error(str(e))
    if args.threads:
        wul3d.set_num_threads(args.threads)
    frames = list(wul3d.read(args.input))
    pipelines = {name: (wul3d.Pipeline(decimate=args.decimate), outputs)
                 for name, outputs in chosen.items()}
    timings = measure(frames, pipelines, args.passes)
    h, w = frames[0].depth.shape
    print(f"{len(frames)} frames {w}x{h}, {args.passes} passes ({args.passes * len(frames)} "
          f"calls a selection after a warm-up pass), decimate {args.decimate}, "
          f"{wul3d.get_num_threads()} threads")
    report(timings)
    if args.cli:
        run_cli(args, len(frames))
    return 0


if __name__ == "__main__":
    sys.exit(main())
