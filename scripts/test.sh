#!/usr/bin/env bash
# Installs the Debian packages the tests need that are missing, builds motiondb and runs the
# whole test suite with ctest.
# Usage: scripts/test.sh [--sanitize] [ctest arguments...]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="$root/build"
build_args=()
if [[ "${1:-}" == "--sanitize" ]]; then
  build_args=(--sanitize)
  build_dir="$root/build-asan"
  shift
fi
"$root/scripts/install-deps.sh"
BUILD_DIR="$build_dir" "$root/scripts/build.sh" "${build_args[@]}"
cd "$build_dir"
ctest --output-on-failure -j "${JOBS:-2}" "$@"
