#include "channel_audit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "crane/common/validation.hpp"

namespace crane::model_audit::detail {

void ChannelAudit::second_opinion(const std::vector<double>&, const Candidate*, const std::vector<double>&,
                                  AuditReport& report) const {
  report.effort_holdout_before = kNaN;
  report.effort_holdout_after = kNaN;
}

double checked_sample_time(const AuditData& data) {
  const std::size_t n = data.time.size();
  if (n < 50) throw DataError(data.source + ": too few samples: " + std::to_string(n) + " (minimum 50)");
  return (data.time.back() - data.time.front()) / static_cast<double>(n - 1);
}

AuditReport run_channel_audit(const ChannelAudit& channel, const AuditOptions& options) {
  const std::size_t n = channel.samples();
  const std::size_t stride = channel.residuals_per_sample();
  const std::size_t residual_count = stride * n;

  AuditReport report;
  report.plant = channel.plant();
  report.channel = channel.channel();
  report.unit = channel.unit();
  report.sample_time = channel.sample_time();
  report.samples = n;

  // Base parameters and what is free in the nominal fit.
  const std::vector<double>& base = channel.base();
  const std::vector<ParameterSpec>& base_specs = channel.base_specs();
  const std::size_t base_count = base.size();
  FreeSet nominal_free;
  for (const std::size_t i : channel.nominal_free(options.calibrate)) nominal_free.add(i, base_specs[i]);

  // Exclusions.
  std::vector<Candidate> candidates = channel.candidates();
  for (auto& candidate : candidates) {
    const auto& allowed = options.causes;
    if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), candidate.name) == allowed.end()) {
      candidate.note = "not requested (--cause)";
    } else if (options.calibrate && !candidate.calibration_note.empty()) {
      candidate.note = candidate.calibration_note;
    } else {
      candidate.note = channel.unavailable(candidate);
    }
  }

  // Nominal.
  const Problem nominal_problem = channel.problem(nullptr);
  std::size_t train_windows = 0;
  for (const auto& w : nominal_problem.windows) train_windows += w.train_count >= 3 ? 1 : 0;
  if (train_windows == 0) throw DataError(channel.source() + ": too few samples for a training window");
  const Fit nominal = fit_problem(nominal_problem, base, nominal_free, initial_nuisance(nominal_problem), residual_count);
  for (std::size_t i = 0; i < base_count; ++i) {
    report.nominal.push_back({base_specs[i].name, base_specs[i].unit, nominal.full[i], 0.0});
  }
  for (std::size_t j = 0; j < nominal_free.index.size(); ++j) {
    report.nominal[nominal_free.index[j]].standard_error = nominal.standard_errors[j];
  }
  const std::vector<double>& summary_input = channel.correlation_input();
  report.before = summarize(nominal, summary_input, options.max_lag);
  const double bic_nominal = bic(nominal.train_rss, nominal.train_n, 0);
  const double holdout_nominal = report.before.holdout_rms;
  const double quantum = channel.quantum();
  // Practical-significance floor of the held-out gain [channel unit].
  const double resolution_floor = std::max(options.min_holdout_gain_quanta * quantum,
                                           options.min_holdout_gain_resolutions * channel.resolution());
  const double relative_floor = channel.second_step_gain_fraction() * holdout_nominal;
  const double floor = relative_floor > 0.0 ? std::min(resolution_floor, relative_floor) : resolution_floor;
  constexpr double kRestartQuanta = 2.0;  // every_grid_start: restart above this training RMS [quanta]

  // Candidates.
  std::vector<Fit> fits(candidates.size());
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    const Candidate& candidate = candidates[c];
    CandidateReport entry;
    entry.name = candidate.name;
    entry.note = candidate.note;
    if (!candidate.note.empty()) {
      report.candidates.push_back(entry);
      continue;
    }
    const Problem problem = channel.problem(&candidate);
    std::vector<double> full = nominal.full;
    full.resize(base_count + candidate.parameters.size(), 0.0);
    // Coarse grid (nuisance and base from the nominal fit), plus the linear estimate.
    auto points = grid_points(candidate);
    if (const auto linear = channel.linear_estimate(candidate, nominal.full)) {
      points.push_back({std::clamp(*linear, candidate.parameters[0].lower, candidate.parameters[0].upper)});
    }
    double best_rss = std::numeric_limits<double>::infinity();
    std::vector<double> best_point;
    const auto data_nuisance = initial_nuisance(problem);
    std::vector<std::pair<double, std::vector<double>>> scored;  // (rss, point), for extra starts
    for (const auto& point : points) {
      std::vector<double> trial = full;
      std::copy(point.begin(), point.end(), trial.begin() + static_cast<std::ptrdiff_t>(base_count));
      const double rss = train_rss_fixed(problem, trial, data_nuisance);
      scored.emplace_back(rss, point);
      if (rss < best_rss) {
        best_rss = rss;
        best_point = point;
      }
    }
    if (candidate.parameters.size() == 1 && points.size() > 2) {
      // Piecewise-constant costs (stick thresholds, dead zones): take the middle of the flat
      // stretch of the grid around the optimum, where numeric derivatives are zero.
      const auto& grid = candidate.parameters[0].grid;
      const auto at = std::find(grid.begin(), grid.end(), best_point[0]);
      if (at != grid.end()) {
        auto lo = at;
        auto hi = at;
        const auto same = [&](double value) {
          std::vector<double> trial = full;
          trial[base_count] = value;
          return train_rss_fixed(problem, trial, data_nuisance) <= best_rss * (1.0 + 1e-9);
        };
        while (lo != grid.begin() && same(*(lo - 1))) --lo;
        while (hi + 1 != grid.end() && same(*(hi + 1))) ++hi;
        best_point[0] = 0.5 * (*lo + *hi);
      }
    }
    std::copy(best_point.begin(), best_point.end(), full.begin() + static_cast<std::ptrdiff_t>(base_count));
    // Signature: what the candidate changes (at its grid optimum) against the nominal residual.
    {
      std::vector<double> signature;
      std::vector<double> residual;
      for (std::size_t w = 0; w < problem.windows.size(); ++w) {
        const Window& window = problem.windows[w];
        if (window.train_count == 0) continue;
        std::vector<double> with(window.count);
        std::vector<double> without(window.count);
        const double* nz = problem.nuisance_size ? data_nuisance[w].data() : nullptr;
        problem.residual(full, nz, window, window.train_count, with.data());
        problem.residual(nominal.full.size() == full.size() ? nominal.full : [&] {
          auto f = full;
          for (std::size_t i = base_count; i < f.size(); ++i) f[i] = 0.0;
          return f;
        }(), nz, window, window.train_count, without.data());
        for (std::size_t i = 0; i < window.train_count; ++i) {
          if (!std::isfinite(with[i]) || !std::isfinite(without[i])) continue;
          signature.push_back(without[i] - with[i]);
          residual.push_back(without[i]);
        }
      }
      entry.signature_correlation = correlation(residual, signature);
    }
    FreeSet free = nominal_free;
    for (std::size_t i = 0; i < candidate.parameters.size(); ++i) free.add(base_count + i, candidate.parameters[i]);
    auto start_nuisance = nominal.nuisance;
    if (problem.nuisance_size != nominal_problem.nuisance_size) {
      for (std::size_t w = 0; w < start_nuisance.size(); ++w) {
        start_nuisance[w].resize(problem.nuisance_size);
        for (std::size_t i = nominal_problem.nuisance_size; i < problem.nuisance_size; ++i) {
          start_nuisance[w][i] = data_nuisance[w][i];
        }
      }
    }
    const auto fit_from = [&](const std::vector<double>& start) {
      return fit_problem(problem, start, free, start_nuisance, residual_count);
    };
    fits[c] = fit_from(full);
    if (candidate.parameters.size() > 1) {
      // Several parameters (stribeck: level and v_s trade off along a valley): the grid scores use
      // unfitted initial states, so also fit from other starts and keep the lowest training RSS.
      // Extra starts: the best grid points at the second parameter's grid neighbours (below and
      // above) of the grid optimum; with every_grid_start, when the fit still leaves more than
      // kRestartQuanta quanta of training RMS, at each of its other grid values too.
      std::sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
      const auto& second = candidate.parameters[1].grid;
      const auto at = std::find(second.begin(), second.end(), best_point[1]);
      std::vector<double> neighbours;
      if (at != second.end() && at != second.begin()) neighbours.push_back(*(at - 1));
      if (at != second.end() && at + 1 != second.end()) neighbours.push_back(*(at + 1));
      const auto fit_from_best_at = [&](std::vector<double> values) {
        for (const auto& [rss, point] : scored) {
          const auto it = std::find(values.begin(), values.end(), point[1]);
          if (it == values.end()) continue;
          values.erase(it);
          std::vector<double> start = full;
          std::copy(point.begin(), point.end(), start.begin() + static_cast<std::ptrdiff_t>(base_count));
          Fit other = fit_from(start);
          if (other.train_rss < fits[c].train_rss) fits[c] = std::move(other);
        }
      };
      fit_from_best_at(neighbours);
      const double train_rms = std::sqrt(fits[c].train_rss / static_cast<double>(std::max<std::size_t>(fits[c].train_n, 1)));
      if (options.every_grid_start && train_rms > kRestartQuanta * quantum) {
        std::vector<double> others;
        for (const double v : second) {
          if (v != best_point[1] && std::find(neighbours.begin(), neighbours.end(), v) == neighbours.end()) others.push_back(v);
        }
        fit_from_best_at(others);
      }
    }
    channel.refine(candidate, problem, nominal_free, fits[c]);
    const Fit& fit = fits[c];
    for (std::size_t i = 0; i < candidate.parameters.size(); ++i) {
      entry.parameters.push_back({candidate.parameters[i].name, candidate.parameters[i].unit,
                                  fit.full[base_count + i], fit.standard_errors[nominal_free.index.size() + i]});
    }
    entry.fitted = true;
    entry.delta_bic = bic(fit.train_rss, fit.train_n, candidate.parameters.size()) - bic_nominal;
    entry.train_rms = fit.train_n ? std::sqrt(fit.train_rss / static_cast<double>(fit.train_n)) : 0.0;
    entry.holdout_rms = fit.holdout_n ? std::sqrt(fit.holdout_rss / static_cast<double>(fit.holdout_n)) : 0.0;
    entry.holdout_gain_percent = holdout_nominal > 0.0 ? 100.0 * (holdout_nominal - entry.holdout_rms) / holdout_nominal : 0.0;
    entry.qualifies = entry.delta_bic < -options.bic_threshold &&
                      entry.holdout_gain_percent >= options.min_holdout_gain_percent &&
                      holdout_nominal - entry.holdout_rms >= floor;
    report.candidates.push_back(entry);
  }

  // Selection.
  std::ptrdiff_t chosen = -1;
  const bool white = report.before.whiteness.lags > 0 && report.before.whiteness.p_value >= 0.05;
  for (std::size_t c = 0; c < report.candidates.size(); ++c) {
    const auto& entry = report.candidates[c];
    if (!entry.qualifies) continue;
    if (chosen < 0 || entry.delta_bic < report.candidates[static_cast<std::size_t>(chosen)].delta_bic) {
      chosen = static_cast<std::ptrdiff_t>(c);
    }
  }
  // Held-out arbitration, then ambiguity (model_audit.hpp).
  std::string arbitration;
  if (chosen >= 0) {
    const auto& best = report.candidates[static_cast<std::size_t>(chosen)];
    std::ptrdiff_t better = -1;
    for (std::size_t c = 0; c < report.candidates.size(); ++c) {
      const auto& entry = report.candidates[c];
      if (!entry.qualifies || static_cast<std::ptrdiff_t>(c) == chosen) continue;
      const double gain = best.holdout_rms - entry.holdout_rms;
      if (gain >= floor && gain >= 0.01 * kArbitrationPercent * best.holdout_rms &&
          (better < 0 || entry.holdout_rms < report.candidates[static_cast<std::size_t>(better)].holdout_rms)) {
        better = static_cast<std::ptrdiff_t>(c);
      }
    }
    if (better >= 0) {
      arbitration = "; " + report.candidates[static_cast<std::size_t>(better)].name + " predicts the held-out data better than " +
                    best.name + " (" + common::format_value(report.candidates[static_cast<std::size_t>(better)].holdout_rms) +
                    " against " + common::format_value(best.holdout_rms) + " " + report.unit + ")";
      chosen = better;
    }
  }
  std::ptrdiff_t twin = -1;
  if (chosen >= 0) {
    const auto& pick = report.candidates[static_cast<std::size_t>(chosen)];
    for (std::size_t c = 0; c < report.candidates.size(); ++c) {
      const auto& entry = report.candidates[c];
      if (!entry.qualifies || static_cast<std::ptrdiff_t>(c) == chosen) continue;
      if (std::abs(entry.delta_bic - pick.delta_bic) < options.bic_threshold &&
          std::abs(entry.holdout_rms - pick.holdout_rms) < floor &&
          (twin < 0 || entry.delta_bic < report.candidates[static_cast<std::size_t>(twin)].delta_bic)) {
        twin = static_cast<std::ptrdiff_t>(c);
      }
    }
  }
  // A shared signature at a bound (Candidate::limit_of): the selected candidate at its limit is
  // ambiguous with the entry it reduces to. (Not the other way round: when the entry it reduces to
  // is selected, that is already the simpler name of the same signature.)
  // `value`: the picked candidate's limit parameter as finally fitted (refitted with a second cause).
  const auto at_limit = [&](std::size_t c, double value) {
    const Candidate& candidate = candidates[c];
    if (candidate.limit_of.empty() || !report.candidates[c].fitted) return false;
    const ParameterSpec& spec = candidate.parameters[candidate.limit_parameter];
    return value <= std::max(spec.lower + 0.05 * std::abs(spec.lower) + 1e-12, candidate.limit_value);
  };
  const auto fitted_limit = [&](std::size_t c) {
    const auto& p = report.candidates[c].parameters;
    return candidates[c].limit_parameter < p.size() ? p[candidates[c].limit_parameter].value : kNaN;
  };
  const auto limit_twin = [&](std::size_t picked, double picked_value) -> std::ptrdiff_t {
    for (std::size_t c = 0; c < report.candidates.size(); ++c) {
      if (c == picked || !report.candidates[c].fitted) continue;
      if (at_limit(picked, picked_value) && report.candidates[c].name == candidates[picked].limit_of) {
        return static_cast<std::ptrdiff_t>(c);
      }
    }
    return -1;
  };
  if (white) {
    report.stop_reason = "the nominal residual is white (Ljung-Box p = " +
                         common::format_value(report.before.whiteness.p_value) + " >= 0.05)";
    chosen = -1;
  } else if (chosen < 0) {
    report.stop_reason = "no candidate earns its parameters (delta-BIC < -" + common::format_value(options.bic_threshold) +
                         " and held-out gain >= " + common::format_value(options.min_holdout_gain_percent) + " %" +
                         (options.min_holdout_gain_quanta > 0.0
                              ? " and >= " + common::format_value(options.min_holdout_gain_quanta) + " quanta of " +
                                    common::format_value(quantum) + " " + report.unit
                              : std::string()) +
                         (relative_floor > 0.0 ? ", or " + common::format_value(100.0 * channel.second_step_gain_fraction()) +
                                                     " % of the held-out RMS left by the first cause"
                                               : std::string()) +
                         ")";
  }

  // Stepwise: a second cause on top of the first while the residual is still not white, by the same
  // rules against the model with the first cause (its parameters refitted in every fit), stopping
  // at "none". When one is found, the other qualifying candidates within kStepwiseBicFraction of
  // the best delta-BIC are tried as the first too (with several causes every single-cause fit is
  // wrong, and the best single one need not be one of them), and the pair with the lowest joint
  // delta-BIC is kept (model_audit.hpp).
  // An ambiguous first cause (twin) goes on too: the pair found from the pick keeps the ambiguity of
  // its first, a pair from another first (the twin among them) or one whose second is the twin
  // resolves it.
  std::optional<AuditReport> second;
  std::string second_note;
  const auto step_two = [&](std::size_t c) -> std::optional<AuditReport> {
    const ResidualSummary after = summarize(fits[c], summary_input, options.max_lag);
    if (after.whiteness.lags > 0 && after.whiteness.p_value >= 0.05) return std::nullopt;
    const auto next = channel.with_first_cause(candidates[c], fits[c].full);
    if (!next) return std::nullopt;
    AuditOptions step = options;
    step.max_causes = options.max_causes - 1;
    return run_channel_audit(*next, step);
  };
  // A second step that names a cause, or two that share a signature (ambiguous).
  const auto named = [](const std::optional<AuditReport>& r) { return r && r->cause != "none"; };
  const auto joint_bic = [&](std::size_t c, const AuditReport& r) {
    const std::string& name = r.cause == "ambiguous" ? r.ambiguous_with.front() : r.cause;
    for (const auto& e : r.candidates) {
      if (e.name == name) return report.candidates[c].delta_bic + e.delta_bic;
    }
    return report.candidates[c].delta_bic;
  };
  if (options.max_causes > 1 && chosen >= 0 && !white) {
    const std::ptrdiff_t picked = chosen;
    const auto first = static_cast<std::size_t>(chosen);
    second = step_two(first);
    double best_joint = report.candidates[first].delta_bic;
    if (named(second)) {
      best_joint = joint_bic(first, *second);
    } else {
      second_note = second ? second->stop_reason : "";
      second.reset();
    }
    double best_single = 0.0;
    for (const auto& e : report.candidates) best_single = e.qualifies ? std::min(best_single, e.delta_bic) : best_single;
    std::vector<std::size_t> others;
    for (std::size_t c = 0; c < report.candidates.size(); ++c) {
      const auto& e = report.candidates[c];
      if (c != first && e.qualifies && e.delta_bic <= kStepwiseBicFraction * best_single) others.push_back(c);
    }
    std::sort(others.begin(), others.end(),
              [&](std::size_t x, std::size_t y) { return report.candidates[x].delta_bic < report.candidates[y].delta_bic; });
    if (others.size() > kStepwiseAlternatives) others.resize(kStepwiseAlternatives);
    for (const std::size_t c : others) {
      auto alternative = step_two(c);
      if (!named(alternative) || joint_bic(c, *alternative) >= best_joint) continue;
      best_joint = joint_bic(c, *alternative);
      arbitration = "; first of the pair with the lowest joint delta-BIC (" + common::format_value(best_joint) +
                    ", against " + common::format_value(report.candidates[first].delta_bic) + " for " +
                    report.candidates[first].name + (second ? " with its second cause" : " alone") + ")";
      chosen = static_cast<std::ptrdiff_t>(c);
      second = std::move(alternative);
      second_note.clear();
    }
    if (twin >= 0 && second) {
      const std::string& twin_name = report.candidates[static_cast<std::size_t>(twin)].name;
      const bool twin_second = second->cause == twin_name ||
                               std::find(second->ambiguous_with.begin(), second->ambiguous_with.end(), twin_name) !=
                                   second->ambiguous_with.end();
      if (chosen != picked || twin_second) twin = -1;
    }
  } else if (options.max_causes > 1 && chosen < 0 && !white && channel.pairs_without_single()) {
    // No single cause earns its parameters, where each of two causes alone can leave the held-out
    // RMS above the floor (ChannelAudit::pairs_without_single): the best first causes by delta-BIC
    // each get a second step, and the pair with the lowest joint delta-BIC is kept when together
    // they lower the held-out RMS by the floor and the held-out gain.
    std::vector<std::size_t> firsts;
    for (std::size_t c = 0; c < report.candidates.size(); ++c) {
      if (report.candidates[c].fitted && report.candidates[c].delta_bic < -options.bic_threshold) firsts.push_back(c);
    }
    std::sort(firsts.begin(), firsts.end(),
              [&](std::size_t x, std::size_t y) { return report.candidates[x].delta_bic < report.candidates[y].delta_bic; });
    if (firsts.size() > kStepwiseAlternatives + 1) firsts.resize(kStepwiseAlternatives + 1);
    double best_joint = -options.bic_threshold;
    for (const std::size_t c : firsts) {
      auto pair = step_two(c);
      if (!named(pair)) continue;
      const double gain = holdout_nominal - pair->holdout_after;
      if (gain < floor || 100.0 * gain < options.min_holdout_gain_percent * holdout_nominal) continue;
      if (joint_bic(c, *pair) >= best_joint) continue;
      best_joint = joint_bic(c, *pair);
      chosen = static_cast<std::ptrdiff_t>(c);
      second = std::move(pair);
    }
    if (second) {
      arbitration = "; no single cause earns its parameters, the pair does: the lowest joint delta-BIC (" +
                    common::format_value(best_joint) + ") among the first " + std::to_string(firsts.size()) +
                    " causes by delta-BIC, held-out RMS " + common::format_value(holdout_nominal) + " -> " +
                    common::format_value(second->holdout_after) + " " + report.unit;
    }
  }

  if (chosen >= 0 && twin < 0) {  // the (pair's) first cause at a limit, as finally fitted
    const auto c = static_cast<std::size_t>(chosen);
    double value = fitted_limit(c);
    if (second && !candidates[c].limit_of.empty() && base_count + candidates[c].limit_parameter < second->extended_nominal.size()) {
      value = second->extended_nominal[base_count + candidates[c].limit_parameter].value;
    }
    twin = limit_twin(c, value);
  }

  const Fit* selected = &nominal;
  const Candidate* selected_candidate = nullptr;
  if (chosen >= 0) {
    const auto& entry = report.candidates[static_cast<std::size_t>(chosen)];
    // candidates and report.candidates are in the same order here (ranking comes later).
    selected = &fits[static_cast<std::size_t>(chosen)];
    selected_candidate = &candidates[static_cast<std::size_t>(chosen)];
    report.cause = entry.name;
    report.parameters = entry.parameters;
    for (std::size_t i = 0; i < base_count; ++i) {
      report.extended_nominal.push_back({base_specs[i].name, base_specs[i].unit, selected->full[i], 0.0});
    }
    for (std::size_t j = 0; j < nominal_free.index.size(); ++j) {
      report.extended_nominal[nominal_free.index[j]].standard_error = selected->standard_errors[j];
    }
    report.stop_reason = "selected " + entry.name + (arbitration.empty() ? " (lowest delta-BIC among qualifying candidates)" : arbitration);
    if (twin >= 0) {
      const auto& other = report.candidates[static_cast<std::size_t>(twin)];
      report.cause = "ambiguous";
      report.ambiguous_with = {entry.name, other.name};
      const Candidate& picked = candidates[static_cast<std::size_t>(chosen)];
      const Candidate& twin_candidate = candidates[static_cast<std::size_t>(twin)];
      const bool at_bound = picked.limit_of == other.name || twin_candidate.limit_of == entry.name;
      const Candidate& limit_case = picked.limit_of == other.name ? picked : twin_candidate;
      report.stop_reason = "ambiguous: " + entry.name + " and " + other.name + " share a signature on these data (" +
                           (at_bound ? limit_case.name + "'s " + limit_case.parameters[limit_case.limit_parameter].name +
                                           " is at its limit, where it is " + limit_case.limit_of
                                     : "delta-BIC " + common::format_value(entry.delta_bic) + " and " +
                                           common::format_value(other.delta_bic) + ", held-out RMS within the floor of " +
                                           common::format_value(floor) + " " + report.unit) +
                           "); the fit shown is " + entry.name;
    }
    report.after = summarize(*selected, summary_input, options.max_lag);
    if (report.after.whiteness.p_value >= 0.05) report.stop_reason += "; the residual is now white";
    else report.stop_reason += "; the residual is still not white";
  } else {
    report.after = report.before;
  }
  report.holdout_before = holdout_nominal;
  report.holdout_after = report.after.holdout_rms;
  report.holdout_percent = holdout_nominal > 0.0 ? 100.0 * (holdout_nominal - report.holdout_after) / holdout_nominal : 0.0;
  channel.second_opinion(nominal.full, selected_candidate, selected->full, report);

  // Series (the first residual of each sample: the swing's in-plane angle phi).
  report.time = channel.time();
  report.measured.assign(n, kNaN);
  report.nominal_prediction.assign(n, kNaN);
  report.extended_prediction.assign(n, kNaN);
  report.holdout.assign(n, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    const double measured = channel.measured(k);
    const std::size_t i = stride * k;
    report.measured[k] = measured;
    report.holdout[k] = nominal.holdout_flag[i];
    if (std::isfinite(nominal.residual_per_sample[i])) report.nominal_prediction[k] = measured - nominal.residual_per_sample[i];
    if (std::isfinite(selected->residual_per_sample[i])) report.extended_prediction[k] = measured - selected->residual_per_sample[i];
  }

  // Rank: fitted candidates by delta-BIC, then the skipped ones.
  std::stable_sort(report.candidates.begin(), report.candidates.end(), [](const auto& a, const auto& b) {
    if (a.fitted != b.fitted) return a.fitted;
    return a.fitted && a.delta_bic < b.delta_bic;
  });

  if (second) {
    report.second_cause = second->cause;
    report.second_ambiguous_with = second->ambiguous_with;
    report.second_parameters = second->parameters;
    // The first cause's parameters as refitted with the second (base entries after the base).
    for (std::size_t i = 0; i < report.parameters.size() && base_count + i < second->extended_nominal.size(); ++i) {
      report.parameters[i].value = second->extended_nominal[base_count + i].value;
      report.parameters[i].standard_error = second->extended_nominal[base_count + i].standard_error;
    }
    report.extended_nominal.assign(second->extended_nominal.begin(),
                                   second->extended_nominal.begin() + static_cast<std::ptrdiff_t>(base_count));
    report.after = second->after;
    report.holdout_after = second->holdout_after;
    report.holdout_percent = holdout_nominal > 0.0 ? 100.0 * (holdout_nominal - report.holdout_after) / holdout_nominal : 0.0;
    report.extended_prediction = second->extended_prediction;
    report.second_candidates = second->candidates;
    report.stop_reason += "; then " + second->stop_reason;
  } else if (!second_note.empty()) {
    report.stop_reason += "; no second cause (" + second_note + ")";
  }
  return report;
}

}  // namespace crane::model_audit::detail
