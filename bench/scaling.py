#!/usr/bin/env python3
"""How each stage scales with threads: `wul3d bench --threads 1,2,...` on one k, then, per
stage, its median time at each thread count, its speed-up over one thread and its serial
share (docs/SPEED.md, "Scaling").

    /usr/bin/python3 bench/scaling.py [INPUT] [--cli build/wul3d] [--threads 1,2]
        [--k 10] [--frames 5] [--passes 10] [--repeats 3] [--csv FILE] [-- BENCH FLAGS...]

The serial share s is Amdahl's: a stage taking T(1) on one thread takes
T(N) = T(1) (s + (1 - s) / N) on N, so s is the least-squares fit of
T(N) / T(1) - 1 / N = s (1 - 1 / N) over the thread counts above one. s = 0: the stage
spreads perfectly; s = 1: it does not spread at all (or it is slower on more threads:
s is not clamped, so s > 1 says so). On a machine with fewer cores than the largest N, or
one that others are using, the fit measures the machine as much as the code.

--repeats runs the whole curve that many times, alternating thread counts, and keeps each
figure's median: machines here are shared and noisy.
"""
import argparse
import csv
import io
import pathlib
import statistics
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
STAGES = ["registration", "decimation", "backprojection", "normals", "background",
          "clustering", "colors", "plane", "segmentation", "objects"]


def serial_share(t1, by_threads):
    """Amdahl's serial share, fitted over {N: T(N)} for N > 1 (None when T(1) is 0)."""
    if t1 <= 0:
        return None
    num = den = 0.0
    for n, tn in by_threads.items():
        if n <= 1:
            continue
        x = 1.0 - 1.0 / n
        num += (tn / t1 - 1.0 / n) * x
        den += x * x
    return num / den if den else None


def run_bench(args, extra):
    cmd = [args.cli, "bench", args.input, "--k", str(args.k), "--threads", args.threads,
           "--frames", str(args.frames), "--passes", str(args.passes), *extra]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=args.timeout)
    if done.returncode != 0:
        sys.exit(f"scaling.py: {' '.join(cmd)} failed: {done.stderr.strip()}")
    return list(csv.DictReader(io.StringIO(done.stdout)))


def table(rows_by_repeat):
    """{threads: {column: median over repeats}} from the bench rows of every repeat."""
    by_threads = {}
    for rows in rows_by_repeat:
        for row in rows:
            cols = by_threads.setdefault(int(row["threads"]), {})
            for name in ["ms_median", *("ms_" + s for s in STAGES)]:
                cols.setdefault(name, []).append(float(row[name]))
    return {t: {c: statistics.median(v) for c, v in cols.items()} for t, cols in by_threads.items()}


def report(medians):
    threads = sorted(medians)
    head = ["stage"] + [f"ms at {t}" for t in threads]
    if 1 in medians and len(threads) > 1:
        head += [f"speed-up at {threads[-1]}", "serial share"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for stage, column in [*((s, "ms_" + s) for s in STAGES), ("frame", "ms_median")]:
        times = {t: medians[t][column] for t in threads}
        if max(times.values()) < 0.0005:
            continue  # a stage that did not run
        cells = [stage] + [f"{times[t]:.3f}" for t in threads]
        if 1 in medians and len(threads) > 1:
            last = times[threads[-1]]
            s = serial_share(times[1], times)
            cells += [f"{times[1] / last:.2f}" if last > 0 else "-",
                      f"{s:.2f}" if s is not None else "-"]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv=None):
    argv = list(sys.argv[1:] if argv is None else argv)
    extra = []
    if "--" in argv:
        cut = argv.index("--")
        argv, extra = argv[:cut], argv[cut + 1:]
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("input", nargs="?", default=str(ROOT / "data/samples/uois_tabletop"))
    p.add_argument("--cli", default=str(ROOT / "build/wul3d"))
    p.add_argument("--threads", default="1,2", help="comma-separated, e.g. 1,2,4,8,16")
    p.add_argument("--k", type=int, default=10)
    p.add_argument("--frames", type=int, default=5)
    p.add_argument("--passes", type=int, default=10)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--timeout", type=float, default=600.0, help="seconds per bench run")
    p.add_argument("--csv", help="also write every bench row of every repeat here")
    args = p.parse_args(argv)
    if args.repeats < 1:
        p.error("--repeats must be at least 1")
    order = args.threads.split(",")
    runs = []
    for r in range(args.repeats):
        # Alternate the order of the thread counts so that a drift of the machine's pace
        # does not fall on one count only.
        args.threads = ",".join(order if r % 2 == 0 else order[::-1])
        runs.append(run_bench(args, extra))
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=["repeat", *runs[0][0].keys()])
            w.writeheader()
            for r, rows in enumerate(runs):
                for row in rows:
                    w.writerow({"repeat": r, **row})
    print(f"{args.input}, k = {args.k}, {args.frames} frames x {args.passes} passes, "
          f"median of {args.repeats} runs")
    print(report(table(runs)))


if __name__ == "__main__":
    main()
