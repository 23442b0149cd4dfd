#!/usr/bin/env bash
# The table of docs/integration.md ("One wake-up per hop"): the DDS lockstep's speed and its hops
# with each cycle run on the DDS listener thread (--wake listener, the default) and on the node's
# own thread (--wake thread, the former path), for Fast DDS and Cyclone DDS, the settings
# alternating so that the machine's drift hits both alike. crane_bench latency --lockstep in a
# private network namespace (deploy/crane bench). A benchmark: run it on an idle machine.
# Usage: deploy/bench_wake.sh [RUNS] [DURATION_S] [OUT_DIR]
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
RUNS=${1:-3} DURATION=${2:-10} OUT=${3:-bench-wake-out}
mkdir -p "$OUT"
"$ROOT/deploy/crane" build
for run in $(seq 1 "$RUNS"); do
  for vendor in cyclone fast; do
    for wake in thread listener; do
      "$ROOT/deploy/crane" bench latency --lockstep --duration "$DURATION" --dds "$vendor" --wake "$wake" --json \
        > "$OUT/${vendor}_${wake}_${run}.json"
    done
  done
done
/usr/bin/python3 - "$OUT" "$RUNS" <<'PY'
import json, statistics, sys
out, runs = sys.argv[1], int(sys.argv[2])
hops = ("sensors->state_estimator", "state_estimator->trajectory_planner", "inputs->tracking",
        "tracking->friction_compensation")
print("| vendor | wake | x real time, median (range) | chain p50 / p99 [us] | " +
      " | ".join(h + " p50 [us]" for h in hops) + " | floor one-way p50 [us] |")
print("|---" * (5 + len(hops)) + "|")
speed = {}
for vendor, label in (("cyclone", "Cyclone DDS"), ("fast", "Fast DDS")):
    for wake in ("thread", "listener"):
        js = [json.load(open("%s/%s_%s_%d.json" % (out, vendor, wake, r))) for r in range(1, runs + 1)]
        med = lambda values: statistics.median(values)
        rt = [j["real_time_factor"] for j in js]
        speed[(vendor, wake)] = med(rt)
        chain = [j["chain_sensors_to_actuators"] for j in js]
        print("| %s | %s | %.1f (%.1f-%.1f) | %.0f / %.0f | %s | %.0f |" % (
            label, wake, med(rt), min(rt), max(rt), med([c["p50_us"] for c in chain]), med([c["p99_us"] for c in chain]),
            " | ".join("%.0f" % med([j["hops"][h]["p50_us"] for j in js]) for h in hops),
            med([j["floor_one_way"]["p50_us"] for j in js])))
for vendor, label in (("cyclone", "Cyclone DDS"), ("fast", "Fast DDS")):
    print("%s: listener / thread = %.2f" % (label, speed[(vendor, "listener")] / speed[(vendor, "thread")]))
PY
