// libFuzzer harness: what a restarted site_service does with the bytes of its memory file
// (site_service --memory; site_memory.hpp, SiteService::recall), on the shipped three-tower site.
// The bytes must be read (memory_from_json) or refused with common::ConfigError, nothing else; a
// memory read must be recalled by a fresh service or refused with a message, never throw; one
// recalled must write back to a text that reads back to itself, and the operator's word for each
// crane must then be answered (taken or refused), never throw.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "crane/anti_collision/site_file.hpp"
#include "crane/anti_collision/site_memory.hpp"
#include "crane/anti_collision/site_service.hpp"
#include "crane/common/validation.hpp"

namespace {

namespace ac = crane::anti_collision;

const ac::SiteLayout& site() {
  static const ac::SiteLayout layout = ac::load_site_layout(CRANE_FUZZ_SITE);
  return layout;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  ac::SiteMemory memory;
  try {
    memory = ac::memory_from_json(text, site(), "fuzz.json");
  } catch (const crane::common::ConfigError&) {
    return 0;
  }
  ac::SiteService service(site(), ac::ArbiterMode::coordinated, 1);
  if (!service.recall(memory).empty()) return 0;
  const std::string written = ac::memory_to_json(memory, site());
  if (ac::memory_to_json(ac::memory_from_json(written, site(), "again.json"), site()) != written) std::abort();
  for (std::size_t i = 0; i < memory.size(); ++i) (void)service.out_of_service(i, 10.0);
  (void)service.step(10.0);
  return 0;
}
