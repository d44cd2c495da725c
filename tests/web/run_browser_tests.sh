#!/usr/bin/env bash
# ctest Web.BrowserTests: the web page's tests in Debian's headless Chromium.
#   run_browser_tests.sh SERVER_BIN CLI_BIN OUT_DIR
# Skips (exit 77) with a message when /usr/bin/chromium or node is missing, the demo BVH files
# are, or web/ needs `npm ci` and the npm registry is unreachable (a machine that reaches only
# Debian's archive); MOTIONDB_REQUIRE_NPM=1 (set by .ci/run) makes that last one a failure.
# Otherwise builds web/ and runs browser_test.mjs with node's test runner. Screenshots are
# written to OUT_DIR.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
(($# == 3)) || { echo "usage: $0 SERVER_BIN CLI_BIN OUT_DIR" >&2; exit 2; }
skip() { echo "SKIPPED: $1 (scripts/install-deps.sh installs it)"; exit 77; }
[[ -x /usr/bin/chromium ]] || skip "/usr/bin/chromium is missing"
command -v node >/dev/null && command -v npm >/dev/null || skip "node or npm is missing"
[[ -d /usr/share/assimp/models/BVH ]] || skip "assimp-testmodels' BVH files are missing"
if [[ ! -f "$root/web/node_modules/.package-lock.json" ]] && ! timeout 60 npm ping >/dev/null 2>&1; then
  [[ "${MOTIONDB_REQUIRE_NPM:-}" == 1 ]] && { echo "FAILED: the npm registry is unreachable (npm ping) and MOTIONDB_REQUIRE_NPM=1" >&2; exit 1; }
  echo "SKIPPED: web/ needs \`npm ci\` and the npm registry is unreachable (npm ping failed)"
  exit 77
fi
"$root/scripts/build-web.sh"
export MOTIONDB_SERVER_BIN="$1" MOTIONDB_CLI_BIN="$2" MOTIONDB_WEB_TEST_OUT="$3"
exec node --test "$here/browser_test.mjs"
