// Internal: the compliances 1/B_i and 1/A_i of a rod model, for its right-hand sides.
//
// Why: a right-hand side is evaluated hundreds of times per residual and divided by each
// stiffness every time; a division costs about ten multiplications, and the 3D rod's five per
// call were its slowest instructions. A constant stiffness (most rods) is divided once here, so
// the equations multiply by the very number 1.0 / B_i(s) they divided by before, bit for bit. A
// stiffness that varies along s is divided at each s, as before.
#pragma once

#include <array>

#include "kirchhoff/model/rod_model.hpp"

namespace kirchhoff::detail {

class Compliances {
 public:
  explicit Compliances(const RodModel& model) {
    for (int i = 0; i < 3; ++i) {
      bending_[i] = model.B[i].is_constant() ? 1.0 / model.B[i](0.0) : kVaries;
      stretching_[i] = model.A[i].is_constant() ? 1.0 / model.A[i](0.0) : kVaries;
    }
  }
  // 1 / B_i(s) and 1 / A_i(s) of the model this was built from.
  double bending(const RodModel& model, int i, double s) const {
    return bending_[i] != kVaries ? bending_[i] : 1.0 / model.B[i](s);
  }
  double stretching(const RodModel& model, int i, double s) const {
    return stretching_[i] != kVaries ? stretching_[i] : 1.0 / model.A[i](s);
  }

 private:
  static constexpr double kVaries = 0.0;  // (no finite stiffness has a zero compliance)
  std::array<double, 3> bending_{}, stretching_{};
};

}  // namespace kirchhoff::detail
