// libFuzzer harness: the YAML configuration loader (crane::stack::parse_stack_config, which reads
// every block through config::ConfigDocument). Contract (stack_config.hpp): any text either gives a
// validated StackConfig or throws common::ConfigError naming the field; nothing else may escape,
// and nothing may crash or trip ASan/UBSan. Seeds: tests/fuzz/corpus/stack_config (the configs
// of deploy/config).
#include <cstddef>
#include <cstdint>
#include <string>

#include "crane/common/validation.hpp"
#include "crane/stack/stack_config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const auto config = crane::stack::parse_stack_config(text, "fuzz.yaml");
    (void)config;
  } catch (const crane::common::ConfigError&) {
    // the documented refusal
  }
  return 0;
}
