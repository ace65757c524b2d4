#include "kirchhoff/spatial_bins.hpp"

#include <cmath>
#include <cstdint>
#include <unordered_map>

namespace kirchhoff {

void for_each_near_pair(const std::vector<Vec3>& points, double cell, std::size_t stride,
                        const std::function<void(std::size_t, std::size_t)>& visit) {
  auto cube = [&](const Vec3& r) {
    return Eigen::Vector3i(static_cast<int>(std::floor(r.x() / cell)), static_cast<int>(std::floor(r.y() / cell)),
                           static_cast<int>(std::floor(r.z() / cell)));
  };
  // Cubes that share a hash share a bin: more pairs get visited, none is missed.
  auto key = [](const Eigen::Vector3i& c) {
    return (static_cast<int64_t>(c.x()) * 73856093) ^ (static_cast<int64_t>(c.y()) * 19349663) ^
           (static_cast<int64_t>(c.z()) * 83492791);
  };
  std::unordered_map<int64_t, std::vector<std::size_t>> bins;
  for (std::size_t i = 0; i < points.size(); i += stride) bins[key(cube(points[i]))].push_back(i);
  for (std::size_t i = 0; i < points.size(); i += stride) {
    const Eigen::Vector3i c = cube(points[i]);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto bin = bins.find(key(c + Eigen::Vector3i(dx, dy, dz)));
          if (bin == bins.end()) continue;
          for (const std::size_t j : bin->second)
            if (j > i) visit(i, j);
        }
  }
}

}  // namespace kirchhoff
