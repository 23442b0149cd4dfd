#pragma once
// A second simulator of the tower crane, written for the test only (issue 17): it shares no code
// with the audit's replay (crane_swing.hpp, audit_models.hpp), the hidden-effect generator or
// plant/; it uses only the audit's public data types (AuditData, CraneParameters) to hand over the
// recording and the nominal.
//
// Dynamics: a Lagrangian of point masses evaluated numerically. Generalized coordinates
//   q = (x, gamma, alpha, beta [, alpha2, beta2 | s])
// trolley position [m], slew angle [rad], and the cable's direction in the jib frame in a chart of
// its own (not the audit's): e(alpha, beta) = (-sin alpha, cos alpha sin beta, -cos alpha cos beta)
// (rotation about the jib axis by beta first, then about the horizontal normal by alpha). The
// point masses, in the inertial frame (R_z(gamma) the slew rotation, z up):
//   trolley  M_trolley at R (x, 0, 0)
//   load     m at R ((x, 0, 0) + L e(alpha, beta))            (single pendulum)
//   hook     s M at R ((x, 0, 0) + L e(alpha, beta)), load (1 - s) M at hook + R l e(alpha2, beta2)
//   rope     load m at R ((x, 0, 0) + (L + s) e(alpha, beta)), potential k s^2 / 2, damping c s'
// plus the constant inertias M_drive - M_trolley on x (the reflected drive) and J_o on gamma. The
// equations are d'Alembert's, sum_i m_i J_i^T (J_i q'' + q'^T H_i q' + g e_z) + D q'' = Q, with the
// Jacobians J_i and the convective terms q'^T H_i q' of each point mass taken exactly by hyper-dual
// numbers (forward-mode differentiation of the position functions); fixed-step classical RK4 over
// (q, q'), kSubsteps per 10 ms sample.
// Drives: F_x = M_drive K_mx (1 + g) S(D(u(t - tau))) - M_drive K_mx f_x, likewise T_gamma with
// J_o K_mgamma (f in volt equivalents: max(0, c_s + slope x) + stribeck + b_s |v|). A drive at rest
// is held (q''_i = 0, its row's constraint force is the friction that holds it) while that force is
// within its breakaway level (the Coulomb level, the configuration's static excess over it, the
// Stribeck level and an injected stiction); a step in which a sliding drive's rate changes sign is cut at the
// reversal (the drive rests there and the rest rule decides).
// Sensors: encoder counts of the lab crane (trolley 1.59 um, slew 17.5 urad, swing 0.26 mrad),
// Gaussian noise of 0.3 count, read as the nearest count; the swing encoders read the plant's
// convention (phi, theta) of the cable (trolley to hook): phi = atan2(-e_x, -e_z), theta = asin e_y.
// Commands through a 13-bit DAC of +-10 V (the recorded input is the applied voltage).
// Maneuver: a PD per drive (trolley 70 V/m, slew 30 V/rad, derivative time 0.25 s: not the
// generator's gains) on a 4.5 s creep triangle (0.025 m/s, 0.025 rad/s) and then three faded-in
// sines per drive, 18 s at 100 Hz, constant cable length.
//
// Cause names are the audit's crane catalog names (model_audit.hpp); "none" is a clean case.

#include <cstdint>
#include <string>
#include <vector>

#include "crane/model_audit/model_audit.hpp"

namespace crane::model_audit::test {

/// The crane catalog entries this simulator produces (every trolley_* and slew_* drive entry,
/// payload_mass_error and the swing entries), in catalog order.
[[nodiscard]] const std::vector<std::string>& independent_crane_entries();

struct IndependentCraneCase {
  std::string cause{"none"};
  std::string main_parameter;  // as the audit names it ("" for none)
  double main_value{0.0};      // true value
  AuditNominal nominal;        // common::CraneParameters as told to the audit
  AuditData data;
};

/// One crane case with `cause` ("none" or an entry of independent_crane_entries()), magnitudes
/// drawn from `seed`. Throws std::invalid_argument for another name.
[[nodiscard]] IndependentCraneCase independent_crane_case(const std::string& cause, std::uint64_t seed);

}  // namespace crane::model_audit::test
