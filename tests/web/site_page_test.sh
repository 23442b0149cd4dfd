#!/usr/bin/env bash
# crane_web's site page (issue 34, item 5; docs/site.md, "Watching the site"): the site service,
# three cranes' reports (site_reports_writer: at rest, one asking for a leg) and crane_web --site in
# one private network namespace; tests/web/site_page_check.js checks the view against
# crane_site_status and its own bound, then the page in Debian's chromium.
#
#   site_page_test.sh BIN_DIR SITE CONFIG NPM_DIR OUT_DIR
#
# The npm packages are foxglove_client_test.sh's (installed there; exit 77 when they cannot be);
# exit 77 too without /usr/bin/chromium.
set -euo pipefail
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
BIN=$(realpath "$1") SITE=$(realpath "$2") CONFIG=$(realpath "$3") NPM_DIR=$(realpath -m "$4") OUT=$(realpath -m "$5")
if [ -z "${CRANE_SITE_PAGE_IN_NAMESPACE:-}" ]; then
  bash "$HERE/foxglove_client_test.sh" --install-only "$NPM_DIR"
  if unshare --net true 2>/dev/null; then
    exec unshare --net env CRANE_SITE_PAGE_IN_NAMESPACE=1 bash -c \
      'ip link set lo up && ip link set lo multicast on && exec bash "$0" "$@"' "${BASH_SOURCE[0]}" "$@"
  fi
  echo "no private network namespace here: every participant stays on loopback"
fi
[ -x /usr/bin/chromium ] || { echo "SKIP: no /usr/bin/chromium"; exit 77; }
export NODE_PATH="$NPM_DIR/node_modules"

rm -rf "$OUT" && mkdir -p "$OUT"
pids=()
cleanup() {
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do kill -TERM "${pids[i]}" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
}
trap cleanup EXIT

"$BIN/site_service" --site "$SITE" > "$OUT/service.log" 2>&1 &
pids+=($!)
# tc1 away from the others, asking for a leg over the middle; tc2 and tc3 at rest toward it.
"$BIN/site_reports_writer" --site "$SITE" --seconds 120 \
  --at tc1:3.1:0.5:0.2 --at tc2:0.3:0.7:0.3 --at tc3:0.0:0.6:0.2 --ask tc1:-0.5:0.9:1.0 > "$OUT/writer.log" 2>&1 &
pids+=($!)
"$BIN/crane_web" --config "$CONFIG" --site "$SITE" --port 0 > "$OUT/web.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do grep -q "ws://" "$OUT/web.log" && break; sleep 0.1; done
URL=$(grep -o "ws://[0-9.]*:[0-9]*" "$OUT/web.log" || true)
[ -n "$URL" ] || { echo "crane_web did not start:"; cat "$OUT/web.log"; exit 1; }
echo "crane_web at $URL"
node "$HERE/site_page_check.js" "$URL" "$OUT/site_page.png" "$BIN/crane_site_status" "$SITE"
