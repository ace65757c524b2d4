// The planar Elastica as a constrained minimisation of its discretised energy, solved by Ipopt:
// an independent check of the shooting solutions (and their contact forces, which here are the
// multipliers of the gap constraints), converging as the number of segments grows.
//
// Clamped-clamped rod of length L and bending stiffness EI, ends at (0, 0) and (L - Delta, 0)
// with horizontal tangents, clear of obstacles (planes, cylinders, level sets). Unknowns: the
// angles theta_i of N equal segments (midpoint rule); energy sum EI/(2 h) (theta_{i+1} - theta_i)^2 with half cells
// EI/h theta^2 at the clamps; equality constraints on the end position; one inequality
// gap >= 0 per interior node and obstacle. The Hessian of the Lagrangian is given exactly:
// tridiagonal with planes, dense with curved obstacles (their curvature couples every pair of
// angles up to a node). Second-order accurate: errors fall as 1/N^2 - on a curved obstacle only
// where the contact falls on a node, since contact is imposed at nodes and its arclength is not an
// unknown; elsewhere the forces converge at first order, irregularly (the energy still at second).
#pragma once

#include <string>
#include <vector>

#include "kirchhoff/shooting.hpp"

namespace kirchhoff {

struct DiscreteElasticaResult {
  bool converged = false;
  std::string status;          // Ipopt's return status
  int iterations = 0;
  double P = 0.0;              // compressive end load, -n_x (the x-constraint's multiplier)
  double n_y = 0.0;            // n_y at s = 0
  double contact_force = 0.0;  // sum of the contact forces' magnitudes
  double energy = 0.0;
  double min_gap = 0.0;
  std::vector<double> x, y, theta;          // nodes (N + 1) and segment angles (N)
  std::vector<double> node_forces;          // contact multiplier per interior node (first obstacle)
};

// Starts from the first clamped-clamped buckling mode with amplitude `amplitude` (below the
// obstacles); throws std::invalid_argument for non-physical input.
DiscreteElasticaResult solve_discrete_clamped_elastica(double L, double EI, double Delta,
                                                       const std::vector<Obstacle>& obstacles, int segments,
                                                       double amplitude = 0.05);

}  // namespace kirchhoff
