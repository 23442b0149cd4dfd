#!/usr/bin/env bash
# Monitoring from another machine, emulated: two network namespaces joined by a veth pair
# (10.77.0.1 <-> 10.77.0.2, multicast on). The stack runs in the first with --lan; crane_topic runs
# in the second and must discover every topic, measure the 100 Hz sensor stream and record it, and
# the recording must be accepted by crane_audit --model crane.
# Both namespaces (and the veth pair with them) are private to this script and vanish with it;
# nothing is sent anywhere else. Needs: unshare --net (root or user namespaces), ip, nsenter.
# Usage: monitor_over_veth.sh BIN_DIR CONFIG OUT_DIR [multicast|unicast PROFILE.xml]
#   multicast (default): --lan, multicast discovery over the pair;
#   unicast PROFILE: multicast switched off on the pair, every process with a copy of the profile
#   pair (deploy/dds/fastdds_lan_unicast.xml and its cyclone_ counterpart) whose peer addresses
#   become the pair's.
# Vendors: CRANE_STACK_DDS (every process of the stack) and CRANE_MONITOR_DDS (crane_topic), fast
# or cyclone, default fast.
# Exit 0 = every check passed.
set -euo pipefail
BIN=$1 CONFIG=$2 OUT=$3 MODE=${4:-multicast} PROFILE=${5:-}
STACK_DDS=${CRANE_STACK_DDS:-fast} MONITOR_DDS=${CRANE_MONITOR_DDS:-fast}
mkdir -p "$OUT"
. "$(dirname "$0")/veth_pair.sh"
enter_namespace_a "$0" "$@"
HOLDER=
cleanup() {
  [ -n "${STACK:-}" ] && kill -INT "$STACK" 2>/dev/null && wait "$STACK" 2>/dev/null
  [ -n "$HOLDER" ] && kill "$HOLDER" 2>/dev/null || true
}
trap cleanup EXIT
make_veth_pair "$MODE"
if [ "$MODE" = multicast ]; then
  NET=(--lan)
else
  for vendor in fastdds cyclone; do
    sed -e 's/192\.168\.10\.1/10.77.0.1/' -e 's/192\.168\.10\.2/10.77.0.2/' \
      "$(dirname "$PROFILE")/${vendor}_$(basename "$PROFILE" | sed 's/^[a-z]*_//')" > "$OUT/${vendor}_lan_unicast.xml"
  done
  NET=(--dds-profile "$OUT/fastdds_lan_unicast.xml")  # each process takes its vendor's file of the pair
fi
NET+=(--insecure-lan)  # monitoring without DDS Security, on purpose (tests/security checks it secured)
inb ip addr show crane_b > "$OUT/address_b.txt"
grep -q 10.77.0.2 "$OUT/address_b.txt"

"$BIN/crane_launch" --config "$CONFIG" "${NET[@]}" --dds "$STACK_DDS" --domain 21 --log-dir "$OUT/logs" > "$OUT/launch.log" 2>&1 &
STACK=$!
# Until the launcher reports every stage matched and alive (at most 30 s).
for _ in $(seq 300); do
  grep -q "all stages matched and alive" "$OUT/launch.log" 2>/dev/null && break
  kill -0 "$STACK" 2>/dev/null || break
  sleep 0.1
done
status=0
inb "$BIN/crane_topic" list "${NET[@]}" --dds "$MONITOR_DDS" --domain 21 --wait 3 --json > "$OUT/list.json" || status=1
inb "$BIN/crane_topic" hz rt/crane/hw/sensors "${NET[@]}" --dds "$MONITOR_DDS" --domain 21 --duration 3 --json > "$OUT/hz.json" || status=1
inb "$BIN/crane_topic" record "${NET[@]}" --dds "$MONITOR_DDS" --domain 21 --duration 2 --out "$OUT/run.csv" 2> "$OUT/record.log" || status=1
# The recording is accepted by the model audit (crane model, nominal parameters from the config).
inb "$BIN/crane_audit" --model crane --data "$OUT/run.csv" --config "$CONFIG" --out "$OUT/audit" > "$OUT/audit.log" 2>&1 \
  || { echo "crane_audit refused the recording: $(tail -3 "$OUT/audit.log")"; status=1; }
# The monitor's participant has no shared memory: everything it got came over the veth pair.
rx=$(rx_bytes)
echo "{\"veth_rx_bytes\": $rx}" > "$OUT/veth.json"
[ "$rx" -gt 100000 ] || { echo "only $rx bytes crossed the veth pair"; status=1; }
/usr/bin/python3 - "$OUT" "$MODE, stack $STACK_DDS, monitor $MONITOR_DDS" <<'PY' || status=1
import json, sys
out = sys.argv[1]
topics = json.load(open(out + "/list.json"))
hz = json.load(open(out + "/hz.json"))
rows = sum(1 for _ in open(out + "/run.csv")) - 1
rx = json.load(open(out + "/veth.json"))["veth_rx_bytes"]
try:
    audit = json.load(open(out + "/audit/report.json"))["cause"]
except (OSError, ValueError, KeyError):
    audit = "no report"
print("[ figure   ] monitor in a second namespace over veth (" + sys.argv[2] + "): %d topics discovered, sensors %.2f Hz (jitter p99 %.2f ms), "
      "%d rows recorded (crane audit: %s), %d bytes received" % (len(topics), hz["receive"]["rate_hz"], hz["receive"]["jitter_p99_ms"], rows, audit, rx))
problems = []
if "rt/crane/hw/sensors" not in topics or [w["participant"] for w in topics["rt/crane/hw/sensors"]["writers"]] != ["plant"]:
    problems.append("the sensor topic and its single writer 'plant' were not discovered")
if len(topics) < 9:
    problems.append("only %d topics discovered" % len(topics))
if abs(hz["receive"]["rate_hz"] - 100.0) > 5.0:
    problems.append("sensor rate %.2f Hz" % hz["receive"]["rate_hz"])
if rows < 100:
    problems.append("only %d rows recorded" % rows)
for p in problems:
    print(p)
sys.exit(1 if problems else 0)
PY
exit $status
