// Pairs of points that are near each other in space, found by binning: points go into cubes of
// side `cell`, and only the 27 cubes around each point are looked at - linear in the number of
// points where all pairs would be quadratic (2e8 pairs per point of a branch at L/2R = 1000).
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "kirchhoff/rod_equations.hpp"

namespace kirchhoff {

// Calls visit(i, j), i < j, for every pair among every stride-th point that lies in the same or
// neighbouring cubes of side `cell`: every pair closer than `cell` is visited (and some further).
void for_each_near_pair(const std::vector<Vec3>& points, double cell, std::size_t stride,
                        const std::function<void(std::size_t, std::size_t)>& visit);

}  // namespace kirchhoff
