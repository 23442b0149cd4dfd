#!/usr/bin/env bash
# The DDS lockstep's speed and its hops under several settings of `crane_bench latency --lockstep`
# (deploy/crane bench: a private network namespace), the settings alternating within each run so
# that the machine's drift hits all of them alike; prints a table of medians (and ranges), each
# setting's speed also against the first's. A benchmark: run it on an idle machine.
# Usage: deploy/bench_transport.sh RUNS DURATION_S OUT_DIR 'LABEL=crane_bench options' ...
#   deploy/bench_transport.sh 3 10 out 'Cyclone DDS, UDP=--dds cyclone' 'Cyclone DDS, iceoryx=--dds cyclone --iceoryx'
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
[ $# -ge 4 ] || { sed -n '2,8p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 2; }
RUNS=$1 DURATION=$2 OUT=$3
shift 3
mkdir -p "$OUT"
"$ROOT/deploy/crane" build
for run in $(seq 1 "$RUNS"); do
  index=0
  for setting in "$@"; do
    read -r -a options <<< "${setting#*=}"
    "$ROOT/deploy/crane" bench latency --lockstep --duration "$DURATION" "${options[@]}" --json \
      > "$OUT/setting${index}_${run}.json"
    index=$((index + 1))
  done
done
/usr/bin/python3 - "$OUT" "$RUNS" "$@" <<'PY'
import json, statistics, sys
out, runs, settings = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
hops = ("sensors->state_estimator", "state_estimator->trajectory_planner", "inputs->tracking",
        "tracking->friction_compensation")
print("| setting | x real time, median (range) | against the first | chain p50 / p99 [us] | " +
      " | ".join(h + " p50 [us]" for h in hops) + " | floor one-way p50 [us] |")
print("|---" * (5 + len(hops)) + "|")
med = statistics.median
first = None
for index, setting in enumerate(settings):
    js = [json.load(open("%s/setting%d_%d.json" % (out, index, r))) for r in range(1, runs + 1)]
    rt = [j["real_time_factor"] for j in js]
    first = first or med(rt)
    # A figure the runs did not measure (crane_bench --sensors-only: no hop readers) prints as -.
    def us(figures, key):
        values = [f[key] for f in figures if key in f]
        return "%.0f" % med(values) if values else "-"
    chain = [j["chain_sensors_to_actuators"] for j in js]
    print("| %s | %.1f (%.1f-%.1f) | %.2f | %s / %s | %s | %.0f |" % (
        setting.split("=", 1)[0], med(rt), min(rt), max(rt), med(rt) / first, us(chain, "p50_us"),
        us(chain, "p99_us"), " | ".join(us([j["hops"][h] for j in js], "p50_us") for h in hops),
        med([j["floor_one_way"]["p50_us"] for j in js])))
PY
