#include "kirchhoff/contact/detail/spatial_bins.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>

namespace kirchhoff {
namespace {

bool before(const CubeIndex& a, const CubeIndex& b) {
  return std::tie(a.x(), a.y(), a.z()) < std::tie(b.x(), b.y(), b.z());
}

// floor(x / cell) clamped to +-2^62: exact where cells can be told apart, and far enough from
// the range of long long that the neighbour offsets +-1 cannot overflow. x is finite.
long long cube_coordinate(double x, double cell) {
  constexpr double kLimit = 4611686018427387904.0;  // 2^62
  return static_cast<long long>(std::clamp(std::floor(x / cell), -kLimit, kLimit));
}

}  // namespace

CubeBins::CubeBins(const std::vector<Vec3>& points, double cell, std::size_t stride) {
  // An infinite cell puts every finite point in cube 0 (all pairs); nan or <= 0 is a caller's bug.
  if (!(cell > 0)) throw std::invalid_argument("CubeBins: the cell must be > 0");
  if (stride < 1) throw std::invalid_argument("CubeBins: the stride must be >= 1");
  std::vector<std::pair<CubeIndex, std::size_t>> binned;
  binned.reserve(points.size() / stride + 1);
  for (std::size_t i = 0; i < points.size(); i += stride) {
    const Vec3& r = points[i];
    if (!r.allFinite()) continue;  // a nan or inf position is within `cell` of nothing
    binned.emplace_back(CubeIndex(cube_coordinate(r.x(), cell), cube_coordinate(r.y(), cell),
                                  cube_coordinate(r.z(), cell)),
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

const CubeBins::Cube* CubeBins::find(const CubeIndex& at) const {
  const auto it = std::lower_bound(cubes_.begin(), cubes_.end(), at,
                                   [](const Cube& c, const CubeIndex& v) { return before(c.at, v); });
  return it != cubes_.end() && it->at == at ? &*it : nullptr;
}

}  // namespace kirchhoff
