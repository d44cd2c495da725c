#!/usr/bin/env bash
# One command for a newcomer: installs missing Debian packages, builds, and starts the
# motiondb server with its embedded default storage (./motiondb.sqlite, gRPC on 127.0.0.1:50051)
# and its web asset browser (HTTP on 127.0.0.1:8080).
#
#   scripts/start.sh           start the server (Ctrl-C stops it gracefully)
#   scripts/start.sh --demo    ... and load a small demo library into it first: the BVH files of
#                              Debian's assimp-testmodels with a space "demo" on the first one's
#                              skeleton, and ../shared/mocap/bandai2-normal when it is there
#                              with a space "bandai"
# Extra arguments after the options go to motiondb-server (e.g. --listen 0.0.0.0:50051).
# Only the server and the CLI are built here (scripts/test.sh builds the rest), in $BUILD_DIR
# (default build/), and the web page into web/dist when its sources changed (build-web.sh).
# The server's log (one line per request) goes to $MOTIONDB_LOG, default ./motiondb-server.log,
# so that this terminal stays free for the CLI.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
demo=0
if [[ "${1:-}" == "--demo" ]]; then
  demo=1
  shift
fi
"$root/scripts/install-deps.sh" --start
build="${BUILD_DIR:-$root/build}"
BUILD_DIR="$build" "$root/scripts/build.sh" motiondb-server motiondb
# The page is the one part that needs the npm registry: without it the server still starts,
# with gRPC and the JSON API, and says how to build the page.
page=1
if ! "$root/scripts/build-web.sh"; then
  page=0
  echo "start.sh: the web page was not built (see above); starting without it." \
    "scripts/build-web.sh builds it once the npm registry is reachable." >&2
fi
server="$build/server/motiondb-server"
cli="$build/client/motiondb"
# The CLI talks to wherever the server was told to listen, and the page is where it serves HTTP
# (a wildcard host is reached locally).
listen="127.0.0.1:50051"
http="127.0.0.1:8080"
scheme=http
args=("$@")
for ((i = 0; i + 1 < ${#args[@]}; i++)); do
  [[ "${args[i]}" == "--listen" ]] && listen="${args[i + 1]}"
  [[ "${args[i]}" == "--http" ]] && http="${args[i + 1]}"
  [[ "${args[i]}" == "--tls-cert" ]] && scheme=https
done
address="${listen/#0.0.0.0:/127.0.0.1:}"

log="${MOTIONDB_LOG:-./motiondb-server.log}"
"$server" --db "${MOTIONDB_DB:-./motiondb.sqlite}" "$@" 2>>"$log" &
pid=$!
echo "motiondb-server: log in $log"
trap 'kill -TERM "$pid" 2>/dev/null || true' INT TERM
for _ in $(seq 100); do
  "$cli" info --server "$address" --timeout 1 >/dev/null 2>&1 && break
  kill -0 "$pid" 2>/dev/null || { tail -5 "$log" >&2; wait "$pid"; exit $?; }
  sleep 0.2
done
"$cli" info --server "$address"

# The skeleton id of the first clip carrying `tag`.
skeleton_of_tag() {
  "$cli" clips --tag "$1" --json --server "$address" | /usr/bin/python3 -c \
    'import json,sys; c=json.load(sys.stdin)["clips"]; print(c[0]["skeleton_id"] if c else "")'
}
if ((demo)); then
  echo "Loading the demo library..."
  "$cli" ingest /usr/share/assimp/models/BVH --tag demo --server "$address" || true
  # The space "demo" is on the skeleton of clip 1, the first CMU file.
  "$cli" space create demo --skeleton "$(skeleton_of_tag demo)" --server "$address" || true
  bandai="$root/../shared/mocap/bandai2-normal"
  if [[ -d "$bandai" ]]; then
    "$cli" ingest "$bandai" --tag bandai --server "$address" || true
    "$cli" space create bandai --skeleton "$(skeleton_of_tag bandai)" --server "$address" || true
  fi
  echo "Try: $cli search --space demo --clip 1 --server $address"
fi
echo
if [[ "$http" != "off" ]]; then
  url="$scheme://${http/#0.0.0.0:/127.0.0.1:}"
  if ((page)); then echo "open $url (web asset browser and JSON API)"; else echo "JSON API: $url"; fi
fi
echo "motiondb-server is running (pid $pid). Use $cli help; Ctrl-C stops the server."
wait "$pid"
