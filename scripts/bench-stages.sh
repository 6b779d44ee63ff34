#!/usr/bin/env bash
# Runs the per-stage micro-benchmarks (build/bench/wul3d_bench, and build/bench/wul3d_bench_pcl
# when PCL was found) with repetitions and prints a Markdown table on stdout: each benchmark's
# median time over the repetitions and, for the peer comparisons, ours / theirs (ratio < 1:
# ours is faster). Benchmark output goes to stderr; the JSON stays in BUILD/bench-stages/.
#
#   scripts/bench-stages.sh [BUILD_DIR] [REPETITIONS] [extra Google Benchmark flags...]
#   e.g. scripts/bench-stages.sh build 3 --benchmark_filter=Cluster
#
# On a machine that another process keeps busy, OpenMP's barriers wait for a descheduled
# thread (a scheduler time slice, milliseconds, per parallel region) and the table measures the
# scheduler: run OMP_NUM_THREADS=1 scripts/bench-stages.sh there (the cv::kmeans peer follows
# OpenMP's thread count; PCL's normals are single-threaded).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

build=${1:-build}
reps=${2:-5}
shift $(($# < 2 ? $# : 2))
out="$build/bench-stages"
mkdir -p "$out"
rm -f "$out"/*.json

ran=0
for exe in wul3d_bench wul3d_bench_pcl; do
  [[ -x "$build/bench/$exe" ]] || continue
  "$build/bench/$exe" --benchmark_repetitions="$reps" --benchmark_report_aggregates_only=true \
    --benchmark_out="$out/$exe.json" --benchmark_out_format=json "$@" >&2
  ran=1
done
[[ $ran -eq 1 ]] || { echo "bench-stages: no $build/bench/wul3d_bench; build it first" >&2; exit 1; }

python3 - "$out"/*.json <<'PY'
import json, sys

print("| benchmark | median ms | ours / theirs (median of per-frame ratios) |")
print("|---|---:|---|")
for path in sys.argv[1:]:
    try:
        with open(path) as f:
            benchmarks = json.load(f)["benchmarks"]
    except (OSError, ValueError):  # a filter that matched nothing in this executable
        continue
    for b in benchmarks:
        if b.get("aggregate_name") != "median":
            continue
        ms = b["real_time"] * {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b["time_unit"]]
        name = b["run_name"].removeprefix("BM_").removesuffix("/real_time")
        peer = ""
        if "ratio" in b:
            peer = f"{b['ours_ms']:.2f} / {b['theirs_ms']:.2f} ms = {b['ratio']:.2f}"
        print(f"| {name} | {ms:.2f} | {peer} |")
PY
