// A spatial rod lying on a cylinder over an interval: the extended contact of a 3D rod with a
// cylinder it touches from outside, and the hard self-contact of the symmetric plectoneme (whose
// strands, related by a half-turn about the ply axis, touch where the half rod lies on the
// cylinder of radius R about that axis; self_contact.hpp, section 7.6).
//
// On the interval the centreline keeps rho = |P (r - c)| = radius (P projects across the axis a
// through c), and the cylinder pushes it outward with a pressure p >= 0 per unit length along the
// radial unit vector e: n' = -p e (frictionless; applied at the surface on the line of centres, so
// no couple). With g = rho - radius, the constraint's derivatives along the rod are, for an
// isotropic (B1 = B2 = B), naturally straight Kirchhoff rod (t = d3, t' = k = (m x t) / B,
// m' = n x t), with alpha = a.t and t_rho = e.t:
//   g'   = t_rho,
//   g''  = (1 - alpha^2 - t_rho^2) / rho + e.k,
//   g''' = -(3 alpha a.k + 2 t_rho g'' + t_rho e.k) / rho - (1 - alpha^2 - t_rho^2) t_rho / rho^2
//          + ((n.t) t_rho - e.n + e.(m x k)) / B,
// exact for any state. g''' is the first to involve n, so p enters g'''' = D g''' + p (1 - t_rho^2)/B
// (D: the derivative along the unloaded equations): the contact is an index-4 constraint, and p
// is what makes g'''' vanish. Integrated with p chosen so that g'''' = 0 alone, round-off and the
// integrator's error would drift off the cylinder like s^3 (the constraint is only held by its
// fourth derivative); p is chosen instead so that
//   g'''' + 4 w g''' + 6 w^2 g'' + 4 w^3 g' + w^4 g = 0   (Baumgarte, a quadruple root at -w),
// which leaves every state on the cylinder (g = g' = g'' = g''' = 0) exactly where it was and
// pulls a state that strays back at the rate w. Entering the interval, the rod must already be on
// the cylinder: g = g' = g'' = 0 there, and g''' = 0 once the concentrated force at the contact's
// edge (a jump of n along -e) is applied - four conditions, which the shooting core imposes.
//
// Only the isotropic, uniform, naturally straight, inextensible and unshearable rod without an
// external field is modelled (rod_on_cylinder_unsupported says why another is refused): there
// m3 is constant and t' = (m x t) / B in closed form.
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <string>

#include "kirchhoff/equations/rod_equations.hpp"

namespace kirchhoff {

struct CylinderSupport {
  Vec3 point = Vec3::Zero();   // a point of the axis
  Vec3 axis = Vec3::UnitZ();   // unit
  double radius = 1.0;         // the centreline's distance to the axis on the interval
  // Baumgarte rate w (1 / length) pulling strayed states back onto the cylinder; 0 takes
  // 0.1 / radius. Faster rates cost integration steps (measured on ply helices over 10 R: 20-60
  // steps at 0.1 / radius, 210-720 at 1-3 / radius, for the same solution); at 0.1 / radius the
  // gap stays below 1e-12 R over 40 R of an exact helix.
  double rate = 0.0;
};

// Why a rod cannot be held on a cylinder by these equations, or "" when it can.
std::string rod_on_cylinder_unsupported(const RodModel& model);

// The spatial equations with the cylinder's pressure: the rod lying on it. Throws
// std::invalid_argument for a rod rod_on_cylinder_unsupported refuses or a radius <= 0.
std::shared_ptr<const RodEquations> make_spatial_equations_on_cylinder(RodModel model, CylinderSupport support);

// g, g', g'', g''' (above) at the spatial state y, and their derivatives in y (4 x 14) when asked.
Eigen::Vector4d cylinder_gap_derivatives(const RodModel& model, const CylinderSupport& support, const Eigen::VectorXd& y,
                                         Eigen::MatrixXd* jacobian = nullptr);
// The outward unit vector e at the state's centreline, with its derivative in y (3 x 14) when asked.
Vec3 cylinder_normal(const CylinderSupport& support, const Eigen::VectorXd& y, Eigen::MatrixXd* jacobian = nullptr);
// The pressure p the cylinder exerts at the spatial state y (force per length along e).
double cylinder_pressure(const RodModel& model, const CylinderSupport& support, const Eigen::VectorXd& y);

}  // namespace kirchhoff
