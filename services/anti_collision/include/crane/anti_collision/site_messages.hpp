#pragma once
// The site's messages (idl/crane_msgs.idl: SiteReport_, SiteInstruction_, SiteStatus_, as the
// plain structs of crane/protocol/messages.hpp) to and from the site service's core
// (site_service.hpp): one translation for the site_service process, each crane's site link and the
// tests. The codes (STATE_*, KIND_*, HOLDING_*) are the IDL's.
//
// Errors: the from-message functions return "" or why the message cannot be read (a count beyond
// its arrays, an unknown code), naming the field and the value; they never throw. Whatever else a
// report may get wrong (non-finite values, counts below their minimum) SiteService::report refuses.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "crane/anti_collision/site_service.hpp"
#include "crane/protocol/messages.hpp"

namespace crane::anti_collision {

/// `message` read into `report`. "" when read, else why not (`report` is then unspecified).
[[nodiscard]] std::string from_message(const protocol::SiteReport& message, CraneReport& report);
/// `report` written into `message` (its header and measured motion untouched). Waypoints beyond
/// MAX_WAYPOINTS are dropped (a report that long is refused by SiteService::report anyway).
void to_message(const CraneReport& report, protocol::SiteReport& message) noexcept;

/// The measured motion of a report: written (the crane's site link) and read (the views, the
/// distance monitor). Reading never fails; a non-finite value is the caller's to judge (is_finite).
void set_motion(const CraneMotion& motion, protocol::SiteReport& message) noexcept;
[[nodiscard]] CraneMotion motion_of(const protocol::SiteReport& message) noexcept;

/// `order` of the service of `epoch` written into `message` (its header's seq is the order's).
void to_message(const SiteOrder& order, std::uint32_t epoch, protocol::SiteInstruction& message) noexcept;
/// `message` read into `order`. "" when read, else why not.
[[nodiscard]] std::string from_message(const protocol::SiteInstruction& message, SiteOrder& order);

/// What `service` holds, who waits for whom and why, its counters and its epoch written into
/// `message` (header untouched); `time` [s], the service's clock (step()'s), gives each pending
/// request's `waited`.
void to_message(const SiteService& service, double time, protocol::SiteStatus& message) noexcept;
/// The IDL's HOLDING_* code of `holding`.
[[nodiscard]] std::uint8_t holding_code(Holding holding) noexcept;
/// The IDL's WAIT_* code of `reason`.
[[nodiscard]] std::uint8_t wait_code(WaitReason reason) noexcept;
/// The names (`layout`'s) of the cranes crane `crane`'s request waits for, as `status` says
/// (its waits_for bits); empty for a crane beyond the status's crane_count.
[[nodiscard]] std::vector<std::string> waits_for_names(const SiteLayout& layout, const protocol::SiteStatus& status,
                                                       std::size_t crane);

}  // namespace crane::anti_collision
