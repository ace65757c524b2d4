// The planar Elastica as a constrained minimisation of its discretised energy, solved by Ipopt:
// an independent check of the shooting solutions (and their contact forces, which here are the
// multipliers of the gap constraints), converging as the number of segments grows, and a way to
// find a starting point and contact set for them (discrete_seed.hpp).
//
// Clamped-clamped rod of length L and bending stiffness EI(s), clear of obstacles (planes,
// cylinders, level sets). Unknowns: the angles theta_i of N equal segments (midpoint rule);
// energy sum EI_k/(2 h) (theta_k - theta_{k-1})^2 over the interior nodes k with half cells
// EI/h (theta - clamp angle)^2 at the clamps; equality constraints on the end position; one
// inequality gap >= 0 per interior node and obstacle. The Hessian of the Lagrangian is given exactly:
// tridiagonal with planes, dense with curved obstacles (their curvature couples every pair of
// angles up to a node). Second-order accurate: errors fall as 1/N^2 - on a curved obstacle only
// where the contact falls on a node, since contact is imposed at nodes and its arclength is not an
// unknown; elsewhere the forces converge at first order, irregularly (the energy still at second).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "kirchhoff/shooting.hpp"

namespace kirchhoff {

// A clamped-clamped planar rod: ends at `start` and `end` with tangent angles `start_angle` and
// `end_angle` (from e_x), bending stiffness EI(s), clear of the obstacles.
struct DiscreteClampedElastica {
  double L = 1.0;
  std::function<double(double)> EI = [](double) { return 1.0; };
  Vec3 start = Vec3::Zero();
  double start_angle = 0.0;
  Vec3 end = Vec3::UnitX();
  double end_angle = 0.0;
  std::vector<Obstacle> obstacles;
};

struct DiscreteElasticaResult {
  bool converged = false;
  std::string status;          // Ipopt's return status
  int iterations = 0;
  double P = 0.0;              // compressive end load, -n_x(L) (the x-constraint's multiplier)
  double n_y = 0.0;            // n_y at s = 0
  Vec3 n_start = Vec3::Zero(); // n(0)
  double m_start = 0.0;        // the clamp's moment at s = 0, EI (theta_0 - start_angle) / (h / 2)
  double contact_force = 0.0;  // sum of the contact forces' magnitudes
  double energy = 0.0;
  double min_gap = 0.0;
  std::vector<double> x, y, theta;  // nodes (N + 1) and segment angles (N)
  // Per obstacle, the contact force at each interior node k = 1..N-1 (index k - 1), and the gap.
  std::vector<std::vector<double>> node_forces, node_gaps;
};

// Starts from the chord between the ends with the first clamped-clamped mode of amplitude
// `amplitude` on it (its sign picks the side it buckles to) and the clamps' angles blended in;
// throws std::invalid_argument for non-physical input (L or EI <= 0, ends further apart than L).
DiscreteElasticaResult solve_discrete_elastica(const DiscreteClampedElastica& rod, int segments,
                                               double amplitude = 0.05);

// The rod of the paper's Fig. 12: ends at (0, 0) and (L - Delta, 0), horizontal tangents.
DiscreteElasticaResult solve_discrete_clamped_elastica(double L, double EI, double Delta,
                                                       const std::vector<Obstacle>& obstacles, int segments,
                                                       double amplitude = 0.05);

}  // namespace kirchhoff
