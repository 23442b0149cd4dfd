#!/usr/bin/env bash
# The stack's topic graph, from the code itself: starts the stack (lockstep, no security) in a
# private network namespace, once on the simulated plant and once with the hardware bridge behind
# the emulated board, and writes what DDS discovery reports (crane_topic list --json: every topic
# with its writers and readers, by participant name) as OUT_DIR/graph_sim.json and
# OUT_DIR/graph_board.json. Then a site's (docs/site.md): the site service, and the stack on the
# simulated plant as a crane of the site (its supervisor's guard, its site link with a job file),
# as OUT_DIR/graph_site.json (the crane's domain: the site link's goals) and
# OUT_DIR/graph_site_domain.json (the site's own domain). crane_security.py derives each process's
# permissions from them, so the only list of who writes and reads what is the nodes' own
# make_writer/make_reader calls.
# Usage: endpoint_graph.sh BIN_DIR CONFIG OUT_DIR [SITE_FILE]
#   SITE_FILE: the site whose graph is taken (default deploy/config/site_two_towers.yaml; its first
#   crane's stack runs CONFIG).
# Exit 0 when the four graphs were written; 1 (with the launcher's log) when a stack did not come up.
set -euo pipefail
BIN=$1 CONFIG=$2 OUT=$3
SITE=${4:-$(cd "$(dirname "$0")/.." && pwd)/config/site_two_towers.yaml}
if [ "${CRANE_IN_NAMESPACE:-}" != 1 ]; then
  if unshare --net true 2>/dev/null; then exec unshare --net env CRANE_IN_NAMESPACE=1 "$0" "$@"; fi
  exec unshare --net --map-root-user env CRANE_IN_NAMESPACE=1 "$0" "$@"
fi
ip link set lo up && ip link set lo multicast on
mkdir -p "$OUT"
STACK= SERVICE=
cleanup() {
  [ -n "$STACK" ] && kill -INT "$STACK" 2>/dev/null && wait "$STACK" 2>/dev/null
  [ -n "$SERVICE" ] && kill -INT "$SERVICE" 2>/dev/null && wait "$SERVICE" 2>/dev/null
  true
}
trap cleanup EXIT

graph() {  # NAME LAUNCH_ARGS...: the graph of the crane's domain; with SITE_DOMAIN set, that one's too
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
  if [ -n "${SITE_DOMAIN:-}" ]; then
    "$BIN/crane_topic" list --domain "$SITE_DOMAIN" --wait 1.5 --json > "$OUT/graph_${name}_domain.json"
  fi
  kill -INT "$STACK"
  wait "$STACK" || true
  STACK=
}

graph sim
graph board --hardware "shm:crane_security_graph_$$"

# The site's domain: its service, and a crane of it with its guard and its site link.
SITE_DOMAIN=$("$BIN/crane_site" check --site "$SITE" | sed -n "s/^site '.*' on domain \([0-9]*\):.*/\1/p")
"$BIN/crane_site" jobs --site "$SITE" --jobs 1 --seed 1 --out "$OUT/site_jobs" > /dev/null
crane=$(awk 'NR == 1 { print $1 }' "$OUT/site_jobs/hosts.txt")
[ -n "$SITE_DOMAIN" ] && [ -n "$crane" ] || { echo "endpoint_graph: no domain_id or crane in $SITE" >&2; exit 1; }
"$BIN/site_service" --site "$SITE" > "$OUT/site_service.log" 2>&1 &
SERVICE=$!
graph site --site "$SITE" --site-crane "$crane" --site-jobs "$OUT/site_jobs/$crane.csv"
kill -INT "$SERVICE"
wait "$SERVICE" || true
SERVICE=
