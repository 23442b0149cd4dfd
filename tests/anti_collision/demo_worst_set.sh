#!/usr/bin/env bash
# The site demo names its worst set (coordinated / solo) by its seed, so that it can be traced alone
# (docs/site.md, "The simulated site"). Cross-check: the demo over SETS sets from FIRST, then each
# set alone (--sets 1 --seed S): the named seed's ratio alone is the worst printed, and no other set
# alone is worse.
# Usage: demo_worst_set.sh CRANE_SITE SITE_FILE FIRST SETS
set -eu
bin=$1 site=$2 first=$3 sets=$4
ratio_line() { "$bin" demo --site "$site" --jobs 1 --threads 1 "$@" 2>&1 | grep "total time coordinated / solo"; }
line=$(ratio_line --sets "$sets" --seed "$first")
echo "over $sets sets: $line"
worst=$(sed -n 's/.* worst \([0-9.]*\) .*/\1/p' <<< "$line")
seed=$(sed -n 's/.*(the worst: set seed \([0-9]*\)).*/\1/p' <<< "$line")
[ -n "$worst" ] && [ -n "$seed" ] || { echo "FAILED: no worst ratio or seed in: $line"; exit 1; }
status=0
for s in $(seq "$first" $((first + sets - 1))); do
  alone=$(ratio_line --sets 1 --seed "$s" | sed -n 's/.* median \([0-9.]*\) .*/\1/p')
  echo "set seed $s alone: $alone"
  if [ "$s" = "$seed" ] && [ "$alone" != "$worst" ]; then
    echo "FAILED: the worst set, seed $seed, gives $alone alone, not $worst"
    status=1
  fi
  if awk -v a="$alone" -v w="$worst" 'BEGIN { exit !(a > w) }'; then
    echo "FAILED: set seed $s alone ($alone) is worse than the worst printed ($worst, seed $seed)"
    status=1
  fi
done
exit $status
