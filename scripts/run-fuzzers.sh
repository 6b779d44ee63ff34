#!/usr/bin/env bash
# Runs every libFuzzer harness of fuzz/ for a bounded time on seeds made from the shipped
# samples, and prints each one's executions and executions per second.
#   scripts/run-fuzzers.sh BUILD_DIR [SECONDS_PER_HARNESS]   (default 20)
# The mutations follow WUL3D_FUZZ_SEED (default 1), so that CI explores the inputs a
# developer's run explored before landing; WUL3D_FUZZ_SEED=0 lets libFuzzer pick one (a
# longer hunt).
# BUILD_DIR was configured with -DWUL3D_BUILD_FUZZERS=ON and built with --target fuzzers.
# Then fuzz/fuzz_batch_discovery.py (Python, no build needed) fuzzes the batch's discovery for
# WUL3D_FUZZ_SECONDS (default: SECONDS_PER_HARNESS) with the same seed; WUL3D_FUZZ_ONLY=batch
# runs only that one (BUILD_DIR is then only where its log goes).
# Any crash, sanitizer report, leak, timeout (10 s) or memory blow-up (2 GB) fails the script;
# libFuzzer leaves the input as BUILD_DIR/fuzz-out/crash-* (or leak-, timeout-, oom-): add it
# as a regression test.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
build=${1:?usage: scripts/run-fuzzers.sh BUILD_DIR [SECONDS]}
seconds=${2:-20}
seed=${WUL3D_FUZZ_SEED:-1}
seeds=$build/fuzz-seeds
out=$build/fuzz-out
only=${WUL3D_FUZZ_ONLY:-}
rm -rf "$seeds" "$out"
mkdir -p "$out"
harnesses="png jpeg intrinsics_json calibration_json tum_list fakenect frame pcd"
if [ "$only" = batch ]; then
  harnesses=""
else
  "$build/fuzz/make_seeds" data/samples "$seeds"
  if [[ -x "$build/fuzz/fuzz_bag" ]]; then  # built where librosbag is (cmake/Ros.cmake)
    "$build/fuzz/make_bag_seeds" "$seeds/bag"
    harnesses="$harnesses bag"
  fi
fi

total_runs=0
printf '%-18s %10s %8s\n' harness executions exec/s
for fuzzer in $harnesses; do
  corpus=$out/corpus_$fuzzer
  mkdir -p "$corpus"
  log=$out/$fuzzer.log
  # One process, -max_total_time bounded; the corpus it grows is thrown away with $out.
  if ! ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
      "$build/fuzz/fuzz_$fuzzer" -max_total_time="$seconds" -seed="$seed" -timeout=10 -rss_limit_mb=2048 \
      -max_len=400000 -print_final_stats=1 -artifact_prefix="$out/$fuzzer-" \
      "$corpus" "$seeds/$fuzzer" >"$log" 2>&1; then
    echo "fuzz_$fuzzer FAILED; its log:" >&2
    tail -n 60 "$log" >&2
    exit 1
  fi
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -n 1)
  printf '%-18s %10s %8s\n' "$fuzzer" "${runs:-?}" "${rate:-?}"
  total_runs=$((total_runs + ${runs:-0}))
done
# The batch's discovery over random trees (links, loops, odd names, FIFOs): Python.
log=$out/batch_discovery.log
if ! "${PYTHON:-python3}" fuzz/fuzz_batch_discovery.py --seconds "${WUL3D_FUZZ_SECONDS:-$seconds}" \
    --seed "$seed" >"$log" 2>&1; then
  echo "fuzz_batch_discovery FAILED; its log:" >&2
  tail -n 60 "$log" >&2
  exit 1
fi
trees=$(sed -n 's/.*, \([0-9]*\) trees in.*/\1/p' "$log")
printf '%-18s %10s %8s\n' batch_discovery "${trees:-?}" "$(sed -n 's/.*(\([0-9]*\)\/s).*/\1/p' "$log")"
total_runs=$((total_runs + ${trees:-0}))
echo "fuzzers: $total_runs executions in all, no finding"
rm -rf "$out"
