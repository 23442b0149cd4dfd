#!/usr/bin/env bash
# Robustness table (issue 3): every controller on the trolley and slew maneuvers of section 3.3.3
# with the simulated crane's cable length and load mass off by +-20 % from what every controller
# assumes (crane_demo --plant-cable-length-factor / --plant-load-mass-factor). Lockstep, friction
# compensation on. Prints one line per run. Usage: deploy/robustness.sh [OUT_DIR]  (after a build)
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD_DIR=${CRANE_BUILD_DIR:-"$ROOT/build"}
OUT=${1:-robustness-out}
mkdir -p "$OUT"
printf '%-24s %-6s %-6s %-8s %9s %9s %10s %10s\n' controller L m maneuver settle_s err_mm resid_deg max_deg
for controller in delay1 pd delay2 fuzzy gain_scheduling_partial gain_scheduling_full; do
  for variation in "1.0 1.0" "1.2 1.0" "0.8 1.0" "1.0 1.2" "1.0 0.8"; do
    read -r l m <<<"$variation"
    run="$OUT/${controller}_L${l}_m${m}"
    rm -rf "$run"
    "$ROOT/deploy/crane" demo --out "$run" --friction-compensation on --controller "$controller" \
      --maneuver trolley --maneuver slew --plant-cable-length-factor "$l" --plant-load-mass-factor "$m" \
      >"$run.log" 2>&1 || { echo "$controller L x$l m x$m: demo failed, see $run.log"; continue; }
    /usr/bin/python3 - "$run/summary.json" "$controller" "$l" "$m" <<'PY'
import json, math, sys
summary, controller, l, m = json.load(open(sys.argv[1])), sys.argv[2], sys.argv[3], sys.argv[4]
for r in summary["maneuvers"]:
    settle = r["settle_time_s"]
    print("%-24s x%-5s x%-5s %-8s %9s %9.2f %10.3f %10.1f" % (
        controller, l, m, r["name"], "-" if settle is None else "%.2f" % settle,
        r["final_position_error_m"] * 1e3, math.degrees(r["residual_swing_rad"]), math.degrees(r["max_swing_rad"])))
PY
  done
done
