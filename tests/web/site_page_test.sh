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
  --at tc1:3.1:0.5:0.2 --at tc2:0.3:0.7:0.3 --at tc3:0.0:0.6:0.2 --ask tc1:-0.5:0.9:1.0 --work tc1:123.4 --work tc3:56.7 > "$OUT/writer.log" 2>&1 &
pids+=($!)
"$BIN/crane_web" --config "$CONFIG" --site "$SITE" --port 0 > "$OUT/web.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do grep -q "ws://" "$OUT/web.log" && break; sleep 0.1; done
URL=$(grep -o "ws://[0-9.]*:[0-9]*" "$OUT/web.log" || true)
[ -n "$URL" ] || { echo "crane_web did not start:"; cat "$OUT/web.log"; exit 1; }
echo "crane_web at $URL"
node "$HERE/site_page_check.js" "$URL" "$OUT/site_page.png" "$BIN/crane_site_status" "$SITE"

# The site operator's word (docs/site.md, "The site service on DDS"): the cranes fall silent (the
# writer stops), the service holds each one's whole reach; crane_site_status --out-of-service tc3
# puts tc3 out of service, and the view shows it holding where it stood: its held outline within
# its jib's reach of its mast, while the others' whole reach goes further.
kill -TERM "${pids[1]}" 2>/dev/null || true
wait "${pids[1]}" 2>/dev/null || true
sleep 1
"$BIN/crane_site_status" --site "$SITE" --wait 15 --out-of-service tc3 > "$OUT/out_of_service.txt" 2>&1 ||
  { echo "FAILED: crane_site_status --out-of-service tc3:"; cat "$OUT/out_of_service.txt"; exit 1; }
/usr/bin/python3 - "${URL/ws:/http:}" <<'PY'
import json, math, sys, time, urllib.request
url = sys.argv[1] + "/site/view.json"
for _ in range(50):
    view = json.load(urllib.request.urlopen(url, timeout=5))
    cranes = {c["name"]: c for c in view["cranes"]}
    if cranes["tc3"]["holding"] == "out_of_service":
        break
    time.sleep(0.1)
def extent(c):  # the held outline's farthest point from the crane's mast [m]
    return max(math.hypot(x - c["base"][0], y - c["base"][1]) for polygon in c["held"] for x, y in polygon)
problems = []
if cranes["tc3"]["holding"] != "out_of_service": problems.append("tc3 holds %s, not out_of_service" % cranes["tc3"]["holding"])
for name in ("tc1", "tc2"):
    if cranes[name]["holding"] != "whole_reach": problems.append("%s holds %s, not whole_reach" % (name, cranes[name]["holding"]))
if not cranes["tc3"]["held"]: problems.append("tc3's held airspace is not drawn")
else:
    out, whole = extent(cranes["tc3"]), extent(cranes["tc1"])
    print("[ figure ] site page: tc3 out of service holds %d box(es) reaching %.3f m from its mast; tc1's whole reach %.3f m"
          % (len(cranes["tc3"]["held"]), out, whole))
    if not out <= cranes["tc3"]["reach"] + 0.2 < whole: problems.append("tc3 held %.3f m, tc1's whole reach %.3f m" % (out, whole))
for p in problems: print("FAILED: " + p)
sys.exit(1 if problems else 0)
PY
/usr/bin/chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --window-size=1400,800 \
  --virtual-time-budget=3000 --screenshot="$OUT/site_page_out_of_service.png" "${URL/ws:/http:}/site.html" \
  > "$OUT/chromium_out_of_service.log" 2>&1 || echo "(no screenshot of the out-of-service page: see $OUT/chromium_out_of_service.log)"
