// The audit on data it has never seen (issue 17): recordings of a second, independent simulator
// written for this test (independent_simulator.hpp: its own RK4, stick-slip rule, injections, PD
// tuning, reference and sensors). Every catalog cause of the axis and the pendulum, seeded random
// magnitudes, plus clean cases; the right cause in >= 95 % of the effect cases, `none` on every clean
// case. A case whose two candidates share a signature and cannot be told apart may be reported as
// `ambiguous` naming both (AuditReport::ambiguous_with); it counts as right only when the truth is
// one of the two named, and it is counted separately.
//
// Counts (env, as the hidden-effect test): CRANE_AUDIT_INDEPENDENT_CASES effect cases per model
// (default axis 20, pendulum 15: every axis entry twice, every pendulum entry 3 times; 30 s and
// 14 s of CPU), CRANE_AUDIT_INDEPENDENT_CLEAN clean cases per
// model (default 5), CRANE_AUDIT_INDEPENDENT_FIRST the first case index (seeds are kept). The rates
// and the confusion matrix are printed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <numbers>
#include <random>
#include <variant>
#include <string>
#include <vector>

#include "audit_test_report.hpp"
#include "crane/model_audit/model_audit.hpp"
#include "independent_simulator.hpp"

namespace ma = crane::model_audit;
namespace mt = crane::model_audit::test;

namespace {

using crane::model_audit::test::env_count;

struct Tally {
  std::map<std::string, std::map<std::string, int>> confusion;
  int cases{0};
  int correct{0};
  int ambiguous{0};
  int clean_cases{0};
  int clean_none{0};
  int spurious_second{0};  // single-cause cases that also named a second cause
};

void print(const std::string& title, const Tally& tally, const std::vector<std::string>& catalog) {
  std::printf("\n%s (independent simulator): right cause %d/%d (%.1f %%, of which %d ambiguous naming the truth); "
              "clean none %d/%d; a spurious second cause in %d\n",
              title.c_str(), tally.correct, tally.cases, tally.cases ? 100.0 * tally.correct / tally.cases : 0.0,
              tally.ambiguous, tally.clean_none, tally.clean_cases, tally.spurious_second);
  for (const auto& [truth, row] : tally.confusion) {
    std::printf("  %-28s", truth.c_str());
    for (const auto& [reported, count] : row) std::printf(" %s:%d", reported.c_str(), count);
    std::printf("\n");
  }
  (void)catalog;
}

// The three best candidates of a missed case (delta-BIC, held-out RMS and gain, parameters).
void print_report(const ma::AuditReport& report) {
  std::printf("    nominal held-out RMS %.4g %s, Ljung-Box p %.3g\n", report.holdout_before, report.unit.c_str(),
              report.before.whiteness.p_value);
  mt::print_candidates(report);
}

// CRANE_AUDIT_INDEPENDENT_DUMP=DIR: each case also as DIR/independent_SEED.csv (t,u,x or
// t,theta,segment: the columns of read_audit_data), for crane_audit.
void dump(const mt::IndependentCase& c, std::uint64_t seed) {
  const char* dir = std::getenv("CRANE_AUDIT_INDEPENDENT_DUMP");
  if (dir == nullptr || *dir == '\0') return;
  std::ofstream out(std::string(dir) + "/independent_" + std::to_string(seed) + ".csv");
  ma::write_audit_data(out, c.data, c.data.input.empty() ? ma::AuditPlant::pendulum : ma::AuditPlant::axis);
}

std::string reported_name(const ma::AuditReport& report) {
  std::string reported = report.cause;
  if (report.cause == "ambiguous") {
    reported = "ambiguous(";
    for (const auto& name : report.ambiguous_with) reported += name + (name == report.ambiguous_with.back() ? ")" : ",");
  }
  if (report.second_cause == "ambiguous") {
    reported += "+ambiguous(" + report.second_ambiguous_with.front() + "," + report.second_ambiguous_with.back() + ")";
  } else if (report.second_cause != "none") {
    reported += "+" + report.second_cause;
  }
  return reported;
}

bool names(const ma::AuditReport& report, const std::string& cause) {
  if (report.cause == cause || report.second_cause == cause) return true;
  for (const auto& name : report.ambiguous_with) {
    if (name == cause) return true;
  }
  for (const auto& name : report.second_ambiguous_with) {
    if (name == cause) return true;
  }
  return false;
}

Tally run(ma::AuditPlant plant, std::size_t effect_cases, std::size_t clean_cases, std::uint64_t seed_base,
          std::size_t first) {
  const auto& catalog = ma::audit_catalog(plant);
  Tally tally;
  for (std::size_t i = first; i < effect_cases + clean_cases; ++i) {
    const bool clean = i >= effect_cases;
    const std::string cause = clean ? "none" : catalog[i % catalog.size()];
    const std::uint64_t seed = seed_base + i;
    const auto c = plant == ma::AuditPlant::axis ? mt::independent_axis_case(cause, seed)
                                                 : mt::independent_pendulum_case(cause, seed);
    dump(c, seed);
    ma::AuditOptions options;
    options.nominal = c.nominal;
    const auto report = ma::run_audit(c.data, options);
    const std::string reported = reported_name(report);
    tally.confusion[cause][reported] += 1;
    if (clean) {
      ++tally.clean_cases;
      tally.clean_none += report.cause == "none" ? 1 : 0;
      if (report.cause != "none") {
        std::printf("  clean seed %llu reported %s\n", static_cast<unsigned long long>(seed), reported.c_str());
        print_report(report);
      }
      continue;
    }
    ++tally.cases;
    if (report.second_cause != "none") {
      ++tally.spurious_second;
      std::printf("  %s seed %llu: also a second cause %s\n", cause.c_str(), static_cast<unsigned long long>(seed),
                  report.second_cause.c_str());
    }
    const auto& twins = report.ambiguous_with;
    if (report.cause == cause || std::find(twins.begin(), twins.end(), cause) != twins.end()) {
      ++tally.correct;
      tally.ambiguous += report.cause == "ambiguous" ? 1 : 0;
    } else {
      std::printf("  missed: %s seed %llu reported %s (%s)\n", cause.c_str(), static_cast<unsigned long long>(seed),
                  reported.c_str(), report.stop_reason.c_str());
      print_report(report);
    }
  }
  return tally;
}

void expect_found(ma::AuditPlant plant, std::size_t default_cases, std::uint64_t seed_base) {
  const std::size_t cases = env_count("CRANE_AUDIT_INDEPENDENT_CASES", default_cases);
  const std::size_t clean = env_count("CRANE_AUDIT_INDEPENDENT_CLEAN", 5);
  const Tally tally = run(plant, cases, clean, seed_base, env_count("CRANE_AUDIT_INDEPENDENT_FIRST", 0));
  print(plant == ma::AuditPlant::axis ? "axis" : "pendulum", tally, ma::audit_catalog(plant));
  EXPECT_GE(tally.correct, static_cast<int>(std::ceil(0.95 * tally.cases)));
  EXPECT_EQ(tally.clean_none, tally.clean_cases);
}

}  // namespace

TEST(IndependentSimulator, AxisAuditNamesEveryCauseAndInventsNothing) { expect_found(ma::AuditPlant::axis, 20, 20000); }

TEST(IndependentSimulator, PendulumAuditNamesEveryCauseAndInventsNothing) {
  expect_found(ma::AuditPlant::pendulum, 15, 30000);
}

// A long large-amplitude free swing with Coulomb pivot friction (issue 17): 1.6 rad decaying to
// about 0.3 rad over about 60 cycles, a 12-bit encoder with 0.5 mrad of noise, 100 Hz; the audit
// (nominal length and viscous damping as simulated, and again with --calibrate from a length 3 %
// off) must name pendulum_coulomb_damping with mu within 10 %.
TEST(IndependentSimulator, LongLargeAmplitudeSwingWithCoulombPivotFrictionIsNamed) {
  constexpr double kLength = 0.15;      // [m] as the Kaheman arm's equivalent length
  constexpr double kCoulomb = 0.30;     // [rad/s^2]
  constexpr double kDamping = 0.005;    // [1/s]
  const auto c = mt::long_coulomb_swing(1.6, kLength, kDamping, kCoulomb, 48.0, 5e-4, 100.0, 4242);
  double last = 0.0;
  for (std::size_t k = c.data.output.size() - 100; k < c.data.output.size(); ++k) {
    last = std::max(last, std::abs(c.data.output[k] - std::numbers::pi));
  }
  std::printf("long swing: 1.6 rad -> %.3f rad after 48 s\n", last);
  for (const bool calibrate : {false, true}) {
    ma::AuditOptions options;
    auto nominal = std::get<ma::PendulumAuditParameters>(c.nominal);
    if (calibrate) nominal.length *= 1.03;
    options.nominal = nominal;
    options.calibrate = calibrate;
    const auto report = ma::run_audit(c.data, options);
    std::printf("long swing%s: cause %s (%s)\n", calibrate ? " (--calibrate)" : "", report.cause.c_str(),
                report.stop_reason.c_str());
    print_report(report);
    EXPECT_EQ(report.cause, "pendulum_coulomb_damping");
    for (const auto& p : report.parameters) {
      if (p.name == "coulomb_damping") {
        EXPECT_NEAR(p.value, kCoulomb, 0.1 * kCoulomb);
      }
    }
  }
}

// Two simultaneous causes (issue 17): pairs of distinct catalog entries drawn with the seed, both
// with seeded random magnitudes; the stepwise audit must name both (in either order; an ambiguous
// first step counts when it names one and the second step the other) in >= 90 % of the cases.
// Env CRANE_AUDIT_INDEPENDENT_PAIRS (per model; default axis 10, pendulum 8).
void expect_pairs_found(ma::AuditPlant plant, std::size_t default_cases, std::uint64_t seed_base) {
  const std::size_t cases = env_count("CRANE_AUDIT_INDEPENDENT_PAIRS", default_cases);
  const auto& catalog = ma::audit_catalog(plant);
  int both = 0;
  int first_only = 0;
  int tried = 0;
  std::map<std::string, int> missed;
  for (std::size_t i = env_count("CRANE_AUDIT_INDEPENDENT_FIRST", 0); i < cases; ++i) {
    ++tried;
    const std::uint64_t seed = seed_base + i;
    std::mt19937_64 pick(seed);
    const std::size_t a = pick() % catalog.size();
    std::size_t b = pick() % (catalog.size() - 1);
    if (b >= a) ++b;
    const auto c = plant == ma::AuditPlant::axis ? mt::independent_axis_case(catalog[a], seed, catalog[b])
                                                 : mt::independent_pendulum_case(catalog[a], seed, catalog[b]);
    ma::AuditOptions options;
    options.nominal = c.nominal;
    const auto report = ma::run_audit(c.data, options);
    const bool found = names(report, catalog[a]) && names(report, catalog[b]);
    both += found ? 1 : 0;
    first_only += !found && (names(report, catalog[a]) || names(report, catalog[b])) ? 1 : 0;
    if (!found) {
      std::printf("  pair %s + %s seed %llu reported %s (%s)\n", catalog[a].c_str(), catalog[b].c_str(),
                  static_cast<unsigned long long>(seed), reported_name(report).c_str(), report.stop_reason.c_str());
      for (const auto& p : report.parameters) std::printf("    first: %s = %.4g\n", p.name.c_str(), p.value);
      for (const auto& p : report.second_parameters) std::printf("    second: %s = %.4g\n", p.name.c_str(), p.value);
      print_report(report);
      missed[catalog[a] + "+" + catalog[b]] += 1;
    }
  }
  std::printf("\n%s pairs (independent simulator): both named %d/%zu (%.1f %%), one of the two %d\n",
              plant == ma::AuditPlant::axis ? "axis" : "pendulum", both, static_cast<std::size_t>(tried),
              tried ? 100.0 * both / static_cast<double>(tried) : 0.0, first_only);
  EXPECT_GE(both, static_cast<int>(std::ceil(0.90 * static_cast<double>(tried))));
}

TEST(IndependentSimulator, AxisAuditNamesBothOfTwoSimultaneousCauses) {
  expect_pairs_found(ma::AuditPlant::axis, 10, 40000);
}

TEST(IndependentSimulator, PendulumAuditNamesBothOfTwoSimultaneousCauses) {
  expect_pairs_found(ma::AuditPlant::pendulum, 8, 50000);
}

// The missed encoder offset: 0.8 deg on one free swing (no segments; theta_zero given), and
// the same swing without it reported none.
TEST(IndependentSimulator, EncoderOffsetOfZeroPointEightDegreesOnOneFreeSwingIsNamed) {
  for (const double offset : {0.8 * std::numbers::pi / 180.0, 0.0}) {
    mt::PendulumTruth truth;
    truth.length = 0.8;
    truth.damping = 0.02;
    truth.offset = offset;
    const double start[1] = {0.35};
    auto data = mt::simulate_free_swings(truth, start, 1, 20.0, 0.01, 1.5e-4, 2.0 * std::numbers::pi / 16384, 77);
    data.segment.clear();
    ma::PendulumAuditParameters nominal;
    nominal.length = truth.length;
    nominal.damping = truth.damping;
    nominal.theta_zero = truth.zero;
    ma::AuditOptions options;
    options.nominal = nominal;
    const auto report = ma::run_audit(data, options);
    std::printf("one free swing, offset %.4f rad: %s (%s)\n", offset, reported_name(report).c_str(), report.stop_reason.c_str());
    print_report(report);
    if (offset == 0.0) {
      EXPECT_EQ(report.cause, "none");
    } else {
      EXPECT_EQ(report.cause, "encoder_offset");
      for (const auto& p : report.parameters) EXPECT_NEAR(p.value, offset, 0.1 * offset);
    }
  }
}
