#!/usr/bin/env bash
# A site of several cranes, each crane on its own host (issue 34, item 2; docs/site.md, "The site
# on its own hosts"). On this machine a host is a network namespace with its own /dev/shm (so that
# no DDS shared memory crosses between hosts), joined to the others by a veth pair through a
# bridge: the site's network, 10.78.0.0/24. The bridge lives in a namespace of this script's own
# (the site office, 10.78.0.1); the site service's host is 10.78.0.2, the cranes' 10.78.0.11, .12,
# ... in the site file's order. Every namespace vanishes with this script; nothing is sent anywhere
# else. On real hosts the same processes run from the systemd units (deploy/systemd).
#
# Each crane's host runs the crane's whole stack (crane_launch: the simulated plant in real time,
# its supervisor enforcing its grant with --site) and its site link (crane_launch --site-jobs), on
# its own DDS domain for the stack (on the host's loopback) and the site's domain for rt/site/* (on
# the site's network: crane_launch --site-lan); the site service's host runs
# site_service. The office runs crane_site_status for the whole run: what the service holds and the
# distance between the cranes from their reports (status.txt, status.json); and crane_web --site,
# the Foxglove WebSocket view of the site's topics (ws://10.78.0.1:8765 from the office).
#
# Usage: site_hosts.sh BIN SITE OUT [--jobs J] [--seed S] [--dds fast|cyclone] [--until-done SECONDS]
#                      [--security DIR] [--fault SPEC ...]
#   BIN   the build's bin folder; SITE the site file; OUT a folder for the logs and figures
#   --security DIR  DDS Security on every domain (deploy/crane security init's material: each process
#                   its own identity, the office's tools the monitor's); without it the site's
#                   network runs --insecure-lan
#   --jobs/--seed   the job set (crane_site jobs: the set `crane_site demo --sets 1 --seed S` runs)
#   --until-done S  stop when every crane has done its jobs (exit 0 when every job is done, no crane
#                   braked and the closest distance keeps the site's stop margin), or after S seconds
#                   (exit 1); without it the site runs until SIGINT/SIGTERM (deploy/crane site start|stop)
#   --fault SPEC    a fault between hosts, at START seconds after every crane is ready, for DURATION s
#                   (whole seconds):
#                     partition:HOST:START:DURATION   the host's link to the bridge down
#                     loss:HOST:PERCENT:START:DURATION  that share of the packets to and from the host
#                                                     dropped (tc netem, else nftables)
#                     delay:HOST:MS:START:DURATION    packets to and from the host delayed MS ms each
#                                                     way (tc netem, else an iptables NFQUEUE rule on
#                                                     the bridge and crane_packet_delay holding them)
#                     kill-service:START:DURATION     the site service killed with -9, started again
#                                                     DURATION s later (a new epoch)
#                     stop-host:CRANE:START           the crane's host stopped for good: every process
#                                                     on it killed with -9 and its link down (a power
#                                                     cut); the others then keep out of its whole reach
#                     out-of-service:CRANE:START      not a fault: the site operator's word that the
#                                                     stopped CRANE stands braked (crane_site_status
#                                                     --out-of-service from the office, the operator's
#                                                     identity); the service then holds where it stood
#                                                     instead of its whole reach; the run fails when
#                                                     the service does not take it within 45 s (a
#                                                     partition of 30 s and a restart of 10 s may
#                                                     keep the word from the service)
#                   HOST is a crane's name or "site" (the service's host). With a host stopped, the
#                   run ends once the faults are over and every other crane has done its jobs or has
#                   waited at rest for 15 s (for the stopped crane's reach); it is safe when no crane
#                   was braked and the closest distance keeps the stop margin.
# Exit status: 0 done and safe, 1 not (the reason printed), 2 bad usage or no namespaces here.
set -euo pipefail

usage() { sed -n '17,51p' "$0" >&2; exit 2; }
[ $# -ge 3 ] || usage
BIN=$(cd "$1" && pwd) SITE=$(realpath "$2") OUT=$3
shift 3
JOBS=1 SEED=1 DDS=cyclone UNTIL=0 FAULTS=() SECURITY=
while [ $# -gt 0 ]; do
  case $1 in
    --jobs) JOBS=$2; shift 2 ;;
    --seed) SEED=$2; shift 2 ;;
    --dds) DDS=$2; shift 2 ;;
    --until-done) UNTIL=$2; shift 2 ;;
    --security) SECURITY=$(realpath "$2"); shift 2 ;;
    --fault) FAULTS+=("$2"); shift 2 ;;
    *) echo "site_hosts.sh: unknown option $1" >&2; usage ;;
  esac
done
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)

# This script in a network namespace of its own: the site office, where the bridge is.
if [ "${CRANE_SITE_NETNS:-}" != 1 ]; then
  unshare --net true 2>/dev/null || { echo "site_hosts.sh: cannot make network namespaces here (unshare --net)" >&2; exit 2; }
  exec unshare --net env CRANE_SITE_NETNS=1 "$0" "$BIN" "$SITE" "$OUT" --jobs "$JOBS" --seed "$SEED" --dds "$DDS" \
    --until-done "$UNTIL" ${SECURITY:+--security "$SECURITY"} ${FAULTS[@]+$(printf -- '--fault %s ' "${FAULTS[@]}")}
fi

declare -A HOLDER ADDRESS PIDS DELAYERS WORDS  # DELAYERS: crane_packet_delay of a delay fault; WORDS: the
                                               # operator's crane_site_status --out-of-service
NAMES=()
MONITOR=
cleanup() {
  [ -n "$MONITOR" ] && kill -INT "$MONITOR" 2>/dev/null && wait "$MONITOR" 2>/dev/null
  local pid
  for pid in "${PIDS[@]}"; do kill -INT "$pid" 2>/dev/null || true; done
  for pid in "${PIDS[@]}"; do wait "$pid" 2>/dev/null || true; done
  for pid in "${DELAYERS[@]}"; do kill -TERM "$pid" 2>/dev/null; wait "$pid" 2>/dev/null || true; done
  for pid in "${WORDS[@]}"; do kill -TERM "$pid" 2>/dev/null || true; wait "$pid" 2>/dev/null || true; done
  for pid in "${HOLDER[@]}"; do kill "$pid" 2>/dev/null || true; done
}
trap cleanup EXIT
trap 'exit 130' INT TERM

ip link set lo up
ip link add site0 type bridge
ip link set site0 type bridge mcast_snooping 0
ip addr add 10.78.0.1/24 dev site0
ip link set site0 up multicast on
ip route add 224.0.0.0/4 dev site0

# A host: a network and mount namespace held by a sleeping process, /dev/shm its own, eth0 on the
# bridge at 10.78.0.$2.
make_host() {
  local name=$1 address=10.78.0.$2
  rm -f "$OUT/.ready_$name"
  unshare --net --mount --propagation private sh -c "mount -t tmpfs tmpfs /dev/shm && touch '$OUT/.ready_$name' && exec sleep 1000000" &
  HOLDER[$name]=$!
  for _ in $(seq 50); do [ -e "$OUT/.ready_$name" ] && break; sleep 0.1; done
  [ -e "$OUT/.ready_$name" ] || { echo "site_hosts.sh: host $name did not start" >&2; exit 1; }
  rm -f "$OUT/.ready_$name"
  ip link add "v-$name" type veth peer name eth0 netns "${HOLDER[$name]}"
  ip link set "v-$name" master site0 up
  on "$name" ip link set lo up multicast on
  on "$name" ip addr add "$address/24" dev eth0
  on "$name" ip link set eth0 up multicast on
  on "$name" ip route add 224.0.0.0/4 dev eth0
  ADDRESS[$name]=$address
}
on() { local name=$1; shift; nsenter -t "${HOLDER[$name]}" -n -m -- "$@"; }
# In the background, appending to LOG: a simple command, so $! is nsenter's pid, and nsenter execs
# the program (no fork for these namespaces): a signal to $! reaches the program itself.
spawn() { local name=$1 log=$2; shift 2; nsenter -t "${HOLDER[$name]}" -n -m -- "$@" >> "$log" 2>&1 & }

NET=(--lan --insecure-lan --dds "$DDS")
[ -n "$SECURITY" ] && NET=(--lan --security "$SECURITY" --dds "$DDS")
# A crane's stack keeps its own domain on its host's loopback; only its supervisor's guard and its
# site link are on the site's network (--site-lan). With --lan the stack's 100 Hz traffic went out
# on the bridge to every host: about 2200 packets a second from each crane's host.
CRANE_NET=(--site-lan --insecure-lan --dds "$DDS")
[ -n "$SECURITY" ] && CRANE_NET=(--site-lan --security "$SECURITY" --dds "$DDS")
# The cranes' slew at most 0.7 rad/s, two thirds of the lab crane's rated 1.05: several whole stacks
# in real time on one small machine miss cycles, and a long slew at the rated rate then overshot the
# supervisor's overspeed limit (slew_overspeed, 2 of 6 runs on this 2-core machine under other load).
SLEW_SPEED=0.7  # the site's network without DDS Security (docs/site.md says why)
rm -f "$OUT/site_service.log" "$OUT/faults.log" "$OUT/out_of_service.txt"
"$BIN/crane_site" jobs --site "$SITE" --jobs "$JOBS" --seed "$SEED" --out "$OUT/jobs" > "$OUT/jobs.log"

# The office's watchers first, so that they hear every instruction (rt/site/instruction keeps no
# history for late joiners).
"$BIN/crane_site_status" --site "$SITE" "${NET[@]}" --wait 86400 --json "$OUT/status.json" > "$OUT/status.txt" 2>&1 &
MONITOR=$!
# The Foxglove view of the site from the office (crane_web --site: the site's topics, every crane's
# reports among them), on the site's network; its /metrics count what it forwarded.
first_config=$(awk 'NR == 1 { print $3 }' "$OUT/jobs/hosts.txt")
"$BIN/crane_web" --config "$first_config" --site "$SITE" "${NET[@]}" --domain 0 --bind 10.78.0.1 --port 8765 \
  > "$OUT/crane_web.log" 2>&1 &
PIDS[crane_web]=$!
make_host site 2
rm -f "$OUT/site_service_memory.json" "$OUT/site_service_memory.json.bad"  # a new site run: no memory of an old one
start_service() {  # its memory file (where each crane stood) outlives a kill-service fault
  spawn site "$OUT/site_service.log" "$BIN/site_service" --site "$SITE" "${NET[@]}" --memory "$OUT/site_service_memory.json"
  PIDS[site_service]=$!
}
start_service
index=11
while read -r name domain config slew trolley; do
  NAMES+=("$name")
  make_host "$name" "$index"
  index=$((index + 1))
  rm -rf "$OUT/$name" "$OUT/$name.json"  # a run dir used before: its logs start afresh
  mkdir -p "$OUT/$name"
  spawn "$name" "$OUT/$name/launch.log" "$BIN/crane_launch" --config "$config" --domain "$domain" "${CRANE_NET[@]}" \
    --initial-slew "$slew" --initial-trolley "$trolley" --site "$SITE" --site-crane "$name" \
    --site-jobs "$OUT/jobs/$name.csv" --site-summary "$OUT/$name.json" --site-slew-speed "$SLEW_SPEED" \
    --log-dir "$OUT/$name"
  PIDS[$name]=$!
done < "$OUT/jobs/hosts.txt"
echo "site: service on 10.78.0.2, cranes ${NAMES[*]} on 10.78.0.11-$((index - 1)); logs in $OUT"

ms() { echo $(($(date +%s%N) / 1000000)); }
# Every crane ready: its launcher reports its stages matched and alive.
t0=$(ms)
for name in "${NAMES[@]}"; do
  until grep -q "all stages matched and alive" "$OUT/$name/launch.log" 2>/dev/null; do
    kill -0 "${PIDS[$name]}" 2>/dev/null || { echo "site_hosts.sh: $name's stack stopped before it was ready (see $OUT/$name)"; exit 1; }
    sleep 0.2
  done
done
ready=$(ms)
echo "every crane ready after $(awk -v ms=$((ready - t0)) 'BEGIN { printf "%.1f", ms / 1000 }') s"

elapsed_ms() { echo $(($(ms) - ready)); }
later() { [ "$(elapsed_ms)" -ge "$(($1 * 1000))" ]; }  # $1 whole seconds after ready
# The faults: each applied at its start and undone at its end (state kept in FAULT_STATE).
declare -A FAULT_STATE
apply_fault() {  # index, spec, phase (on|off)
  local i=$1 phase=$3 kind host value start duration
  IFS=: read -r kind host value start duration <<< "$2"
  case $kind in
    partition)
      duration=$start start=$value
      if [ "$phase" = on ]; then ip link set "v-$host" down; else ip link set "v-$host" up; fi ;;
    loss | delay)
      if [ "$phase" = on ]; then
        local arg=$([ "$kind" = loss ] && echo "loss $value%" || echo "delay ${value}ms")
        if tc qdisc replace dev "v-$host" root netem $arg 2>/dev/null && on "$host" tc qdisc replace dev eth0 root netem $arg 2>/dev/null; then
          FAULT_STATE[$i]=netem
        elif [ "$kind" = loss ]; then
          nft add table inet crane_fault_$i
          nft add chain inet crane_fault_$i drop_in "{ type filter hook forward priority 0; }"
          nft add rule inet crane_fault_$i drop_in iifname "v-$host" numgen random mod 100 "<" "$value" drop
          nft add rule inet crane_fault_$i drop_in oifname "v-$host" numgen random mod 100 "<" "$value" drop
          FAULT_STATE[$i]=nft
        else
          # The bridge hands its IPv4 packets to the forward hook (bridge-nf-call-iptables); queue
          # 100+i holds those to and from the host (--queue-bypass: they pass if the holder is gone).
          command -v iptables >/dev/null || { echo "site_hosts.sh: fault $2: no tc netem and no iptables here" >&2; exit 2; }
          sysctl -q net.bridge.bridge-nf-call-iptables=1
          "$BIN/crane_packet_delay" --queue $((100 + i)) --delay-ms "$value" >> "$OUT/packet_delay_$i.log" 2>&1 &
          DELAYERS[$i]=$!
          sleep 0.2
          kill -0 "${DELAYERS[$i]}" 2>/dev/null || { echo "site_hosts.sh: fault $2: crane_packet_delay failed (see $OUT/packet_delay_$i.log)" >&2; exit 1; }
          for dir in in out; do
            iptables -I FORWARD -m physdev --physdev-$dir "v-$host" -j NFQUEUE --queue-num $((100 + i)) --queue-bypass
          done
          FAULT_STATE[$i]=nfqueue
        fi
      elif [ "${FAULT_STATE[$i]:-}" = netem ]; then
        tc qdisc del dev "v-$host" root 2>/dev/null || true
        on "$host" tc qdisc del dev eth0 root 2>/dev/null || true
      elif [ "${FAULT_STATE[$i]:-}" = nfqueue ]; then
        for dir in in out; do
          iptables -D FORWARD -m physdev --physdev-$dir "v-$host" -j NFQUEUE --queue-num $((100 + i)) --queue-bypass || true
        done
        kill -TERM "${DELAYERS[$i]}" 2>/dev/null || true
        wait "${DELAYERS[$i]}" 2>/dev/null || true
        unset "DELAYERS[$i]"
      else
        nft delete table inet crane_fault_$i 2>/dev/null || true
      fi ;;
    stop-host)
      if [ "$phase" = on ]; then
        local net victim
        [ -n "${HOLDER[$host]:-}" ] || { echo "site_hosts.sh: fault $2: no host $host" >&2; exit 2; }
        net=$(readlink "/proc/${HOLDER[$host]}/ns/net")
        [ -n "$net" ] || { echo "site_hosts.sh: fault $2: host $host has no network namespace" >&2; exit 2; }
        STOPPED[$host]=1
        for victim in /proc/[0-9]*; do
          victim=${victim#/proc/}
          [ "$victim" = "${HOLDER[$host]}" ] && continue
          [ "$(readlink "/proc/$victim/ns/net" 2>/dev/null)" = "$net" ] && kill -9 "$victim" 2>/dev/null || true
        done
        ip link set "v-$host" down
        wait "${PIDS[$host]}" 2>/dev/null || true
      fi ;;
    out-of-service)  # in the background for up to 45 s: the other faults keep their times
      if [ "$phase" = on ]; then
        "$BIN/crane_site_status" --site "$SITE" "${NET[@]}" --out-of-service "$host" --wait 45 \
          > "$OUT/out_of_service_$host.txt" 2>&1 &
        WORDS[$i]=$!
      else
        local rc=0
        wait "${WORDS[$i]}" || rc=$?
        unset "WORDS[$i]"
        echo "$host $rc" >> "$OUT/out_of_service.txt"
      fi ;;
    kill-service)
      duration=$value start=$host
      if [ "$phase" = on ]; then
        kill -9 "${PIDS[site_service]}" 2>/dev/null || true
        wait "${PIDS[site_service]}" 2>/dev/null || true
      else
        start_service
      fi ;;
    *) echo "site_hosts.sh: unknown fault $2" >&2; exit 2 ;;
  esac
  echo "$(awk -v ms="$(elapsed_ms)" 'BEGIN { printf "%.1f", ms / 1000 }') s: fault $2 $phase" | tee -a "$OUT/faults.log"
}
fault_times() {  # the spec's start and end, in whole seconds after ready
  local kind a b c d
  IFS=: read -r kind a b c d <<< "$1"
  case $kind in
    partition) echo "$b $((b + c))" ;;
    kill-service) echo "$a $((a + b))" ;;
    stop-host) echo "$b $b" ;;
    out-of-service) echo "$b $((b + 46))" ;;  # crane_site_status --wait 45, and its ending (or sooner: the word taken)
    *) echo "$c $((c + d))" ;;
  esac
}
declare -A FAULT_DONE=() STOPPED=()
# Every crane whose host runs has done its jobs; with a host stopped, or waits at rest ("asking").
all_done() {
  local name waiting_ok=0
  [ ${#STOPPED[@]} -gt 0 ] && waiting_ok=1
  for name in "${NAMES[@]}"; do
    [ -n "${STOPPED[$name]:-}" ] && continue
    [ -e "$OUT/$name.json" ] || return 1
    /usr/bin/python3 -c 'import json,sys; j=json.load(open(sys.argv[1]))
sys.exit(0 if j["jobs_done"] == j["jobs"] or (sys.argv[2] == "1" and j["phase"] in ("asking", "done")) else 1)' \
      "$OUT/$name.json" "$waiting_ok" || return 1
  done
}
settled_since=  # [ms] since when all_done has held (with a host stopped: 15 s of it ends the run)
while :; do
  for name in "${!PIDS[@]}"; do
    kill -0 "${PIDS[$name]}" 2>/dev/null && continue
    [ "$name" = site_service ] && [ "${FAULT_DONE[service_down]:-}" = 1 ] && continue
    [ -n "${STOPPED[$name]:-}" ] && continue
    echo "site_hosts.sh: $name stopped (see $OUT)"; exit 1
  done
  for i in "${!FAULTS[@]}"; do
    read -r from to <<< "$(fault_times "${FAULTS[$i]}")"
    if [ -z "${FAULT_DONE[$i]:-}" ] && later "$from"; then
      FAULT_DONE[$i]=on
      [[ ${FAULTS[$i]} == kill-service:* ]] && FAULT_DONE[service_down]=1
      apply_fault "$i" "${FAULTS[$i]}" on
    elif [ "${FAULT_DONE[$i]:-}" = on ] && { later "$to" ||
           { [[ ${FAULTS[$i]} == out-of-service:* ]] && ! kill -0 "${WORDS[$i]}" 2>/dev/null; }; }; then
      FAULT_DONE[$i]=off
      apply_fault "$i" "${FAULTS[$i]}" off
      [[ ${FAULTS[$i]} == kill-service:* ]] && FAULT_DONE[service_down]=0
    fi
  done
  if [ "$UNTIL" != 0 ]; then
    faults_over=1
    for i in "${!FAULTS[@]}"; do [ "${FAULT_DONE[$i]:-}" = off ] || faults_over=0; done
    if [ "$faults_over" = 1 ] && all_done; then
      [ ${#STOPPED[@]} -eq 0 ] && break
      settled_since=${settled_since:-$(elapsed_ms)}
      [ $(($(elapsed_ms) - settled_since)) -ge 15000 ] && break
    else
      settled_since=
    fi
    if later "$UNTIL"; then echo "site_hosts.sh: not every job done within $UNTIL s"; break; fi
  fi
  sleep 0.2
done
run_time=$(elapsed_ms)
/usr/bin/python3 -c 'import sys, urllib.request; sys.stdout.write(urllib.request.urlopen("http://10.78.0.1:8765/metrics", timeout=5).read().decode())' \
  > "$OUT/crane_web_metrics.txt" 2>&1 || true
kill -INT "$MONITOR" 2>/dev/null && wait "$MONITOR" 2>/dev/null || true
MONITOR=
cat "$OUT/status.txt"
/usr/bin/python3 - "$OUT" "$SITE" "$run_time" "${!STOPPED[*]}" "${NAMES[@]}" <<'PY'
import json, re, sys
out, site, run_time, stopped, names = sys.argv[1], sys.argv[2], float(sys.argv[3]) / 1000.0, sys.argv[4].split(), sys.argv[5:]
stop = float(re.search(r"^\s*stop:\s*([0-9.]+)", open(site).read(), re.M).group(1))
problems = []
put_out = {}  # the site operator's words (out-of-service:CRANE:START): crane -> crane_site_status's exit
try:
    for line in open(out + "/out_of_service.txt"):
        crane, rc = line.split()
        put_out[crane] = int(rc)
        if int(rc) != 0: problems.append("the site service did not put %s out of service (exit %s)" % (crane, rc))
except OSError:
    pass
print("crane  jobs  finish_s  waiting_s  yields  halts  aborted  phase")
for name in names:
    try:
        s = json.load(open(out + "/" + name + ".json"))
    except (OSError, ValueError):
        problems.append(name + ": no summary"); continue
    print("%-6s %d/%d %9.1f %10.1f %7d %6d %8d  %s" % (name, s["jobs_done"], s["jobs"], s["finish_time_s"], s["waiting_time_s"],
                                                     s["yields"], s["halts"], s.get("aborted_moves", 0), s["phase"]))
    if name in stopped:
        print("       its host was stopped (every process killed with -9)")
        if name in put_out:
            print("       put out of service by the site operator" if put_out[name] == 0 else
                  "       NOT put out of service (crane_site_status exit %d: see out_of_service_%s.txt)" % (put_out[name], name))
        continue
    if s["jobs_done"] != s["jobs"] and not (stopped and s["phase"] in ("asking", "done")):
        problems.append("%s did %d of %d jobs" % (name, s["jobs_done"], s["jobs"]))
    elif s["jobs_done"] != s["jobs"]:
        print("       waits at rest (for what the stopped crane holds: its whole reach, or where it stood once out of service)")
    if s["phase"] == "braked": problems.append(name + " was braked")
    if s["reactions_s"]:
        print("       link losses: reactions [ms] " + " ".join("%.0f" % (1e3 * r) for r in s["reactions_s"]))
try:
    status = json.load(open(out + "/status.json"))
    d = status.get("min_distance_m")
    print("[ figure   ] site on %d hosts: run %.1f s after ready, closest reported distance %s (stop margin %.3f m)"
          % (len(names) + 1, run_time, "%.3f m, %s" % (d, status["closest"]) if d is not None else "none", stop))
    if d is None or d < stop: problems.append("closest distance %s below the stop margin %.3f m" % (d, stop))
    for r in status.get("closest_reports", []):
        print("       then %s %s: slew %.3f rad/s, trolley %.3f m/s, swing %.3f rad (envelope %.3f m)" % (
            r["crane"], "moving" if r["moving"] else "at rest", r["slew_rate_rad_s"], r["trolley_velocity_m_s"], r["swing_rad"],
            r["swing_envelope_m"]))
    if "closest_reports_apart_s" in status:
        print("       the older of the two reports heard %.3f s before" % status["closest_reports_apart_s"])
except (OSError, ValueError):
    problems.append("no status from the site office")
# The Foxglove view (crane_web --site in the office) forwarded the site's topics.
try:
    metrics = open(out + "/crane_web_metrics.txt").read()
except OSError:
    metrics = ""
forwarded = {t: int(float(n)) for t, n in re.findall(r'crane_topic_samples_received_total\{topic="(rt/site/[a-z]+)"\} ([0-9.e+]+)', metrics)}
print("[ figure   ] the office's Foxglove server (crane_web --site) forwarded " +
      ", ".join("%s %d" % (t, n) for t, n in sorted(forwarded.items())))
for topic in ("rt/site/report", "rt/site/status", "rt/site/instruction"):
    if forwarded.get(topic, 0) == 0: problems.append("crane_web forwarded no sample of " + topic)
for p in problems: print("FAILED: " + p)
sys.exit(1 if problems else 0)
PY
