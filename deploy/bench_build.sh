#!/usr/bin/env bash
# Benchmark of the build as a newcomer meets it (docs/build.md): a fresh clone of this repository's
# HEAD in a temporary folder, then, timed one after the other,
#   1. deploy/crane demo   (packages already installed, empty build folder, the given ccache)
#   2. deploy/crane test   (the rest of the build, then every test)
# and the ten slowest compile steps of the clone's build (ninja's log). Run it twice with the same
# cache folder for the warm-cache figure (a second fresh clone on the same machine):
#
#   deploy/bench_build.sh /tmp/ccache-bench          # first: empty cache (the folder is emptied)
#   deploy/bench_build.sh /tmp/ccache-bench --warm   # second: the cache the first one filled
#   deploy/bench_build.sh /tmp/ccache-bench --demo-only
#
# Usage: bench_build.sh CCACHE_DIR [--warm] [--demo-only] [--keep]
set -uo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
CACHE=${1:?usage: bench_build.sh CCACHE_DIR [--warm] [--demo-only] [--keep]}
shift
WARM=0 DEMO_ONLY=0 KEEP=0
for a in "$@"; do
  case "$a" in
    --warm) WARM=1 ;;
    --demo-only) DEMO_ONLY=1 ;;
    --keep) KEEP=1 ;;
    *) echo "bench_build: unknown option $a" >&2; exit 2 ;;
  esac
done
[ $WARM -eq 0 ] && rm -rf "$CACHE"
mkdir -p "$CACHE"
export CCACHE_DIR=$CACHE
# The clone sits beside shared/ as CI's does (the real-data tests read ../shared/data).
PARENT=$(dirname "$ROOT")
CLONE=$(mktemp -d "$PARENT/bench_build.XXXXXX")
cleanup() { [ $KEEP -eq 1 ] || rm -rf "$CLONE"; }
trap cleanup EXIT
git clone -q "$ROOT" "$CLONE/main"
cd "$CLONE/main"
ccache -z >/dev/null 2>&1

t0=$(date +%s.%N)
deploy/crane demo --out "$CLONE/demo-out" > "$CLONE/demo.log" 2>&1
demo_rc=$?
t1=$(date +%s.%N)
printf 'demo: exit %d, %.0f s from the clone to the printed table (%s ccache)\n' "$demo_rc" "$(echo "$t1 - $t0" | bc)" \
  "$([ $WARM -eq 1 ] && echo warm || echo empty)"
sed -n '/^maneuver/,/^speed:/p' "$CLONE/demo.log"
if [ $DEMO_ONLY -eq 0 ]; then
  deploy/crane test > "$CLONE/test.log" 2>&1
  test_rc=$?
  t2=$(date +%s.%N)
  printf 'test: exit %d, %.0f s after the demo, %.0f s from the clone\n' "$test_rc" "$(echo "$t2 - $t1" | bc)" \
    "$(echo "$t2 - $t0" | bc)"
  grep -E "tests passed|Total Test time" "$CLONE/test.log"
fi
ccache -s 2>/dev/null | grep -Ei "hits|misses|hit rate" | head -4
echo "slowest compile steps (s):"
awk -F'\t' '!/^#/ {printf "%8.1f %s\n", ($2 - $1) / 1000.0, $4}' build/.ninja_log | sort -rn | head -10
[ $KEEP -eq 1 ] && echo "clone kept in $CLONE"
exit 0
