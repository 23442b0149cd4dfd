// crane_topic: watch the crane's topics from any machine that reaches the DDS domain, with a
// read-only participant (it creates readers only).
//
//   crane_topic list [--wait S] [--json]           topics from discovery: types, writers, readers, QoS
//   crane_topic echo TOPIC [--count N] [--timeout S]   samples as JSON lines
//   crane_topic hz TOPIC [--duration S] [--json]       rate and period jitter (receive time and the
//                                                     writer's stamps)
//   crane_topic record --out run.csv [--duration S] [--timeout S]   the audit's CSV (t,u_x,u_gamma,x,gamma,phi,
//                                                     theta,L, one row per sensor cycle) and every
//                                                     sample of every topic in run.csv.samples.jsonl
//   crane_topic record --mcap run.mcap [...]          every sample of every topic in MCAP, ros2 profile
//                                                     (with --out too: both from the same samples)
//   crane_topic convert run.mcap --out run.csv        the audit's CSV from such a recording (no DDS)
//   crane_topic replay run.mcap --domain N [--rate F]  republishes it (not goals or supervisor
//                                                     commands), --domain required: not onto a stack
//
// Common options: --dds fast|cyclone, --domain N, --lan (default: bound to loopback, as the stack).
// Exit codes: 0 done, 1 nothing received within the time given, 2 bad usage (unknown topic...).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include "crane/launch/mcap_reader.hpp"
#include "crane/launch/mcap_writer.hpp"
#include "crane/protocol/ros2_schemas.hpp"
#include "crane/runtime/node_runtime.hpp"
#include "crane/transport/cdr.hpp"
#include "message_json.hpp"

namespace {

using namespace crane;
namespace tp = transport::topics;
using Clock = std::chrono::steady_clock;
using nlohmann::json;

const std::vector<std::string>& topic_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> all;
    tp::for_each_topic([&]<class Topic>() { all.emplace_back(Topic::name); });
    return all;
  }();
  return names;
}

/// Calls f.template operator()<Topic>() for the topic tag named `name`; false if none is.
template <class F>
bool with_topic(const std::string& name, F&& f) {
  bool found = false;
  tp::for_each_topic([&]<class Topic>() {
    if (!found && name == Topic::name) {
      f.template operator()<Topic>();
      found = true;
    }
  });
  return found;
}

/// rt/crane/hw/sensors -> /crane/hw/sensors: the ROS 2 topic name of a DDS topic (rosbag2 records
/// ROS names; the "rt" prefix is ROS 2's mangling of topics on the wire).
std::string ros2_topic_name(const std::string& dds_name) {
  return dds_name.rfind("rt/", 0) == 0 ? dds_name.substr(2) : dds_name;
}

/// The offered_qos_profiles metadata of a channel in the ros2 profile: rosbag2's YAML of the
/// writer's QoS (history keep last = 1, reliability reliable = 1 / best effort = 2, durability
/// transient local = 1 / volatile = 2, liveliness automatic = 1 / manual by topic = 3; durations
/// as {sec, nsec}, "infinite" as rosbag2 writes it).
std::string offered_qos_yaml(transport::QosKind kind) {
  const auto q = transport::qos_profile(kind);
  const auto duration = [](std::chrono::nanoseconds d) {
    if (d.count() == 0) return std::string("\n    sec: 2147483647\n    nsec: 4294967295");
    return "\n    sec: " + std::to_string(d.count() / 1000000000) + "\n    nsec: " + std::to_string(d.count() % 1000000000);
  };
  return "- history: 1\n  depth: " + std::to_string(q.history_depth) +
         "\n  reliability: " + (q.reliability == transport::Reliability::reliable ? "1" : "2") +
         "\n  durability: " + (q.durability == transport::Durability::transient_local ? "1" : "2") +
         "\n  deadline:" + duration(q.writer_deadline) + "\n  lifespan:" + duration(std::chrono::nanoseconds{0}) +
         "\n  liveliness: " + (q.manual_by_topic_liveliness ? "3" : "1") +
         "\n  liveliness_lease_duration:" + duration(q.liveliness_lease) +
         "\n  avoid_ros_namespace_conventions: false";
}

/// The audit's CSV (t,u_x,u_gamma,x,gamma,phi,theta,L,seq) of the sensor samples by cycle: row k
/// is the sensors of cycle k and the voltages applied during cycle k, which sample k+1 reports
/// (cycles without a successor are left out). t from the cycle number (the sensor writer is the
/// clock; wall stamps jitter, and in lockstep they are not simulated time). Returns the rows
/// written; throws std::runtime_error when `path` cannot be written.
std::size_t write_audit_csv(const std::map<std::uint64_t, tp::msgs::SensorSample_>& sensors, const std::string& path,
                            double sample_period) {
  std::ofstream csv(path);
  if (!csv) throw std::runtime_error("cannot write " + path);
  csv << "t,u_x,u_gamma,x,gamma,phi,theta,L,seq\n";
  csv.precision(10);
  std::size_t rows = 0;
  const std::uint64_t seq0 = sensors.empty() ? 0 : sensors.begin()->first;
  for (auto it = sensors.begin(); it != sensors.end(); ++it) {
    const auto next = std::next(it);
    if (next == sensors.end() || next->first != it->first + 1) continue;
    const auto& s = it->second;
    const double t = static_cast<double>(it->first - seq0) * sample_period;
    csv << t << ',' << next->second.applied_trolley_voltage() << ',' << next->second.applied_slew_voltage() << ','
        << s.trolley_position() << ',' << s.slew_angle() << ',' << s.swing_in_plane() << ','
        << s.swing_out_of_plane() << ',' << s.cable_length() << ',' << s.header().seq() << '\n';
    ++rows;
  }
  if (!csv) throw std::runtime_error("cannot write " + path);
  return rows;
}

/// crane_topic convert: the audit's CSV from the sensor channel of an MCAP recording.
int convert(const std::string& mcap_path, const std::string& out_path, double sample_period) {
  std::map<std::uint64_t, tp::msgs::SensorSample_> sensors;
  const std::string topic = ros2_topic_name(tp::Sensors::name);
  std::size_t refused = 0;
  launch::read_mcap_messages(mcap_path, [&](const launch::McapMessageView& m) {
    if (m.channel->topic != topic) return;
    tp::msgs::SensorSample_ s;
    if (m.channel->message_encoding != "cdr" || !transport::deserialize_cdr<tp::Sensors>(m.data, m.size, s)) {
      ++refused;
      return;
    }
    sensors[s.header().seq()] = s;
  });
  if (refused > 0) {
    std::fprintf(stderr, "crane_topic: %zu messages of %s could not be decoded (not cdr, or not a SensorSample_)\n",
                 refused, topic.c_str());
  }
  const auto rows = write_audit_csv(sensors, out_path, sample_period);
  std::fprintf(stderr, "crane_topic: %zu sensor cycles of %s -> %s\n", rows, mcap_path.c_str(), out_path.c_str());
  return rows > 0 ? 0 : 1;
}

/// crane_topic replay: republishes an MCAP recording's samples on the bus at `rate` times their
/// recorded pace (log times), each topic through its own writer. Operator inputs (goals, supervisor
/// commands) are never replayed. Returns the number of samples written.
std::size_t replay(transport::Participant& participant, const std::string& mcap_path, double rate) {
  struct Sample {
    std::size_t writer;
    std::uint64_t log_time;
    std::vector<std::uint8_t> bytes;
  };
  std::vector<std::function<bool(const std::vector<std::uint8_t>&)>> writers;
  std::vector<std::shared_ptr<void>> keep;
  std::map<std::string, std::size_t> writer_of_topic;
  tp::for_each_topic([&]<class T>() {
    if constexpr (std::is_same_v<T, tp::Goal> || std::is_same_v<T, tp::SafetyCommand>) return;
    auto writer = std::shared_ptr(participant.make_writer<T>());
    keep.push_back(writer);
    writer_of_topic[ros2_topic_name(T::name)] = writers.size();
    writers.push_back([writer](const std::vector<std::uint8_t>& bytes) {
      typename T::Message m;
      return transport::deserialize_cdr<T>(bytes.data(), bytes.size(), m) && writer->write(m);
    });
  });
  std::vector<Sample> samples;
  launch::read_mcap_messages(mcap_path, [&](const launch::McapMessageView& m) {
    const auto found = writer_of_topic.find(m.channel->topic);
    if (found == writer_of_topic.end() || m.channel->message_encoding != "cdr") return;
    samples.push_back({found->second, m.log_time, std::vector<std::uint8_t>(m.data, m.data + m.size)});
  });
  if (samples.empty()) throw std::runtime_error(mcap_path + ": no sample of a replayed topic");
  // Discovery: the readers of another process need a moment to match the new writers.
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const auto start = Clock::now();
  const auto t0 = samples.front().log_time;
  std::size_t written = 0, refused = 0;
  for (const auto& s : samples) {
    if (runtime::stop_requested()) break;
    const auto due = std::chrono::nanoseconds(static_cast<std::int64_t>(static_cast<double>(s.log_time - t0) / rate));
    std::this_thread::sleep_until(start + due);
    if (writers[s.writer](s.bytes)) {
      ++written;
    } else {
      ++refused;
    }
  }
  std::fprintf(stderr, "crane_topic: replayed %zu samples of %s at %gx (%zu refused)\n", written, mcap_path.c_str(),
               rate, refused);
  return written;
}

Clock::time_point after(double seconds) {
  return Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(std::lround(p / 100.0 * static_cast<double>(v.size() - 1)));
  return v[i];
}

json period_statistics(const std::vector<double>& times) {
  std::vector<double> periods;
  for (std::size_t i = 1; i < times.size(); ++i) periods.push_back(times[i] - times[i - 1]);
  json j;
  j["samples"] = times.size();
  if (periods.empty()) return j;
  double mean = 0.0;
  for (const double p : periods) mean += p;
  mean /= static_cast<double>(periods.size());
  double variance = 0.0;
  std::vector<double> deviation;
  for (const double p : periods) {
    variance += (p - mean) * (p - mean);
    deviation.push_back(std::fabs(p - mean));
  }
  variance /= static_cast<double>(periods.size());
  j["rate_hz"] = 1.0 / mean;
  j["period_mean_ms"] = mean * 1e3;
  j["period_std_ms"] = std::sqrt(variance) * 1e3;
  j["period_min_ms"] = *std::min_element(periods.begin(), periods.end()) * 1e3;
  j["period_max_ms"] = *std::max_element(periods.begin(), periods.end()) * 1e3;
  j["jitter_p99_ms"] = percentile(deviation, 99) * 1e3;
  return j;
}

template <class M>
double origin_seconds(const M& m) {
  if constexpr (requires { m.header(); }) {
    return static_cast<double>(runtime::to_nanoseconds(m.header().origin())) * 1e-9;
  } else {
    return std::nan("");
  }
}

int list(transport::Participant& participant, double wait, bool as_json) {
  std::this_thread::sleep_for(std::chrono::duration<double>(wait));
  const auto endpoints = participant.discovered_endpoints();
  if (as_json) {
    json topics = json::object();
    for (const auto& e : endpoints) {
      auto& t = topics[e.topic];
      t["type"] = e.type;
      json endpoint{{"participant", e.participant}, {"guid", e.guid}, {"reliable", e.reliable},
                    {"transient_local", e.transient_local}, {"deadline_s", e.deadline}};
      t[e.writer ? "writers" : "readers"].push_back(endpoint);
    }
    for (auto& [name, t] : topics.items()) {
      if (!t.contains("writers")) t["writers"] = json::array();
      if (!t.contains("readers")) t["readers"] = json::array();
    }
    std::printf("%s\n", topics.dump(2).c_str());
  } else {
    std::string topic;
    for (const auto& e : endpoints) {
      if (e.topic != topic) {
        topic = e.topic;
        std::printf("%s  [%s]\n", e.topic.c_str(), e.type.c_str());
      }
      char deadline[32] = "none";
      if (e.deadline > 0.0) std::snprintf(deadline, sizeof(deadline), "%.0f ms", e.deadline * 1e3);
      std::printf("    %-6s %-24s %-11s %-15s deadline %s\n", e.writer ? "writer" : "reader", e.participant.c_str(),
                  e.reliable ? "reliable" : "best_effort", e.transient_local ? "transient_local" : "volatile", deadline);
    }
    if (endpoints.empty()) std::printf("no other participant seen on this domain within %.1f s\n", wait);
  }
  return endpoints.empty() ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"crane_topic: list, echo, measure and record the crane's DDS topics (read-only participant)"};
  app.require_subcommand(1);
  runtime::NodeOptions node;
  bool lan = false;
  auto common = [&](CLI::App* sub) {
    sub->add_option("--dds", node.dds, "DDS vendor: fast | cyclone (default: $CRANE_DDS, else fast)");
    sub->add_option("--domain", node.domain_id, "DDS domain id")->check(CLI::Range(0, 232));
    sub->add_option("--dds-profile", node.dds_profile, "network profile (deploy/dds/*.xml)")->check(CLI::ExistingFile);
    sub->add_flag("--lan", lan, "use the network (UDP on every interface, no shared memory: as from another "
                                "machine) instead of loopback only");
    runtime::add_iceoryx_option(*sub, node);
    runtime::add_security_options(*sub, node);
  };
  auto* list_cmd = app.add_subcommand("list", "topics from discovery: types, writers, readers, QoS");
  double wait = 2.0;
  bool as_json = false;
  list_cmd->add_option("--wait", wait, "[s] discovery time")->check(CLI::Range(0.1, 60.0));
  list_cmd->add_flag("--json", as_json, "one JSON object");
  common(list_cmd);
  std::string topic;
  auto* echo_cmd = app.add_subcommand("echo", "print samples as JSON lines");
  int count = 0;
  double timeout = 5.0;
  echo_cmd->add_option("topic", topic, "topic name, e.g. rt/crane/hw/sensors")->required();
  echo_cmd->add_option("--count", count, "stop after N samples (0: until Ctrl-C)")->check(CLI::Range(0, 1000000000));
  echo_cmd->add_option("--timeout", timeout, "[s] give up when nothing arrives this long")->check(CLI::Range(0.1, 3600.0));
  common(echo_cmd);
  auto* hz_cmd = app.add_subcommand("hz", "rate and period jitter of a topic");
  double duration = 5.0;
  hz_cmd->add_option("topic", topic, "topic name")->required();
  hz_cmd->add_option("--duration", duration, "[s] measuring time")->check(CLI::Range(0.1, 3600.0));
  hz_cmd->add_flag("--json", as_json, "one JSON object");
  common(hz_cmd);
  auto* record_cmd = app.add_subcommand("record", "the audit's CSV and every sample (JSON lines)");
  std::string out_path, mcap_path;
  auto* out_option = record_cmd->add_option("--out", out_path, "CSV file (t,u_x,u_gamma,x,gamma,phi,theta,L)");
  auto* mcap_option = record_cmd->add_option("--mcap", mcap_path,
                                             "MCAP file: every sample of every topic (ros2 profile, cdr, ros2msg schemas)");
  record_cmd->add_option("--duration", duration, "[s] recording time, from the first sensor sample")
      ->check(CLI::Range(0.1, 86400.0));
  record_cmd->add_option("--timeout", timeout, "[s] give up when no sensor sample arrives this long")
      ->check(CLI::Range(0.1, 3600.0));
  double sample_period = 0.01;
  record_cmd->add_option("--sample-period", sample_period, "[s] of the sensor stream (t = cycle number * this)")
      ->check(CLI::Range(1e-4, 1.0));
  common(record_cmd);
  auto* convert_cmd = app.add_subcommand("convert", "the audit's CSV from an MCAP recording (record --mcap)");
  std::string convert_in;
  convert_cmd->add_option("mcap", convert_in, "MCAP file written by crane_topic record --mcap")->required()
      ->check(CLI::ExistingFile);
  convert_cmd->add_option("--out", out_path, "CSV file (t,u_x,u_gamma,x,gamma,phi,theta,L,seq)")->required();
  convert_cmd->add_option("--sample-period", sample_period, "[s] of the sensor stream (t = cycle number * this)")
      ->check(CLI::Range(1e-4, 1.0));
  auto* replay_cmd = app.add_subcommand("replay", "republish an MCAP recording on the bus (never goals or commands)");
  std::string replay_in;
  double replay_rate = 1.0;
  replay_cmd->add_option("mcap", replay_in, "MCAP file written by crane_topic record --mcap")->required()
      ->check(CLI::ExistingFile);
  replay_cmd->add_option("--rate", replay_rate, "pace, times the recorded one")->check(CLI::Range(0.01, 100.0));
  common(replay_cmd);
  replay_cmd->get_option("--domain")->required();  // never by default onto domain 0, where a stack runs
  CLI11_PARSE(app, argc, argv);
  if (convert_cmd->parsed()) {
    try {
      return convert(convert_in, out_path, sample_period);
    } catch (const std::exception& error) {
      std::fprintf(stderr, "crane_topic: %s\n", error.what());
      return 1;
    }
  }
  if (record_cmd->parsed() && out_option->count() == 0 && mcap_option->count() == 0) {
    std::fprintf(stderr, "crane_topic record: give --out run.csv, --mcap run.mcap, or both\n");
    return 2;
  }
  node.loopback_only = !lan;
  node.shared_memory = !lan;
  if (node.identity.empty()) node.identity = "monitor";  // a read-only tool: the monitor role

  try {
    runtime::configure_logging("warn", "crane_topic");
    auto participant = runtime::make_participant(node, "crane_topic");
    transport::Wakeup wakeup;
    runtime::install_stop_handlers(&wakeup);
    if (list_cmd->parsed()) return list(*participant, wait, as_json);
    if (replay_cmd->parsed()) return replay(*participant, replay_in, replay_rate) > 0 ? 0 : 1;

    if (echo_cmd->parsed() || hz_cmd->parsed()) {
      int status = 1;
      const bool known = with_topic(topic, [&]<class T>() {
        auto reader = participant->make_recording_reader<T>(&wakeup, 1024);
        typename T::Message m;
        std::vector<double> receive, origin;
        int printed = 0;
        const auto end = after(hz_cmd->parsed() ? duration : 1e9);
        auto idle_deadline = after(timeout);
        while (!runtime::stop_requested() && Clock::now() < end) {
          while (reader->take_next(m)) {
            status = 0;
            if (echo_cmd->parsed()) {
              std::printf("%s\n", launch::message_json(m).dump().c_str());
              std::fflush(stdout);
              if (count > 0 && ++printed >= count) return;
            } else {
              receive.push_back(static_cast<double>(runtime::now_nanoseconds()) * 1e-9);
              origin.push_back(origin_seconds(m));
            }
            idle_deadline = after(timeout);
          }
          if (echo_cmd->parsed() && Clock::now() > idle_deadline) return;
          wakeup.wait_until(std::min(end, Clock::now() + std::chrono::milliseconds(50)));
        }
        if (hz_cmd->parsed()) {
          json j{{"topic", topic}, {"duration_s", duration}, {"receive", period_statistics(receive)}};
          if (!origin.empty() && std::isfinite(origin.front())) j["writer_stamps"] = period_statistics(origin);
          if (as_json) {
            std::printf("%s\n", j.dump(2).c_str());
          } else if (receive.size() > 1) {
            const auto& r = j["receive"];
            std::printf("%s: %.2f Hz over %zu samples; period mean %.3f ms, std %.3f ms, min %.3f ms, max %.3f ms, "
                        "jitter p99 %.3f ms\n",
                        topic.c_str(), r["rate_hz"].get<double>(), receive.size(), r["period_mean_ms"].get<double>(),
                        r["period_std_ms"].get<double>(), r["period_min_ms"].get<double>(),
                        r["period_max_ms"].get<double>(), r["jitter_p99_ms"].get<double>());
          } else {
            std::printf("%s: %zu samples in %.1f s\n", topic.c_str(), receive.size(), duration);
          }
        }
      });
      if (!known) {
        std::fprintf(stderr, "crane_topic: unknown topic '%s'; the crane's topics are:\n", topic.c_str());
        for (const auto& n : topic_names()) std::fprintf(stderr, "  %s\n", n.c_str());
        return 2;
      }
      return status;
    }

    // record: every topic to JSON lines; the sensor stream to the audit's CSV; with --mcap every
    // sample as its CDR bytes to MCAP.
    std::ofstream samples;
    if (!out_path.empty()) {
      samples.open(out_path + ".samples.jsonl");
      if (!samples) throw std::runtime_error("cannot write " + out_path + ".samples.jsonl");
    }
    std::unique_ptr<launch::McapWriter> mcap;
    if (!mcap_path.empty()) mcap = std::make_unique<launch::McapWriter>(mcap_path, "ros2", "crane_topic (idl/crane_msgs.idl)");
    std::map<std::uint64_t, tp::msgs::SensorSample_> sensors;
    std::vector<std::function<void()>> drains;
    std::vector<std::shared_ptr<void>> readers;
    for (const auto& name : topic_names()) {
      with_topic(name, [&]<class T>() {
        auto reader = std::shared_ptr(participant->make_recording_reader<T>(&wakeup, 4096));
        readers.push_back(reader);
        std::uint16_t channel = 0;
        if (mcap) {
          const auto* schema = protocol::ros2_schema(T::type_name);
          if (schema == nullptr) throw std::logic_error(std::string("no ROS 2 schema for ") + T::type_name);
          const auto schema_id = mcap->add_schema(std::string(schema->ros2_type_name), "ros2msg",
                                                  std::string(schema->msg_definition));
          channel = mcap->add_channel(schema_id, ros2_topic_name(name), "cdr",
                                      {{"offered_qos_profiles", offered_qos_yaml(T::qos)}});
        }
        drains.push_back([reader, &samples, &sensors, name, &mcap, channel, sequence = std::uint32_t{0}]() mutable {
          typename T::Message m;
          std::vector<std::uint8_t> bytes;
          while (reader->take_next(m)) {
            const auto receive_ns = runtime::now_nanoseconds();
            if (samples.is_open()) {
              samples << json{{"topic", name}, {"receive_ns", receive_ns}, {"sample", launch::message_json(m)}}.dump()
                      << '\n';
            }
            if (mcap && transport::serialize_cdr<T>(m, bytes)) {
              const auto& stamp = m.header().stamp();
              const auto publish_ns = static_cast<std::uint64_t>(stamp.sec()) * 1000000000ULL + stamp.nanosec();
              mcap->write_message(channel, sequence++, static_cast<std::uint64_t>(receive_ns), publish_ns, bytes.data(),
                                  bytes.size());
            }
            if constexpr (std::is_same_v<T, tp::Sensors>) sensors[m.header().seq()] = m;
          }
        });
      });
    }
    // The recording time counts from the first sensor sample (discovery across vendors or by
    // unicast can take a second or two); give up after --timeout without one.
    auto end = after(timeout);
    bool started = false;
    while (!runtime::stop_requested() && Clock::now() < end) {
      for (auto& d : drains) d();
      if (!started && !sensors.empty()) {
        started = true;
        end = after(duration);
      }
      wakeup.wait_until(std::min(end, Clock::now() + std::chrono::milliseconds(20)));
    }
    if (!started) throw std::runtime_error("no sensor sample arrived within --timeout " + std::to_string(timeout) + " s");
    for (auto& d : drains) d();
    if (mcap) {
      mcap->finish();
      std::fprintf(stderr, "crane_topic: %llu samples -> %s\n", static_cast<unsigned long long>(mcap->message_count()),
                   mcap_path.c_str());
      if (out_path.empty()) return mcap->message_count() > 0 ? 0 : 1;
    }
    const std::size_t rows = write_audit_csv(sensors, out_path, sample_period);
    std::fprintf(stderr, "crane_topic: %zu sensor cycles -> %s, every sample -> %s.samples.jsonl\n", rows,
                 out_path.c_str(), out_path.c_str());
    return rows > 0 ? 0 : 1;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "crane_topic: %s\n", error.what());
    return 1;
  }
}
