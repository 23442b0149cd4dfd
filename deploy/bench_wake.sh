#!/usr/bin/env bash
# The table of docs/integration.md ("One wake-up per hop"): the DDS lockstep's speed and its hops
# with each cycle run on the node's own thread (--wake thread, the former path) and on the DDS
# listener thread (--wake listener, the default), for Cyclone DDS and Fast DDS
# (deploy/bench_transport.sh). A benchmark: run it on an idle machine.
# Usage: deploy/bench_wake.sh [RUNS] [DURATION_S] [OUT_DIR]
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
exec "$ROOT/deploy/bench_transport.sh" "${1:-3}" "${2:-10}" "${3:-bench-wake-out}" \
  'Cyclone DDS, thread=--dds cyclone --wake thread' 'Cyclone DDS, listener=--dds cyclone --wake listener' \
  'Fast DDS, thread=--dds fast --wake thread' 'Fast DDS, listener=--dds fast --wake listener'
