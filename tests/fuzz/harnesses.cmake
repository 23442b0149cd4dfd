# The libFuzzer harnesses (one place): each is tests/fuzz/fuzz_<name>.cpp, built as fuzz_<name> in the
# clang fuzz build (tests/fuzz/CMakeLists.txt), seeded as run_harness.sh says, and run for a
# few seconds by the ctest test fuzz.<name> of the normal build (tests/CMakeLists.txt).
set(CRANE_FUZZ_HARNESSES stack_config audit_csv mcap_reader jog_input web_client_message topic_gates
                         operator_request site_memory)
