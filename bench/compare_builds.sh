#!/usr/bin/env bash
# The search-latency and server benchmarks of two Release builds, interleaved (before, after,
# before, ...) in one run, so that the machine's drifting speed weighs on both alike.
#   bench/compare_builds.sh BEFORE_BUILD_DIR AFTER_BUILD_DIR [OUT_DIR]
# Each build folder needs bench/search_latency and bench/server_bench (and the server).
set -euo pipefail
before=$1 after=$2 out=${3:-compare-builds}
mkdir -p "$out"
run() { "$1/bench/$2" "${@:4}" >"$out/$3.txt" 2>&1; }
for round in 1 2 3 4 5 6; do
  run "$before" search_latency "lat70_before_$round" --scenario 70s120 --queries 20 --exact-queries 1
  run "$after" search_latency "lat70_after_$round" --scenario 70s120 --queries 20 --exact-queries 1
done
for round in 1 2 3; do
  run "$after" search_latency "lat1h_after_$round" --scenario 1h30 --queries 20 --exact-queries 1
  run "$before" search_latency "lat1h_before_$round" --scenario 1h30 --queries 20 --exact-queries 1
done
for round in 1 2; do
  run "$before" server_bench "server_before_$round" --seconds 4 --hours 1
  run "$after" server_bench "server_after_$round" --seconds 4 --hours 1
done
grep -H "^fast: p50\|^fast, no refinement: p50\|^exact: p50" "$out"/lat*.txt
