#!/usr/bin/env bash
# The latency table of docs/architecture.md ("Latency"): crane_bench latency for Fast DDS only,
# Cyclone DDS only and a mixed stack (plant and state estimator on Cyclone, the rest on Fast DDS),
# at 100 Hz and 1 kHz, each with its DDS floor measured in the same run. Runs inside a private
# network namespace (deploy/crane bench does the same). A benchmark: run it on an idle machine.
# Usage: deploy/bench_vendors.sh [DURATION_S] [OUT_DIR]
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
DURATION=${1:-10} OUT=${2:-bench-vendors-out}
mkdir -p "$OUT"
"$ROOT/deploy/crane" build
for rate in 100 1000; do
  for mix in fast cyclone mixed; do
    case $mix in
      fast) args=(--dds fast) ;;
      cyclone) args=(--dds cyclone) ;;
      mixed) args=(--dds fast --dds-mix plant=cyclone,state_estimator=cyclone) ;;
    esac
    "$ROOT/deploy/crane" bench latency --rate "$rate" --duration "$DURATION" "${args[@]}" --json > "$OUT/${mix}_${rate}.json"
  done
done
/usr/bin/python3 - "$OUT" <<'PY'
import json, sys
out = sys.argv[1]
print("| vendors | rate | end to end p50 / p99 / max [us] | floor one-way p50 / p99 [us] | p99 / floor p99 | overruns / cycles |")
print("|---|---|---|---|---|---|")
for rate in (100, 1000):
    for mix, label in (("fast", "Fast DDS"), ("cyclone", "Cyclone DDS"), ("mixed", "mixed (plant, estimator on Cyclone)")):
        j = json.load(open("%s/%s_%d.json" % (out, mix, rate)))
        e, f = j["end_to_end"], j["floor_one_way"]
        print("| %s | %d Hz | %.0f / %.0f / %.0f | %.0f / %.0f (%s) | %.1f | %d / %d |" % (
            label, rate, e["p50_us"], e["p99_us"], e["max_us"], f["p50_us"], f["p99_us"], j["floor_vendors"],
            j.get("p99_ratio_to_floor", float("nan")), j["overruns"], e["samples"]))
PY
