#include "kirchhoff/spatial_bins.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>

namespace kirchhoff {
namespace {

bool before(const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
  return std::tie(a.x(), a.y(), a.z()) < std::tie(b.x(), b.y(), b.z());
}

}  // namespace

CubeBins::CubeBins(const std::vector<Vec3>& points, double cell, std::size_t stride) {
  std::vector<std::pair<Eigen::Vector3i, std::size_t>> binned;
  binned.reserve(points.size() / stride + 1);
  for (std::size_t i = 0; i < points.size(); i += stride) {
    const Vec3& r = points[i];
    binned.emplace_back(Eigen::Vector3i(static_cast<int>(std::floor(r.x() / cell)),
                                        static_cast<int>(std::floor(r.y() / cell)),
                                        static_cast<int>(std::floor(r.z() / cell))),
                        i);
  }
  std::sort(binned.begin(), binned.end(), [](const auto& a, const auto& b) {
    return before(a.first, b.first) || (a.first == b.first && a.second < b.second);
  });
  indices_.reserve(binned.size());
  for (std::size_t k = 0; k < binned.size(); ++k) {
    if (k == 0 || binned[k].first != binned[k - 1].first) cubes_.push_back(Cube{binned[k].first, k, k});
    indices_.push_back(binned[k].second);
    cubes_.back().end = k + 1;
  }
}

const CubeBins::Cube* CubeBins::find(const Eigen::Vector3i& at) const {
  const auto it = std::lower_bound(cubes_.begin(), cubes_.end(), at,
                                   [](const Cube& c, const Eigen::Vector3i& v) { return before(c.at, v); });
  return it != cubes_.end() && it->at == at ? &*it : nullptr;
}

}  // namespace kirchhoff
