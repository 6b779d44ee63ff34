#!/usr/bin/env python3
"""Plots `wul3d bench` CSV files as the paper's Figure 7: FPS and peak memory against k.

Usage: scripts/plot-bench.py OUT.png CSV [CSV ...]   (needs Debian's python3-matplotlib)

Each CSV (`wul3d bench --csv`, one thread count) is one line per panel,
labelled by its resolution and, from its file name, the pipeline: a name containing "paper"
is `wul3d bench --pipeline paper` (the paper's steps alone), any other the object pipeline;
"decimateN" in the name adds `--decimate N`.
"""
import csv
import re
import sys

try:
    import matplotlib
except ImportError:
    sys.exit("plot-bench.py: matplotlib is missing (apt-get install python3-matplotlib)")
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__.strip().splitlines()[2])
    out, files = sys.argv[1], sys.argv[2:]
    fig, (ax_fps, ax_mem) = plt.subplots(1, 2, figsize=(10, 4))
    for path in files:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
        if not rows:
            sys.exit(f"plot-bench.py: {path} has no rows")
        k = [int(r["k"]) for r in rows]
        name = path.rsplit("/", 1)[-1]
        pipeline = "paper's steps" if "paper" in name else "objects"
        decimate = re.search(r"decimate(\d+)", name)
        if decimate:
            pipeline += f", --decimate {decimate[1]}"
        label = f"{rows[0]['width']}x{rows[0]['height']}, {pipeline}"
        ax_fps.plot(k, [float(r["fps_median"]) for r in rows], "o-", label=label)
        ax_mem.plot(k, [float(r["peak_rss_mb"]) for r in rows], "o-", label=label)
    ax_fps.set(xlabel="k (clusters)", ylabel="frames per second (median)", title="Speed")
    ax_mem.set(xlabel="k (clusters)", ylabel="peak RSS (MB)", title="Memory", ylim=(0, None))
    for ax in (ax_fps, ax_mem):
        ax.grid(True, alpha=0.3)
        ax.legend()
    fig.suptitle("wul3d bench, 2-core AMD EPYC, 2 threads")
    fig.tight_layout()
    fig.savefig(out, dpi=100)


if __name__ == "__main__":
    main()
