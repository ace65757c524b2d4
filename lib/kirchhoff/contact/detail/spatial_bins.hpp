// Pairs of points that are near each other in space, found by binning: points go into cubes of
// side `cell`, and only the 27 cubes around each cube are looked at - linear in the number of
// points where all pairs would be quadratic (2e8 pairs per point of a branch at L/2R = 1000).
#pragma once

#include <cstddef>
#include <vector>

#include "kirchhoff/equations/rod_equations.hpp"

namespace kirchhoff {

// Cube coordinates: 64-bit, as r / cell exceeds the range of int long before r stops being a
// usable position (1e-3 cells of a rod 1e7 away).
using CubeIndex = Eigen::Matrix<long long, 3, 1>;

// Every stride-th point, sorted by the cube it lies in, with each occupied cube's range.
// Points with a non-finite coordinate are left out: they are near no point. Coordinates beyond
// +-2^62 cells share the outermost cube (they are at least a cell apart unless equal, as a
// double's spacing there exceeds a cell): never undefined float-to-integer conversions.
// Throws std::invalid_argument unless cell > 0 (inf: one cube) and stride >= 1.
class CubeBins {
 public:
  CubeBins(const std::vector<Vec3>& points, double cell, std::size_t stride);

  struct Cube {
    CubeIndex at;
    std::size_t begin, end;  // its points are indices()[begin, end)
  };
  const std::vector<Cube>& cubes() const { return cubes_; }
  const std::vector<std::size_t>& indices() const { return indices_; }
  // The occupied cube at `at`, if any (binary search: cubes() is sorted).
  const Cube* find(const CubeIndex& at) const;

 private:
  std::vector<Cube> cubes_;
  std::vector<std::size_t> indices_;
};

// Calls visit(i, j), i < j, for every pair among every stride-th point that lies in the same or
// neighbouring cubes of side `cell`: every pair closer than `cell` is visited (and some further).
// A template: the visitor is called millions of times per branch at L/2R = 1000, and the
// neighbours are looked up once per cube, not once per point.
template <class Visit>
void for_each_near_pair(const std::vector<Vec3>& points, double cell, std::size_t stride, Visit&& visit) {
  const CubeBins bins(points, cell, stride);
  const auto& index = bins.indices();
  for (const auto& cube : bins.cubes())
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const CubeBins::Cube* other = bins.find(cube.at + CubeIndex(dx, dy, dz));
          if (!other) continue;
          for (std::size_t a = cube.begin; a < cube.end; ++a)
            for (std::size_t b = other->begin; b < other->end; ++b)
              if (index[b] > index[a]) visit(index[a], index[b]);
        }
}

}  // namespace kirchhoff
