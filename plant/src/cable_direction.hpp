#pragma once
// Direction of the cable from the trolley to the load, tower sign convention (ERRATA), shared by
// the tower and overhead crane models (internal header of crane::plant):
//   u(phi, theta) = (-cos(theta) sin(phi), sin(theta), -cos(theta) cos(phi))
// in the frame of the trolley's axes (x along the trolley's travel, z up), with its partial
// derivatives. The load sits at trolley + L u.

#include <Eigen/Core>
#include <cmath>

namespace crane::plant::detail {

struct CableDirection {
  Eigen::Vector3d u;     // unit vector trolley -> load
  Eigen::Vector3d u_p;   // du/dphi
  Eigen::Vector3d u_t;   // du/dtheta
  Eigen::Vector3d u_pp;  // d2u/dphi2
  Eigen::Vector3d u_pt;  // d2u/dphi dtheta
  Eigen::Vector3d u_tt;  // d2u/dtheta2 (= -u)
};

inline CableDirection cable_direction(double phi, double theta) {
  const double sp = std::sin(phi), cp = std::cos(phi), st = std::sin(theta), ct = std::cos(theta);
  CableDirection d;
  d.u = Eigen::Vector3d(-ct * sp, st, -ct * cp);
  d.u_p = Eigen::Vector3d(-ct * cp, 0.0, ct * sp);
  d.u_t = Eigen::Vector3d(st * sp, ct, st * cp);
  d.u_pp = Eigen::Vector3d(ct * sp, 0.0, ct * cp);
  d.u_pt = Eigen::Vector3d(st * cp, 0.0, -st * sp);
  d.u_tt = -d.u;
  return d;
}

}  // namespace crane::plant::detail
