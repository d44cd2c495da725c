#!/usr/bin/env bash
# Installs the Debian 12 packages motiondb needs that are not installed yet.
#   scripts/install-deps.sh               everything: build, start, tests, benchmarks, tools
#                                         (scripts/test.sh, CI)
#   scripts/install-deps.sh --start       what scripts/start.sh needs: the build and its demo
#   scripts/install-deps.sh --build-only  what a Release server and CLI build needs (Docker)
# Idempotent: does nothing (and needs no network) when everything is present.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
lists=("$here/packages-build.txt")
case "${1:-}" in
  --build-only) ;;
  --start) lists+=("$here/packages-start.txt") ;;
  "") lists+=("$here/packages-start.txt" "$here/packages-dev.txt") ;;
  *) echo "install-deps: unknown option '$1' (--start, --build-only or none)" >&2; exit 2 ;;
esac
# A line is a package name, optionally followed by `command=NAME`: then the package also counts
# as present when NAME is on PATH (another source installed it, e.g. a nodejs that bundles npm,
# which Debian's npm package would conflict with).
mapfile -t wanted < <(grep -hv '^\s*#' "${lists[@]}" | awk 'NF {print $1, $2}')

missing=()
for line in "${wanted[@]}"; do
  read -r pkg marker <<<"$line"
  [[ "$marker" == command=* ]] && command -v "${marker#command=}" >/dev/null && continue
  status="$(dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null || true)"
  [[ "$status" == "install ok installed" ]] || missing+=("$pkg")
done

if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#wanted[@]} packages present"
  exit 0
fi

sudo=()
if ((EUID != 0)); then
  command -v sudo >/dev/null || { echo "install-deps: run as root or install sudo" >&2; exit 1; }
  sudo=(sudo)
fi
echo "install-deps: installing ${missing[*]}"
"${sudo[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
# The tests use the prometheus package for its promtool only: the server it ships and starts
# (on :9090, every interface, no authentication) is not wanted on a developer's machine.
if [[ " ${missing[*]} " == *" prometheus "* && -d /run/systemd/system ]]; then
  "${sudo[@]}" systemctl disable --now prometheus.service
fi
# Likewise etcd-server's etcd (on 127.0.0.1:2379): the cluster tests and scripts/cluster.sh start
# their own on free ports.
if [[ " ${missing[*]} " == *" etcd-server "* && -d /run/systemd/system ]]; then
  "${sudo[@]}" systemctl disable --now etcd.service
fi
