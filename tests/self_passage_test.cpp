// The check that a continuation step does not carry the rod through itself (self_passage.hpp).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <set>
#include <vector>

#include "kirchhoff/contact/detail/spatial_bins.hpp"
#include "kirchhoff/contact/self_passage.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

constexpr double kR = 0.01;

// A hairpin of two parallel strands, 2.2 R apart like the strands of a ply: the whole rod runs
// out along e1 and back, the return strand at `offset` from the first; the turn itself is left
// out (a whole rod sampled R/2 apart, arclengths as a rod's).
std::vector<WholeRodSection> hairpin(const Vec3& offset, const Mat3& turn = Mat3::Identity()) {
  std::vector<WholeRodSection> rod;
  const int n = 200;
  const double h = 0.5 * kR;
  for (int k = 0; k <= n; ++k) rod.push_back({k * h, turn * Vec3(k * h, 0.0, 0.0)});
  for (int k = n; k >= 0; --k) rod.push_back({(2 * n + 1 - k) * h + 10 * kR, turn * (Vec3(k * h, 0.0, 0.0) + offset)});
  return rod;
}

// The return strand moved from above the first to below it: half way, the two strands meet.
TEST(SelfPassage, StrandsSwappingSidesMeetOnTheWay) {
  const Vec3 above(0.0, 0.0, 2.2 * kR);
  const SelfPassage p = closest_approach_in_motion(hairpin(above), hairpin(-above), M_PI * kR, kR);
  EXPECT_LT(p.distance, 1e-12);
  EXPECT_NEAR(p.t, 0.5, 1e-12);
  EXPECT_GT(std::abs(p.s_second - p.s_first), M_PI * kR);
}

// Moves a ply makes between close points keep the strands apart: one strand sliding along the
// other by 5 R (the partner of each section changes), and the pair turning about its axis by 60
// degrees (half way the strands are 2.2 R cos 30 = 1.9 R apart). Turned by 150 degrees in one
// step the straight paths cut the corner to 2.2 R cos 75 = 0.57 R: refused, conservatively -
// such a step is retried shorter.
TEST(SelfPassage, SlidingAndTurningPliesKeepTheirDistance) {
  const Vec3 above(0.0, 0.0, 2.2 * kR);
  const Vec3 centre = 0.5 * above;
  auto about_axis = [&](double degrees) {
    return Eigen::AngleAxisd(degrees * M_PI / 180.0, Vec3::UnitX()).toRotationMatrix();
  };
  EXPECT_EQ(closest_approach_in_motion(hairpin(above), hairpin(above + Vec3(5 * kR, 0, 0)), M_PI * kR, kR).distance,
            INFINITY);
  // Turning about the line half-way between the strands: shift, turn, shift back.
  auto turned = [&](double degrees) {
    auto rod = hairpin(above);
    for (auto& section : rod) section.r = centre + about_axis(degrees) * (section.r - centre);
    return rod;
  };
  EXPECT_EQ(closest_approach_in_motion(hairpin(above), turned(60.0), M_PI * kR, kR).distance, INFINITY);
  const SelfPassage p = closest_approach_in_motion(hairpin(above), turned(150.0), M_PI * kR, kR);
  EXPECT_NEAR(p.distance, 2.2 * kR * std::cos(75.0 * M_PI / 180.0), 1e-12);
}

// Different samplings cannot be compared.
TEST(SelfPassage, RefusesDifferentSamplings) {
  auto shorter = hairpin(Vec3(0, 0, 2.2 * kR));
  shorter.pop_back();
  EXPECT_THROW(closest_approach_in_motion(hairpin(Vec3(0, 0, 2.2 * kR)), shorter, M_PI * kR, kR),
               std::invalid_argument);
}

// The binned search visits every pair closer than the cell among the strided points, each once
// with i < j: checked against all pairs on a cloud (points on both sides of the origin, so cubes
// of negative index too) and on the hairpin's two strands.
TEST(NearPairs, AreEveryPairCloserThanTheCellVisitedOnce) {
  std::vector<Vec3> cloud;
  for (int k = 0; k < 600; ++k)
    cloud.push_back(Vec3(std::sin(1.3 * k), std::cos(0.7 * k + 0.2), std::sin(0.37 * k) * std::cos(2.1 * k)));
  std::vector<Vec3> strands;
  for (const auto& section : hairpin(Vec3(0.0, 0.0, 2.2 * kR))) strands.push_back(section.r);
  for (const auto& [points, cell] : {std::pair{cloud, 0.15}, std::pair{strands, 4.0 * kR}})
    for (const std::size_t stride : {1, 3}) {
      std::set<std::pair<std::size_t, std::size_t>> visited;
      int repeats = 0;
      for_each_near_pair(points, cell, stride, [&](std::size_t i, std::size_t j) {
        EXPECT_LT(i, j);
        EXPECT_EQ(i % stride, 0u);
        EXPECT_EQ(j % stride, 0u);
        repeats += visited.insert({i, j}).second ? 0 : 1;
      });
      EXPECT_EQ(repeats, 0);
      int close = 0;
      for (std::size_t i = 0; i < points.size(); i += stride)
        for (std::size_t j = i + stride; j < points.size(); j += stride)
          if ((points[i] - points[j]).norm() < cell) {
            ++close;
            EXPECT_TRUE(visited.count({i, j})) << i << " " << j;
          }
      EXPECT_GT(close, 20);  // the case has pairs to find
    }
}

}  // namespace
}  // namespace kirchhoff
