#!/usr/bin/env bash
# Kills the server with SIGKILL at random moments of ingest, space creation and propagation jobs,
# ROUNDS times, restarting it on the same database after each, and checks that no acknowledged
# write is lost and no half write is left. It runs the server test
# ServerTest.KillAtRandomPointsLosesNoAcknowledgedWriteAndLeavesNoHalfWrite, which the suite
# runs with 3 rounds, with more rounds and a seed of your choice (the kill points follow it).
#   scripts/crash-loop.sh [ROUNDS=20] [SEED=1]
# Environment: BUILD_DIR (default build/).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${BUILD_DIR:-$root/build}"
BUILD_DIR="$build_dir" "$root/scripts/build.sh" server_crash_test motiondb-server >/dev/null
MOTIONDB_CRASH_ROUNDS="${1:-20}" MOTIONDB_CRASH_SEED="${2:-1}" \
  "$build_dir/tests/server_crash_test" \
  --gtest_filter='ServerTest.KillAtRandomPointsLosesNoAcknowledgedWriteAndLeavesNoHalfWrite'
