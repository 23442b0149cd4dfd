#include "crane/anti_collision/site_memory.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "crane/common/validation.hpp"

namespace crane::anti_collision {
namespace {

using nlohmann::json;

// The motion's fields, in one place for both directions.
struct MotionField {
  const char* name;
  double CraneMotion::*member;
};
constexpr MotionField kMotionFields[] = {
    {"slew", &CraneMotion::slew},
    {"slew_rate", &CraneMotion::slew_rate},
    {"trolley", &CraneMotion::trolley},
    {"trolley_velocity", &CraneMotion::trolley_velocity},
    {"cable_length", &CraneMotion::cable_length},
    {"cable_rate", &CraneMotion::cable_rate},
    {"swing_in_plane", &CraneMotion::swing_in_plane},
    {"swing_out_of_plane", &CraneMotion::swing_out_of_plane},
    {"swing_in_plane_rate", &CraneMotion::swing_in_plane_rate},
    {"swing_out_of_plane_rate", &CraneMotion::swing_out_of_plane_rate},
};
constexpr double JointBox::*kBoxFields[] = {&JointBox::slew_low,    &JointBox::slew_high,  &JointBox::trolley_low,
                                            &JointBox::trolley_high, &JointBox::cable_low, &JointBox::cable_high,
                                            &JointBox::swing_radius};
constexpr std::size_t kBoxNumbers = sizeof kBoxFields / sizeof kBoxFields[0];

class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}
  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    throw common::ConfigError(source_ + ": " + field + " " + what);
  }
  const json& member(const json& object, const std::string& field, const char* name) const {
    if (!object.is_object()) fail(field, "is not an object");
    const auto it = object.find(name);
    if (it == object.end()) fail(field + "." + name, "is missing");
    return *it;
  }
  double number(const json& value, const std::string& field) const {
    if (value.is_number()) return value.get<double>();
    fail(field, "= " + value.dump() + " is not a number");
  }
  bool boolean(const json& value, const std::string& field) const {
    if (!value.is_boolean()) fail(field, "= " + value.dump() + " is not true or false");
    return value.get<bool>();
  }

 private:
  std::string source_;
};

}  // namespace

std::string memory_to_json(const SiteMemory& memory, const SiteLayout& layout) {
  if (memory.size() != layout.cranes.size()) {
    throw std::invalid_argument("site memory: " + std::to_string(memory.size()) + " cranes, the site " +
                                std::to_string(layout.cranes.size()));
  }
  json cranes = json::array();
  for (std::size_t i = 0; i < memory.size(); ++i) {
    const CraneMemory& m = memory[i];
    json motion = json::object();
    for (const MotionField& f : kMotionFields) motion[f.name] = m.motion.*f.member;
    json place = nullptr;
    if (m.place) {
      json boxes = json::array();
      for (std::size_t k = 0; k < m.place->airspace.count && k < Airspace::kMaxBoxes; ++k) {
        json box = json::array();
        for (const auto field : kBoxFields) box.push_back(m.place->airspace.boxes[k].*field);
        boxes.push_back(std::move(box));
      }
      place = {{"moving", m.place->moving}, {"boxes", std::move(boxes)}};
    }
    cranes.push_back({{"name", layout.cranes[i].name},
                      {"out_of_service", m.out_of_service},
                      {"motion", std::move(motion)},
                      {"place", std::move(place)}});
  }
  const json out = {{"format", kSiteMemoryFormat}, {"site", layout.name}, {"cranes", std::move(cranes)}};
  return out.dump(1) + "\n";
}

SiteMemory memory_from_json(const std::string& text, const SiteLayout& layout, const std::string& source_name) {
  const Reader r(source_name);
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& error) {  // a syntax error, or a number beyond a double (out_of_range)
    r.fail("the file", std::string("is not JSON: ") + error.what());
  }
  const json& format = r.member(doc, "the file", "format");
  if (format != kSiteMemoryFormat) r.fail("format", "= " + format.dump() + ": must be \"" + kSiteMemoryFormat + "\"");
  const json& site = r.member(doc, "the file", "site");
  if (site != layout.name) r.fail("site", "= " + site.dump() + ": the site file is '" + layout.name + "'");
  const json& cranes = r.member(doc, "the file", "cranes");
  if (!cranes.is_array() || cranes.size() != layout.cranes.size()) {
    r.fail("cranes", "has " + (cranes.is_array() ? std::to_string(cranes.size()) : std::string("no")) +
                         " entries: the site has " + std::to_string(layout.cranes.size()) + " cranes");
  }
  SiteMemory memory(cranes.size());
  for (std::size_t i = 0; i < cranes.size(); ++i) {
    const std::string at = "cranes[" + std::to_string(i) + "]";
    const json& c = cranes[i];
    const json& name = r.member(c, at, "name");
    if (name != layout.cranes[i].name) {
      r.fail(at + ".name", "= " + name.dump() + ": the site file's crane " + std::to_string(i) + " is '" +
                               layout.cranes[i].name + "'");
    }
    CraneMemory& m = memory[i];
    m.out_of_service = r.boolean(r.member(c, at, "out_of_service"), at + ".out_of_service");
    const json& motion = r.member(c, at, "motion");
    for (const MotionField& f : kMotionFields) {
      m.motion.*f.member = r.number(r.member(motion, at + ".motion", f.name), at + ".motion." + f.name);
    }
    const json& place = r.member(c, at, "place");
    if (place.is_null()) continue;
    SiteArbiter::Place p;
    p.moving = r.boolean(r.member(place, at + ".place", "moving"), at + ".place.moving");
    const json& boxes = r.member(place, at + ".place", "boxes");
    if (!boxes.is_array() || boxes.empty() || boxes.size() > Airspace::kMaxBoxes) {
      r.fail(at + ".place.boxes", "has " + (boxes.is_array() ? std::to_string(boxes.size()) : std::string("no")) +
                                      " boxes: must be 1 to " + std::to_string(Airspace::kMaxBoxes));
    }
    for (std::size_t k = 0; k < boxes.size(); ++k) {
      const std::string box_at = at + ".place.boxes[" + std::to_string(k) + "]";
      if (!boxes[k].is_array() || boxes[k].size() != kBoxNumbers) {
        r.fail(box_at, "has " + (boxes[k].is_array() ? std::to_string(boxes[k].size()) : std::string("no")) +
                           " numbers: must be " + std::to_string(kBoxNumbers));
      }
      for (std::size_t f = 0; f < kBoxNumbers; ++f) {
        p.airspace.boxes[k].*kBoxFields[f] = r.number(boxes[k][f], box_at + "[" + std::to_string(f) + "]");
      }
    }
    p.airspace.count = boxes.size();
    m.place = p;
  }
  return memory;
}

std::optional<SiteMemory> read_memory_file(const std::string& path, const SiteLayout& layout) {
  std::ifstream in(path);
  if (!in) {
    if (errno == ENOENT) return std::nullopt;
    throw common::ConfigError(path + ": cannot be read: " + std::strerror(errno));
  }
  std::ostringstream text;
  text << in.rdbuf();
  return memory_from_json(text.str(), layout, path);
}

void write_memory_file(const std::string& path, const std::string& text) {
  const std::string temporary = path + ".tmp";
  const auto failed = [&](const std::string& what) {
    throw std::runtime_error("site memory: " + what + " " + temporary + ": " + std::strerror(errno));
  };
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) failed("cannot open");
  std::size_t written = 0;
  while (written < text.size()) {
    const ssize_t n = ::write(fd, text.data() + written, text.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      ::close(fd);
      failed("cannot write");
    }
    written += static_cast<std::size_t>(n);
  }
  if (::fdatasync(fd) != 0) {
    ::close(fd);
    failed("cannot flush");
  }
  if (::close(fd) != 0) failed("cannot close");
  if (std::rename(temporary.c_str(), path.c_str()) != 0) failed("cannot rename to " + path + ":");
}

}  // namespace crane::anti_collision
