#!/usr/bin/env bash
# tests/fuzz/run_harness.sh FUZZ_BUILD_DIR NAME SECONDS: runs the libFuzzer harness fuzz_NAME of
# FUZZ_BUILD_DIR for SECONDS on its seed corpus (tests/fuzz/corpus/NAME; for stack_config also the
# shipped configurations, deploy/config, read where they are so that the seeds never fall out of
# step with them) and its working corpus (FUZZ_BUILD_DIR/fuzz-corpus/NAME, which grows from run to
# run). Prints the executions and, on a
# finding, the crash file and the sanitizer's report. Exit 0: no finding; 77: the harness is not
# built (ctest skips: deploy/crane fuzz builds it); otherwise libFuzzer's exit status.
# Used by deploy/crane fuzz and by the ctest tests fuzz.NAME (docs/robustness.md).
set -uo pipefail
dir=$1 name=$2 seconds=$3
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
exe="$dir/bin/fuzz_$name"
if [ ! -x "$exe" ]; then
  echo "SKIP: $exe is not built (deploy/crane fuzz configures $dir with clang and builds it)"
  exit 77
fi
mkdir -p "$dir/fuzz-corpus/$name" "$dir/fuzz-artifacts/$name"
seeds=()
[ -d "$here/corpus/$name" ] && seeds+=("$here/corpus/$name")
[ "$name" = stack_config ] && seeds+=("$here/../../deploy/config")
log="$dir/fuzz-artifacts/$name/last-run.log"
# -timeout: an input running 10 s is a hang (reported as a finding); -rss_limit_mb: libFuzzer's default.
"$exe" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
  -artifact_prefix="$dir/fuzz-artifacts/$name/" "$dir/fuzz-corpus/$name" "${seeds[@]}" >"$log" 2>&1
rc=$?
executions=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
corpus=$(ls "$dir/fuzz-corpus/$name" | wc -l)
echo "fuzz $name: ${executions:-?} executions in ${seconds} s, working corpus ${corpus} inputs, exit $rc"
if [ $rc -ne 0 ]; then
  grep -E "^(==[0-9]+==ERROR|SUMMARY)|runtime error|Test unit written to" "$log" | head -20
  echo "full log: $log"
  echo "reproduce: $exe <crash file>   (topic_gates: CRANE_FUZZ_TRACE=1 prints every sample)"
fi
exit $rc
