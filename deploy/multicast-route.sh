#!/usr/bin/env bash
# Makes sure LCM's multicast group is routable. LCM refuses to start without a route to
# 239.255.76.67; a host with a default route has one, an isolated host (or a fresh network
# namespace) does not. Then, as root, this adds a route over loopback for single-host use (ttl=0).
# Usage: deploy/multicast-route.sh [--check]  (--check: only report)
set -euo pipefail
group=239.255.76.67
if ip route get "$group" >/dev/null 2>&1; then
  exit 0
fi
if [[ "${1:-}" == "--check" || $(id -u) -ne 0 ]]; then
  echo "evldt: no route to the LCM multicast group $group; as root run: ip link set lo multicast on; ip route add 224.0.0.0/4 dev lo" >&2
  exit 1
fi
echo "evldt: no multicast route: adding 224.0.0.0/4 via lo (single-host use)" >&2
ip link set lo multicast on
ip route add 224.0.0.0/4 dev lo
