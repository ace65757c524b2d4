#include "kirchhoff/continuation/detail/singular_point_index.hpp"

#include <algorithm>

namespace kirchhoff::detail {

void settle_singular_point_index(PointRecord* singular, const PointRecord& before, const PointRecord& after) {
  if (!singular->stability_index || !before.stability_index || !after.stability_index) return;
  const int lower = std::min(*before.stability_index, *after.stability_index);
  const int upper = std::max(*before.stability_index, *after.stability_index);
  // Equal neighbours: the zero eigenvalue may touch zero from either side without crossing, and
  // only the point's own count can say which.
  if (lower == upper || *singular->stability_index == lower) return;
  const int crossing_zero_modes = singular->zero_modes - std::min(before.zero_modes, after.zero_modes);
  if (crossing_zero_modes >= upper - lower)
    singular->stability_index = lower;
  else
    singular->stability_index.reset();
}

}  // namespace kirchhoff::detail
