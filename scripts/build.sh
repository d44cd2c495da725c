#!/usr/bin/env bash
# Configures and builds motiondb.
#   scripts/build.sh [--sanitize] [TARGET...]
#   --sanitize  AddressSanitizer + UndefinedBehaviorSanitizer build (in build-asan/, no benchmarks)
#   TARGET      build only these (e.g. motiondb-server motiondb); default: everything
# Environment: BUILD_DIR overrides the build folder, JOBS the parallel jobs (default 2).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
options=(-DCMAKE_BUILD_TYPE=RelWithDebInfo)
build_dir="$root/build"
if [[ "${1:-}" == "--sanitize" ]]; then
  options+=(-DMOTIONDB_SANITIZE=ON -DMOTIONDB_BUILD_BENCH=OFF)
  build_dir="$root/build-asan"
  shift
fi
targets=()
for target in "$@"; do targets+=(--target "$target"); done
build_dir="${BUILD_DIR:-$build_dir}"
cmake -S "$root" -B "$build_dir" "${options[@]}" >/dev/null
cmake --build "$build_dir" -j "${JOBS:-2}" "${targets[@]}"
