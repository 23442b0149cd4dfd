#!/usr/bin/env bash
# Installs the crane stack as systemd services: binaries to /opt/crane/bin, configuration and
# environment to /etc/crane, units to /etc/systemd/system. Run as root after deploy/crane build.
# Usage: deploy/systemd/install.sh [BUILD_DIR]
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
BUILD=${1:-"$ROOT/build"}
install -d /opt/crane/bin /etc/crane
for exe in supervisor state_estimator trajectory_planner anti_swing tracking friction_compensation hardware_bridge \
           plant operator_relay crane_operator crane_safety crane_move crane_jog crane_topic; do
  install -m 0755 "$BUILD/bin/$exe" /opt/crane/bin/
done
[ -f /etc/crane/lab_tower_crane.yaml ] || install -m 0644 "$ROOT/deploy/config/lab_tower_crane.yaml" /etc/crane/
[ -f /etc/crane/crane.env ] || install -m 0644 "$ROOT/deploy/systemd/crane.env" /etc/crane/
install -m 0644 "$ROOT"/deploy/systemd/*.service "$ROOT/deploy/systemd/crane.target" /etc/systemd/system/
systemctl daemon-reload
echo "installed; edit /etc/crane/crane.env and /etc/crane/lab_tower_crane.yaml (arm_on_start: false on a real"
echo "crane), then: systemctl enable --now crane.target; /opt/crane/bin/crane_operator status"
