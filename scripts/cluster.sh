#!/usr/bin/env bash
# A local motiondb cluster on loopback (issue 41): a 3-member etcd, N shard nodes and a router.
#
#   scripts/cluster.sh up [--nodes N] [--shards S]   start etcd, N shard nodes (default 2) and a
#                                                    router, and create the cluster's shard map
#                                                    of S logical shards (default 64)
#   scripts/cluster.sh status                        the nodes, their leases and the shard map
#   scripts/cluster.sh etcd                          the etcd endpoints (for --etcd, --cluster)
#   scripts/cluster.sh router                        the router's gRPC address (for --server)
#   scripts/cluster.sh down                          stop everything, remove the cluster's folder
#
# Everything lives in $MOTIONDB_CLUSTER_DIR (default ./motiondb-cluster): etcd's data, each
# node's database and log, the pids and the ports (free loopback ports picked at `up`). Needs
# etcd (Debian's etcd-server, scripts/install-deps.sh) and a build of motiondb-server and the
# CLI in $BUILD_DIR (default build/; scripts/start.sh or scripts/build.sh make it). What works
# today (README.md, "A local cluster"): nodes register, follow the shard map and survive etcd
# going away; the router stores each ingested clip on its shard's node and passes a call on one
# clip to it; searches and listings are not routed yet.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-$root/build}"
dir="${MOTIONDB_CLUSTER_DIR:-./motiondb-cluster}"
server="$build/server/motiondb-server"
cli="$build/client/motiondb"

die() { echo "cluster.sh: $*" >&2; exit 1; }

# N free loopback ports, one a line (the kernel's picks, released at once).
free_ports() {
  python3 -c 'import socket,sys
socks=[socket.socket() for _ in range(int(sys.argv[1]))]
for s in socks: s.bind(("127.0.0.1", 0))
print("\n".join(str(s.getsockname()[1]) for s in socks))' "$1"
}

# Polls `$@` until it succeeds, for up to a minute.
wait_for() {
  for _ in $(seq 600); do
    if "$@" >/dev/null 2>&1; then return 0; fi
    sleep 0.1
  done
  return 1
}

live_nodes() {
  "$cli" cluster status --etcd "$(cat "$dir/etcd")" | sed -n 's/^\([0-9]*\) live nodes$/\1/p'
}

up() {
  local nodes=2 shards=64
  while (($#)); do
    case "$1" in
      --nodes) nodes="$2"; shift 2 ;;
      --shards) shards="$2"; shift 2 ;;
      *) die "unknown option '$1' (up takes --nodes N and --shards S)" ;;
    esac
  done
  [[ "$nodes" =~ ^[1-9][0-9]?$ ]] || die "--nodes wants 1 to 99, not '$nodes'"
  command -v etcd >/dev/null || die "etcd is not installed (Debian package etcd-server)"
  [[ -x "$server" && -x "$cli" ]] || die "no build in $build (scripts/start.sh or scripts/build.sh)"
  [[ -e "$dir" ]] && die "$dir exists: a cluster is up (scripts/cluster.sh down first)"
  mkdir -p "$dir"
  mapfile -t ports < <(free_ports $((6 + 2 * (nodes + 1))))
  local initial="" endpoints="" i
  for i in 0 1 2; do
    initial+="${initial:+,}e$i=http://127.0.0.1:${ports[3 + i]}"
    endpoints+="${endpoints:+,}127.0.0.1:${ports[i]}"
  done
  echo "$endpoints" >"$dir/etcd"
  for i in 0 1 2; do
    etcd --name "e$i" --data-dir "$dir/etcd-e$i" \
      --listen-client-urls "http://127.0.0.1:${ports[i]}" \
      --advertise-client-urls "http://127.0.0.1:${ports[i]}" \
      --listen-peer-urls "http://127.0.0.1:${ports[3 + i]}" \
      --initial-advertise-peer-urls "http://127.0.0.1:${ports[3 + i]}" \
      --initial-cluster "$initial" --initial-cluster-state new \
      --initial-cluster-token "motiondb-$$" --logger zap --log-level warn \
      >"$dir/etcd-e$i.log" 2>&1 &
    echo $! >"$dir/etcd-e$i.pid"
  done
  wait_for "$cli" cluster status --etcd "$endpoints" || die "etcd did not start (see $dir/etcd-e*.log)"
  local names=() node
  for ((i = 1; i <= nodes; i++)); do names+=("shard-$i"); done
  names+=(router)
  for i in "${!names[@]}"; do
    node="${names[i]}"
    local role=shard
    [[ "$node" == router ]] && role=router
    "$server" --db "$dir/$node.sqlite" --listen "127.0.0.1:${ports[6 + 2 * i]}" \
      --http "127.0.0.1:${ports[7 + 2 * i]}" --cluster "$endpoints" --node-id "$node" \
      --role "$role" --quiet >"$dir/$node.log" 2>&1 &
    echo $! >"$dir/$node.pid"
    echo "$node: gRPC 127.0.0.1:${ports[6 + 2 * i]}, HTTP 127.0.0.1:${ports[7 + 2 * i]}" >>"$dir/nodes"
    if [[ "$node" == router ]]; then echo "127.0.0.1:${ports[6 + 2 * i]}" >"$dir/router"; fi
  done
  # shellcheck disable=SC2317  # called through wait_for
  all_live() { [[ "$(live_nodes)" == "$((nodes + 1))" ]]; }
  wait_for all_live || die "the nodes did not register (see $dir/*.log)"
  "$cli" cluster init --etcd "$endpoints" --shards "$shards"
  cat "$dir/nodes"
}

down() {
  [[ -d "$dir" ]] || die "no cluster in $dir"
  local pidfile pid
  # The nodes first (each leaves the cluster), then etcd.
  for pidfile in "$dir"/shard-*.pid "$dir"/router.pid "$dir"/etcd-*.pid; do
    [[ -f "$pidfile" ]] || continue
    pid="$(cat "$pidfile")"
    kill "$pid" 2>/dev/null || continue
    # Gone, or a zombie its new parent has yet to reap.
    while kill -0 "$pid" 2>/dev/null && [[ "$(ps -o stat= -p "$pid")" != Z* ]]; do sleep 0.1; done
  done
  rm -rf "$dir"
  echo "cluster down"
}

case "${1:-}" in
  up) shift; up "$@" ;;
  down) down ;;
  status)
    [[ -f "$dir/etcd" ]] || die "no cluster in $dir (scripts/cluster.sh up)"
    "$cli" cluster status --etcd "$(cat "$dir/etcd")"
    cat "$dir/nodes" ;;
  etcd | router)
    [[ -f "$dir/$1" ]] || die "no cluster in $dir (scripts/cluster.sh up)"
    cat "$dir/$1" ;;
  *) die "usage: scripts/cluster.sh up [--nodes N] [--shards S] | status | etcd | router | down" ;;
esac
