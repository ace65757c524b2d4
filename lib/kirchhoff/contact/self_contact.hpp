// Self-contact of a rod that is symmetric under a half-turn about an axis: the symmetric
// plectoneme of section 7.6 (Fig. 10), after van der Heijden et al. (2003) and Thompson et al. (2002).
//
// Why this formulation. A clamped rod whose ends are related by a half-turn S about an axis
// (the plectoneme's axis) has symmetric equilibria with r(L - s) = S r(s). We solve the half rod
// s in [0, L/2]; the point r(L/2) lies on the axis. In the interwound (double-helix) part the
// cross-section at s touches the one at L - s, its image: |r(s) - S r(s)| = 2 rho(s), with rho
// the distance to the axis. Self-contact of the whole rod thus becomes contact of the half rod
// with a cylinder of radius R (the cross-section radius) about the axis, with the contact
// pressure radial - one strand, one constraint, no search for contact partners. Pairs other
// than (s, L - s) are checked afterwards (the self_distance measure), not imposed.
//
// The contact is a stiff, short-range repulsion rather than complementarity: in a plectoneme
// the contact is a line that starts and ends with concentrated forces and may split into
// several pieces as the turns grow, and the barrier follows all of that through continuation
// without an active set - the same soft-wall idea as eq. (64), with the hard limit approached
// as the strength b -> 0 (the gap and the error in the loads fall like b^(1/2)). The potential
//     W(s, r) = w(s) b exp(-(g/c)^2) / g,   g = rho - R > 0,
// is ~ b/g near contact and negligible a few ranges c away. It is smooth: a barrier cut off
// with finitely many continuous derivatives stalls Newton where a cross-section enters its
// support, because the integrator's error control (order 7-8) then no longer makes the flow
// smooth to the corrector's tolerance. w(s) switches the contact off near s = L/2, where the
// rod crosses the axis through its own end loop (those cross-sections are neighbours along the
// rod, not in contact): w = 1 for s <= L/2 - 2 lambda, 0 for s >= L/2 - lambda. There H' = -w' W,
// negligible while the loop stays several ranges c clear of the cylinder (loop_clearance: at
// 4 ranges the Gaussian has fallen by 1e-7).
#pragma once

#include <vector>

#include "kirchhoff/equations/rod_equations.hpp"
#include "kirchhoff/model/rod_model.hpp"

namespace kirchhoff {

// A cross-section of the whole rod: its arclength along the whole rod and its centre.
struct WholeRodSection {
  double s_whole = 0.0;
  Vec3 r = Vec3::Zero();
};

// The half-turn S about an axis through `origin` that relates the two halves of a symmetric
// plectoneme (r(L - s) = S r(s)), with the cross-section radius R: the strands touch where the
// half rod is R from the axis. What the barrier (below) and the hard contact (a cylinder of
// radius R about the axis, plectoneme.hpp) have in common.
struct HalfTurnGeometry {
  Vec3 origin = Vec3::Zero();
  Vec3 axis = Vec3::UnitX();  // unit
  double radius = 0.0;        // R
  double symmetry_s = 0.0;    // arclength of the point on the axis (the end of the half rod)

  // Component of r - origin across the axis.
  Vec3 radial(const Vec3& r) const;
  double distance_to_axis(const Vec3& r) const { return radial(r).norm(); }
  // The image S r of a point under the half-turn.
  Vec3 image(const Vec3& r) const { return r - 2.0 * radial(r); }
  // The whole rod from samples of the half rod [0, L/2]: the half followed by its image,
  // traversed backwards (r(L - s) = S r(s)).
  std::vector<WholeRodSection> whole_rod(const std::vector<RodPoint>& half) const;
};

struct HalfTurnSelfContactOptions {
  double radius = 0.0;          // R, the cross-section radius: centrelines stay 2R apart
  Vec3 axis = Vec3::UnitX();    // the half-turn axis, through `origin`
  Vec3 origin = Vec3::Zero();
  double symmetry_s = 0.0;      // arclength of the point on the axis (the end of the half rod)
  double strength = 0.0;        // b
  double range = 0.0;           // c
  double adjacent = 0.0;        // lambda
};

class HalfTurnSelfContact final : public ExternalField {
 public:
  // Throws std::invalid_argument naming the option that is out of range.
  explicit HalfTurnSelfContact(const HalfTurnSelfContactOptions& options);

  double potential(double s, const Vec3& r) const override;
  Vec3 force(double s, const Vec3& r) const override;
  Mat3 force_gradient(double s, const Vec3& r) const override;
  // rho - R where the contact acts, NaN near the end loop where it does not.
  double gap(double s, const Vec3& r) const override;

  const HalfTurnGeometry& geometry() const { return geometry_; }
  // The weight w(s) that switches contact off near the end loop.
  double weight(double s) const;
  const HalfTurnSelfContactOptions& options() const { return options_; }

 private:
  // The barrier at a cross-section: weight w(s), radial vector d and |d|, and phi(g) with its
  // first two derivatives. Throws IntegrationError when g <= 0 where the barrier acts (the rod
  // would pass through itself, which a Newton iterate may try: the step is then shortened).
  struct Barrier {
    double w = 0.0;  // 0: the barrier is off here and the rest is not evaluated
    Vec3 d = Vec3::Zero();
    double rho = 0.0, phi = 0.0, dphi = 0.0, ddphi = 0.0;
  };
  Barrier barrier(double s, const Vec3& r) const;

  HalfTurnSelfContactOptions options_;
  HalfTurnGeometry geometry_;
};

// The half-turn self-contact among a model's fields (directly or in a FieldSum), or null.
const HalfTurnSelfContact* find_half_turn_self_contact(const RodModel& model);

}  // namespace kirchhoff
