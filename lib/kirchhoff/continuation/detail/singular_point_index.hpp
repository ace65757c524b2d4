// The stability index at a fold or branch point, from the points on either side of it.
//
// At a singular point of a branch an eigenvalue of the second variation is zero, so a direct
// count there sits on a knife's edge: an eigenvalue that is zero in exact arithmetic, or a second
// one that is small there for another reason (the soft wall's branch point, where a conjugate
// point of the clamped problem also lies within 1e-7 of the end), may come out either side. The
// regular points around it do not have that trouble, and continuity along the branch settles the
// count: every eigenvalue negative at the singular point is negative at both neighbours, and every
// one negative at both that does not cross zero between them is negative there. With no crossing
// inside the step other than the located one (what the detectors assume when they locate it), the
// index at the singular point is the smaller of its neighbours' indices, and the zero eigenvalues
// there are those that cross, |a - b| of them, besides the symmetries' zero modes. Where a = b
// nothing crossed, and an eigenvalue that only touches zero there may do so from below (index
// a - 1 with a zero mode) or above (a): the point's own count stands where it has that zero mode.
// Where it has not (its count took the eigenvalue for one sign, as at the soft wall's branch
// point at log_b = -5 revisited along the branch switched to there: index 1 and no zero mode, a
// conjugate point 5e-8 before the end, where the first visit settled 0 with one), nothing says
// which sign was right: the index is undefined and the zero mode is reported.
#pragma once

#include "kirchhoff/continuation/continuation.hpp"

namespace kirchhoff::detail {

// Sets `singular`'s index to min(a, b) and its zero modes to at least the fewer of its neighbours'
// plus |a - b| (the crossing eigenvalues), a and b the indices of the regular points before and
// after it, where its own count lies between a and b (the crossing eigenvalues came out of either
// sign there: the soft wall's branch point, located to 1e-8 of its step, has its crossing
// eigenvalue decisively positive with the fields at the state's 1e-12) or its extra zero modes
// account for the change; a count that neither explains becomes undefined (an empty index).
// Where a = b, leaves a count with a zero mode beyond its neighbours' alone and makes one without
// undefined, with that zero mode. A point whose own count is undefined gets min(a, b) and the
// crossing zero modes where a != b, and stays undefined where a = b; a point is left alone where
// a neighbour's index is undefined.
void settle_singular_point_index(PointRecord* singular, const PointRecord& before, const PointRecord& after);

}  // namespace kirchhoff::detail
