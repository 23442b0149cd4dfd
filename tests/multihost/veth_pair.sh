# Two emulated hosts for the multihost scripts (sourced, not run): namespace "A" is the script's
# own, namespace "B" is held by a placeholder process; a veth pair joins them, 10.77.0.1 (crane_a,
# in A) <-> 10.77.0.2 (crane_b, in B). Nothing else is reachable; both vanish with the script.
#
#   enter_namespace_a "$0" "$@"   re-runs the script inside a fresh network namespace (first line)
#   make_veth_pair multicast|unicast
#                                 B, the pair, addresses, links up; multicast on (with a route for
#                                 224.0.0.0/4) or off on both ends. Sets HOLDER (B's holder pid).
#   inb CMD ...                   runs CMD in namespace B
#   rx_bytes                      bytes received so far on crane_b (what reached host B)
# The caller's EXIT trap must kill "$HOLDER".

enter_namespace_a() {
  if [ "${CRANE_IN_NAMESPACE:-}" != 1 ]; then
    local script=$1
    shift
    if unshare --net true 2>/dev/null; then exec unshare --net env CRANE_IN_NAMESPACE=1 "$script" "$@"; fi
    exec unshare --net --map-root-user env CRANE_IN_NAMESPACE=1 "$script" "$@"
  fi
  ip link set lo up && ip link set lo multicast on
}

inb() { nsenter -t "$HOLDER" -n "$@"; }

rx_bytes() {
  inb ip -j -s link show dev crane_b | /usr/bin/python3 -c 'import json,sys; print(json.load(sys.stdin)[0]["stats64"]["rx"]["bytes"])'
}

make_veth_pair() {
  unshare --net sleep 3600 &
  HOLDER=$!
  sleep 0.2
  ip link add crane_a type veth peer name crane_b
  ip link set crane_b netns "$HOLDER"
  ip addr add 10.77.0.1/24 dev crane_a
  ip link set crane_a up
  inb ip link set lo up
  inb ip addr add 10.77.0.2/24 dev crane_b
  inb ip link set crane_b up
  if [ "$1" = multicast ]; then
    ip link set crane_a multicast on
    ip route add 224.0.0.0/4 dev crane_a
    inb ip link set crane_b multicast on
    inb ip route add 224.0.0.0/4 dev crane_b
  else
    ip link set crane_a multicast off
    inb ip link set crane_b multicast off
  fi
}
