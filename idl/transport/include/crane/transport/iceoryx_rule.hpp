#pragma once
// Which participants may put their samples in iceoryx shared memory (docs/architecture.md, "Shared
// memory (iceoryx)"): the one rule. transport::Participant refuses a participant with it, and the
// launcher checks every process of a stack with it before it starts any (launch::stack_processes).
// Header-only and free of DDS: the launcher's library builds without DDS (the fuzz build).

#include <string>

namespace crane::transport {

/// Why a participant cannot be on iceoryx: it must be Cyclone DDS (`cyclone_dds`), on loopback
/// (not `lan`), with no network profile (`profile` empty) and no DDS Security (`security_directory`
/// empty): its samples lie unencrypted in this machine's shared memory, and only Cyclone DDS 0.10
/// is built with iceoryx in Debian. Returns "" when it can; otherwise one sentence naming each
/// reason (`vendor`, the vendor's name, for the first). Never throws but std::bad_alloc.
[[nodiscard]] inline std::string iceoryx_refusal(bool cyclone_dds, const std::string& vendor, bool lan,
                                                 const std::string& profile, const std::string& security_directory) {
  std::string reasons;
  const auto add = [&reasons](const std::string& reason) { reasons += (reasons.empty() ? "" : ", ") + reason; };
  if (!cyclone_dds) add("on " + vendor);
  if (lan) add("with --lan");
  if (!profile.empty()) add("with the network profile " + profile);
  if (!security_directory.empty()) add("with --security " + security_directory);
  if (reasons.empty()) return reasons;
  return "iceoryx shared memory needs Cyclone DDS on loopback without a network profile or DDS Security (its "
         "samples lie unencrypted in shared memory): this participant is " +
         reasons;
}

}  // namespace crane::transport
