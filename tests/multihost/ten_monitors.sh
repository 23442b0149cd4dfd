#!/usr/bin/env bash
# Ten monitors on another host do not disturb the loop (issue 6): the stack's latency benchmark
# (crane_bench latency, realtime, --lan) in namespace A, once alone and once while ten crane_topic
# monitors in namespace B (joined by a veth pair) each follow the sensor stream and echo the status.
# Prints both runs' end-to-end p50/p99 and overruns and the p99 ratio. A benchmark, not a ctest:
# two runs on a shared machine differ by their own noise (run it on an idle machine).
# Usage: ten_monitors.sh BIN_DIR CONFIG OUT_DIR [DURATION_S]
# The monitors run under SCHED_IDLE (chrt --idle): in this emulation they share the machine's two
# cores with the stack, where on a real second host they would have CPUs of their own; idle
# scheduling leaves the stack's processes the CPU, so what remains measured is what monitors cost
# the stack itself (discovery, one more destination per writer, the bytes on the pair).
# CRANE_MONITOR_SCHED=normal runs them at normal priority (the whole machine shared).
# Vendors: CRANE_STACK_DDS (every process of the stack and the bench) and CRANE_MONITOR_DDS (the
# monitors), fast or cyclone, default fast.
set -euo pipefail
BIN=$1 CONFIG=$2 OUT=$3 DURATION=${4:-10}
STACK_DDS=${CRANE_STACK_DDS:-fast} MONITOR_DDS=${CRANE_MONITOR_DDS:-fast}
SCHED=(chrt --idle 0)
[ "${CRANE_MONITOR_SCHED:-idle}" = normal ] && SCHED=()
mkdir -p "$OUT"
. "$(dirname "$0")/veth_pair.sh"
enter_namespace_a "$0" "$@"
HOLDER=
MONITORS=()
cleanup() {
  for p in "${MONITORS[@]}"; do kill "$p" 2>/dev/null || true; done
  [ -n "$HOLDER" ] && kill "$HOLDER" 2>/dev/null || true
}
trap cleanup EXIT
make_veth_pair multicast

"$BIN/crane_bench" latency --config "$CONFIG" --lan --insecure-lan --dds "$STACK_DDS" --domain 22 --duration "$DURATION" --json > "$OUT/alone.json"
RX0=$(rx_bytes)
for i in $(seq 1 10); do
  inb "${SCHED[@]}" "$BIN/crane_topic" hz rt/crane/hw/sensors --lan --insecure-lan --dds "$MONITOR_DDS" --domain 22 --duration $((DURATION + 15)) --json \
    > "$OUT/monitor_$i.json" 2>&1 &
  MONITORS+=($!)
done
"$BIN/crane_bench" latency --config "$CONFIG" --lan --insecure-lan --dds "$STACK_DDS" --domain 22 --duration "$DURATION" --json > "$OUT/monitored.json"
for p in "${MONITORS[@]}"; do wait "$p" || true; done
MONITORS=()
echo "{\"rx_bytes\": $(( $(rx_bytes) - RX0 ))}" > "$OUT/veth.json"
/usr/bin/python3 - "$OUT" "$STACK_DDS" "$MONITOR_DDS" "${CRANE_MONITOR_SCHED:-idle}" <<'PY'
import json, sys, glob
out = sys.argv[1]
print("stack on %s, monitors on %s (%s scheduling)" % (sys.argv[2], sys.argv[3], sys.argv[4]))
a, m = json.load(open(out + "/alone.json")), json.load(open(out + "/monitored.json"))
rates = [json.load(open(f))["receive"].get("rate_hz", 0) for f in sorted(glob.glob(out + "/monitor_*.json"))]
for name, r in (("alone", a), ("10 monitors", m)):
    e = r["end_to_end"]
    print("%-12s end to end p50 %7.1f us  p99 %7.1f us  max %8.1f us  overruns %d" % (name, e["p50_us"], e["p99_us"], e["max_us"], r["overruns"]))
print("monitors received the sensor stream at %s Hz" % ", ".join("%.1f" % x for x in rates))
print("bytes into the monitors' host while monitored: %.1f MB" % (json.load(open(out + "/veth.json"))["rx_bytes"] / 1e6))
print("p99 ratio monitored / alone = %.2f" % (m["end_to_end"]["p99_us"] / a["end_to_end"]["p99_us"]))
PY
