// The frame's turn angle about e3 (the state's chi) is undefined where the tangent points along
// -e3 (spatial_state.hpp, kTurnAngleFloor). A rod clamped pointing down could not be integrated
// at all; it is now the rotated image of the same rod clamped pointing sideways, whose tangent
// never comes near -e3 - an independent solve of the same physics.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "kirchhoff/analysis/solution.hpp"
#include "kirchhoff/analysis/stability.hpp"
#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/shooting/shooting.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

// A heavy rod (weight w) clamped at the origin with frame `clamp` (rows of its matrix), gravity
// against `up`, a dead tip force `tip`; `guess` is n(0), which statics gives exactly.
std::string heavy_rod(const std::string& clamp, const std::string& up, const std::string& tip,
                      const std::string& guess) {
  return "model = \"spatial\"\n[parameters]\nw = 2.0\nF = 1.5\n"
         "[rod]\nlength = 1.0\nB = 1.0\nB3 = 0.8\ngravity = { weight = \"w\", up = " + up + " }\n"
         "[start]\ntype = \"clamped\"\nposition = [0, 0, 0]\norientation = { matrix = " + clamp + " }\n"
         "[end]\ntype = \"loaded\"\nforce = " + tip + "\nmoment = [0, 0, 0]\n"
         "[guess]\nforce = " + guess + "\nmoment = [0, 0, 0]\n";
}

struct Solved {
  Case c;
  std::unique_ptr<ShootingProblem> problem;
  ShootingResult result;
  RodPoint tip;
};

Solved solve_text(const std::string& text, const std::string& name) {
  const std::string path = testing::scratch_path(name);
  std::ofstream(path) << text;
  Solved out;
  out.c = load_case(path);
  out.problem = std::make_unique<ShootingProblem>(out.c.definition);
  out.result = solve(*out.problem, out.problem->initial_unknowns(out.c.start_guess));
  EXPECT_TRUE(out.result.summary.converged()) << name << ": " << out.result.summary.brief_report();
  out.tip = out.problem->sample(out.result.x, {1.0}).front();
  return out;
}

TEST(TurnAngle, ARodClampedPointingDownIsTheRotatedSidewaysRod) {
  // Hanging: d3 = -e3 at the clamp, gravity along -e3, the tip pushed along e1. The same rod
  // turned by Q (Q e1 = e3, Q e2 = e2, Q e3 = -e1): clamped with d3 = e1, gravity along e1, the tip
  // pushed along e3. Q maps (x, y, z) to (-z, y, x). Both integrate at 1e-12 per step and solve
  // to 1e-10: their tips agree to 1e-9.
  const Solved hanging = solve_text(heavy_rod("[[1, 0, 0], [0, -1, 0], [0, 0, -1]]", "[0, 0, 1]", "[\"F\", 0, 0]",
                                              "[\"F\", 0, \"-w\"]"),
                                    "hanging.toml");
  const Solved sideways = solve_text(heavy_rod("[[0, 0, 1], [0, -1, 0], [1, 0, 0]]", "[-1, 0, 0]", "[0, 0, \"F\"]",
                                               "[\"w\", 0, \"F\"]"),
                                     "sideways.toml");
  const Vec3 turned(-hanging.tip.r.z(), hanging.tip.r.y(), hanging.tip.r.x());
  EXPECT_LE((turned - sideways.tip.r).norm(), 1e-9) << hanging.tip.r.transpose() << " / " << sideways.tip.r.transpose();
  EXPECT_GT(hanging.tip.r.x(), 0.1);  // bent by the tip force, not straight
  // Both stable (a hanging rod pushed sideways), by the conjugate points.
  const StabilityReport a = analyse_stability(*hanging.problem, hanging.result.x);
  const StabilityReport b = analyse_stability(*sideways.problem, sideways.result.x);
  ASSERT_TRUE(a.index.has_value()) << a.reason;
  ASSERT_TRUE(b.index.has_value()) << b.reason;
  EXPECT_EQ(*a.index, 0);
  EXPECT_EQ(*b.index, 0);
}

TEST(TurnAngle, AStraightRodHangingDownHasItsWeightAsTension) {
  // Without the tip force the rod hangs straight along -e3, where w = qz = 0 all along: the
  // tension n.d3 = w (L - s), the tip at (0, 0, -1). The rates are constant along it (r' = d3,
  // n' = w e3), which the integrator follows exactly: 1e-12 is round-off.
  const Solved hanging = solve_text(heavy_rod("[[1, 0, 0], [0, -1, 0], [0, 0, -1]]", "[0, 0, 1]", "[0, 0, 0]",
                                              "[0, 0, \"-w\"]"),
                                    "hanging_straight.toml");
  EXPECT_LE((hanging.tip.r - Vec3(0.0, 0.0, -1.0)).norm(), 1e-12);
  const RodPoint top = hanging.problem->sample(hanging.result.x, {0.0}).front();
  EXPECT_NEAR(top.n.dot(top.R.col(2)), 2.0, 1e-12);
}

}  // namespace
}  // namespace kirchhoff
