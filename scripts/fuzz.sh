#!/usr/bin/env bash
# Builds motiondb's libFuzzer targets (clang, ASan + UBSan) in build-fuzz/ and runs each for a
# time budget, one after another.
#
#   scripts/fuzz.sh [--seconds S] [TARGET...]   (default: every target, 60 s each)
#
# Targets (tests/fuzz/TARGET_fuzzer.cc): bvh_reader, search_request, page_token, space_request,
# stream_ingest, http_route, http_request, label_file. Each keeps its corpus in build-fuzz/corpus/TARGET
# (build* is gitignored), seeded from tests/fuzz/seeds/TARGET/; the BVH-reading targets also from
# ../shared/mocap/conformance/*.bvh when present (copied into the corpus only: their licence
# forbids copying them into the repository). Prints each target's executions; exits non-zero at
# the first crash, sanitizer error or property violation, whose reproducer is saved in
# build-fuzz/findings/ (rerun the fuzzer binary on that file to reproduce it).
set -euo pipefail

seconds=60
if [[ "${1:-}" == "--seconds" ]]; then
  seconds="${2:-}"
  shift 2
fi
if ! [[ "$seconds" =~ ^[0-9]+$ ]]; then
  echo "usage: $0 [--seconds S] [TARGET...]" >&2
  exit 2
fi
targets=("$@")
((${#targets[@]})) || targets=(bvh_reader search_request page_token space_request stream_ingest http_route http_request
  label_file)

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$root/build-fuzz"
findings="$build/findings"

# A separate build directory: the fuzz flags instrument every target, which must not leak into
# the ordinary build/.
CC=clang-14 CXX=clang++-14 cmake -S "$root" -B "$build" \
  -DMOTIONDB_FUZZ=ON -DMOTIONDB_BUILD_TESTS=OFF -DMOTIONDB_BUILD_BENCH=OFF >/dev/null
cmake --build "$build" -j2 $(printf -- '--target %s_fuzzer ' "${targets[@]}")

mkdir -p "$findings"
conformance="$root/../shared/mocap/conformance"
for target in "${targets[@]}"; do
  corpus="$build/corpus/$target"
  mkdir -p "$corpus"
  seeds="$root/tests/fuzz/seeds/$target"
  [[ -d "$seeds" ]] && cp "$seeds"/* "$corpus"/
  options=(-max_total_time="$seconds" -print_final_stats=1 -artifact_prefix="$findings/$target-")
  if [[ "$target" == bvh_reader || "$target" == stream_ingest ]]; then
    cp "$root"/tests/fuzz/seeds/bvh_reader/*.bvh "$corpus"/
    if [[ -d "$conformance" ]]; then cp "$conformance"/*.bvh "$corpus"/; fi
    options+=(-max_len=65536 -dict="$root/tests/fuzz/bvh.dict")
  fi
  if [[ "$target" == http_route ]]; then
    # The in-process server's threads allocate and free across inputs, so libFuzzer's
    # per-input leak check (run when an input's mallocs and frees differ) scanned the heap on
    # most inputs: 4.2x the executions without it (1830 against 434 a second, 2026-12-03).
    # LeakSanitizer still checks the whole run at its end.
    options+=(-detect_leaks=0)
  fi
  export LSAN_OPTIONS="suppressions=$root/tests/fuzz/lsan_suppressions.txt"
  log="$build/$target.log"
  echo "fuzz: $target for ${seconds}s, corpus $corpus"
  status=0
  "$build/tests/fuzz/${target}_fuzzer" "$corpus" "${options[@]}" >"$log" 2>&1 || status=$?
  runs="$(grep -o 'number_of_executed_units: [0-9]*' "$log" | grep -o '[0-9]*$' || echo '?')"
  if ((status != 0)); then
    tail -n 40 "$log" >&2
    echo "fuzz: $target found a failure after $runs executions (exit $status); reproducer in" \
      "$findings/, log $log" >&2
    exit "$status"
  fi
  echo "fuzz: $target: $runs executions in ${seconds}s, no failure"
done
