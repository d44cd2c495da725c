#!/usr/bin/env bash
# Builds the web asset browser (web/ -> web/dist, which motiondb-server serves) when its
# sources are newer than the build: `npm ci` when web/node_modules is missing or older than
# package-lock.json (the only step that needs the npm registry), then `npm run build`
# (TypeScript check and Vite bundle: the page fetches nothing from the network when it runs).
#   scripts/build-web.sh           build when needed
#   scripts/build-web.sh --force   build anyway
set -euo pipefail
web="$(cd "$(dirname "${BASH_SOURCE[0]}")/../web" && pwd)"
command -v npm >/dev/null || { echo "build-web: npm is missing (scripts/install-deps.sh)" >&2; exit 1; }
cd "$web"
# One build at a time (start.sh and the browser tests may start together).
exec 9>.build-web.lock
flock 9
if [[ ! -f node_modules/.package-lock.json || package-lock.json -nt node_modules/.package-lock.json ]]; then
  echo "build-web: npm ci"
  npm ci --no-audit --no-fund --loglevel=error
fi
stamp=dist/index.html
if [[ "${1:-}" == "--force" || ! -f "$stamp" ]] ||
  [[ -n "$(find index.html package.json package-lock.json tsconfig.json vite.config.ts src \
            -newer "$stamp" -print -quit)" ]]; then
  echo "build-web: npm run build"
  npm run --silent build
fi
