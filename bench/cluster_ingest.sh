#!/usr/bin/env bash
# Ingest throughput of one node against a local cluster on the same machine: the same folder of
# motion files sent by `motiondb ingest` to a single motiondb-server, then to the router of
# scripts/cluster.sh (a 3-member etcd, N shard nodes, the router), each on a fresh database.
#
#   bench/cluster_ingest.sh FOLDER [--nodes N] [--shards S]     (defaults: 2 nodes, 64 shards)
#
# Prints one line a setup: files, bytes, seconds, files/s, MB/s, and for the cluster how many
# clips each shard node holds. Needs a build in $BUILD_DIR (default build/) and etcd.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-$root/build}"
cli="$build/client/motiondb"
server="$build/server/motiondb-server"
die() { echo "cluster_ingest.sh: $*" >&2; exit 1; }

(($# >= 1)) || die "usage: bench/cluster_ingest.sh FOLDER [--nodes N] [--shards S]"
folder="$1"; shift
nodes=2 shards=64
while (($#)); do
  case "$1" in
    --nodes) nodes="$2"; shift 2 ;;
    --shards) shards="$2"; shift 2 ;;
    *) die "unknown option '$1'" ;;
  esac
done
[[ -d "$folder" ]] || die "no folder '$folder'"
[[ -x "$server" && -x "$cli" ]] || die "no build in $build"
work="$(mktemp -d)"
single_pid=""
cleanup() {
  [[ -n "$single_pid" ]] && kill "$single_pid" 2>/dev/null && wait "$single_pid" 2>/dev/null
  [[ -d "$work/cluster" ]] && MOTIONDB_CLUSTER_DIR="$work/cluster" "$root/scripts/cluster.sh" down >/dev/null
  rm -rf "$work"
}
trap cleanup EXIT

files=$(find "$folder" -type f \( -iname '*.bvh' -o -iname '*.fbx' -o -iname '*.glb' -o -iname '*.gltf' \) | wc -l)
bytes=$(find "$folder" -type f \( -iname '*.bvh' -o -iname '*.fbx' -o -iname '*.glb' -o -iname '*.gltf' \) -printf '%s\n' | awk '{s += $1} END {print s}')

# Seconds `motiondb ingest` of the folder took against $1.
ingest_seconds() {
  local start end
  start=$(date +%s.%N)
  "$cli" ingest "$folder" --recursive --server "$1" >"$work/ingest.log" 2>&1 || {
    cat "$work/ingest.log" >&2
    die "the ingest into $1 failed"
  }
  end=$(date +%s.%N)
  awk -v a="$start" -v b="$end" 'BEGIN { print b - a }'
}
report() {  # SETUP SECONDS [NOTE]
  awk -v setup="$1" -v s="$2" -v files="$files" -v bytes="$bytes" -v note="${3:-}" 'BEGIN {
    printf "%-28s %4d files %7.1f MB %7.2f s %6.1f files/s %6.2f MB/s %s\n",
      setup, files, bytes / 1e6, s, files / s, bytes / 1e6 / s, note }'
}

port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
"$server" --db "$work/one.sqlite" --listen "127.0.0.1:$port" --http off --quiet >"$work/one.log" 2>&1 &
single_pid=$!
for _ in $(seq 600); do "$cli" info --server "127.0.0.1:$port" >/dev/null 2>&1 && break; sleep 0.1; done
report "one node" "$(ingest_seconds "127.0.0.1:$port")"
kill "$single_pid"; wait "$single_pid" 2>/dev/null || true; single_pid=""

export MOTIONDB_CLUSTER_DIR="$work/cluster"
"$root/scripts/cluster.sh" up --nodes "$nodes" --shards "$shards" >/dev/null
router="$("$root/scripts/cluster.sh" router)"
seconds="$(ingest_seconds "$router")"
held=""
while read -r node address; do
  count=$("$cli" clips --server "$address" --json | python3 -c 'import json, sys; print(len(json.load(sys.stdin)["clips"]))')
  held+="${held:+, }$node $count"
done < <(sed -n 's/^\(shard-[0-9]*\): gRPC \([^,]*\),.*/\1 \2/p' "$MOTIONDB_CLUSTER_DIR/nodes")
report "router, $nodes shard nodes" "$seconds" "(clips: $held)"
