#include "crane/model_audit/audit_report.hpp"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "crane/common/validation.hpp"
#include "crane/model_audit/measured_data.hpp"

namespace crane::model_audit {

void write_audit_report(const AuditReport& report, const std::filesystem::path& directory,
                        const std::string& command_line) {
  std::error_code error;
  std::filesystem::create_directories(directory, error);
  if (error) throw DataError(directory.string() + ": cannot create the output directory: " + error.message());
  const auto number = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  const auto parameters_json = [&](const std::vector<FittedParameter>& list) {
    nlohmann::json out = nlohmann::json::object();
    for (const auto& p : list) {
      out[p.name] = {{"value", number(p.value)}, {"standard_error", number(p.standard_error)}, {"unit", p.unit}};
    }
    return out;
  };
  const auto summary_json = [&](const ResidualSummary& s) {
    nlohmann::json a = nlohmann::json::array();
    for (const double r : s.whiteness.autocorrelation) a.push_back(number(r));
    return nlohmann::json{{"train_rms", number(s.train_rms)},
                          {"holdout_rms", number(s.holdout_rms)},
                          {"ljung_box_q", number(s.whiteness.ljung_box_statistic)},
                          {"ljung_box_p", number(s.whiteness.p_value)},
                          {"lags", s.whiteness.lags},
                          {"white", s.whiteness.lags > 0 && s.whiteness.p_value >= 0.05},
                          {"autocorrelation", a},
                          {"input_correlation", number(s.input_correlation)}};
  };
  nlohmann::json json;
  json["model"] = report.plant;
  json["channel"] = report.channel;
  json["cause"] = report.cause;
  if (!report.ambiguous_with.empty()) json["ambiguous_with"] = report.ambiguous_with;
  json["stop_reason"] = report.stop_reason;
  json["parameters"] = parameters_json(report.parameters);
  json["second_cause"] = report.second_cause;
  if (!report.second_ambiguous_with.empty()) json["second_ambiguous_with"] = report.second_ambiguous_with;
  if (report.second_cause != "none") json["second_parameters"] = parameters_json(report.second_parameters);
  if (!report.second_channel.empty()) json["second_channel"] = report.second_channel;
  json["gain"] = {{"metric", "holdout_rms_" + report.channel + " [" + report.unit + "]"},
                  {"before", number(report.holdout_before)},
                  {"after", number(report.holdout_after)},
                  {"percent", number(report.holdout_percent)}};
  json["nominal"] = parameters_json(report.nominal);
  if (!report.extended_nominal.empty()) json["nominal_refitted_with_cause"] = parameters_json(report.extended_nominal);
  json["residual_before"] = summary_json(report.before);
  json["residual_after"] = summary_json(report.after);
  const auto effort_json = [&](const AuditReport& r) {
    return nlohmann::json{{"before", number(r.effort_holdout_before)}, {"after", number(r.effort_holdout_after)}};
  };
  if (report.plant == "axis") json["effort_holdout_rms_V"] = effort_json(report);
  if (!report.channels.empty()) {
    nlohmann::json channels = nlohmann::json::array();
    for (const auto& c : report.channels) {
      nlohmann::json entry{{"name", c.plant},
                           {"channel", c.channel},
                           {"unit", c.unit},
                           {"cause", c.cause},
                           {"stop_reason", c.stop_reason},
                           {"holdout_rms", {{"before", number(c.holdout_before)}, {"after", number(c.holdout_after)}}},
                           {"residual_before", summary_json(c.before)},
                           {"residual_after", summary_json(c.after)}};
      if (c.channel == "position") entry["effort_holdout_rms_V"] = effort_json(c);
      channels.push_back(entry);
    }
    json["channels"] = channels;
  }
  nlohmann::json list = nlohmann::json::array();
  int rank = 0;
  for (const auto& c : report.candidates) {
    nlohmann::json entry{{"name", c.name}, {"fitted", c.fitted}};
    if (c.fitted) {
      entry["rank"] = ++rank;
      entry["delta_bic"] = number(c.delta_bic);
      entry["holdout_rms"] = number(c.holdout_rms);
      entry["holdout_gain_percent"] = number(c.holdout_gain_percent);
      entry["train_rms"] = number(c.train_rms);
      entry["signature_correlation"] = number(c.signature_correlation);
      entry["qualifies"] = c.qualifies;
      entry["parameters"] = parameters_json(c.parameters);
    } else {
      entry["note"] = c.note;
    }
    list.push_back(entry);
  }
  json["candidates"] = list;
  json["sample_time"] = report.sample_time;
  json["samples"] = report.samples;
  json["command"] = command_line;
  {
    std::ofstream out(directory / "report.json");
    out << json.dump(2) << '\n';
    if (!out) throw DataError((directory / "report.json").string() + ": write failed");
  }
  {
    std::ofstream md(directory / "report.md");
    md << "# Model audit: " << report.plant << "\n\n";
    md << "Command: `" << command_line << "`\n\n";
    md << "**Cause: `" << report.cause << "`** (" << report.stop_reason << ")\n\n";
    if (!report.parameters.empty()) {
      md << "| parameter | value | std. error | unit |\n|---|---|---|---|\n";
      for (const auto& p : report.parameters) {
        md << "| " << p.name << " | " << common::format_value(p.value) << " | " << common::format_value(p.standard_error)
           << " | " << p.unit << " |\n";
      }
      md << "\n";
    }
    if (report.second_cause != "none") {
      md << "\n**Second cause: `" << report.second_cause << "`** ("
         << (report.second_channel.empty() ? "stepwise, on top of the first"
                                           : "on the " + report.second_channel + " channel, beside the first")
         << ")\n\n";
      md << "| parameter | value | std. error | unit |\n|---|---|---|---|\n";
      for (const auto& p : report.second_parameters) {
        md << "| " << p.name << " | " << common::format_value(p.value) << " | " << common::format_value(p.standard_error)
           << " | " << p.unit << " |\n";
      }
      md << "\n";
    }
    md << "Held-out RMS (" << report.channel << ", " << report.unit << "): " << common::format_value(report.holdout_before)
       << " -> " << common::format_value(report.holdout_after) << " (" << common::format_value(report.holdout_percent)
       << " %)\n\n";
    md << "Nominal:";
    for (const auto& p : report.nominal) md << " " << p.name << " = " << common::format_value(p.value) << " " << p.unit << ";";
    if (!report.channels.empty()) {
      md << "\n\n| channel | cause | held-out RMS before | after | effort RMS before [V] | after [V] | Ljung-Box p |\n"
            "|---|---|---|---|---|---|---|\n";
      for (const auto& c : report.channels) {
        md << "| " << c.plant << " " << c.channel << " [" << c.unit << "] | " << c.cause << " | "
           << common::format_value(c.holdout_before) << " | " << common::format_value(c.holdout_after) << " | "
           << common::format_value(c.effort_holdout_before) << " | " << common::format_value(c.effort_holdout_after)
           << " | " << common::format_value(c.before.whiteness.p_value) << " |\n";
      }
    }
    md << "\n\nResidual before: Ljung-Box p = " << common::format_value(report.before.whiteness.p_value)
       << ", after: p = " << common::format_value(report.after.whiteness.p_value) << "\n\n";
    md << "| rank | candidate | delta-BIC | held-out RMS | gain % | signature corr. | parameters |\n|---|---|---|---|---|---|---|\n";
    int r = 0;
    for (const auto& c : report.candidates) {
      if (!c.fitted) {
        md << "| - | " << c.name << " | skipped: " << c.note << " | | | | |\n";
        continue;
      }
      md << "| " << ++r << " | " << c.name << " | " << common::format_value(std::round(c.delta_bic * 10) / 10) << " | "
         << common::format_value(c.holdout_rms) << " | " << common::format_value(std::round(c.holdout_gain_percent * 10) / 10)
         << " | " << common::format_value(std::round(c.signature_correlation * 100) / 100) << " |";
      for (const auto& p : c.parameters) md << " " << p.name << " = " << common::format_value(p.value);
      md << " |\n";
    }
  }
  {
    std::ofstream csv(directory / "series.csv");
    write_time_series_csv(csv, {"model audit series: " + report.plant + ", channel " + report.channel + " [" + report.unit + "]"},
                          {"t", "measured", "nominal", "extended", "holdout"},
                          {report.time, report.measured, report.nominal_prediction, report.extended_prediction, report.holdout});
  }
}

}  // namespace crane::model_audit
