#pragma once
// The model audit's report files (crane_audit, library crane::model_audit_report): the audit
// itself (crane::model_audit) writes no files.
//
//  - report.json: model, channel, cause, stop_reason, parameters of the cause {value,
//    standard_error, unit}, gain {metric, before, after, percent} on the held-out part, nominal
//    (and nominal_refitted_with_cause), residual_before/after (RMS, Ljung-Box Q and p, lags, white,
//    autocorrelation, input correlation), effort_holdout_rms_V (axis), channels (crane), ranked
//    candidates {rank, delta_bic, holdout_rms, holdout_gain_percent, train_rms,
//    signature_correlation, qualifies, parameters} or {note} when skipped, sample_time, samples,
//    command. Non-finite numbers are written as null.
//  - report.md: the same for a reader, with the candidate table.
//  - series.csv: t [s], measured, nominal, extended (predictions), holdout (1 = held out), in the
//    channel's unit.

#include <filesystem>
#include <string>

#include "crane/model_audit/model_audit.hpp"

namespace crane::model_audit {

/// Writes DIR/report.json, DIR/report.md and DIR/series.csv of `report`. `command_line` goes into
/// the JSON and the markdown. Creates DIR. Throws DataError (measured_data.hpp) on I/O failure.
void write_audit_report(const AuditReport& report, const std::filesystem::path& directory,
                        const std::string& command_line);

}  // namespace crane::model_audit
