#!/usr/bin/env bash
# What Foxglove clients of crane_web cost the stack (issue 16, "Load"): crane_bench latency (the
# simulated stack, realtime) alone, with crane_web and no client, and while crane_web serves CLIENTS
# WebSocket clients subscribed to every channel; prints both runs' end-to-end p50/p99 and overruns, the p99 ratio, and
# crane_web's CPU and resident memory with 0 and CLIENTS clients (per client: the difference / CLIENTS).
# The clients run under SCHED_IDLE (they stand for viewers on other machines), crane_web at normal
# priority beside the stack. A benchmark, not a ctest. In a private network namespace when possible.
#
#   deploy/bench_web.sh [SECONDS=20] [CLIENTS=20] [PRIORITY=70]
#
# PRIORITY: the stages at SCHED_FIFO from it, as crane_launch and the systemd units run them
# (crane_bench latency --realtime-priority; 0: normal priority).
#
# Needs the built tree (deploy/crane build) and the test clients' npm folder
# (build/npm-test-clients, installed by ctest -R web.FoxgloveClient).
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD_DIR=${CRANE_BUILD_DIR:-"$ROOT/build"}
BIN=$BUILD_DIR/bin
DURATION=${1:-20}
CLIENTS=${2:-20}
PRIORITY=${3:-70}
CONFIG=$ROOT/deploy/config/lab_tower_crane.yaml
export NODE_PATH=$BUILD_DIR/npm-test-clients/node_modules
[ -d "$NODE_PATH/ws" ] || { echo "no $NODE_PATH/ws: run 'ctest --test-dir $BUILD_DIR -R web.FoxgloveClient' once"; exit 2; }
if [ -z "${CRANE_BENCH_WEB_IN_NAMESPACE:-}" ] && unshare --net true 2>/dev/null; then
  exec unshare --net env CRANE_BENCH_WEB_IN_NAMESPACE=1 bash -c \
    'ip link set lo up && ip link set lo multicast on && exec bash "$0" "$@"' "${BASH_SOURCE[0]}" "$@"
fi
OUT=$(mktemp -d /tmp/bench_web.XXXXXX)
pids=()
cleanup() {
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do kill -TERM "${pids[i]}" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
}
trap cleanup EXIT
cpu_ticks() { awk '{print $14 + $15}' "/proc/$1/stat"; }
rss_kb() { awk '/VmRSS/ {print $2}' "/proc/$1/status"; }

echo "alone: crane_bench latency --duration $DURATION" >&2
"$BIN/crane_bench" latency --config "$CONFIG" --domain 30 --duration "$DURATION" --realtime-priority "$PRIORITY" --json > "$OUT/alone.json"

${CRANE_WEB_PREFIX:-} "$BIN/crane_web" --config "$CONFIG" --port 0 --domain 30 > "$OUT/web.log" 2>&1 &
WEB=$!
pids+=($WEB)
for _ in $(seq 100); do grep -q "ws://" "$OUT/web.log" && break; sleep 0.1; done
URL=$(grep -o "ws://[0-9.]*:[0-9]*" "$OUT/web.log")
sleep 1
RSS0=$(rss_kb $WEB)
echo "crane_web without clients: crane_bench latency --duration $DURATION" >&2
"$BIN/crane_bench" latency --config "$CONFIG" --domain 30 --duration "$DURATION" --realtime-priority "$PRIORITY" --json > "$OUT/web_idle.json"
# The clients stand for viewers on other machines: SCHED_IDLE, so that their own work (Node
# decoding 20 x 800 frames/s) does not count as crane_web's cost on these shared cores.
chrt --idle 0 node "$ROOT/tests/web/foxglove_client.js" load "$URL" "$CLIENTS" $((DURATION + 12)) > "$OUT/load.json" &
pids+=($!)
LOADER=$!
sleep 3
echo "loaded: $CLIENTS clients on every channel, crane_bench latency --duration $DURATION" >&2
T0=$(cpu_ticks $WEB)
S0=$(date +%s.%N)
"$BIN/crane_bench" latency --config "$CONFIG" --domain 30 --duration "$DURATION" --realtime-priority "$PRIORITY" --json > "$OUT/loaded.json"
T1=$(cpu_ticks $WEB)
S1=$(date +%s.%N)
RSS1=$(rss_kb $WEB)
wait $LOADER || true
/usr/bin/python3 - "$OUT" "$CLIENTS" "$T0" "$T1" "$S0" "$S1" "$RSS0" "$RSS1" "$(getconf CLK_TCK)" <<'PY'
import json, sys
out, clients = sys.argv[1], int(sys.argv[2])
t0, t1, s0, s1, rss0, rss1, hz = (float(x) for x in sys.argv[3:10])
a, m = json.load(open(out + "/alone.json")), json.load(open(out + "/loaded.json"))
load = json.load(open(out + "/load.json"))
w = json.load(open(out + "/web_idle.json"))
for name, r in (("alone", a), ("web, 0 clients", w), ("%d clients" % clients, m)):
    e = r["end_to_end"]
    print("%-14s end to end p50 %7.1f us  p99 %7.1f us  max %8.1f us  overruns %d (%d samples)"
          % (name, e["p50_us"], e["p99_us"], e["max_us"], r["overruns"], e["samples"]))
print("p99 ratio to alone: crane_web without clients %.2f, with %d clients %.2f"
      % (w["end_to_end"]["p99_us"] / a["end_to_end"]["p99_us"], clients, m["end_to_end"]["p99_us"] / a["end_to_end"]["p99_us"]))
cpu = (t1 - t0) / hz / (s1 - s0) * 100.0
print("crane_web CPU with %d clients: %.1f %% of one core (%.2f %% per client)" % (clients, cpu, cpu / clients))
print("crane_web resident memory: %.1f MB with 0 clients, %.1f MB with %d (%.0f kB per client)"
      % (rss0 / 1024, rss1 / 1024, clients, (rss1 - rss0) / clients))
print("frames per client over %d s: %d-%d (all channels), %.1f MB sent in all"
      % (load["seconds"], load["frames_per_client_min"], load["frames_per_client_max"], load["bytes_total"] / 1e6))
PY
