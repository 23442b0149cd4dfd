#!/usr/bin/env bash
# deploy/sanitize.sh [asan | tsan | all] [--jobs N]: the tests under the sanitizers (docs/robustness.md).
#
#   asan: build-asan with -DCRANE_SANITIZE=ON (AddressSanitizer + UndefinedBehaviorSanitizer, gcc):
#         the unit tests of every core, the closed-loop tests and the transport tests.
#   tsan: build-tsan with -DCRANE_SANITIZE_THREAD=ON (ThreadSanitizer, gcc): the transport tests
#         (DDS readers, writers, listeners and the node runtime they link, across both vendors).
#   all:  both (the default).
# Each prints how long its build and its tests took. Exit status: non-zero when a build fails or a
# test fails (a sanitizer report fails its test: halt_on_error, exitcode 1).
# Only the test executables named below are built (not the whole tree), each build directory
# beside the normal one, through ccache like deploy/crane build.
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
mode=all
jobs=$(nproc 2>/dev/null || echo 2)
while [ $# -gt 0 ]; do
  case "$1" in
    asan|tsan|all) mode=$1 ;;
    --jobs) jobs=$2; shift ;;
    -h|--help) sed -n '2,/^set -euo/p' "${BASH_SOURCE[0]}" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "sanitize.sh: unknown argument '$1' (asan | tsan | all, --jobs N)" >&2; exit 2 ;;
  esac
  shift
done

# The unit suites of the pure cores, the closed-loop runs (core + plant, no DDS), the transport.
ASAN_TARGETS=(
  test_plant_model test_plant_simulator test_plant_friction test_plant_drives_and_sensors test_plant_gantry_overhead
  test_services_state_estimator test_services_trajectory_planner test_services_anti_swing test_services_tracking
  test_services_friction_compensation test_services_stages test_speed_reference test_supervisor test_actuation_gate
  test_config test_gain_scheduling crane_gains test_trajectory_profiles test_jog_input
  test_hardware_bridge_board_config test_hardware_bridge_bridge_core test_hardware_bridge_conversions
  test_hardware_bridge_shm_board test_hardware_bridge_comedi_board
  test_services_adaptation test_plant_hook_and_wind test_operator_command
  test_closed_loop test_operate test_adaptation test_gantry_gain_study test_convergence test_transport test_anti_collision)
ASAN_TESTS='^(test_plant_[a-z_]+|services|supervisor|config|gain_scheduling|trajectory_profiles|launch|hardware_bridge|closed_loop|transport|anti_collision)\.'
TSAN_TARGETS=(test_transport)
TSAN_TESTS='^transport\.'

export CCACHE_BASEDIR="$ROOT" CCACHE_NOHASHDIR=1
status=0

# run NAME DIR CMAKE_OPTION TEST_REGEX TARGETS...
run() {
  local name=$1 dir=$2 option=$3 regex=$4
  shift 4
  local t0 t1 t2
  t0=$(date +%s)
  if [ ! -f "$dir/CMakeCache.txt" ]; then
    cmake -S "$ROOT" -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release "$option" -DCRANE_BUILD_BENCHMARKS=OFF >&2
  fi
  local targets=()
  for t in "$@"; do targets+=(--target "$t"); done
  cmake --build "$dir" -j"$jobs" "${targets[@]}" >&2 || { echo "[sanitize] $name: build failed" >&2; return 1; }
  t1=$(date +%s)
  local rc=0
  # In a private network namespace when possible (DDS stays on this machine), like deploy/crane test.
  local ctest=(ctest --test-dir "$dir" --output-on-failure -j "$jobs" -R "$regex")
  if unshare --net true 2>/dev/null; then
    unshare --net bash -c 'ip link set lo up && ip link set lo multicast on && exec "$@"' sanitize "${ctest[@]}" || rc=$?
  else
    "${ctest[@]}" || rc=$?
  fi
  t2=$(date +%s)
  echo "[sanitize] $name: build $((t1 - t0)) s, tests $((t2 - t1)) s, ctest exit $rc" >&2
  return $rc
}

if [ "$mode" = asan ] || [ "$mode" = all ]; then
  # halt_on_error: the first report fails the test; detect_leaks: LeakSanitizer at exit.
  # new_delete_type_mismatch=0: Fast DDS 2.9.1 (Debian's libfastrtps) allocates an 88-byte
  # StatisticsWriterImpl and deletes it as a 56-byte type in RTPSWriter::~RTPSWriter, whenever a
  # DataWriter is deleted (transport.CrossVendor.*, 2026-11-22): the whole stack is inside the
  # library. ASan cannot suppress that check per library, so it is off for every test; the
  # sanitizer figures in docs/robustness.md say so.
  export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:halt_on_error=1:abort_on_error=0:exitcode=1:new_delete_type_mismatch=0}
  export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
  # The seeded zone runs at a fifth of their count: under ASan the 1000 goals took longer than the
  # test's timeout here (2026-11-22). The sanitizer looks for memory errors, which the first 200
  # goals exercise as the 1000 do; the full counts run in deploy/crane test.
  export CRANE_ZONE_GOALS=${CRANE_ZONE_GOALS:-200} CRANE_ZONE_SESSIONS=${CRANE_ZONE_SESSIONS:-20}
  run asan "$ROOT/build-asan" -DCRANE_SANITIZE=ON "$ASAN_TESTS" "${ASAN_TARGETS[@]}" || status=1
fi
if [ "$mode" = tsan ] || [ "$mode" = all ]; then
  # Suppressions: reports inside the two DDS libraries only, each with its reason in the file.
  export TSAN_OPTIONS=${TSAN_OPTIONS:-halt_on_error=1:exitcode=1:second_deadlock_stack=1:suppressions=$ROOT/deploy/tsan_suppressions.txt}
  run tsan "$ROOT/build-tsan" -DCRANE_SANITIZE_THREAD=ON "$TSAN_TESTS" "${TSAN_TARGETS[@]}" || status=1
fi
command -v fastdds >/dev/null 2>&1 && fastdds shm clean >/dev/null 2>&1 || true
exit $status
