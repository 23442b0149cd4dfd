#!/usr/bin/env bash
# The table of docs/integration.md ("The DDS lockstep on shared memory"): the DDS lockstep's speed
# and its hops with Cyclone DDS on loopback UDP and on iceoryx shared memory (--iceoryx), on iceoryx
# with the bench reading the sensor clock alone (--sensors-only: the stack's speed without the
# bench's five per-hop readers), and Fast DDS on loopback UDP, the settings alternating
# (deploy/bench_transport.sh). A benchmark: run it on an idle machine.
# Usage: deploy/bench_shm.sh [RUNS] [DURATION_S] [OUT_DIR]
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
exec "$ROOT/deploy/bench_transport.sh" "${1:-3}" "${2:-10}" "${3:-bench-shm-out}" \
  'Cyclone DDS, loopback UDP=--dds cyclone' 'Cyclone DDS, iceoryx=--dds cyclone --iceoryx' \
  'Cyclone DDS, iceoryx, the bench on the sensors alone=--dds cyclone --iceoryx --sensors-only' \
  'Fast DDS, loopback UDP=--dds fast'
