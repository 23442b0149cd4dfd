// The crane audit on data it has never seen (issue 17): recordings of a second, independent tower-
// crane simulator written for this test (crane_independent_simulator.hpp: its own chart of the
// cable, Lagrangian by hyper-dual numbers, RK4, stick-slip rule, injections, PD tuning, references
// and sensors). Every crane catalog entry (the ten drive entries on each drive, the swing entries,
// payload_mass_error), seeded random magnitudes, plus clean cases; the right cause in >= 95 % of
// the effect cases, `none` on every clean case. A case reported `ambiguous` counts as right only
// when the truth is one of the two named.
//
// Counts (env): CRANE_AUDIT_INDEPENDENT_CRANE_CASES effect cases (default 4), case i takes entry
// (7 i) mod 29 (so 29 cases take every entry once, 58 twice); CRANE_AUDIT_INDEPENDENT_CRANE_CLEAN
// clean cases (default 2); CRANE_AUDIT_INDEPENDENT_CRANE_FIRST the first case index (seeds are kept:
// 60000 + i); CRANE_AUDIT_INDEPENDENT_DUMP=DIR writes each recording as a crane CSV. The rates, the
// confusion matrix and the fitted main parameters are printed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <string>

#include "audit_test_report.hpp"
#include "crane/model_audit/model_audit.hpp"
#include "crane_independent_simulator.hpp"

namespace ma = crane::model_audit;
namespace mt = crane::model_audit::test;

namespace {

using crane::model_audit::test::env_count;

std::string reported_name(const ma::AuditReport& report) {
  std::string reported = report.cause;
  if (report.cause == "ambiguous") {
    reported = "ambiguous(";
    for (const auto& name : report.ambiguous_with) reported += name + (name == report.ambiguous_with.back() ? ")" : ",");
  }
  if (report.second_cause != "none") reported += "+" + report.second_cause;
  return reported;
}

void print_report(const ma::AuditReport& report) {
  for (const auto& channel : report.channels) {
    std::printf("    channel %-16s cause %-28s training %.4g, held-out %.4g %s, Ljung-Box p %.3g\n",
                channel.channel.c_str(), channel.cause.c_str(), channel.before.train_rms, channel.holdout_before,
                channel.unit.c_str(), channel.before.whiteness.p_value);
    mt::print_candidates(channel, 2, 34);
  }
  mt::print_candidates(report, 4, 34);
  std::printf("    stop reason: %s\n", report.stop_reason.c_str());
}

// CRANE_AUDIT_INDEPENDENT_DUMP=DIR: each case also as DIR/independent_crane_SEED.csv (the crane
// columns of read_audit_data), for crane_audit.
void dump(const mt::IndependentCraneCase& c, std::uint64_t seed) {
  const char* dir = std::getenv("CRANE_AUDIT_INDEPENDENT_DUMP");
  if (dir == nullptr || *dir == '\0') return;
  std::ofstream out(std::string(dir) + "/independent_crane_" + std::to_string(seed) + ".csv");
  ma::write_audit_data(out, c.data, ma::AuditPlant::crane);
}

}  // namespace

TEST(IndependentSimulator, CraneAuditNamesEveryCauseAndInventsNothing) {
  const auto& entries = mt::independent_crane_entries();
  // This simulator produces every entry of the audit's crane catalog.
  const auto& catalog = ma::audit_catalog(ma::AuditPlant::crane);
  EXPECT_EQ(entries.size(), catalog.size());
  for (const auto& e : entries) EXPECT_NE(std::find(catalog.begin(), catalog.end(), e), catalog.end()) << e;
  const std::size_t cases = env_count("CRANE_AUDIT_INDEPENDENT_CRANE_CASES", 4);
  const std::size_t clean = env_count("CRANE_AUDIT_INDEPENDENT_CRANE_CLEAN", 2);
  const std::size_t first = env_count("CRANE_AUDIT_INDEPENDENT_CRANE_FIRST", 0);
  std::map<std::string, std::map<std::string, int>> confusion;
  int effect_cases = 0, correct = 0, ambiguous = 0, clean_cases = 0, clean_none = 0, spurious_second = 0;
  for (std::size_t i = first; i < cases + clean; ++i) {
    const bool is_clean = i >= cases;
    const std::string cause = is_clean ? "none" : entries[(7 * i) % entries.size()];
    const std::uint64_t seed = 60000 + i;
    const auto c = mt::independent_crane_case(cause, seed);
    dump(c, seed);
    ma::AuditOptions options;
    options.nominal = c.nominal;
    const auto report = ma::run_audit(c.data, options);
    const std::string reported = reported_name(report);
    confusion[cause][reported] += 1;
    if (is_clean) {
      ++clean_cases;
      clean_none += report.cause == "none" ? 1 : 0;
      std::printf("  clean seed %llu: %s\n", static_cast<unsigned long long>(seed), reported.c_str());
      print_report(report);
      continue;
    }
    ++effect_cases;
    const auto& twins = report.ambiguous_with;
    const bool right = report.cause == cause || std::find(twins.begin(), twins.end(), cause) != twins.end();
    correct += right ? 1 : 0;
    ambiguous += right && report.cause == "ambiguous" ? 1 : 0;
    spurious_second += report.second_cause != "none" ? 1 : 0;
    double fitted = std::nan("");
    for (const auto& p : report.parameters) {
      if (p.name == c.main_parameter) fitted = p.value;
    }
    std::printf("  %-40s seed %llu: %s  %s true %.5g fitted %.5g (%+.1f %%)\n", cause.c_str(),
                static_cast<unsigned long long>(seed), reported.c_str(), c.main_parameter.c_str(), c.main_value, fitted,
                100.0 * (fitted - c.main_value) / std::abs(c.main_value));
    if (!right || report.second_cause != "none") print_report(report);
  }
  std::printf("\ncrane (independent simulator): right cause %d/%d (%.1f %%, of which %d ambiguous naming the truth); "
              "clean none %d/%d; a second cause in %d\n",
              correct, effect_cases, effect_cases ? 100.0 * correct / effect_cases : 0.0, ambiguous, clean_none,
              clean_cases, spurious_second);
  for (const auto& [truth, row] : confusion) {
    std::printf("  %-40s", truth.c_str());
    for (const auto& [reported, count] : row) std::printf(" %s:%d", reported.c_str(), count);
    std::printf("\n");
  }
  EXPECT_GE(correct, static_cast<int>(std::ceil(0.95 * effect_cases)));
  EXPECT_EQ(clean_none, clean_cases);
}
