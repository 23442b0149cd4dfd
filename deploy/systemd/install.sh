#!/usr/bin/env bash
# Installs the crane stack as systemd services: binaries to /opt/crane/bin, configuration and
# environment to /etc/crane, units to /etc/systemd/system. Run as root after deploy/crane build.
# --iceoryx: every unit's samples through iceoryx shared memory (Cyclone DDS; crane-roudi.service);
# without it, any such drop-in of an earlier install is removed.
# Usage: deploy/systemd/install.sh [--iceoryx] [BUILD_DIR]
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
ICEORYX=0
if [ "${1:-}" = --iceoryx ]; then ICEORYX=1; shift; fi
BUILD=${1:-"$ROOT/build"}
if [ $ICEORYX -eq 1 ] && ! command -v iox-roudi > /dev/null; then
  echo "install.sh --iceoryx: iox-roudi is not on PATH (Debian package iceoryx)" >&2
  exit 1
fi
install -d /opt/crane/bin /etc/crane
for exe in supervisor state_estimator trajectory_planner anti_swing tracking friction_compensation hardware_bridge \
           plant operator_relay crane_operator crane_safety crane_move crane_jog crane_topic; do
  install -m 0755 "$BUILD/bin/$exe" /opt/crane/bin/
done
[ -f /etc/crane/lab_tower_crane.yaml ] || install -m 0644 "$ROOT/deploy/config/lab_tower_crane.yaml" /etc/crane/
[ -f /etc/crane/crane.env ] || install -m 0644 "$ROOT/deploy/systemd/crane.env" /etc/crane/
install -m 0644 "$ROOT"/deploy/systemd/*.service "$ROOT/deploy/systemd/crane.target" /etc/systemd/system/
for unit in "$ROOT"/deploy/systemd/crane-*.service; do
  name=$(basename "$unit")
  [ "$name" = crane-roudi.service ] && continue
  if [ $ICEORYX -eq 1 ]; then
    install -d "/etc/systemd/system/$name.d"
    install -m 0644 "$ROOT/deploy/systemd/iceoryx.conf" "/etc/systemd/system/$name.d/iceoryx.conf"
  else
    rm -f "/etc/systemd/system/$name.d/iceoryx.conf"
  fi
done
if [ $ICEORYX -eq 1 ] && ! grep -q '^CRANE_DDS=cyclone$' /etc/crane/crane.env; then
  echo "note: --iceoryx needs CRANE_DDS=cyclone in /etc/crane/crane.env (each process refuses Fast DDS on iceoryx)"
fi
systemctl daemon-reload
echo "installed; edit /etc/crane/crane.env and /etc/crane/lab_tower_crane.yaml (arm_on_start: false on a real"
echo "crane), then: systemctl enable --now crane.target; /opt/crane/bin/crane_operator status"
