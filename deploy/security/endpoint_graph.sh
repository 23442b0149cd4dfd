#!/usr/bin/env bash
# The stack's topic graph, from the code itself: starts the stack (lockstep, no security) in a
# private network namespace, once on the simulated plant and once with the hardware bridge behind
# the emulated board, and writes what DDS discovery reports (crane_topic list --json: every topic
# with its writers and readers, by participant name) as OUT_DIR/graph_sim.json and
# OUT_DIR/graph_board.json. crane_security.py derives each process's permissions from them, so the
# only list of who writes and reads what is the nodes' own make_writer/make_reader calls.
# Usage: endpoint_graph.sh BIN_DIR CONFIG OUT_DIR
# Exit 0 when both graphs were written; 1 (with the launcher's log) when a stack did not come up.
set -euo pipefail
BIN=$1 CONFIG=$2 OUT=$3
if [ "${CRANE_IN_NAMESPACE:-}" != 1 ]; then
  if unshare --net true 2>/dev/null; then exec unshare --net env CRANE_IN_NAMESPACE=1 "$0" "$@"; fi
  exec unshare --net --map-root-user env CRANE_IN_NAMESPACE=1 "$0" "$@"
fi
ip link set lo up && ip link set lo multicast on
mkdir -p "$OUT"
STACK=
cleanup() { [ -n "$STACK" ] && kill -INT "$STACK" 2>/dev/null && wait "$STACK" 2>/dev/null || true; }
trap cleanup EXIT

graph() {  # NAME LAUNCH_ARGS...
  local name=$1
  shift
  "$BIN/crane_launch" --config "$CONFIG" --lockstep --domain 7 --log-dir "$OUT/logs_$name" "$@" \
    > "$OUT/launch_$name.log" 2>&1 &
  STACK=$!
  for _ in $(seq 300); do
    grep -q "all stages matched and alive" "$OUT/launch_$name.log" 2>/dev/null && break
    kill -0 "$STACK" 2>/dev/null || break
    sleep 0.1
  done
  if ! grep -q "all stages matched and alive" "$OUT/launch_$name.log"; then
    echo "endpoint_graph: the stack ($name) did not come up:" >&2
    tail -5 "$OUT/launch_$name.log" >&2
    exit 1
  fi
  "$BIN/crane_topic" list --domain 7 --wait 1.5 --json > "$OUT/graph_$name.json"
  kill -INT "$STACK"
  wait "$STACK" || true
  STACK=
}

graph sim
graph board --hardware "shm:crane_security_graph_$$"
