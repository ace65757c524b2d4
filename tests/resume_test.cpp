// `kirchhoff continue --resume` repeats the uninterrupted run: a run killed after any row and
// resumed with the same command plus --resume writes the same CSV, byte for byte.
//
// The kills are deterministic: KIRCHHOFF_TEST_KILL_AFTER_ROW=K makes the run SIGKILL itself right
// after row K is written and flushed, before the state is saved for it (the narrowest window a
// real kill can hit; K = -1: before the first point). tests/resume_soak.sh kills the same
// commands at random times instead.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "cli_run_support.hpp"

namespace {

using kirchhoff::testing::lines_of;
using kirchhoff::testing::run_to_end;
namespace fs = std::filesystem;

// The README's Euler column: along the straight column from P = 1 to its first branch point
// (P = pi^2, row 19), switched onto the buckled branch (origin row 20; --to 12 does not apply
// there), followed through a branch point of that branch (row 63) to theta0 = 3 at P = 65.25
// (row 146).
std::vector<std::string> euler_args(const fs::path& csv) {
  return {KIRCHHOFF_CLI, "continue", std::string(KIRCHHOFF_CASES_DIR) + "/euler_column.toml", "--param", "P",
          "--to", "12", "--set", "P=1", "--set", "theta_guess=0", "--switch-at-bp", "1", "--event", "theta0=3",
          "--max-step", "1", "--out", csv.string()};
}

// The README's wall: contact at Delta = 0.02507 (row 7), the contact flattens at 0.03075 (row
// 84; row 83 is the branch point there, where a single contact moving off mid-span branches off
// the symmetric one), the flat contact buckles into a hanging fold at 0.04805 (row 236), a fold
// at 0.046613 (row 279), Delta = 0.07 at P = 197.23 (row 359). A few seconds.
std::vector<std::string> wall_args(const fs::path& csv, const std::string& max_points = "6000") {
  return {KIRCHHOFF_CLI, "continue", std::string(KIRCHHOFF_CASES_DIR) + "/wall.toml", "--param", "Delta",
          "--to", "0.07", "--set", "Delta=0.005", "--set", "m_guess=0.9", "--max-step", "2",
          "--max-points", max_points, "--out", csv.string()};
}

// The first line of a CSV (after its header) that holds `text`, -1 if none.
int first_line_with(const std::vector<std::string>& lines, const std::string& text) {
  for (size_t i = 1; i < lines.size(); ++i)
    if (lines[i].find(text) != std::string::npos) return static_cast<int>(i);
  return -1;
}

std::vector<std::string> with_resume(std::vector<std::string> args) {
  args.push_back("--resume");
  return args;
}

class ResumeTest : public kirchhoff::testing::ScratchFolderTest {
 protected:
  // Runs `args` (whose --out is `csv`) killed right after row `row`; checks that it wrote rows 0
  // to `row` and no more.
  void run_killed_after(const std::vector<std::string>& args, const fs::path& csv, int row) {
    fs::remove(csv);
    fs::remove(csv.string() + ".state.json");
    setenv("KIRCHHOFF_TEST_KILL_AFTER_ROW", std::to_string(row).c_str(), 1);
    run_to_end(args, dir_ / "killed.log");
    unsetenv("KIRCHHOFF_TEST_KILL_AFTER_ROW");
    ASSERT_EQ(lines_of(csv).size(), static_cast<size_t>(row + 2)) << "the header and rows 0.." << row;
  }
  // Kills the run after `row`, resumes it and compares its CSV with `expected`, line by line.
  // Both save their state after every point (--checkpoint 0), so the resume starts from row
  // `row` - 1's state, the march's own, not from the last timed checkpoint (with the default of
  // a second, a run of a few seconds would resume from its start and test little).
  void expect_resume_repeats(std::vector<std::string> args, const fs::path& csv,
                             const std::vector<std::string>& expected, int row) {
    SCOPED_TRACE("killed after row " + std::to_string(row));
    args.insert(args.end(), {"--checkpoint", "0"});
    run_killed_after(args, csv, row);
    ASSERT_EQ(run_to_end(with_resume(args), dir_ / "resume.log"), 0);
    const auto resumed = lines_of(csv);
    ASSERT_EQ(resumed.size(), expected.size());
    for (size_t i = 0; i < expected.size(); ++i) ASSERT_EQ(resumed[i], expected[i]) << "line " << i;
  }
};

// (a) Killed on the straight column at its branch point, on the switched branch's origin, below
// P = 12 on the buckled branch (where --to 12 used to stop a resumed run: 31 rows, "endpoint"),
// at the buckled branch's own branch point and further on: each resumed run ends at theta0 = 3
// with the uninterrupted run's rows (108).
TEST_F(ResumeTest, EulerColumnResumedOnTheBuckledBranchRepeatsTheRun) {
  const fs::path full = dir_ / "full.csv", csv = dir_ / "killed.csv";
  ASSERT_EQ(run_to_end(euler_args(full), dir_ / "full.log"), 0);
  const auto expected = lines_of(full);
  ASSERT_GT(expected.size(), 101u);
  ASSERT_NE(expected[20].find("19,0,"), std::string::npos);
  ASSERT_NE(expected[20].find(",branch_point,"), std::string::npos);
  ASSERT_NE(expected.back().find(",event,0,theta0=3"), std::string::npos);
  for (int row : {18, 19, 20, 21, 25, 63, 100}) expect_resume_repeats(euler_args(csv), csv, expected, row);
  EXPECT_NE(lines_of(dir_ / "resume.log").back().find("stopped: event"), std::string::npos);
}

// max_points counts a branch's points across a resume as in one run (it used to be re-derived
// from the CSV's rows, one off on the switched branch).
TEST_F(ResumeTest, PointBudgetIsTheSameAcrossAResume) {
  auto args_for = [](const fs::path& csv) {
    auto a = euler_args(csv);
    a.insert(a.end() - 2, {"--max-points", "30"});
    return a;
  };
  const fs::path full = dir_ / "full.csv", csv = dir_ / "killed.csv";
  ASSERT_EQ(run_to_end(args_for(full), dir_ / "full.log"), 0);
  const auto expected = lines_of(full);
  ASSERT_NE(lines_of(dir_ / "full.log").back().find("stopped: max_points"), std::string::npos);
  ASSERT_EQ(expected.size(), 51u);  // the header, 20 rows on the straight column, 30 on the buckled branch
  for (int row : {10, 35, 48})
    expect_resume_repeats(args_for(csv), csv, expected, row);
}

// (b) The wall, killed right after the contact flattens (the state is then the new leg's start,
// which is not a row of its own), on the flat contact's long ill-conditioned leg and on the
// hanging fold's leg past its fold: the same rows, the same active-set changes, the same
// end (P = 197.23 at Delta = 0.07; resumed runs used to end at 349.65 or 287.37 after a fold at
// 0.047725).
TEST_F(ResumeTest, WallResumedOnItsContactLegsRepeatsTheRun) {
  const fs::path full = dir_ / "wall.csv", csv = dir_ / "killed.csv";
  ASSERT_EQ(run_to_end(wall_args(full), dir_ / "wall.log"), 0);
  const auto expected = lines_of(full);
  // Where the legs begin (line i of the CSV is row i - 1): the flattening, the hanging fold's
  // event, then its fold; the run ends on the target.
  const int flattens = first_line_with(expected, "contact_flattens"),
            hanging = first_line_with(expected, "flat_contact_buckles"), fold = first_line_with(expected, ",fold,"),
            last = static_cast<int>(expected.size()) - 1;
  ASSERT_TRUE(0 < flattens && flattens < hanging && hanging < fold && fold + 2 < last)
      << flattens << " " << hanging << " " << fold << " " << last;
  ASSERT_NE(expected.back().find(",endpoint,"), std::string::npos);
  EXPECT_NE(expected.back().find(",0.07,"), std::string::npos);
  EXPECT_NE(expected.back().find(",197.228"), std::string::npos) << "P at the end";
  // (Each kill costs a whole run: the point-contact leg's kills are in the test below.)
  for (int row : {flattens, (flattens + hanging) / 2, (fold + last) / 2})
    expect_resume_repeats(wall_args(csv), csv, expected, row);
}

// The cavity's flat contact (from row 283, Delta = 0.030749) is a long leg whose corrector lands
// on the branch to its tolerance only along a weakly determined direction: a resumed run whose
// first step was predicted from the tangent alone, not from the last two points as the
// uninterrupted run's was, landed 3e-8 away, and the two runs ended on different branches at
// Delta = 0.1 (P = 273.97 against 169.81). Killed on that leg, the resumed run writes the same rows.
TEST_F(ResumeTest, CavityResumedOnItsFlatLegRepeatsTheRun) {
  auto args_for = [](const fs::path& csv) {
    return std::vector<std::string>{KIRCHHOFF_CLI, "continue", std::string(KIRCHHOFF_CASES_DIR) + "/cavity.toml",
                                    "--param", "Delta", "--to", "0.1", "--max-points", "600", "--out", csv.string()};
  };
  const fs::path full = dir_ / "full.csv", csv = dir_ / "killed.csv";
  ASSERT_EQ(run_to_end(args_for(full), dir_ / "full.log"), 0);
  const auto expected = lines_of(full);
  ASSERT_EQ(expected.size(), 601u);
  const int flattens = first_line_with(expected, "contact_flattens");
  ASSERT_TRUE(200 < flattens && flattens < 400) << flattens;
  for (int row : {flattens + 20, flattens + 200}) expect_resume_repeats(args_for(csv), csv, expected, row);
}

// The legs of a contact run share --max-points: a resumed leg gets the share it had (killed on
// the point-contact leg, at the flat contact's start and on it).
TEST_F(ResumeTest, WallPointBudgetIsTheSameAcrossAResume) {
  const fs::path full = dir_ / "wall.csv", csv = dir_ / "killed.csv";
  ASSERT_EQ(run_to_end(wall_args(full, "150"), dir_ / "wall.log"), 0);
  const auto expected = lines_of(full);
  ASSERT_EQ(expected.size(), 151u);
  const int flattens = first_line_with(expected, "contact_flattens");  // the row after it: the flat leg's start
  ASSERT_TRUE(40 < flattens && flattens < 140) << flattens;
  for (int row : {40, flattens, 140}) expect_resume_repeats(wall_args(csv, "150"), csv, expected, row);
}

// A wrap lowered off its disc: the wrap shrinks to a point contact (row 26), after which the
// next leg arms contact_flattens at that contact's starting g'' (-1.3e-13, not 0), and the
// contact lifts off (row 48). Resumed on that leg, the event is armed where it was: killed
// before the shrinking, right after it, on the point contact's leg and at the lift-off.
TEST_F(ResumeTest, UnwoundWrapResumedOnItsPointContactLegRepeatsTheRun) {
  auto args_for = [](const fs::path& csv) {
    return std::vector<std::string>{KIRCHHOFF_CLI, "continue", std::string(KIRCHHOFF_CASES_DIR) + "/wrapped_indenter.toml",
                                    "--set", "radius=0.5", "--set", "half_span=0.5", "--set", "rise=0.18", "--param",
                                    "rise", "--to", "-0.01", "--step", "0.01", "--max-step", "1", "--out", csv.string()};
  };
  const fs::path full = dir_ / "full.csv", csv = dir_ / "killed.csv";
  ASSERT_EQ(run_to_end(args_for(full), dir_ / "full.log"), 0);
  const auto expected = lines_of(full);
  const int shrinks = first_line_with(expected, "contact_shrinks_to_a_point"),
            lifts = first_line_with(expected, "contact_lifts_off");
  ASSERT_TRUE(1 < shrinks && shrinks + 2 < lifts) << shrinks << " " << lifts;
  // (Line i of the CSV is row i - 1.)
  for (int row : {shrinks - 2, shrinks - 1, (shrinks + lifts) / 2, lifts - 1})
    expect_resume_repeats(args_for(csv), csv, expected, row);
}

// (c) Killed before its first point was saved (before it, or after the start's row but before
// its state): --resume starts the run over and writes the same CSV.
TEST_F(ResumeTest, RunKilledBeforeItsFirstSaveStartsOver) {
  const fs::path full = dir_ / "full.csv", csv = dir_ / "killed.csv";
  ASSERT_EQ(run_to_end(euler_args(full), dir_ / "full.log"), 0);
  const auto expected = lines_of(full);
  for (int row : {-1, 0}) {
    expect_resume_repeats(euler_args(csv), csv, expected, row);
    EXPECT_NE(lines_of(dir_ / "resume.log").front().find("starts from the beginning"), std::string::npos);
  }
  // The same with a contact run.
  const fs::path wall = dir_ / "wall.csv";
  run_killed_after(wall_args(wall, "20"), wall, -1);
  EXPECT_FALSE(fs::exists(wall.string() + ".state.json"));
  ASSERT_EQ(run_to_end(with_resume(wall_args(wall, "20")), dir_ / "wall_resume.log"), 0);
  ASSERT_EQ(run_to_end(wall_args(dir_ / "wall_full.csv", "20"), dir_ / "wall_full.log"), 0);
  EXPECT_EQ(lines_of(wall), lines_of(dir_ / "wall_full.csv"));
}

// (d) A run started from another one (--start-from), killed and resumed with the same command:
// the resumed run keeps the parameter values it started with (the first run's --set and its
// endpoint, which its own --set does not hold) and repeats the uninterrupted run. Resumed
// without --start-from it is refused (other arguments). Without obstacles (soft_wall from its
// endpoint at Delta = 0.026 with log_b = -4, in log_b) and with (the wall from its point
// contact at Delta = 0.028, in the wall's height a, through the contact's flattening).
TEST_F(ResumeTest, RunStartedFromAnotherResumesWithItsStartingValues) {
  const std::string soft_wall = std::string(KIRCHHOFF_CASES_DIR) + "/soft_wall.toml";
  const fs::path first = dir_ / "first.csv";
  ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", soft_wall, "--set", "log_b=-4", "--set", "Delta=0.02", "--set",
                        "m_guess=1", "--param", "Delta", "--to", "0.026", "--out", first.string()},
                       dir_ / "first.log"),
            0);
  auto from_first = [&](const fs::path& csv) {
    return std::vector<std::string>{KIRCHHOFF_CLI, "continue", soft_wall, "--start-from",
                                    first.string() + ".state.json", "--param", "log_b", "--to", "-3",
                                    "--out", csv.string()};
  };
  const fs::path full = dir_ / "full.csv", csv = dir_ / "killed.csv";
  ASSERT_EQ(run_to_end(from_first(full), dir_ / "full.log"), 0);
  const auto expected = lines_of(full);
  ASSERT_GT(expected.size(), 30u);
  for (int row : {0, 10, 25}) expect_resume_repeats(from_first(csv), csv, expected, row);

  ASSERT_NO_FATAL_FAILURE(run_killed_after(from_first(csv), csv, 10));
  auto without = from_first(csv);
  without.erase(without.begin() + 3, without.begin() + 5);  // --start-from FILE
  EXPECT_EQ(run_to_end(with_resume(without), dir_ / "without.log"), 2);
  EXPECT_NE(lines_of(dir_ / "without.log").front().find("other arguments"), std::string::npos);

  const fs::path point = dir_ / "point.csv";
  ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", std::string(KIRCHHOFF_CASES_DIR) + "/wall.toml", "--param",
                        "Delta", "--to", "0.028", "--set", "Delta=0.005", "--set", "m_guess=0.9", "--max-step", "2",
                        "--out", point.string()},
                       dir_ / "point.log"),
            0);
  auto wall_from_point = [&](const fs::path& out) {
    return std::vector<std::string>{KIRCHHOFF_CLI, "continue", std::string(KIRCHHOFF_CASES_DIR) + "/wall.toml",
                                    "--start-from", point.string() + ".state.json", "--param", "a", "--to", "0.09",
                                    "--max-step", "2", "--max-points", "3000", "--out", out.string()};
  };
  const fs::path wall_full = dir_ / "wall_full.csv", wall_csv = dir_ / "wall_killed.csv";
  ASSERT_EQ(run_to_end(wall_from_point(wall_full), dir_ / "wall_full.log"), 0);
  const auto wall_expected = lines_of(wall_full);
  size_t flattens = 0;
  for (size_t i = 0; i < wall_expected.size(); ++i)
    if (wall_expected[i].find("flattens") != std::string::npos) flattens = i;
  ASSERT_GT(flattens, 21u);
  ASSERT_GT(wall_expected.size(), flattens + 20);
  // On the point contact's leg, and on the flat contact's.
  for (int row : {20, static_cast<int>(flattens + (wall_expected.size() - flattens) / 2)})
    expect_resume_repeats(wall_from_point(wall_csv), wall_csv, wall_expected, row);
}

// What cannot be resumed is refused with the reason, and the CSV is left as it was: rows with
// no state file (it was removed: nothing says where the march stood), and a state saved by a run
// with other arguments (resuming it would not continue that run).
TEST_F(ResumeTest, UnresumableRunsAreRefusedWithTheReason) {
  const fs::path csv = dir_ / "run.csv";
  ASSERT_NO_FATAL_FAILURE(run_killed_after(euler_args(csv), csv, 30));
  const auto before = lines_of(csv);

  auto other = euler_args(csv);
  other[other.size() - 3] = "0.5";  // --max-step
  ASSERT_EQ(other[other.size() - 4], "--max-step");
  EXPECT_EQ(run_to_end(with_resume(other), dir_ / "other.log"), 2);
  const auto other_log = lines_of(dir_ / "other.log");
  ASSERT_FALSE(other_log.empty());
  EXPECT_NE(other_log.front().find("other arguments (saved max_step=1, now max_step=0.5)"), std::string::npos)
      << other_log.front();
  EXPECT_EQ(other_log.front().find("cannot be read"), std::string::npos) << other_log.front();  // (from a probe)
  EXPECT_EQ(lines_of(csv), before);

  fs::remove(csv.string() + ".state.json");
  EXPECT_EQ(run_to_end(with_resume(euler_args(csv)), dir_ / "nostate.log"), 2);
  const auto log = lines_of(dir_ / "nostate.log");
  ASSERT_FALSE(log.empty());
  EXPECT_NE(log.front().find("has 31 rows but there is no state file"), std::string::npos) << log.front();
  EXPECT_EQ(lines_of(csv), before);
}

// A CSV that lost rows its state file counts on (cut, a row deleted, a row cut short, or the
// file gone) is refused with the reason and left as it is: the resume appended after the gap with
// exit 0 (from a probe; a kill cannot do this, each row being flushed before the state is saved).
TEST_F(ResumeTest, ACsvThatLostRowsBeforeItsSavedOneIsRefused) {
  const fs::path csv = dir_ / "run.csv";
  auto args = euler_args(csv);
  args.insert(args.end(), {"--checkpoint", "0"});
  ASSERT_NO_FATAL_FAILURE(run_killed_after(args, csv, 30));  // state saved after row 29
  const auto killed = lines_of(csv);
  const auto write = [&](const std::vector<std::string>& lines) {
    std::ofstream out(csv, std::ios::trunc);
    for (const auto& line : lines) out << line << "\n";
  };
  const auto expect_refused = [&](const std::string& reason) {
    SCOPED_TRACE(reason);
    const auto before = fs::exists(csv) ? lines_of(csv) : std::vector<std::string>{};
    EXPECT_EQ(run_to_end(with_resume(args), dir_ / "refused.log"), 2);
    const std::string log = kirchhoff::testing::read_text(dir_ / "refused.log");
    EXPECT_NE(log.find(reason), std::string::npos) << log;
    EXPECT_EQ(fs::exists(csv) ? lines_of(csv) : std::vector<std::string>{}, before);
  };
  write({killed.begin(), killed.begin() + 11});  // the header and rows 0..9
  expect_refused("it ends at row 9, where its state file saved the run after row 29");
  auto cut = killed;
  cut[21] = cut[21].substr(0, 30);  // row 20 cut short
  write(cut);
  expect_refused("the row after row 19 is not whole");
  auto gap = killed;
  gap.erase(gap.begin() + 16);  // row 15 deleted
  write(gap);
  expect_refused("row 16 follows row 14");
  fs::remove(csv);
  expect_refused("is missing, while its state file is there");
  // Restored, it resumes.
  write(killed);
  EXPECT_EQ(run_to_end(with_resume(args), dir_ / "resumed.log"), 0);
}

}  // namespace
