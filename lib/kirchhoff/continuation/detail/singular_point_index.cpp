#include "kirchhoff/continuation/detail/singular_point_index.hpp"

#include <algorithm>
#include <string>

namespace kirchhoff::detail {

void settle_singular_point_index(PointRecord* singular, const PointRecord& before, const PointRecord& after) {
  if (!before.stability_index || !after.stability_index) return;
  const int lower = std::min(*before.stability_index, *after.stability_index);
  const int upper = std::max(*before.stability_index, *after.stability_index);
  const int common = std::min(before.zero_modes, after.zero_modes);
  // A count that is undefined at the singular point itself (its constraints degenerate exactly
  // there: a clamped column where its ends meet) between neighbours that differ: continuity
  // settles it as it settles a count between theirs. Between equal ones nothing does.
  if (!singular->stability_index) {
    if (lower == upper) return;
    singular->stability_index = lower;
    singular->zero_modes = common + (upper - lower);
    singular->stability_reason.clear();  // settled: no longer why it is empty
    return;
  }
  // Equal neighbours: the zero eigenvalue may touch zero from either side without crossing, and
  // only the point's own count can say which - where it sees that eigenvalue as zero. A count
  // without it took the eigenvalue for negative or positive, and which was right is not known.
  if (lower == upper) {
    if (singular->zero_modes > common) return;
    singular->stability_index.reset();
    singular->zero_modes = common + 1;
    singular->stability_reason =
        "an eigenvalue touches zero at this fold or branch point without crossing (both neighbours have index " +
        std::to_string(lower) + "), and the point's own count took it for nonzero: its sign is not known";
    return;
  }
  const int own = *singular->stability_index;
  const int crossing = upper - lower;
  // The crossing eigenvalues are small at the located point, of either sign or zero within their
  // resolution: a count between the neighbours' says so, and so does one outside it whose extra
  // zero modes account for the change.
  const bool explained = (own >= lower && own <= upper) || singular->zero_modes - common >= crossing;
  if (!explained) {
    singular->stability_index.reset();
    singular->stability_reason = "the point's own count (" + std::to_string(own) +
                                 ") is outside its neighbours' indices (" + std::to_string(lower) + " and " +
                                 std::to_string(upper) + ") and its zero modes do not explain it";
    return;
  }
  singular->stability_index = lower;
  singular->zero_modes = std::max(singular->zero_modes, common + crossing);
}

}  // namespace kirchhoff::detail
