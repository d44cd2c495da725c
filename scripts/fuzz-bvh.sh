#!/usr/bin/env bash
# The BVH reader's fuzzer alone (scripts/fuzz.sh bvh_reader):
#
#   scripts/fuzz-bvh.sh [SECONDS]   (default 60)
set -euo pipefail
exec "$(dirname "${BASH_SOURCE[0]}")/fuzz.sh" --seconds "${1:-60}" bvh_reader
