// `kirchhoff continue` saves its state file at the first point, then at most once per
// --checkpoint seconds, and at the end. A run killed between two saves resumes from the last
// one: the CSV is cut back to that save's row and the rows after it are computed again, so the
// resumed CSV is the uninterrupted run's, byte for byte (nothing lost, nothing duplicated).
//
// The kills are deterministic (KIRCHHOFF_TEST_KILL_AFTER_ROW, see tests/resume_test.cpp); so are
// the saves with --checkpoint 100000: only the first point's state (row 0) is saved before the
// kill, however far the run got.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_run_support.hpp"

namespace {

using kirchhoff::testing::lines_of;
using kirchhoff::testing::run_to_end;
namespace fs = std::filesystem;

// The README's Euler column (as tests/resume_test.cpp): the straight column to its branch point
// (row 19), the buckled branch from row 20 to theta0 = 3 (row 146).
std::vector<std::string> euler_args(const fs::path& csv, const std::string& checkpoint) {
  return {KIRCHHOFF_CLI, "continue", std::string(KIRCHHOFF_CASES_DIR) + "/euler_column.toml", "--param", "P",
          "--to", "12", "--set", "P=1", "--set", "theta_guess=0", "--switch-at-bp", "1", "--event", "theta0=3",
          "--max-step", "1", "--checkpoint", checkpoint, "--out", csv.string()};
}

// The wall through its contact legs, 300 points (as tests/resume_test.cpp's, shorter).
std::vector<std::string> wall_args(const fs::path& csv, const std::string& checkpoint) {
  return {KIRCHHOFF_CLI, "continue", std::string(KIRCHHOFF_CASES_DIR) + "/wall.toml", "--param", "Delta",
          "--to", "0.07", "--set", "Delta=0.005", "--set", "m_guess=0.9", "--max-step", "2",
          "--max-points", "300", "--checkpoint", checkpoint, "--out", csv.string()};
}

std::vector<std::string> with(std::vector<std::string> args, const std::string& extra) {
  args.push_back(extra);
  return args;
}

int saved_row(const fs::path& csv) {
  std::ifstream in(csv.string() + ".state.json");
  return nlohmann::json::parse(in).at("row").get<int>();
}

int written_row(const fs::path& csv) {
  std::ifstream in(csv.string() + ".state.json");
  return nlohmann::json::parse(in).at("written").at("row").get<int>();
}

class CheckpointTest : public kirchhoff::testing::ScratchFolderTest {
 protected:
  // Kills the run (whose --out is `csv`) right after `row`; returns the row its state was saved at.
  int kill_after(const std::vector<std::string>& args, const fs::path& csv, int row) {
    fs::remove(csv);
    fs::remove(csv.string() + ".state.json");
    setenv("KIRCHHOFF_TEST_KILL_AFTER_ROW", std::to_string(row).c_str(), 1);
    run_to_end(args, dir_ / "killed.log");
    unsetenv("KIRCHHOFF_TEST_KILL_AFTER_ROW");
    EXPECT_EQ(lines_of(csv).size(), static_cast<size_t>(row + 2)) << "the header and rows 0.." << row;
    return saved_row(csv);
  }
};

// Killed far past the only save (row 0): on the straight column, on the switched branch (the
// resumed run switches again at the branch point) and with a row cut short by the kill after the
// last whole one. Each resumed CSV is the uninterrupted run's.
TEST_F(CheckpointTest, RunKilledBetweenCheckpointsResumesToTheSameRows) {
  const fs::path full = dir_ / "full.csv", csv = dir_ / "killed.csv";
  ASSERT_EQ(run_to_end(euler_args(full, "0"), dir_ / "full.log"), 0);
  const auto expected = lines_of(full);
  const int last = static_cast<int>(expected.size()) - 2;  // the last row (108 rows: 107)
  ASSERT_GT(last, 70);
  ASSERT_NE(expected.back().find(",event,"), std::string::npos) << expected.back();
  // Saving after every point or once a second gives the same rows.
  ASSERT_EQ(run_to_end(euler_args(dir_ / "default.csv", "1"), dir_ / "default.log"), 0);
  EXPECT_EQ(lines_of(dir_ / "default.csv"), expected);
  for (int row : {15, 60, last - 6}) {
    SCOPED_TRACE("killed after row " + std::to_string(row));
    EXPECT_EQ(kill_after(euler_args(csv, "100000"), csv, row), 0) << "saved only at the first point";
    if (row == last - 6) {
      std::ofstream partial(csv, std::ios::app);
      partial << "1";  // the start of the next row, cut short (it reads as the index 1)
    }
    ASSERT_EQ(run_to_end(with(euler_args(csv, "100000"), "--resume"), dir_ / "resume.log"), 0);
    EXPECT_EQ(lines_of(csv), expected);
    // Saved at the end: the last point a march goes on from (the row before the last; the
    // event in the last row is not one), with the last row written, where --start-from starts.
    EXPECT_EQ(saved_row(csv), last - 1);
    EXPECT_EQ(written_row(csv), last);
  }
  // A resume with another --checkpoint continues the same run (it does not decide the points).
  EXPECT_EQ(kill_after(euler_args(csv, "100000"), csv, 80), 0);
  ASSERT_EQ(run_to_end(with(euler_args(csv, "0"), "--resume"), dir_ / "resume.log"), 0);
  EXPECT_EQ(lines_of(csv), expected);
}

// The same through the wall's contact legs (the first contact at row 7, the contact flattening
// at row 84): the resumed run changes the active set again where the uninterrupted one did.
TEST_F(CheckpointTest, ContactRunKilledBetweenCheckpointsResumesToTheSameRows) {
  const fs::path full = dir_ / "wall_full.csv", csv = dir_ / "wall.csv";
  ASSERT_EQ(run_to_end(wall_args(full, "0"), dir_ / "wall_full.log"), 0);
  const auto expected = lines_of(full);
  ASSERT_EQ(expected.size(), 301u);  // the header and --max-points 300 rows (row 0 the start)
  ASSERT_NE(expected[85].find("contact_flattens"), std::string::npos) << expected[85];
  for (int row : {50, 120}) {
    SCOPED_TRACE("killed after row " + std::to_string(row));
    EXPECT_EQ(kill_after(wall_args(csv, "100000"), csv, row), 0);
    ASSERT_EQ(run_to_end(with(wall_args(csv, "100000"), "--resume"), dir_ / "wall_resume.log"), 0);
    EXPECT_EQ(lines_of(csv), expected);
  }
}

}  // namespace
