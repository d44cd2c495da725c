#!/usr/bin/env bash
# One command for a newcomer: installs missing Debian packages, builds, and runs motiondb.
# Until the server lands (issue 5), "runs" means: the offline CLI inspects a few real BVH files
# (Debian's assimp-testmodels) and prints where the binary is.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/install-deps.sh"
"$root/scripts/build.sh"
cli="$root/build/client/motiondb"
echo
echo "Built $cli. Inspecting the demo BVH files from assimp-testmodels:"
"$cli" inspect /usr/share/assimp/models/BVH/*.bvh
echo
echo "Next: $cli help    (the gRPC server is not built yet; see README.md)"
