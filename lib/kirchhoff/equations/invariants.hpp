// The Noether invariants of section 5 evaluated along a solution: the arclength Hamiltonian
// H = n.v + m.u - V (eq. 29, V including W_ext), the twisting moment m3 (eq. 48), n.m (eq. 44),
// the force n (eq. 37) and the moment about the origin r x n + m (eq. 40c). Each comes with
// whether the symmetry behind it holds for the model, so a report never claims an invariant
// that theory does not promise.
#pragma once

#include <vector>

#include "kirchhoff/equations/rod_equations.hpp"

namespace kirchhoff {

struct InvariantStats {
  double mean = 0.0, min = 0.0, max = 0.0;
  double spread = 0.0;  // max - min along the rod
  double scale = 0.0;   // magnitude of the terms that make it up, to judge the spread against
  bool applies = false; // the model has the symmetry that makes it conserved
  double relative_spread() const { return scale > 0 ? spread / scale : spread; }
};

struct VectorInvariantStats {
  Vec3 mean = Vec3::Zero();
  double spread = 0.0;  // largest range of a component along the rod
  double scale = 0.0;
  bool applies = false;
};

struct InvariantReport {
  InvariantStats H, m3, n_dot_m;
  VectorInvariantStats n, moment_about_origin;
};

// Energy density V = W_bend + W_shear + W_ext (eq. 14) at a point.
double energy_density(const RodModel& model, const RodPoint& p);
// H(s) = n.v + m.u - V (eq. 29); with v = R v_body, u = R u_body in the lab frame.
double hamiltonian(const RodModel& model, const RodPoint& p);
// The non-invariant part used in Fig. 12: h = H + W_ext.
double hamiltonian_without_field(const RodModel& model, const RodPoint& p);

InvariantReport compute_invariants(const RodModel& model, const std::vector<RodPoint>& profile);

}  // namespace kirchhoff
