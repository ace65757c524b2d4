// The kinked minimum (continuation/detail/kinked_minimum.hpp), which locates branch points of even
// multiplicity, on monitors whose minimum is known: an exact V (found by one fit), a V with
// curvature and unequal slopes (as the smallest singular value near a branch point), a V that
// does not reach zero, a smooth minimum (golden sections carry it), and starts that are no bracket.
// Each counts its evaluations against golden sections' 58 for the same width, which Brent takes
// on a kink.
#include "kirchhoff/continuation/detail/kinked_minimum.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace kirchhoff::detail {
namespace {

constexpr double kTolerance = 1e-12;  // the continuation's kLocateTolerance on a step of 1
constexpr int kMaxEvaluations = 60;

KinkedMinimum minimise_on_unit_step(const std::function<double(double)>& f) {
  return minimise_kinked(f, {0.0, f(0.0)}, {0.5, f(0.5)}, {1.0, f(1.0)}, kTolerance, kMaxEvaluations);
}

TEST(KinkedMinimum, AnExactVIsFoundByOneFit) {
  const double h_star = 0.6180339887;
  const auto result = minimise_on_unit_step([&](double h) { return 3.0 * std::abs(h - h_star); });
  // The fit through (0, 0.5, 1) lands on h* to round-off; f(h*) ~ 1e-16, not exactly 0.
  EXPECT_NEAR(result.best.h, h_star, 1e-14);
  EXPECT_LE(result.evaluations, 3);
}

TEST(KinkedMinimum, ACurvedUnevenVConvergesFast) {
  // sigma(h) = |h - h*| (c + d (h - h*)) with different slopes on the two sides, as the smallest
  // singular value of a matrix J0 + (h - h*) J1 + (h - h*)^2 J2 near its singular point.
  for (double h_star : {0.36, 0.5, 0.71, 0.66}) {  // each bracketed by (0, 0.5, 1)
    const auto result = minimise_on_unit_step([&](double h) {
      const double t = h - h_star;
      return std::abs(t) * (2.0 + (t > 0 ? 1.5 : 0.4) + 0.8 * t);
    });
    ASSERT_TRUE(result.bracketed) << "h* = " << h_star;
    EXPECT_NEAR(result.best.h, h_star, 1e-11) << "h* = " << h_star;
    // Golden sections need 58 evaluations to 1e-12; the fits about a third of that.
    EXPECT_LE(result.evaluations, 25) << "h* = " << h_star;
  }
}

TEST(KinkedMinimum, AVAboveZeroIsLocated) {
  // A near miss: the two singular values pass close to zero without reaching it.
  const double h_star = 0.4321;
  const auto result = minimise_on_unit_step([&](double h) { return 1e-3 + 5.0 * std::abs(h - h_star); });
  EXPECT_NEAR(result.best.h, h_star, 1e-11);
  EXPECT_NEAR(result.best.value, 1e-3, 1e-10);
  // Found by the first fit; the bracket then closes by probes of a quarter of its nearer side.
  EXPECT_LE(result.evaluations, 25);
}

TEST(KinkedMinimum, ASmoothMinimumIsStillFound) {
  // No kink: the fits stall and golden sections take over. The value is quadratic there, so the
  // location is only as good as sqrt of the bracket's values' resolution; the bracket itself
  // shrinks to the tolerance within the evaluation budget.
  const double h_star = 0.37;
  const auto result = minimise_on_unit_step([&](double h) { return 1.0 + (h - h_star) * (h - h_star); });
  EXPECT_NEAR(result.best.h, h_star, 1e-6);
  EXPECT_LE(result.evaluations, kMaxEvaluations);
}

TEST(KinkedMinimum, NoBracketIsReportedAndNotSearched) {
  int calls = 0;
  const auto rising = [&](double h) {
    ++calls;
    return h;
  };
  const auto result = minimise_kinked(rising, {0.0, 0.0}, {0.5, 0.5}, {1.0, 1.0}, kTolerance, kMaxEvaluations);
  EXPECT_FALSE(result.bracketed);
  EXPECT_EQ(calls, 0);
  EXPECT_EQ(result.evaluations, 0);
}

TEST(KinkedMinimum, UnevaluablePointsCountAsHigh) {
  // The corrector fails left of 0.2 (the monitor returns +inf there); the kink is at 0.3.
  const auto result = minimise_kinked(
      [](double h) { return h < 0.2 ? INFINITY : std::abs(h - 0.3); }, {0.0, INFINITY}, {0.5, 0.2}, {1.0, 0.7},
      kTolerance, kMaxEvaluations);
  EXPECT_NEAR(result.best.h, 0.3, 1e-11);
}

}  // namespace
}  // namespace kirchhoff::detail
