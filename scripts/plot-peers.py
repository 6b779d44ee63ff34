#!/usr/bin/env python3
"""Draws wul3d against the classical peers from eval/peers.py's CSVs: quality (bars of Overlap F
and Boundary F per frame set) and speed (median ms per frame at 640x480).

Usage: scripts/plot-peers.py QUALITY.csv SPEED.csv QUALITY.png SPEED.png
       (needs Debian's python3-matplotlib; e.g. docs/peers_quality.csv docs/peers_speed.csv
        docs/peers_quality.png docs/peers_speed.png)
"""
import csv
import sys

try:
    import matplotlib
except ImportError:
    sys.exit("plot-peers.py: matplotlib is missing (apt-get install python3-matplotlib)")
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"plot-peers.py: {path} has no rows")
    return rows


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__.strip().splitlines()[3])
    quality, speed = read(sys.argv[1]), read(sys.argv[2])
    methods = list(dict.fromkeys(r["method"] for r in quality))
    sets = list(dict.fromkeys(r["set"] for r in quality))
    by = {(r["method"], r["set"]): r for r in quality}

    fig, axes = plt.subplots(1, 2, figsize=(11, 4), sharey=True)
    width = 0.8 / len(methods)
    for ax, key, title in zip(axes, ("overlap_f", "boundary_f"), ("Overlap F", "Boundary F")):
        for i, m in enumerate(methods):
            xs = [j + (i - (len(methods) - 1) / 2) * width for j in range(len(sets))]
            ys = [float(by[(m, s)][key]) if (m, s) in by else 0.0 for s in sets]
            bars = ax.bar(xs, ys, width, label=m)
            ax.bar_label(bars, fmt="%.1f", fontsize=7, padding=2)
        ax.set_xticks(range(len(sets)))
        ax.set_xticklabels([f"{s}\n({by[(methods[0], s)]['images']} frames)" for s in sets], fontsize=8)
        ax.set_title(title + " (%, wul3d eval)")
        ax.set_ylim(0, 105)
        ax.grid(axis="y", alpha=0.3)
    # Above the panels, one row: inside them it hid the first group's bars.
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper center", ncol=len(methods), fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0, 1, 0.93))
    fig.savefig(sys.argv[3], dpi=110)

    fig, ax = plt.subplots(figsize=(8, 2.2 + 0.4 * len(speed)))
    names = [r["method"] for r in speed]
    ms = [float(r["ms_median"]) for r in speed]
    bars = ax.barh(names, ms, color=[f"C{i}" for i in range(len(speed))])
    ax.bar_label(bars, labels=[f"{m:.1f} ms ({1000 / m:.0f} FPS)" for m in ms], padding=3, fontsize=8)
    ax.invert_yaxis()
    threads = speed[0].get("threads", "?")
    ax.set_title(f"{speed[0]['frames']}: median ms per frame, no disk I/O, "
                 f"{threads} OpenMP thread{'' if threads == '1' else 's'} each", fontsize=9)
    ax.set_xlabel("ms per frame (lower is faster)")
    ax.set_xlim(0, max(ms) * 1.35)
    ax.grid(axis="x", alpha=0.3)
    fig.tight_layout()
    fig.savefig(sys.argv[4], dpi=110)
    print(f"plot-peers.py: {sys.argv[3]}, {sys.argv[4]}")


if __name__ == "__main__":
    main()
