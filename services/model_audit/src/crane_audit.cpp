// The crane audit (model_audit.hpp): three channels (trolley, slew, swing), each an audit of its own
// (AxisAudit per drive with the coupling of the full model, SwingAudit), combined.
#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <optional>

#include "axis_audit.hpp"
#include "crane/common/validation.hpp"
#include "crane/model_audit/zero_phase_filter.hpp"
#include "pendulum_audit.hpp"

namespace crane::model_audit::detail {

namespace {

constexpr const char* kTrolleyPrefix = "trolley_";  // crane catalog names of the trolley axis entries
constexpr const char* kSlewPrefix = "slew_";
constexpr double kSwingWindow = 5.0;  // [s] shortest replay window of the crane swing channel
constexpr double kSwingCutoff = 5.0;  // [Hz] low-pass of the swing angles in the drives' coupling (swing ~0.5 Hz)

// Causes of one channel requested by the crane options: names with `prefix` stripped, pendulum
// names, or payload_mass_error. `requested` = false when the options name causes but none here.
std::vector<std::string> channel_causes(const std::vector<std::string>& causes, const std::string& prefix,
                                        const std::vector<std::string>& catalog, bool with_payload, bool& requested) {
  requested = causes.empty();
  std::vector<std::string> out;
  for (const auto& cause : causes) {
    std::string name = cause;
    if (!prefix.empty()) {
      if (cause == "payload_mass_error" && with_payload) {
        out.push_back(cause);
        continue;
      }
      if (cause.rfind(prefix, 0) != 0) continue;
      name = cause.substr(prefix.size());
    }
    if (std::find(catalog.begin(), catalog.end(), name) != catalog.end()) out.push_back(name);
  }
  requested = requested || !out.empty();
  return out;
}

// Measured motion of the crane per sample: central differences (one-sided copies at the ends).
struct CraneMotion {
  std::vector<plant::ModelState> state;
  std::vector<plant::CoordinateVector> acceleration;
  std::vector<plant::HoistMotion> hoist;
};

CraneMotion crane_motion(const AuditData& data, double sample_time) {
  const std::size_t n = data.time.size();
  const std::vector<double>* q[plant::kNumCoordinates] = {&data.output, &data.swing_in_plane, &data.slew_angle,
                                                           &data.swing_out_of_plane};
  CraneMotion m;
  m.state.resize(n);
  m.acceleration.resize(n);
  m.hoist.resize(n);
  const double t = sample_time;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t c = std::clamp<std::size_t>(k, 1, n - 2);  // stencil centre
    for (int j = 0; j < plant::kNumCoordinates; ++j) {
      const auto& v = *q[j];
      m.state[k].position[j] = v[k];
      m.state[k].velocity[j] = (v[c + 1] - v[c - 1]) / (2.0 * t);
      m.acceleration[k][j] = (v[c + 1] - 2.0 * v[c] + v[c - 1]) / (t * t);
    }
    const auto& L = data.cable_length;
    m.hoist[k] = {L[k], (L[c + 1] - L[c - 1]) / (2.0 * t), (L[c + 1] - 2.0 * L[c] + L[c - 1]) / (t * t)};
  }
  return m;
}

// Drive motion held over [t_k, t_k+1) for the swing replay: position and rates at t_k, the
// acceleration of the interval (mean of the second differences at k and k+1).
std::vector<DriveMotion> swing_drive_motion(const CraneMotion& m) {
  const std::size_t n = m.state.size();
  std::vector<DriveMotion> out(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t next = std::min(k + 1, n - 1);
    DriveMotion& d = out[k];
    d.trolley_position = m.state[k].position[plant::kTrolleyIndex];
    d.trolley_velocity = m.state[k].velocity[plant::kTrolleyIndex];
    d.trolley_acceleration = 0.5 * (m.acceleration[k][plant::kTrolleyIndex] + m.acceleration[next][plant::kTrolleyIndex]);
    d.slew_angle = m.state[k].position[plant::kSlewIndex];
    d.slew_rate = m.state[k].velocity[plant::kSlewIndex];
    d.slew_acceleration = 0.5 * (m.acceleration[k][plant::kSlewIndex] + m.acceleration[next][plant::kSlewIndex]);
    d.cable_length = m.hoist[k].cable_length;
    d.cable_length_rate = m.hoist[k].cable_length_rate;
    d.cable_length_acceleration = m.hoist[k].cable_length_acceleration;
  }
  return out;
}

// Coupling of the drive axes (inverse dynamics of the full model with the measured motion). The
// swing accelerations are not differentiated twice (the swing encoders' quanta would give several
// rad/s^2 of noise): the swing rows of TowerCraneModel give them from the drive accelerations,
// s'' = -M_ss^-1 (M_sa a'' + bias_s), so the drive rows become M_eff a'' + b_eff = (F_x, T_gamma) with
//   M_eff = M_aa - M_as M_ss^-1 M_sa,  b_eff = bias_a - M_as M_ss^-1 bias_s
// at the measured positions and (central-difference) rates. Drive i: I_i a_i + C_i with the inertia
// I_i = M_eff,ii and C_i = b_eff,i + M_eff,ij a_j (the other drive's measured acceleration). The swing
// rows do not depend on the load mass and the drive rows are affine in it, so I and C are affine in
// m: I = I(0) + m dI, C = C(0) + m dC (evaluated at two masses).
// With a swing cause in `effects` (the swing channel's cause, crane_swing.hpp) the swing rows
// are the swing replay's: the encoder offset taken off phi, the cable length scaled by (1 + e), the
// damping terms added to the swing accelerations, and the wind's generalized force (its share of
// the drive rows does not depend on the load mass). With a hook or an elastic rope the rows are the
// extended model's (hooked_model, roped_model: the hook's and the load's masses, the rope's
// stiffness and damping all scale with the suspended mass, so the affinity holds), and the states
// the encoders do not measure (the rigging's angles, the stretch) are those of follow_swing(): the
// model's response to the measured cable angles, from rest at the first sample.
struct DriveCoupling {
  std::vector<double> inertia;           // at the nominal load mass
  std::vector<double> inertia_per_mass;
  std::vector<double> force;
  std::vector<double> force_per_mass;
};

std::pair<DriveCoupling, DriveCoupling> crane_coupling(const common::CraneParameters& crane, const CraneMotion& motion,
                                                      double sample_time, const SwingEffects& effects = {}) {
  const std::size_t n = motion.state.size();
  const bool hooked = effects.rigging_length > 0.0;
  const bool extended = hooked || effects.rope_stretch_ratio > 0.0;
  // The models at the suspended masses 1 and 2 kg (the extended ones split or scale with it).
  common::CraneParameters one = crane;
  one.load_mass = 1.0;
  common::CraneParameters two = crane;
  two.load_mass = 2.0;
  const plant::TowerCraneModel model[2] = {
      extended ? (hooked ? hooked_model(one, effects) : roped_model(one, effects)) : plant::TowerCraneModel(one),
      extended ? (hooked ? hooked_model(two, effects) : roped_model(two, effects)) : plant::TowerCraneModel(two)};
  // The unmeasured states along the record (with a hook or a rope).
  std::vector<SwingState> swing(n);
  for (std::size_t k = 0; k < n; ++k) {
    const plant::ModelState& q = motion.state[k];
    swing[k] = {q.position[plant::kInPlaneSwingIndex] - effects.encoder_offset, q.velocity[plant::kInPlaneSwingIndex],
                q.position[plant::kOutOfPlaneSwingIndex], q.velocity[plant::kOutOfPlaneSwingIndex]};
  }
  if (extended) {
    swing = follow_swing(plant::TowerCraneModel(crane), effects, swing_drive_motion(motion), swing, sample_time);
  }
  std::pair<DriveCoupling, DriveCoupling> out;
  for (auto* c : {&out.first, &out.second}) {
    c->inertia.resize(n);
    c->inertia_per_mass.resize(n);
    c->force.resize(n);
    c->force_per_mass.resize(n);
  }
  const double scale = 1.0 + effects.length_error;
  for (std::size_t k = 0; k < n; ++k) {
    plant::ExtendedState state;
    state.position.head<plant::kNumCoordinates>() = motion.state[k].position;
    state.velocity.head<plant::kNumCoordinates>() = motion.state[k].velocity;
    state.position[plant::kInPlaneSwingIndex] = swing[k].in_plane;
    state.position[plant::kRiggingInPlaneIndex] = swing[k].rigging_in_plane;
    state.velocity[plant::kRiggingInPlaneIndex] = swing[k].rigging_in_plane_rate;
    state.position[plant::kRiggingOutOfPlaneIndex] = swing[k].rigging_out_of_plane;
    state.velocity[plant::kRiggingOutOfPlaneIndex] = swing[k].rigging_out_of_plane_rate;
    const plant::HoistMotion& measured_hoist = motion.hoist[k];
    const plant::HoistMotion hoist{measured_hoist.cable_length * scale, measured_hoist.cable_length_rate * scale,
                                   measured_hoist.cable_length_acceleration * scale};
    const Eigen::Vector2d a(motion.acceleration[k][plant::kTrolleyIndex], motion.acceleration[k][plant::kSlewIndex]);
    const Eigen::Vector2d damping = swing_damping(effects, swing[k].in_plane_rate, swing[k].out_of_plane_rate);
    const HookedSwingElimination e[2] = {eliminate_swing_at(model[0], effects, state, hoist, damping),
                                         eliminate_swing_at(model[1], effects, state, hoist, damping)};
    const Eigen::Matrix2d inertia[2] = {e[0].drive_inertia, e[1].drive_inertia};
    const Eigen::Vector2d bias[2] = {e[0].drive_bias, e[1].drive_bias};
    for (int i = 0; i < 2; ++i) {
      DriveCoupling& c = i == 0 ? out.first : out.second;
      const double force1 = bias[0](i) + inertia[0](i, 1 - i) * a(1 - i);  // at 1 kg
      const double force2 = bias[1](i) + inertia[1](i, 1 - i) * a(1 - i);  // at 2 kg
      c.inertia_per_mass[k] = inertia[1](i, i) - inertia[0](i, i);
      c.force_per_mass[k] = force2 - force1;
      c.inertia[k] = inertia[0](i, i) + (crane.load_mass - 1.0) * c.inertia_per_mass[k];
      c.force[k] = force1 + (crane.load_mass - 1.0) * c.force_per_mass[k];
    }
  }
  return out;
}

// The slew's units: the axis model's metres are radians there ("m/s^2/m" -> "rad/s^2/rad").
std::string slew_unit(const std::string& unit) {
  std::string out;
  std::size_t start = 0;
  while (start <= unit.size()) {
    const std::size_t end = std::min(unit.find('/', start), unit.size());
    const std::string token = unit.substr(start, end - start);
    out += (token == "m" ? "rad" : token.rfind("m^", 0) == 0 ? "rad" + token.substr(1) : token);
    if (end < unit.size()) out += '/';
    start = end + 1;
  }
  return out;
}

// The delta-BIC of one step's cause among its candidates (an ambiguous cause by its better name;
// "none" adds nothing).
double step_delta_bic(const std::vector<CandidateReport>& candidates, const std::string& cause,
                      const std::vector<std::string>& ambiguous_with) {
  const std::string& name = cause == "ambiguous" && !ambiguous_with.empty() ? ambiguous_with.front() : cause;
  for (const auto& candidate : candidates) {
    if (candidate.name == name) return candidate.delta_bic;
  }
  return 0.0;
}

// The joint delta-BIC of a channel's causes against its nominal: its first step's plus its second
// step's.
double pair_delta_bic(const AuditReport& report) {
  return step_delta_bic(report.candidates, report.cause, report.ambiguous_with) +
         step_delta_bic(report.second_candidates, report.second_cause, report.second_ambiguous_with);
}

}  // namespace

AuditReport run_crane_audit(const AuditData& data, const AuditOptions& options) {
  if (options.channel == AuditChannel::effort) {
    throw common::ConfigError("channel: the crane audit fits the position and swing channels and reports the "
                              "effort channel of each drive as a second opinion; do not give --channel effort");
  }
  const std::size_t n = data.time.size();
  if (n < 50) throw DataError(data.source + ": too few samples: " + std::to_string(n) + " (minimum 50)");
  for (const auto* column : {&data.input, &data.output, &data.slew_input, &data.slew_angle, &data.swing_in_plane,
                             &data.swing_out_of_plane, &data.cable_length}) {
    if (column->size() != n) throw DataError(data.source + ": crane columns of different lengths");
  }
  const common::CraneParameters& crane = std::get<common::CraneParameters>(options.nominal);
  const double sample_time = (data.time.back() - data.time.front()) / static_cast<double>(n - 1);
  const CraneMotion motion = crane_motion(data, sample_time);
  // The coupling uses the swing angles low-passed (zero phase, kSwingCutoff): their encoder quanta
  // would otherwise reach the drives through the rates in the centripetal and Coriolis terms.
  AuditData smoothed = data;
  if (sample_time < 0.25 / kSwingCutoff) {
    smoothed.swing_in_plane = zero_phase_low_pass(data.swing_in_plane, kSwingCutoff, 1.0 / sample_time);
    smoothed.swing_out_of_plane = zero_phase_low_pass(data.swing_out_of_plane, kSwingCutoff, 1.0 / sample_time);
  }
  const CraneMotion smoothed_motion = crane_motion(smoothed, sample_time);
  const auto [trolley_coupling, slew_coupling] = crane_coupling(crane, smoothed_motion, sample_time);

  AuditReport report;
  report.plant = "crane";
  report.sample_time = sample_time;
  report.samples = n;
  // With calibrate, each drive's K_m, b and c are fitted first (the AxisAudit's nominal_free); the
  // nominal asymmetries and breakaway excess stay as configured, in volts. The swing channel has no parameter of its own to calibrate (the
  // cable length is measured, gravity is gravity); its catalog is searched as without calibrate.
  common::CraneParameters calibrated = crane;
  std::map<std::string, double> calibrated_errors;  // [the field's unit] first-order standard errors
  std::string calibration_notes;

  // The calibrated K_m, b, c of one drive (its channel's nominal) back in the configuration's terms.
  const auto calibrate_drive = [&](const std::string& prefix, const std::vector<FittedParameter>& fitted,
                                   AxisAuditParameters axis) {
    std::map<std::string, FittedParameter> by_name;
    for (const auto& p : fitted) by_name[p.name] = p;
    // The asymmetries and breakaway excess are the configured volts (AxisAudit scales them with K_m).
    const double scale = by_name.at("K_m").value / axis.motor_constant;
    axis.coulomb_asymmetry *= scale;
    axis.viscous_asymmetry *= scale;
    axis.stiction *= scale;
    axis.stiction_asymmetry *= scale;
    axis.motor_constant = by_name.at("K_m").value;
    axis.viscous = by_name.at("b").value;
    axis.coulomb = by_name.at("c").value;
    DriveParameters drive;
    try {
      drive = drive_parameters_from_axis(axis);
    } catch (const common::ConfigError& e) {
      calibration_notes += prefix + "drive: calibrated K_m " + common::format_value(axis.motor_constant) + ", b " +
                           common::format_value(axis.viscous) + ", c " + common::format_value(axis.coulomb) +
                           " with the configured asymmetries give " + e.what() +
                           ": not expressible in the configuration's terms, its configured values are shown; ";
      return;
    }
    const bool slew = prefix == kSlewPrefix;
    (slew ? calibrated.slew_friction : calibrated.trolley_friction) = drive.friction;
    (slew ? calibrated.slew_drive_gain : calibrated.trolley_drive_gain) = drive.gain;
    // First order, without the covariance of K_m with b and c: (x/K)' = x'/K - x K'/K^2.
    const double k = axis.motor_constant;
    const double se_k = by_name.at("K_m").standard_error;
    const auto ratio_error = [&](double numerator, double se_numerator) {
      return std::hypot(se_numerator / k, numerator * se_k / (k * k));
    };
    calibrated_errors[prefix + "drive_gain"] = se_k;
    const double se_b = by_name.at("b").standard_error;
    const double se_c = by_name.at("c").standard_error;
    calibrated_errors[prefix + "viscous_positive"] = ratio_error(axis.viscous + axis.viscous_asymmetry, se_b);
    calibrated_errors[prefix + "viscous_negative"] = ratio_error(axis.viscous - axis.viscous_asymmetry, se_b);
    calibrated_errors[prefix + "coulomb_positive"] = ratio_error(axis.coulomb + axis.coulomb_asymmetry, se_c);
    calibrated_errors[prefix + "coulomb_negative"] = ratio_error(axis.coulomb - axis.coulomb_asymmetry, se_c);
    calibrated_errors[prefix + "static_positive"] = calibrated_errors[prefix + "coulomb_positive"];
    calibrated_errors[prefix + "static_negative"] = calibrated_errors[prefix + "coulomb_negative"];
  };

  // Drive axes.
  const auto& drive_catalog = audit_catalog(AuditPlant::axis);
  const auto drive_channel = [&](const std::string& prefix, const std::vector<double>& input,
                                 const std::vector<double>& position, const DriveCoupling& coupling,
                                 double drive_inertia, const common::AxisFriction& friction, double gain,
                                 int max_causes) -> std::optional<AuditReport> {
    bool requested = false;
    AuditOptions axis_options = options;
    axis_options.causes = channel_causes(options.causes, prefix, drive_catalog, true, requested);
    if (!requested) return std::nullopt;
    if (max_causes > 1) {
      // A second cause on this drive alone is not payload_mass_error: the load is in both drive rows
      // (a payload error the other drive does not show is another cause's echo).
      if (axis_options.causes.empty()) axis_options.causes = drive_catalog;
      std::erase(axis_options.causes, std::string("payload_mass_error"));
      if (axis_options.causes.empty()) return std::nullopt;  // (an empty list would mean the whole catalog)
    }
    axis_options.nominal = drive_axis_parameters(friction, gain);
    axis_options.min_holdout_gain_quanta = kCraneResolutionQuanta;
    axis_options.max_causes = max_causes;  // 1 first (the combination picks one), 2 for a second on it
    axis_options.every_grid_start = true;
    AuditData axis_data;
    axis_data.source = data.source;
    axis_data.time = data.time;
    axis_data.input = input;
    axis_data.output = position;
    axis_data.coupling_inertia = coupling.inertia;
    axis_data.coupling_inertia_per_mass = coupling.inertia_per_mass;
    axis_data.coupling_force = coupling.force;
    axis_data.coupling_force_per_mass = coupling.force_per_mass;
    axis_data.drive_inertia = drive_inertia;
    axis_data.load_mass = crane.load_mass;
    validate(axis_options);
    AuditReport channel =
        run_channel_audit(AxisAudit(axis_data, std::get<AxisAuditParameters>(axis_options.nominal), axis_options), axis_options);
    channel.plant = prefix.substr(0, prefix.size() - 1);
    const bool slew = prefix == kSlewPrefix;
    if (slew) channel.unit = slew_unit(channel.unit);
    for (auto& candidate : channel.candidates) {
      if (candidate.name != "payload_mass_error") candidate.name = prefix + candidate.name;
      for (auto& p : candidate.parameters) p.unit = slew ? slew_unit(p.unit) : p.unit;
    }
    for (auto& p : channel.extended_nominal) p.unit = slew ? slew_unit(p.unit) : p.unit;
    for (auto& p : channel.second_parameters) p.unit = slew ? slew_unit(p.unit) : p.unit;
    const auto prefixed = [&](const std::string& name) { return name == "payload_mass_error" ? name : prefix + name; };
    if (channel.cause != "none" && channel.cause != "ambiguous") channel.cause = prefixed(channel.cause);
    for (auto& name : channel.ambiguous_with) name = prefixed(name);
    if (channel.second_cause != "none" && channel.second_cause != "ambiguous") channel.second_cause = prefixed(channel.second_cause);
    for (auto& name : channel.second_ambiguous_with) name = prefixed(name);
    for (auto& candidate : channel.second_candidates) candidate.name = prefixed(candidate.name);
    if (options.calibrate && max_causes == 1) calibrate_drive(prefix, channel.nominal, std::get<AxisAuditParameters>(axis_options.nominal));
    return channel;
  };
  const auto trolley_channel = [&](int max_causes, const DriveCoupling& coupling) {
    return drive_channel(kTrolleyPrefix, data.input, data.output, coupling, crane.trolley_drive_mass,
                         crane.trolley_friction, crane.trolley_drive_gain, max_causes);
  };
  const auto slew_channel = [&](int max_causes, const DriveCoupling& coupling) {
    return drive_channel(kSlewPrefix, data.slew_input, data.slew_angle, coupling, crane.jib_inertia,
                         crane.slew_friction, crane.slew_drive_gain, max_causes);
  };
  if (auto c = trolley_channel(1, trolley_coupling)) report.channels.push_back(std::move(*c));
  if (auto c = slew_channel(1, slew_coupling)) report.channels.push_back(std::move(*c));

  // Swing: one cause first (max_causes 1), two for a second on it.
  const auto swing_channel = [&](int max_causes) -> std::optional<AuditReport> {
    bool requested = false;
    AuditOptions swing_options = options;
    std::vector<std::string> swing_catalog;  // the pendulum entries and the crane-only swing entries
    for (const auto& cause : pendulum_catalog()) swing_catalog.emplace_back(cause.name);
    swing_options.causes = channel_causes(options.causes, "", swing_catalog, false, requested);
    double mean_length = 0.0;
    for (const double L : data.cable_length) mean_length += L / static_cast<double>(n);
    PendulumAuditParameters swing_nominal;
    swing_nominal.length = mean_length;
    swing_nominal.gravity = crane.gravity;
    swing_options.nominal = swing_nominal;
    swing_options.window_duration = std::max(options.window_duration, kSwingWindow);
    swing_options.min_holdout_gain_quanta = kCraneResolutionQuanta;
    swing_options.max_causes = max_causes;
    swing_options.calibrate = false;  // nothing of its own to calibrate (above)
    if (!requested) return std::nullopt;
    std::vector<double> measured(2 * n);
    for (std::size_t k = 0; k < n; ++k) {
      measured[2 * k] = data.swing_in_plane[k];
      measured[2 * k + 1] = data.swing_out_of_plane[k];
    }
    AuditData swing_data;
    swing_data.source = data.source;
    swing_data.time = data.time;
    swing_data.output = data.swing_in_plane;
    validate(swing_options);
    const SwingAudit swing(swing_data, std::make_shared<const plant::TowerCraneModel>(crane), swing_drive_motion(motion),
                           std::move(measured), mean_length, crane.gravity, swing_options);
    return run_channel_audit(swing, swing_options);
  };
  if (auto c = swing_channel(1)) report.channels.push_back(std::move(*c));

  // The swing channel's cause in the drives' coupling: with the nominal swing rows a swing cause is
  // also an error of the drives' generalized forces, which a drive entry takes up (an encoder offset
  // is a constant force on the trolley, as a Coulomb asymmetry is). So when the swing channel names
  // a cause, the drives that named one are audited again with it in their coupling (crane_coupling;
  // a hook's rigging or a rope's stretch followed from the measured cable angles). A drive cause does not
  // enter the swing channel's replay (it holds the measured drive motion), so the swing's cause is
  // not the echo of a drive's.
  std::string recoupled;
  const auto swing_report = std::find_if(report.channels.begin(), report.channels.end(),
                                         [](const AuditReport& c) { return c.plant == "swing"; });
  if (swing_report != report.channels.end() && swing_report->cause != "none") {
    const std::string& name = swing_report->cause == "ambiguous" ? swing_report->ambiguous_with.front() : swing_report->cause;
    const auto entry = std::find_if(pendulum_catalog().begin(), pendulum_catalog().end(),
                                    [&](const PendulumCause& c) { return name == c.name; });
    const auto candidate = std::find_if(swing_report->candidates.begin(), swing_report->candidates.end(),
                                        [&](const CandidateReport& c) { return c.name == name; });
    const bool drive_named = std::any_of(report.channels.begin(), report.channels.end(), [](const AuditReport& c) {
      return (c.plant == "trolley" || c.plant == "slew") && c.cause != "none";
    });
    if (drive_named && entry != pendulum_catalog().end() && candidate != swing_report->candidates.end()) {
      std::vector<double> values;
      for (const auto& p : candidate->parameters) values.push_back(p.value);
      SwingEffects effects;
      entry->apply_swing(values.data(), effects);
      const auto [trolley, slew] = crane_coupling(crane, smoothed_motion, sample_time, effects);
      for (auto& channel : report.channels) {
        if (channel.cause == "none" || (channel.plant != "trolley" && channel.plant != "slew")) continue;
        auto again = channel.plant == "trolley" ? trolley_channel(1, trolley) : slew_channel(1, slew);
        if (!again) continue;
        recoupled += "; the " + channel.plant + " channel, which named " + channel.cause + ", audited again with the swing's " +
                     name + " in its coupling: " + again->cause;
        channel = std::move(*again);
      }
    }
  }

  // Two causes on the swing channel where neither alone earns its parameters (each leaves the
  // held-out RMS above the floor; SwingAudit::pairs_without_single): the swing channel audited
  // again with max_causes, its pair kept below (when its joint delta-BIC beats the crane's first
  // cause). The drives' causes are then the pair's echo in their coupling.
  std::optional<AuditReport> swing_pair;
  if (options.max_causes > 1 && swing_report != report.channels.end() && swing_report->cause == "none" &&
      !(swing_report->before.whiteness.lags > 0 && swing_report->before.whiteness.p_value >= 0.05)) {
    auto pair = swing_channel(options.max_causes);
    if (pair && pair->cause != "none" && pair->second_cause != "none") swing_pair = std::move(pair);
  }

  // The nominal as used: the configuration's, with the calibrated drives if asked.
  for (const auto& [name, value] : parameter_values(calibrated)) {
    const auto error = calibrated_errors.find(name);
    report.nominal.push_back({name, "", value, error == calibrated_errors.end() ? 0.0 : error->second});
  }

  // Combine: the qualifying candidate with the lowest delta-BIC over the channels whose nominal
  // residual is not white; payload_mass_error (fitted on both drives) keeps its better fit.
  const AuditReport* chosen_channel = nullptr;
  const CandidateReport* chosen = nullptr;
  const CandidateReport* payload = nullptr;
  for (const auto& channel : report.channels) {
    const bool white = channel.before.whiteness.lags > 0 && channel.before.whiteness.p_value >= 0.05;
    for (const auto& candidate : channel.candidates) {
      if (candidate.name == "payload_mass_error" && candidate.fitted &&
          (payload == nullptr || candidate.delta_bic < payload->delta_bic)) {
        payload = &candidate;
      }
      if (white || !candidate.qualifies) continue;
      if (chosen == nullptr || candidate.delta_bic < chosen->delta_bic) {
        chosen = &candidate;
        chosen_channel = &channel;
      }
    }
  }
  for (const auto& channel : report.channels) {
    for (const auto& candidate : channel.candidates) {
      if (candidate.name == "payload_mass_error" && candidate.fitted && &candidate != payload) continue;
      report.candidates.push_back(candidate);
    }
  }
  std::stable_sort(report.candidates.begin(), report.candidates.end(), [](const auto& a, const auto& b) {
    if (a.fitted != b.fitted) return a.fitted;
    return a.fitted && a.delta_bic < b.delta_bic;
  });
  // The report shows one channel's residuals and series.
  const auto show = [&report](const AuditReport& shown) {
    report.channel = shown.plant + " " + shown.channel;
    report.unit = shown.unit;
    report.before = shown.before;
    report.after = shown.after;
    report.holdout_before = shown.holdout_before;
    report.holdout_after = shown.holdout_after;
    report.holdout_percent = shown.holdout_percent;
    report.effort_holdout_before = shown.effort_holdout_before;
    report.effort_holdout_after = shown.effort_holdout_after;
    report.time = shown.time;
    report.measured = shown.measured;
    report.nominal_prediction = shown.nominal_prediction;
    report.extended_prediction = shown.extended_prediction;
    report.holdout = shown.holdout;
  };
  const AuditReport& shown = chosen_channel != nullptr ? *chosen_channel : report.channels.front();
  show(shown);
  // A cause's parameters as reported; payload_mass_error adds the resulting load_mass.
  const auto cause_parameters = [&](const CandidateReport& cause) {
    std::vector<FittedParameter> out = cause.parameters;
    if (cause.name == "payload_mass_error") {
      const double dm = cause.parameters.front().value;
      out.push_back({"load_mass", "kg", crane.load_mass + dm, cause.parameters.front().standard_error});
    }
    return out;
  };
  if (chosen != nullptr) {
    report.cause = chosen->name;
    report.parameters = cause_parameters(*chosen);
    report.extended_nominal = shown.extended_nominal;
    report.stop_reason = "selected " + chosen->name + " on the " + report.channel +
                         " channel (lowest delta-BIC among qualifying candidates of all channels)" + recoupled;
    // Second cause, across the channels: the cause another channel names by its own selection (its
    // residual not white, a qualifying candidate: delta-BIC, held-out gain beyond the floor, held-out
    // arbitration, ambiguity), the one with the lowest delta-BIC when two channels name one. A channel
    // that names the first cause is explained by it (payload_mass_error is fitted on both drives: one
    // cause). Each channel's replay holds the other channels' measured motion, so a cause of one
    // channel does not enter another's residual; but the load mass is in both drive rows, and a swing
    // cause enters the drives' coupling (nominal swing rows), so a swing cause can leave a drive
    // channel a spurious cause of its own (docs/model_audit.md, "Two causes on different channels").
    const AuditReport* second_channel = nullptr;
    const CandidateReport* second = nullptr;  // the second cause's candidate (ambiguous: the better one)
    for (const auto& channel : report.channels) {
      if (&channel == chosen_channel || channel.cause == "none") continue;
      const std::vector<std::string> names =
          channel.cause == "ambiguous" ? channel.ambiguous_with : std::vector<std::string>{channel.cause};
      if (std::find(names.begin(), names.end(), chosen->name) != names.end()) continue;
      const auto candidate = std::find_if(channel.candidates.begin(), channel.candidates.end(),
                                          [&](const CandidateReport& c) { return c.name == names.front(); });
      if (candidate == channel.candidates.end()) continue;
      if (second == nullptr || candidate->delta_bic < second->delta_bic) {
        second = &*candidate;
        second_channel = &channel;
      }
    }
    // A second cause stepwise on the first cause's own channel (its residual with the first cause
    // still not white; the channel audited again with two causes):
    // - a drive's first cause (not payload_mass_error), when no other channel names a second: a drive
    //   cause does not enter the other channels' replays (each holds the others' measured motion);
    // - a swing cause, also against another channel's second: a swing cause enters the drives'
    //   coupling (nominal swing rows) and can leave a drive a spurious cause, so the swing channel's
    //   own second is kept when its step's delta-BIC is lower than the other channel's cause.
    // The pair is kept when its first is the crane's, or when its joint delta-BIC (first step plus
    // second step) is lower than the crane's first cause alone: the channel's own selection (held-out
    // arbitration, its search over first causes for the pair) may take another first, and with two
    // causes the best single fit is often neither (the rule of kStepwiseBicFraction). The cause, its
    // parameters and the held-out figures are then the pair's.
    std::optional<AuditReport> stepwise;
    std::string stepwise_note;  // why the stepwise pair was not kept
    const bool drive = chosen_channel->plant == "trolley" || chosen_channel->plant == "slew";
    const bool swing = chosen_channel->plant == "swing";
    const bool white_after = chosen_channel->after.whiteness.lags > 0 && chosen_channel->after.whiteness.p_value >= 0.05;
    if (!white_after && options.max_causes > 1 &&
        ((drive && second == nullptr && chosen->name != "payload_mass_error") || swing)) {
      stepwise = swing                                  ? swing_channel(options.max_causes)
                 : chosen_channel->plant == "trolley" ? trolley_channel(options.max_causes, trolley_coupling)
                                                       : slew_channel(options.max_causes, slew_coupling);
      const double joint = stepwise ? pair_delta_bic(*stepwise) : 0.0;
      const bool same_first = stepwise && (stepwise->cause == chosen->name ||
                                           (stepwise->cause == "ambiguous" && stepwise->ambiguous_with.front() == chosen->name));
      const bool beats_other = second == nullptr ||
                               (stepwise && step_delta_bic(stepwise->second_candidates, stepwise->second_cause,
                                                           stepwise->second_ambiguous_with) < second->delta_bic);
      if (stepwise && stepwise->second_cause != "none" && (same_first || joint < chosen->delta_bic) && beats_other) {
        if (!same_first) {
          report.stop_reason = "selected " + stepwise->cause + " on the " + report.channel +
                               " channel, the first of the pair with the lowest joint delta-BIC (" + common::format_value(joint) +
                               ", against " + common::format_value(chosen->delta_bic) + " for " + chosen->name + " alone)";
        }
        report.cause = stepwise->cause;
        report.ambiguous_with = stepwise->ambiguous_with;
        report.parameters = stepwise->parameters;
        report.extended_nominal = stepwise->extended_nominal;
        report.after = stepwise->after;
        report.holdout_after = stepwise->holdout_after;
        report.holdout_percent = stepwise->holdout_percent;
        report.extended_prediction = stepwise->extended_prediction;
        report.second_cause = stepwise->second_cause;
        report.second_ambiguous_with = stepwise->second_ambiguous_with;
        report.second_parameters = stepwise->second_parameters;
        report.second_channel = chosen_channel->plant + " " + chosen_channel->channel;
        report.stop_reason += "; second cause " + report.second_cause + " on the same " + report.second_channel +
                              " channel, stepwise (" + stepwise->stop_reason + ")";
        if (second != nullptr) {
          report.stop_reason += "; instead of " + second_channel->cause + " on the " + second_channel->plant + " " +
                                second_channel->channel + " channel (delta-BIC " + common::format_value(second->delta_bic) + ")";
        }
      } else {
        if (stepwise) {
          stepwise_note = "; stepwise on the " + chosen_channel->plant + " channel: " +
                          (stepwise->second_cause == "none" ? stepwise->stop_reason
                                                            : "its pair " + stepwise->cause + " + " + stepwise->second_cause +
                                                                  " not kept (joint delta-BIC " + common::format_value(joint) + ")");
        }
        stepwise.reset();
      }
    } else if ((drive || swing) && white_after) {
      stepwise_note = "; the " + chosen_channel->plant + " residual with the first cause is white";
    }
    if (!stepwise && second != nullptr) {
      report.second_cause = second_channel->cause;
      report.second_ambiguous_with = second_channel->ambiguous_with;
      report.second_parameters = cause_parameters(*second);
      report.second_channel = second_channel->plant + " " + second_channel->channel;
      report.stop_reason += "; second cause " + report.second_cause + " on the " + report.second_channel +
                            " channel (" + second_channel->stop_reason + ")" + stepwise_note;
    } else if (!stepwise) {
      report.stop_reason += "; no other channel names a second cause" + stepwise_note;
    }
  } else {
    report.stop_reason = "no channel has a candidate that earns its parameters (";
    for (const auto& channel : report.channels) {
      report.stop_reason += channel.plant + " " + channel.channel + ": " + channel.stop_reason + "; ";
    }
    report.stop_reason.resize(report.stop_reason.size() - 2);
    report.stop_reason += ")";
  }
  if (swing_pair && (chosen == nullptr || pair_delta_bic(*swing_pair) < chosen->delta_bic)) {
    const AuditReport& pair = *swing_pair;
    const std::string replaced =
        chosen == nullptr ? std::string()
                          : "; instead of " + report.cause + (report.second_cause == "none" ? "" : " + " + report.second_cause) +
                                " (delta-BIC " + common::format_value(chosen->delta_bic) + " for " + chosen->name +
                                ", an echo of the swing's causes in the drives' coupling)";
    show(pair);
    report.cause = pair.cause;
    report.ambiguous_with = pair.ambiguous_with;
    report.parameters = pair.parameters;
    report.extended_nominal = pair.extended_nominal;
    report.second_cause = pair.second_cause;
    report.second_ambiguous_with = pair.second_ambiguous_with;
    report.second_parameters = pair.second_parameters;
    report.second_channel = report.channel;
    report.stop_reason = "two causes on the " + report.channel + " channel, neither alone earning its parameters (joint delta-BIC " +
                         common::format_value(pair_delta_bic(pair)) + "): " + pair.stop_reason + replaced;
    *swing_report = std::move(*swing_pair);
  }
  if (!calibration_notes.empty()) {
    calibration_notes.resize(calibration_notes.size() - 2);
    report.stop_reason += " (calibrate: " + calibration_notes + ")";
  }
  return report;
}

}  // namespace crane::model_audit::detail
