#!/usr/bin/env bash
# crane_web seen by an independent Foxglove client (issue 16): the simulated stack (crane_launch
# --sim, realtime), crane_web, crane_topic record and tests/web/foxglove_client.js (Foxglove's own
# npm packages) in one private network namespace. The client lists the channels (>= 10), receives
# rt/crane/hw/sensors for 5 s (100 +- 5 Hz by arrival time), decodes every sample of every channel
# with the advertised IDL schema, and the decoded values equal crane_topic record's (1e-9). Then bad
# input (malformed JSON, unknown ids, binary and oversized frames, a client that never reads: closed
# 1008 after --close-stalled) is answered for that client only, and /metrics counts it. The recorder
# also writes MCAP (--mcap), read by @mcap/core: one channel per topic, 100 Hz x 9 s +- 2 % sensor
# messages, every message decoded (ros2msg schema, Foxglove's ROS 2 CDR reader) equal to the JSON
# record; the model audit of it (deploy/crane audit --data run.mcap's steps) reports what the audit
# of the CSV does. Last, the operator page in Debian's chromium: what it decoded equals Foxglove's
# decoder, its views and plots drawn, the configuration's no-go zone drawn off and then enforced;
# then its controls (operator_check.js): read-only without a login, publishing refused to clients
# without the operator's session or from another origin, and "move to" pressed by the logged-in
# operator brings the trolley and slew to the targets.
#
#   foxglove_client_test.sh BIN_DIR CONFIG NPM_DIR OUT_DIR
#   foxglove_client_test.sh --install-only NPM_DIR      (deploy/crane test, before its namespace)
#
# NPM_DIR holds the npm packages (installed on the first run, reused offline afterwards). Exit 77
# (ctest: skipped) when they are not there and the npm registry cannot be reached, or when every
# other check passed but there is no /usr/bin/chromium for the page's.
set -euo pipefail
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
PACKAGES=(@foxglove/ws-protocol@0.8.0 @foxglove/omgidl-parser@1.1.0 @foxglove/omgidl-serialization@1.0.3 ws@8.18.0
          @mcap/core@2.2.2 @foxglove/rosmsg@5.0.5 @foxglove/rosmsg2-serialization@3.1.0 puppeteer-core@24.43.1)

# The client's packages into NPM_DIR, once (a stamp names the package list); exit 77 when npm or
# its registry is not there and nothing is cached.
install_clients() {
  local npm_dir=$1
  local stamp
  stamp="$npm_dir/installed-$(printf '%s\n' "${PACKAGES[@]}" | md5sum | cut -c1-12)"
  [ -f "$stamp" ] && return 0
  command -v npm >/dev/null || { echo "SKIP: npm is not installed"; exit 77; }
  if ! timeout 15 npm view @foxglove/ws-protocol version >/dev/null 2>&1; then
    echo "SKIP: the npm registry is not reachable and $npm_dir has no cached client packages"
    exit 77
  fi
  mkdir -p "$npm_dir"
  [ -f "$npm_dir/package.json" ] || echo '{"name":"crane-web-test-client","private":true}' > "$npm_dir/package.json"
  (cd "$npm_dir" && timeout 300 npm install --no-audit --no-fund --loglevel=error "${PACKAGES[@]}")
  touch "$stamp"
}

# deploy/crane test installs them before it enters its private network namespace (no registry there).
if [ "${1:-}" = "--install-only" ]; then
  install_clients "$2"
  exit 0
fi
BIN=$(realpath "$1") CONFIG=$(realpath "$2") NPM_DIR=$(realpath -m "$3") OUT=$(realpath -m "$4")  # absolute: the audit runs in a folder of OUT

# 1. The client's packages, outside the namespace (the registry is on the network).
if [ -z "${CRANE_WEB_TEST_IN_NAMESPACE:-}" ]; then
  install_clients "$NPM_DIR"
  # 2. Everything else in a private network namespace when the system allows one.
  if unshare --net true 2>/dev/null; then
    exec unshare --net env CRANE_WEB_TEST_IN_NAMESPACE=1 bash -c \
      'ip link set lo up && ip link set lo multicast on && exec bash "$0" "$@"' "${BASH_SOURCE[0]}" "$@"
  fi
  echo "no private network namespace here: every participant stays on loopback"
fi
export NODE_PATH="$NPM_DIR/node_modules"

rm -rf "$OUT" && mkdir -p "$OUT/logs"
DOMAIN=47
pids=()
cleanup() {
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do kill -TERM "${pids[i]}" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
}
trap cleanup EXIT

"$BIN/crane_launch" --config "$CONFIG" --sim --domain "$DOMAIN" --log-dir "$OUT/logs" > "$OUT/launch.log" 2>&1 &
pids+=($!)
for _ in $(seq 600); do grep -q "all stages matched and alive" "$OUT/launch.log" && break; sleep 0.1; done
grep -q "all stages matched and alive" "$OUT/launch.log" || { echo "stack not ready:"; cat "$OUT/launch.log"; exit 1; }

# An operator for the page's controls (its token printed once; the file holds its hash).
STALLED_CLOSE=3  # [s] of drops before crane_web closes a client that reads nothing (the abuse step's window: 8 s)
TOKEN=$("$BIN/crane_web" --operators "$OUT/operators" --new-operator alice 2>/dev/null)
"$BIN/crane_web" --config "$CONFIG" --port 0 --queue 64 --close-stalled "$STALLED_CLOSE" --domain "$DOMAIN" --operators "$OUT/operators" > "$OUT/web.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do grep -q "ws://" "$OUT/web.log" && break; sleep 0.1; done
URL=$(grep -o "ws://[0-9.]*:[0-9]*" "$OUT/web.log" || true)
[ -n "$URL" ] || { echo "crane_web did not start:"; cat "$OUT/web.log"; exit 1; }
echo "crane_web at $URL"

# The recorder starts first and ends after the client, so every decoded sample has its twin.
"$BIN/crane_topic" record --out "$OUT/run.csv" --mcap "$OUT/run.mcap" --duration 9 --domain "$DOMAIN" > "$OUT/record.log" 2>&1 &
record_pid=$!
pids+=($record_pid)
sleep 1
# A move in the recording (trolley and slew), for the audit below and the page's views later.
"$BIN/crane_move" --domain "$DOMAIN" --trolley 0.9 --slew 60 > "$OUT/move.log" 2>&1 &
pids+=($!)
status=0
node "$HERE/foxglove_client.js" live "$URL" "$OUT/decoded.jsonl" 5 10 | tee "$OUT/live.json" || status=1
wait "$record_pid" || { echo "crane_topic record failed:"; cat "$OUT/record.log"; exit 1; }
node "$HERE/foxglove_client.js" compare "$OUT/decoded.jsonl" "$OUT/run.csv.samples.jsonl" | tee "$OUT/compare.json" || status=1
# The same recording as MCAP (ros2 profile), read by @mcap/core and decoded by Foxglove's ROS 2 reader.
node "$HERE/mcap_check.js" "$OUT/run.mcap" "$OUT/run.csv.samples.jsonl" 9 | tee "$OUT/mcap.json" || status=1
# The audit's CSV from the MCAP file (crane_topic convert, what deploy/crane audit --data run.mcap
# reads) is the CSV the recorder wrote, byte for byte.
"$BIN/crane_topic" convert "$OUT/run.mcap" --out "$OUT/run_from_mcap.csv" || status=1
cmp "$OUT/run.csv" "$OUT/run_from_mcap.csv" && echo "run.csv and the CSV converted from run.mcap are identical" || status=1
# The model audit of the run (the move in it) as deploy/crane audit --data run.mcap does it
# (crane_topic convert to DIR/run.csv, then crane_audit on that CSV), and of the recorder's CSV:
# the same report, byte for byte (each run from its own folder with the same arguments, since the
# report quotes its command line).
mkdir -p "$OUT/audit_of_mcap" "$OUT/audit_of_csv"
"$BIN/crane_topic" convert "$OUT/run.mcap" --out "$OUT/audit_of_mcap/run.csv" > /dev/null || status=1
cp "$OUT/run.csv" "$OUT/audit_of_csv/run.csv"
for dir in audit_of_mcap audit_of_csv; do
  (cd "$OUT/$dir" && "$BIN/crane_audit" --model crane --data run.csv --config "$CONFIG" --out report > audit.log 2>&1) \
    || { echo "crane_audit in $dir failed:"; tail -3 "$OUT/$dir/audit.log"; status=1; }
done
if diff -r "$OUT/audit_of_mcap/report" "$OUT/audit_of_csv/report" > "$OUT/audit_diff.txt"; then
  echo "crane_audit: the report of run.mcap equals the report of run.csv ($(ls "$OUT/audit_of_csv/report" | tr '\n' ' ')):" \
       "$(grep -o -m1 '^\*\*Cause: `[a-z_]*`' "$OUT/audit_of_csv/report/report.md")"
else
  echo "crane_audit: the reports of run.mcap and run.csv differ:"; head -20 "$OUT/audit_diff.txt"; status=1
fi
# Replayed (3x) into another domain, recorded there: every replayed sample is one of the run's.
"$BIN/crane_topic" record --out "$OUT/replay.csv" --duration 2 --timeout 20 --domain $((DOMAIN + 1)) > "$OUT/replay_record.log" 2>&1 &
replay_record=$!
pids+=($replay_record)
"$BIN/crane_topic" replay "$OUT/run.mcap" --rate 3 --domain $((DOMAIN + 1)) || status=1
wait "$replay_record" || { echo "recording the replay failed:"; cat "$OUT/replay_record.log"; status=1; }
node "$HERE/foxglove_client.js" compare "$OUT/replay.csv.samples.jsonl" "$OUT/run.csv.samples.jsonl" > "$OUT/replay_compare.json" \
  || { cat "$OUT/replay_compare.json"; status=1; }
echo "replay: $(grep -c hw/sensors "$OUT/replay.csv.samples.jsonl") sensor samples recorded from the replay, all equal to the run's"
rate=$(node -e 'console.log(JSON.parse(require("fs").readFileSync(process.argv[1])).sensor_rate_hz)' "$OUT/live.json")
echo "[ figure ] rt/crane/hw/sensors through crane_web: $rate Hz over 5 s (required 100 +- 5)"
node -e 'const r=+process.argv[1]; process.exit(r >= 95 && r <= 105 ? 0 : 1)' "$rate" || { echo "rate $rate Hz outside 100 +- 5"; status=1; }
# Bad input and /metrics, while the stack runs (crane_web's queue small, so the stalled client's
# drops come within seconds, and it is closed --close-stalled seconds later).
node "$HERE/foxglove_client.js" abuse "$URL" 8 "$STALLED_CLOSE" | tee "$OUT/abuse.json" || status=1
# The operator page in Debian's chromium (headless, puppeteer-core), the crane where the move took it; its
# no-go zone (the configuration's) drawn off, then enforced once crane_safety switches it on.
if [ -x /usr/bin/chromium ]; then
  node "$HERE/page_check.js" "$URL" "$OUT/operator_page.png" "$BIN/crane_safety" --domain "$DOMAIN" zone \
    | tee "$OUT/page.json" || status=1
  # The controls: read-only without a login, refused to foreign clients, "move to" for the operator.
  node "$HERE/operator_check.js" "$URL" "$TOKEN" "$OUT/operator_controls.png" | tee "$OUT/operator.json" || status=1
  grep -q "operator alice published rt/crane/planner/goal" "$OUT/web.log" \
    || { echo "crane_web did not log the operator's goal"; status=1; }
elif [ $status -eq 0 ]; then
  # Everything else passed; the browser checks were not done: skipped (ctest shows it), not passed.
  echo "SKIP: the operator page and its controls not checked: no /usr/bin/chromium (Debian: chromium)"
  exit 77
fi
exit $status
