#!/usr/bin/env bash
# Benchmark of the lockstep main job (docs/architecture.md, "The 100 Hz cycle"): runs the whole demo
# N times in a row (default 10), every other run while stress-ng loads both cores at normal
# priority, and prints per run: the table's figures, overruns, faults, stages that died, and the
# speed (simulated time / wall time of the stepping loop). Every CSV must equal run 1's to the last
# bit. Exit 0 when every run is identical and clean, 1 otherwise. Not a ctest (the ctest
# integration.Lockstep.* runs a shorter version); run it inside a private network namespace, as
# deploy/crane does for the demo:
#
#   unshare --net bash -c 'ip link set lo up; ip link set lo multicast on; deploy/bench_lockstep.sh 10'
#   deploy/bench_lockstep.sh 50 --no-stress     # counts aborted stages over 50 demos
#
# Usage: bench_lockstep.sh [N] [--no-stress] [--out DIR] [-- demo options]
set -uo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BIN=${CRANE_BUILD_DIR:-"$ROOT/build"}/bin
N=10
STRESS=1
OUT=$(mktemp -d /tmp/bench_lockstep.XXXXXX)
DEMO_ARGS=()
while [ $# -gt 0 ]; do
  case "$1" in
    --no-stress) STRESS=0 ;;
    --out) OUT=$2; shift ;;
    --) shift; DEMO_ARGS=("$@"); break ;;
    *) N=$1 ;;
  esac
  shift
done
[ -x "$BIN/crane_demo" ] || { echo "bench_lockstep: $BIN/crane_demo is not built (deploy/crane build)" >&2; exit 2; }
if [ $STRESS -eq 1 ] && ! command -v stress-ng >/dev/null; then
  echo "bench_lockstep: stress-ng is not installed (apt-get install stress-ng), or pass --no-stress" >&2
  exit 2
fi
mkdir -p "$OUT"
stress_pid=
cleanup() { [ -n "$stress_pid" ] && kill "$stress_pid" 2>/dev/null; wait 2>/dev/null; }
trap 'cleanup; exit 130' INT TERM
trap cleanup EXIT

printf '%-4s %-7s %-6s %9s %9s %9s %8s %7s %7s %s\n' run stress exit simulated wall factor overruns faults died identical
bad=0
died_total=0
for i in $(seq 1 "$N"); do
  loaded=no
  if [ $STRESS -eq 1 ] && [ $((i % 2)) -eq 0 ]; then
    stress-ng --cpu 2 --timeout 3600s --quiet &
    stress_pid=$!
    loaded=yes
  fi
  dir="$OUT/run$i"
  "$BIN/crane_demo" --config "$ROOT/deploy/config/lab_tower_crane.yaml" --out "$dir" --domain 40 "${DEMO_ARGS[@]}" \
    >"$dir.log" 2>&1
  rc=$?
  if [ -n "$stress_pid" ]; then kill "$stress_pid" 2>/dev/null; wait "$stress_pid" 2>/dev/null; stress_pid=; fi
  read -r simulated wall factor overruns died < <(/usr/bin/python3 - "$dir/summary.json" <<'EOF'
import json, sys
try:
    s = json.load(open(sys.argv[1]))["loop"]
    print(f'{s["simulated_time_s"]:.1f} {s["wall_time_s"]:.2f} {s["real_time_factor"]:.1f} {s["overruns"]} {len(s["failures"])}')
except Exception:
    print("- - - - -")
EOF
)
  faults=$(cat "$dir"/logs/*/faults.jsonl 2>/dev/null | grep -c '"raised"')
  identical=yes
  if [ "$i" -gt 1 ]; then
    for f in "$OUT"/run1/*.csv; do
      cmp -s "$f" "$dir/$(basename "$f")" || identical="no ($(basename "$f"))"
    done
  fi
  [ "$died" != "-" ] && died_total=$((died_total + died))
  printf '%-4s %-7s %-6s %9s %9s %9s %8s %7s %7s %s\n' "$i" "$loaded" "$rc" "$simulated" "$wall" "${factor}x" \
    "$overruns" "$faults" "$died" "$identical"
  if [ "$rc" -ne 0 ] || [ "$overruns" != 0 ] || [ "$faults" != 0 ] || [ "$identical" != yes ]; then bad=$((bad + 1)); fi
  if [ "$i" -eq 1 ]; then sed -n '/^maneuver/,/^loop:/p' "$dir.log"; fi
done
echo "runs: $N, not identical or not clean: $bad, stages that died: $died_total (output in $OUT)"
[ $bad -eq 0 ]
