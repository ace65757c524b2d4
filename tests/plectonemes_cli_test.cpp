// `kirchhoff plectonemes` killed with SIGKILL half-way through a branch and run again with
// --resume: the rows written before the kill stay as they were, indices run on without a gap or a
// repeat, the branch ends where the uninterrupted one ends, and a finished branch is left alone.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cli_run_support.hpp"

namespace {

using kirchhoff::testing::csv_field;
using kirchhoff::testing::lines_of;
using kirchhoff::testing::run_and_kill;
using kirchhoff::testing::run_to_end;
namespace fs = std::filesystem;

// L/2R = 100 from the untwisted rod to 3 turns: through both folds and the loop's closing, a few
// hundred points in ~10 s.
std::vector<std::string> sweep_args(const fs::path& dir) {
  return {KIRCHHOFF_CLI, "plectonemes", "--slenderness", "100", "--turns", "3", "--out", dir.string()};
}

using PlectonemesCli = kirchhoff::testing::ScratchFolderTest;

TEST_F(PlectonemesCli, KilledSweepResumesOnTheSameBranch) {
  const fs::path full = dir_ / "full", killed = dir_ / "killed";
  ASSERT_EQ(run_to_end(sweep_args(full), dir_ / "full.log", true), 0);
  const auto expected = lines_of(full / "plectoneme_100.csv");
  ASSERT_GT(expected.size(), 60u);
  EXPECT_EQ(expected[0].substr(0, 27), "index,turns,type,T_ext,heli");

  const fs::path csv = killed / "plectoneme_100.csv";
  ASSERT_TRUE(run_and_kill(sweep_args(killed), dir_ / "killed.log",
                           [&] { return lines_of(csv).size() >= expected.size() / 2; }))
      << "the sweep finished before it could be killed";
  const auto before = lines_of(csv);

  auto resume = sweep_args(killed);
  resume.push_back("--resume");
  ASSERT_EQ(run_to_end(resume, dir_ / "resume.log", true), 0);
  const auto after = lines_of(csv);
  // Rows up to the last resumable point are untouched. The resumed march recomputes the matrix
  // of its first point (the state keeps none), so its steps differ from the uninterrupted run's
  // and the two reach turns = 3 by different corrector paths: measured 1.5e-6 apart in T_ext,
  // with the residual 1e-8 on forces ~1e2. The bar, 1e-5, still tells another branch (O(1) apart).
  for (size_t i = 0; i + 3 < before.size(); ++i) EXPECT_EQ(after[i], before[i]) << "line " << i;
  for (size_t i = 1; i < after.size(); ++i)
    EXPECT_EQ(std::stoi(after[i].substr(0, after[i].find(','))), static_cast<int>(i - 1)) << "line " << i;
  ASSERT_NE(after.back().find(",endpoint,"), std::string::npos);
  EXPECT_NEAR(csv_field(after.back(), 1), 3.0, 3e-9);  // the located end point, to 1e-9 relative
  EXPECT_NEAR(csv_field(after.back(), 3) / csv_field(expected.back(), 3), 1.0, 1e-5);  // T_ext at 3 turns

  // A finished branch is left as it is.
  ASSERT_EQ(run_to_end(resume, dir_ / "again.log", true), 0);
  EXPECT_EQ(lines_of(csv), after);
  const auto log = lines_of(dir_ / "again.log");
  std::string all;
  for (const auto& l : log) all += l + "\n";
  EXPECT_NE(all.find("already complete"), std::string::npos) << all;
}

}  // namespace
