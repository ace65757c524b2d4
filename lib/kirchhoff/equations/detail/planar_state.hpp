// Internal: the state layout of the planar rod equations (planar_equations.cpp), shared with the
// code that reads the state directly (the planar vibrations, vibration.cpp).
//
// State (6): the position (x, y), the tangent's angle theta, the force (n_x, n_y) and the moment
// m_z, all in the plane's fixed axes.
#pragma once

namespace kirchhoff::detail {

constexpr int kPlanarStateSize = 6;
enum PlanarIndex { kX = 0, kY = 1, kTheta = 2, kNx = 3, kNy = 4, kMoment = 5 };

}  // namespace kirchhoff::detail
