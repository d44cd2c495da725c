#!/usr/bin/env bash
# Builds the BVH reader's libFuzzer target (clang, ASan + UBSan) in build-fuzz/ and runs it.
#
#   scripts/fuzz-bvh.sh [SECONDS]   (default 60)
#
# The corpus lives in build-fuzz/corpus (build* is gitignored): it is seeded from
# tests/fuzz/seeds/ and, when present, ../shared/mocap/conformance/*.bvh, which are copied into the
# corpus only because their licence forbids copying them into the repository. Findings are
# written to build-fuzz/findings/. Exits non-zero when the fuzzer finds a crash, a sanitizer
# error or a round-trip property violation.
set -euo pipefail

seconds="${1:-60}"
if ! [[ "$seconds" =~ ^[0-9]+$ ]]; then
  echo "usage: $0 [SECONDS]" >&2
  exit 2
fi

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$root/build-fuzz"
corpus="$build/corpus"
findings="$build/findings"

# A separate build directory: the fuzz flags instrument every target, which must not leak into
# the ordinary build/.
CC=clang-14 CXX=clang++-14 cmake -S "$root" -B "$build" \
  -DMOTIONDB_FUZZ=ON -DMOTIONDB_BUILD_TESTS=OFF -DMOTIONDB_BUILD_BENCH=OFF >/dev/null
cmake --build "$build" --target bvh_reader_fuzzer -j2

mkdir -p "$corpus" "$findings"
cp "$root"/tests/fuzz/seeds/*.bvh "$corpus"/
conformance="$root/../shared/mocap/conformance"
if [[ -d "$conformance" ]]; then
  cp "$conformance"/*.bvh "$corpus"/
else
  echo "fuzz-bvh: $conformance not found; seeding from tests/fuzz/seeds only"
fi

# libFuzzer stops and exits non-zero at its first finding, saving the reproducer as
# $findings/crash-* (or leak-*, timeout-*, oom-*); rerun the fuzzer binary on that file to
# reproduce it.
echo "fuzz-bvh: fuzzing for ${seconds}s, corpus $corpus"
status=0
"$build/tests/fuzz/bvh_reader_fuzzer" "$corpus" \
  -max_total_time="$seconds" -max_len=65536 -print_final_stats=1 -dict="$root/tests/fuzz/bvh.dict" \
  -artifact_prefix="$findings/" || status=$?
if ((status != 0)); then
  echo "fuzz-bvh: the fuzzer found a failure (exit $status); reproducer in $findings/" >&2
  exit "$status"
fi
echo "fuzz-bvh: no crash in ${seconds}s"
