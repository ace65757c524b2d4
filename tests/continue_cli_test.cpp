// `kirchhoff continue` end to end: the branch CSV, progress, and a run killed with SIGKILL and
// resumed with --resume, which must reproduce the uninterrupted run without losing or
// duplicating a point.
#include <gtest/gtest.h>

#include <sstream>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <algorithm>
#include <map>
#include <cstdlib>
#include <iomanip>
#include <nlohmann/json.hpp>

#include "cli_run_support.hpp"
#include "foundation_column_case.hpp"
#include "kirchhoff/analysis/analytic.hpp"

namespace {

using kirchhoff::testing::csv_field;
using kirchhoff::testing::csv_fields;
using kirchhoff::testing::csv_header;
using kirchhoff::testing::lines_of;
using kirchhoff::testing::read_text;
using kirchhoff::testing::run_and_kill;
using kirchhoff::testing::run_to_end;
namespace fs = std::filesystem;

// The run: the Euler column from P = 1 along the straight branch, switching at the first
// branch point onto the buckled branch up to theta0 = 3; many samples per point make it slow
// enough (~1 s) to be killed half-way.
std::vector<std::string> continue_args(const fs::path& csv) {
  return {KIRCHHOFF_CLI, "continue", std::string(KIRCHHOFF_CASES_DIR) + "/euler_column.toml", "--param", "P",
          "--to", "12", "--set", "P=1", "--set", "theta_guess=0", "--switch-at-bp", "1", "--event", "theta0=3",
          "--max-step", "0.5", "--max-points", "2000", "--samples", "4001", "--out", csv.string()};
}

using ContinueCli = kirchhoff::testing::ScratchFolderTest;

TEST_F(ContinueCli, KilledRunResumesWithoutLosingOrDuplicatingPoints) {
  const fs::path full = dir_ / "full.csv", killed = dir_ / "killed.csv";
  ASSERT_EQ(run_to_end(continue_args(full), dir_ / "full.log"), 0);
  const auto expected = lines_of(full);
  ASSERT_GT(expected.size(), 100u);

  // Kill the second run with SIGKILL once it has written a third of the points.
  ASSERT_TRUE(run_and_kill(continue_args(killed), dir_ / "killed.log",
                           [&] { return lines_of(killed).size() >= expected.size() / 3; }))
      << "the run finished before it could be killed";
  const size_t written = lines_of(killed).size();
  ASSERT_LT(written, expected.size());

  auto args = continue_args(killed);
  args.push_back("--resume");
  ASSERT_EQ(run_to_end(args, dir_ / "resume.log"), 0);
  const auto resumed = lines_of(killed);
  ASSERT_EQ(resumed.size(), expected.size()) << "killed after " << written << " lines";
  for (size_t i = 0; i < expected.size(); ++i) EXPECT_EQ(resumed[i], expected[i]) << "line " << i;
}

// A run that reaches its --max-seconds stops after its last written point with time_limit (exit
// 1), and --resume finishes it with the uninterrupted run's rows. The limit is a fraction of the
// run's ~1 s, so whatever the machine's speed it stops part-way or, on a very fast one, ends.
TEST_F(ContinueCli, TimeLimitedRunStopsResumably) {
  const fs::path full = dir_ / "full.csv", limited = dir_ / "limited.csv";
  ASSERT_EQ(run_to_end(continue_args(full), dir_ / "full.log"), 0);
  auto args = continue_args(limited);
  args.insert(args.end(), {"--max-seconds", "0.2"});
  const int status = run_to_end(args, dir_ / "limited.log");
  if (status != 0) {
    EXPECT_EQ(status, 1);
    std::ifstream log(dir_ / "limited.log");
    const std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("time_limit"), std::string::npos) << text;
    args = continue_args(limited);
    args.push_back("--resume");
    ASSERT_EQ(run_to_end(args, dir_ / "resume.log"), 0);
  }
  EXPECT_EQ(lines_of(limited), lines_of(full));
}

// A contact run (the active set changes along it) killed with SIGKILL half-way and resumed writes
// the uninterrupted run's CSV, byte for byte, through its flat contact's ill-conditioned leg (until
// 2026-12-02 the resumed point's tangent was solved for again, and rounding differences of 1e-13
// changed the later step sizes; see tests/resume_test.cpp for kills at chosen rows).
TEST_F(ContinueCli, KilledContactRunResumesToTheSameRows) {
  auto args_for = [&](const fs::path& csv) {
    return std::vector<std::string>{KIRCHHOFF_CLI, "continue", std::string(KIRCHHOFF_CASES_DIR) + "/wall.toml",
                                    "--param", "Delta", "--to", "0.034", "--set", "Delta=0.005", "--set",
                                    "m_guess=0.9", "--max-step", "2", "--max-points", "3000", "--samples", "2001",
                                    "--out", csv.string()};
  };
  const fs::path full = dir_ / "wall_full.csv", killed = dir_ / "wall_killed.csv";
  ASSERT_EQ(run_to_end(args_for(full), dir_ / "wall_full.log"), 0);
  const auto expected = lines_of(full);
  ASSERT_TRUE(run_and_kill(args_for(killed), dir_ / "wall_killed.log",
                           [&] { return lines_of(killed).size() >= expected.size() / 2; }));
  const auto before = lines_of(killed);
  auto args = args_for(killed);
  args.push_back("--resume");
  ASSERT_EQ(run_to_end(args, dir_ / "wall_resume.log"), 0);
  const auto after = lines_of(killed);
  ASSERT_LT(before.size(), expected.size());
  ASSERT_EQ(after.size(), expected.size()) << "killed after " << before.size() << " lines";
  for (size_t i = 0; i < expected.size(); ++i) ASSERT_EQ(after[i], expected[i]) << "line " << i;
  EXPECT_NE(after.back().find(",endpoint,"), std::string::npos);
}

// Where Newton cannot start the branch from the case's guess at the --set values (the wall at
// Delta = 0.04: the active-set loop from the arch's guess does not settle, and the run used to
// stop with start_failed), the branch starts from the equilibrium `solve` reports there, reached
// by homotopy from the file's values, and says so: its first row is that equilibrium (P as
// `solve --json` gives it, to the two runs' identical arithmetic: both solve the same way).
TEST_F(ContinueCli, StartsFromSolvesEquilibriumWhereNewtonFromTheGuessFails) {
  const std::string wall = std::string(KIRCHHOFF_CASES_DIR) + "/wall.toml";
  const fs::path csv = dir_ / "wall.csv", json = dir_ / "solve.json";
  ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", wall, "--set", "Delta=0.04", "--param", "Delta", "--to", "0.045",
                        "--out", csv.string()},
                       dir_ / "continue.log"),
            0);
  bool noted = false;
  for (const auto& line : lines_of(dir_ / "continue.log"))
    noted = noted || line.find("the branch starts from the equilibrium solve reaches, by homotopy from the file's "
                               "values (Delta = 0.026 -> 0.04)") != std::string::npos;
  EXPECT_TRUE(noted);
  ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "solve", wall, "--set", "Delta=0.04", "--json"}, json, true), 0);
  std::ifstream in(json);
  const nlohmann::json solved = nlohmann::json::parse(in);
  const auto rows = lines_of(csv);
  ASSERT_GT(rows.size(), 2u);
  const int P_column = 4;  // index, branch, Delta, arclength, P, ...
  ASSERT_EQ(csv_field(rows[1], 2), 0.04);
  EXPECT_NEAR(csv_field(rows[1], P_column), solved["derived"]["P"].get<double>(), 1e-12 * 251.69);
  EXPECT_NE(rows.back().find(",endpoint,"), std::string::npos);
}

// The stability index along the run: the straight column is stable below pi^2 and the branch
// point there has a zero mode; the buckled branch is stable until its ends meet (theta0 =
// 2.2813, where the continuation finds a second branch point, the rod free to turn about the
// pin) and has index 1 past it (tests/stability_test.cpp checks this against a discretised
// energy).
TEST_F(ContinueCli, StabilityIndexExchangesAtTheBranchPoints) {
  const fs::path csv = dir_ / "s.csv";
  auto args = continue_args(csv);
  args[args.size() - 3] = "21";
  ASSERT_EQ(run_to_end(args, dir_ / "s.log"), 0);
  const auto lines = lines_of(csv);
  ASSERT_GT(lines.size(), 10u);
  int stable_straight = 0, stable_buckled = 0, unstable_buckled = 0, branch_points_with_zero_mode = 0;
  for (size_t i = 1; i < lines.size(); ++i) {
    std::vector<std::string> f;
    std::stringstream row(lines[i]);
    for (std::string cell; std::getline(row, cell, ',');) f.push_back(cell);
    ASSERT_EQ(f.size(), 17u) << lines[i];
    const int branch = std::stoi(f[1]), index = std::stoi(f[15]), zero_modes = std::stoi(f[16]);
    const double theta0 = std::abs(std::stod(f[4]));
    if (f[11] == "branch_point") {
      branch_points_with_zero_mode += zero_modes >= 1;
      continue;
    }
    if (branch == 0) stable_straight += index == 0;
    if (branch == 1 && theta0 < 2.27) {
      stable_buckled += index == 0;
      EXPECT_EQ(index, 0) << lines[i];
    }
    if (branch == 1 && theta0 > 2.29) {
      unstable_buckled += index == 1;
      EXPECT_EQ(index, 1) << lines[i];
    }
  }
  EXPECT_GT(stable_straight, 3);
  EXPECT_GT(stable_buckled, 10);
  EXPECT_GT(unstable_buckled, 10);
  EXPECT_GE(branch_points_with_zero_mode, 3);  // pi^2 (ending branch 0, starting branch 1), ends meeting
}

TEST_F(ContinueCli, BranchCsvHasTheDocumentedColumnsAndPointTypes) {
  const fs::path csv = dir_ / "b.csv";
  auto args = continue_args(csv);
  args[args.size() - 3] = "21";  // few samples: fast
  ASSERT_EQ(args[args.size() - 4], "--samples");
  ASSERT_EQ(run_to_end(args, dir_ / "b.log"), 0);
  const auto lines = lines_of(csv);
  EXPECT_EQ(lines[0],
            "index,branch,P,arclength,theta0,y_max,end_to_end,H_relative_spread,m3_relative_spread,n_dot_m_relative_spread,H_flat,type,"
            "multiplicity,event,newton_iterations,stability_index,zero_modes");
  std::string all;
  for (const auto& l : lines) all += l + "\n";
  EXPECT_NE(all.find(",start,"), std::string::npos);
  EXPECT_NE(all.find(",branch_point,"), std::string::npos);
  EXPECT_NE(all.find(",event,0,theta0=3"), std::string::npos);
  // Progress went to stderr as plain lines (not a terminal), ending with the reason.
  const auto log = lines_of(dir_ / "b.log");
  ASSERT_FALSE(log.empty());
  EXPECT_NE(log.back().find("stopped: event"), std::string::npos);
  EXPECT_EQ(log.front().find('\r'), std::string::npos);
}

// --no-branch-points: the straight column is followed past its Euler loads with no branch point
// row; asking to switch at one without looking for them is refused.
// tapered.toml lists its unknown P and the derived quantity H_spread (max - min of H, which varies
// with EI(s)) among its outputs: each is one column, and H_spread is the absolute spread, apart
// from the relative spreads of the invariants (H_relative_spread = H_spread / H's scale).
TEST_F(ContinueCli, EveryColumnIsNamedOnceAndHSpreadIsAbsolute) {
  const fs::path csv = dir_ / "tapered.csv";
  ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", std::string(KIRCHHOFF_CASES_DIR) + "/tapered.toml", "--param",
                        "theta0", "--to", "1.2", "--no-stability", "--out", csv.string()},
                       dir_ / "t.log"),
            0);
  const auto header = csv_fields(lines_of(csv)[0]);
  for (const std::string& name : header)
    EXPECT_EQ(std::count(header.begin(), header.end(), name), 1) << name << " in " << lines_of(csv)[0];
  const auto rows = lines_of(csv);
  ASSERT_GT(rows.size(), 2u);
  const auto column = csv_header(rows[0]);
  const double absolute = csv_field(rows.back(), column.at("H_spread"));
  const double relative = csv_field(rows.back(), column.at("H_relative_spread"));
  EXPECT_GT(absolute, 0.1);  // EI doubles along the rod: H changes by O(1), not by round-off
  EXPECT_LT(relative, absolute);
}

// --resume appends to the CSV of the run it continues: a header of other outputs (here one more
// derived column) is refused, rows are not appended under it; the header an earlier version wrote
// (the relative spreads named H_spread, m3_spread, n_dot_m_spread) is renamed and the run goes on.
TEST_F(ContinueCli, ResumeRefusesACsvOfOtherColumnsAndRenamesTheEarlierSpreads) {
  const fs::path full = dir_ / "full.csv", partial = dir_ / "partial.csv";
  ASSERT_EQ(run_to_end(continue_args(full), dir_ / "full.log"), 0);
  const auto expected = lines_of(full);
  ASSERT_TRUE(run_and_kill(continue_args(partial), dir_ / "killed.log",
                           [&] { return lines_of(partial).size() >= expected.size() / 3; }));
  auto rewrite_header = [&](const std::string& header) {
    auto lines = lines_of(partial);
    lines[0] = header;
    std::ofstream out(partial, std::ios::trunc);
    for (const auto& l : lines) out << l << "\n";
  };
  const std::string earlier = std::string(expected[0]).replace(expected[0].find("H_relative_spread"),
                                                               std::string("H_relative_spread,m3_relative_spread,"
                                                                           "n_dot_m_relative_spread").size(),
                                                               "H_spread,m3_spread,n_dot_m_spread");
  auto resume = continue_args(partial);
  resume.push_back("--resume");
  rewrite_header(expected[0] + ",kappa_max");
  EXPECT_EQ(run_to_end(resume, dir_ / "refused.log"), 2);
  std::ifstream log(dir_ / "refused.log");
  const std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("its header is not this run's"), std::string::npos) << text;
  rewrite_header(earlier);
  ASSERT_EQ(run_to_end(resume, dir_ / "resume.log"), 0);
  EXPECT_EQ(lines_of(partial), expected);
}

// A pinned column on a stiff Winkler foundation k = 1e6 (a soft wall balanced by a uniform weight
// towards it), in 1 and 8 shooting segments: its bordered matrix spans many orders of magnitude at
// every point, so several singular values are below branch_point_tolerance of the largest
// everywhere. Its branch points are exactly the critical loads P_j = (j pi)^2 + k / (j pi)^2, each
// simple, multiplicity 1. Two defects this guards: each said 8 or 9 (the count of small singular
// values, not the count beyond the regular points'), and shallow ripples of the smallest singular
// value, ~1e-13 everywhere, were reported as branch points (P = 1069.9 and 1349.1, below the
// first critical load, and 3486.2 and 3865.0). Located to the secant's accuracy: 1e-6 relative.
// An anisotropic rod (B1 = 1.5, B2 = 1) clamped at both ends half its length apart, the clamps
// turned by -/+ pi turns about their common axis, without self-contact: as a whole rod, and as the
// half that plectoneme.toml solves (the half-turn about e1 maps one half onto the other).
std::string turned_rod_case(bool half, double B1 = 1.5) {
  std::ostringstream text;
  text << "model = \"spatial\"\n[parameters]\nturns = 0.0\nend_distance = 0.5\n"
       << "[rod]\nlength = " << (half ? "0.5" : "1.0") << "\nB1 = " << B1 << "\nB2 = 1.0\nB3 = 0.769230769230769\n"
       << "[start]\ntype = \"clamped\"\nposition = [0, 0, \"-end_distance/2\"]\n"
       << "orientation = { axis = [0, 0, 1], angle = \"-_pi*turns\" }\ntrack_turns = true\n";
  if (half)
    text << "[end]\ntype = \"half_turn\"\naxis = [1, 0, 0]\ndirector = 1\n";
  else
    text << "[end]\ntype = \"clamped\"\nposition = [0, 0, \"end_distance/2\"]\n"
         << "orientation = { axis = [0, 0, 1], angle = \"_pi*turns\" }\ntrack_turns = true\n";
  // The planar clamped-clamped Elastica's reactions at end_distance = 0.5 (plectoneme.toml).
  text << "[guess]\nforce = [0, 0, -53.2741126]\nmoment = [0, 9.9437843, 0]\n[solver]\ntolerance = 1e-8\n";
  return text.str();
}

// The half rod's Jacobian cannot see the whole rod's bifurcations that break the half-turn
// symmetry, but its index (both halves' perturbations) changes there: the change is located and
// reported as an index_change row. Checked against the whole rod, continued the same way: its
// regular rows have the same index as the half's (0, 1 between the bifurcations, 0), and its
// branch points, found by the whole problem's determinant, lie at the same turns with the same
// index and zero mode. Measured: the whole rod's determinant at fixed turns changes sign at
// 0.5732216 and 0.861536; its branch points are located at 0.5732220 and 0.8615332; the
// index_change rows are 0.5732190 and 0.8615425, the middle of the window (~2e-5 wide) where the
// crossing eigenvalue is within the index's resolution: hence 2e-5. (The whole rod's Jacobian is
// ill-conditioned in turns here, its smallest singular value below 3e-8 of the largest within 1e-4
// of each branch point: before the located branch point had to lie well below the step's ends,
// the second was located at 0.861468, with no index.)
TEST_F(ContinueCli, AHalfRodsBranchMarksWhereTheWholeRodBifurcatesOffItsSymmetry) {
  auto continued = [&](bool half) {
    const fs::path toml = dir_ / (half ? "half.toml" : "whole.toml"), csv = dir_ / (half ? "half.csv" : "whole.csv");
    std::ofstream(toml) << turned_rod_case(half);
    EXPECT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", toml.string(), "--param", "turns", "--to", "1", "--max-step", "20",
                          "--out", csv.string()},
                         dir_ / "run.log"),
              0);
    return lines_of(csv);
  };
  // (type, turns, stability_index, zero_modes) of the special rows; the regular rows' index is 0,
  // and 1 between the two bifurcations.
  auto special_rows = [&](const std::vector<std::string>& rows) {
    const auto column = csv_header(rows.at(0));
    std::vector<std::vector<std::string>> special;
    for (size_t i = 1; i < rows.size(); ++i) {
      const auto fields = csv_fields(rows[i]);
      const std::string type = fields[column.at("type")];
      if (type == "index_change" || type == "branch_point")
        special.push_back({type, fields[column.at("turns")], fields[column.at("stability_index")],
                           fields[column.at("zero_modes")]});
      const double turns = std::stod(fields[column.at("turns")]);
      if (type == "regular" && std::abs(turns - 0.5732) > 1e-3 && std::abs(turns - 0.8615) > 1e-3)
        EXPECT_EQ(fields[column.at("stability_index")], turns > 0.5732 && turns < 0.8615 ? "1" : "0") << rows[i];
    }
    return special;
  };
  const auto half = special_rows(continued(true)), whole = special_rows(continued(false));
  ASSERT_EQ(half.size(), 2u);
  ASSERT_EQ(whole.size(), 2u);
  for (int k = 0; k < 2; ++k) {
    SCOPED_TRACE("bifurcation " + std::to_string(k + 1));
    EXPECT_EQ(half[k][0], "index_change");
    EXPECT_EQ(whole[k][0], "branch_point");
    EXPECT_NEAR(std::stod(half[k][1]), std::stod(whole[k][1]), 2e-5);
    // At the bifurcation: the smaller index of the two sides, and the crossing eigenvalue's zero mode.
    for (const auto* row : {&half[k], &whole[k]}) {
      EXPECT_EQ((*row)[2], "0");
      EXPECT_EQ((*row)[3], "1");
    }
  }
}

// The same whole rod with B1 = 2: near its first branch point the secant's trials on a long step
// landed on the crossing branch, and the branch point came out at turns 0.506293 (--max-step 5,
// 2.3e-3 off) and 0.508476 (--max-step 20, 1e-4 off, with no zero mode). The located point must
// now lie well below the step's ends in the smallest singular value, else the step is retaken
// shorter. Reference: the half rod's index change, where the whole rod's own determinant changes
// sign (0.5085800 measured by bisection on solve's zero-mode window; 0.5085799 with --max-step 1).
TEST_F(ContinueCli, ABranchPointIsLocatedOnItsOwnBranchWhateverTheStep) {
  const fs::path toml = dir_ / "whole.toml";
  std::ofstream(toml) << turned_rod_case(false, 2.0);
  for (const char* max_step : {"5", "20"}) {
    SCOPED_TRACE(std::string("--max-step ") + max_step);
    const fs::path csv = dir_ / (std::string("whole") + max_step + ".csv");
    ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", toml.string(), "--param", "turns", "--to", "0.6", "--max-step",
                          max_step, "--out", csv.string()},
                         dir_ / "run.log"),
              0);
    const auto rows = lines_of(csv);
    const auto column = csv_header(rows.at(0));
    int branch_points = 0;
    for (size_t i = 1; i < rows.size(); ++i) {
      const auto fields = csv_fields(rows[i]);
      if (fields[column.at("type")] != "branch_point") continue;
      ++branch_points;
      // Within the index's zero-mode window (~1e-5 wide) of the crossing.
      EXPECT_NEAR(std::stod(fields[column.at("turns")]), 0.50858, 1e-5) << rows[i];
      EXPECT_EQ(fields[column.at("stability_index")], "0") << rows[i];
      EXPECT_EQ(fields[column.at("zero_modes")], "1") << rows[i];
    }
    EXPECT_EQ(branch_points, 1);
  }
}

// The straight twisted rod (twisted_clamped.toml, T = 0) has double branch points where the
// twisting moment M = C phi / L meets M L / B = 2 x_k, x_k the roots of tan x = x (the clamped
// rod's Greenhill points; the first is analytic.hpp's clamped_twisted_critical_moment): phi =
// 11.6829, 20.0857, 28.3507. Their determinant keeps its sign, and the two-step minimum of the
// smallest singular value missed the second and third with --max-step 20 (samples at phi = 16.2
// and 21.3 around 20.09, the next step holding 28.35): the index jumped 2 -> 4 -> 6 between
// regular rows. The index change now finds them, at every step size, to the located minimum's
// accuracy (1e-10 of phi at the first and second, measured), each with its two zero modes.
TEST_F(ContinueCli, EveryGreenhillPointIsFoundWhateverTheStep) {
  const double C = 0.769230769230769, B = 1.0, L = 1.0;
  std::vector<double> expected;
  for (int k = 1; k <= 3; ++k) {
    double lo = k * M_PI, hi = (k + 0.5) * M_PI - 1e-9;  // tan x - x goes from - to + on it
    for (int i = 0; i < 200; ++i) {
      const double mid = 0.5 * (lo + hi);
      (std::tan(mid) - mid < 0 ? lo : hi) = mid;
    }
    expected.push_back(2.0 * lo * B / C);  // phi = M L / C with M L / B = 2 x
  }
  ASSERT_NEAR(expected[0] * C / L, kirchhoff::analytic::clamped_twisted_critical_moment(B, 0.0, L), 1e-12);
  // From phi = 1 at --max-step 20 the third point lies in the step that reaches phi = 30.
  const std::pair<const char*, const char*> runs[] = {{"6", "20"}, {"6", "5"}, {"1", "20"}};
  for (const auto& [start, max_step] : runs) {
    SCOPED_TRACE(std::string("from phi = ") + start + ", --max-step " + max_step);
    const fs::path csv = dir_ / (std::string("twist") + start + "_" + max_step + ".csv");
    ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", std::string(KIRCHHOFF_CASES_DIR) + "/twisted_clamped.toml",
                          "--param", "phi", "--to", "30", "--set", std::string("phi=") + start, "--set", "tension=0",
                          "--max-step", max_step, "--out", csv.string()},
                         dir_ / "run.log"),
              0);
    const auto rows = lines_of(csv);
    const auto column = csv_header(rows.at(0));
    std::vector<double> found;
    for (size_t i = 1; i < rows.size(); ++i) {
      const auto fields = csv_fields(rows[i]);
      const std::string type = fields[column.at("type")];
      EXPECT_NE(type, "index_change") << rows[i];
      if (type != "branch_point") continue;
      found.push_back(std::stod(fields[column.at("phi")]));
      EXPECT_EQ(fields[column.at("multiplicity")], "2") << rows[i];
      EXPECT_EQ(fields[column.at("zero_modes")], "2") << rows[i];
      EXPECT_EQ(fields[column.at("stability_index")], std::to_string(2 * (found.size() - 1))) << rows[i];
    }
    ASSERT_EQ(found.size(), 3u);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(found[k], expected[k], 1e-8 * expected[k]);
  }
}

// With B2 = 2 B1 the twisted rod's double branch points split into pairs of simple ones: the
// first two at phi = 13.66254 and 14.96081, where a finite-element discretisation of the straight
// rod's second variation (linear elements, N = 400 and 800, Richardson-extrapolated; a probe's,
// independent of this code) gives 13.66257 and 14.96083. The determinant changes sign twice in a
// step holding both, and the tests saw one of them: at --max-step 2 one row at 14.9608 said index 0
// with two zero modes and multiplicity 1, the point at 13.6625 and the index 1 between them missing.
// A step whose index changes by more than the singular points found in it account for, or whose
// index-change trials show an index strictly between its ends', is now taken again shorter.
TEST_F(ContinueCli, TwoSimpleBranchPointsInOneStepAreEachFound) {
  std::string text = read_text(fs::path(KIRCHHOFF_CASES_DIR) / "twisted_clamped.toml");
  const std::string isotropic = "B = \"B\"\n";
  ASSERT_NE(text.find(isotropic), std::string::npos);
  text.replace(text.find(isotropic), isotropic.size(), "B1 = \"B\"\nB2 = \"2*B\"\n");
  const fs::path toml = dir_ / "anisotropic.toml";
  std::ofstream(toml) << text;
  const double expected[] = {13.66257, 14.96083};
  for (const char* max_step : {"2", "5", "0.5"}) {
    SCOPED_TRACE(std::string("--max-step ") + max_step);
    const fs::path csv = dir_ / (std::string("anisotropic_") + max_step + ".csv");
    ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", toml.string(), "--param", "phi", "--to", "16", "--set", "phi=1",
                          "--max-step", max_step, "--out", csv.string()},
                         dir_ / "run.log"),
              0);
    const auto rows = lines_of(csv);
    const auto column = csv_header(rows.at(0));
    std::vector<double> found;
    for (size_t i = 1; i < rows.size(); ++i) {
      const auto fields = csv_fields(rows[i]);
      const std::string type = fields[column.at("type")], index = fields[column.at("stability_index")];
      if (type == "branch_point") {
        found.push_back(std::stod(fields[column.at("phi")]));
        EXPECT_EQ(fields[column.at("multiplicity")], "1") << rows[i];
        EXPECT_EQ(fields[column.at("zero_modes")], "1") << rows[i];
        EXPECT_EQ(index, std::to_string(found.size() - 1)) << rows[i];
      } else if (type == "regular") {
        // Between regular rows the index changes only across a branch point's row, by one.
        EXPECT_EQ(std::stoi(index), static_cast<int>(found.size())) << rows[i];
      }
    }
    ASSERT_EQ(found.size(), 2u);
    // 1e-4: the extrapolated discretisation's uncertainty (its N = 400 and 800 values differ by 7e-4).
    for (int k = 0; k < 2; ++k) EXPECT_NEAR(found[k], expected[k], 1e-4);
  }
}

// Just past the branch point a branch starts from, the eigenvalue that crossed there is still
// within the index's resolution: the first rows count it as a zero mode (index 2, two zero modes
// on the branch leaving the twisted rod's second Greenhill point), the next as negative (3, one).
// That is the branch point's own exchange of stability, not another bifurcation: no index_change
// row (there was one at arclength 0.1375 from the branch point).
TEST_F(ContinueCli, NoIndexChangeWhereALeavingBranchResolvesItsBranchPointsEigenvalue) {
  const fs::path csv = dir_ / "switched.csv";
  ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", std::string(KIRCHHOFF_CASES_DIR) + "/twisted_clamped.toml", "--param",
                        "phi", "--to", "22", "--set", "phi=6", "--set", "tension=0", "--max-step", "1", "--switch-at-bp",
                        "2", "--event", "end_to_end=0.3", "--out", csv.string()},
                       dir_ / "run.log"),
            0);
  const auto rows = lines_of(csv);
  const auto column = csv_header(rows.at(0));
  int on_the_new_branch = 0, resolved = 0;
  for (size_t i = 1; i < rows.size(); ++i) {
    const auto fields = csv_fields(rows[i]);
    EXPECT_NE(fields[column.at("type")], "index_change") << rows[i];
    if (fields[column.at("branch")] != "1" || fields[column.at("type")] != "regular") continue;
    ++on_the_new_branch;
    resolved += fields[column.at("stability_index")] == "3" && fields[column.at("zero_modes")] == "1";
  }
  EXPECT_GT(on_the_new_branch, 20);
  EXPECT_GE(resolved, on_the_new_branch - 3);  // all but the first rows past the branch point
}

TEST_F(ContinueCli, BranchPointsOfABadlyScaledProblemAreTheCriticalLoadsEachSimple) {
  const fs::path path = dir_ / "foundation.toml";
  std::ofstream(path) << kirchhoff::testing::foundation_column_case(1000.0, 1e6);
  std::vector<double> critical;
  for (int j = 1; j < 40; ++j) {
    const double P = kirchhoff::testing::foundation_column_critical_load(j, 1e6);
    if (P > 1000 && P < 4000) critical.push_back(P);
  }
  ASSERT_EQ(critical.size(), 14u);
  const auto near_one_of = [](double P, const std::vector<double>& list) {
    return std::any_of(list.begin(), list.end(), [&](double f) { return std::abs(f - P) < 1e-6 * P; });
  };
  for (const char* segments : {"segments=1", "segments=8"}) {
    SCOPED_TRACE(segments);
    const fs::path csv = dir_ / (std::string(segments) + ".csv");
    ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", path.string(), "--param", "P", "--to", "4000", "--max-step", "20",
                          "--solver", segments, "--no-stability", "--out", csv.string()},
                         dir_ / "f.log"),
              0);
    const auto rows = lines_of(csv);
    const auto column = csv_header(rows[0]);
    std::vector<double> found;
    for (size_t i = 1; i < rows.size(); ++i) {
      const auto fields = csv_fields(rows[i]);
      if (fields[column.at("type")] != "branch_point") continue;
      EXPECT_EQ(fields[column.at("multiplicity")], "1") << rows[i];
      // --no-stability: no index, and no zero-mode count that would read as one (it said 0).
      EXPECT_EQ(fields[column.at("stability_index")], "") << rows[i];
      EXPECT_EQ(fields[column.at("zero_modes")], "") << rows[i];
      found.push_back(std::stod(fields[column.at("P")]));
      EXPECT_TRUE(near_one_of(found.back(), critical)) << "not a critical load: " << rows[i];
    }
    for (double P : critical) EXPECT_TRUE(near_one_of(P, found)) << "missed P = " << P;
  }
}

// The same column's straight branch with its stability: where the conjugate points leave the index
// undefined (the held end's response to its load, ~1e-8, is below their zero tolerance: 33 of 240
// points were empty) the discretised energy gives it, as solve does. Every row's index is the
// number of critical loads below P (at a branch point, those strictly below it: the smaller
// neighbour's).
TEST_F(ContinueCli, EveryPointOfAStiffFoundationsStraightBranchHasItsIndex) {
  const fs::path path = dir_ / "foundation.toml", csv = dir_ / "f.csv";
  std::ofstream(path) << kirchhoff::testing::foundation_column_case(1000.0, 1e6);
  ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", path.string(), "--param", "P", "--to", "2300", "--max-step", "20",
                        "--out", csv.string()},
                       dir_ / "f.log"),
            0);
  const auto rows = lines_of(csv);
  const auto column = csv_header(rows[0]);
  ASSERT_GT(rows.size(), 60u);
  for (size_t i = 1; i < rows.size(); ++i) {
    const auto fields = csv_fields(rows[i]);
    const double P = std::stod(fields[column.at("P")]);
    int below = 0;
    for (int j = 1; j < 60; ++j) below += kirchhoff::testing::foundation_column_critical_load(j, 1e6) < P * (1 - 1e-6);
    EXPECT_EQ(fields[column.at("stability_index")], std::to_string(below)) << rows[i];
  }
}

// The axial phase condition is degenerate on the straight twisted rod: continued from it, the
// march went along the unfolding couple mu at a fixed twist (mu = 11.5 at row 59), every row a
// "stable" regular point, exit 0. A point with mu != 0 is not an equilibrium: each step is
// refused, and the run stops saying why.
TEST_F(ContinueCli, TheAxialPhaseConditionFromTheStraightRodGivesNoRowsOffEquilibrium) {
  const fs::path csv = dir_ / "axial.csv", log = dir_ / "axial.log";
  EXPECT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", std::string(KIRCHHOFF_CASES_DIR) + "/twisted_clamped.toml", "--param",
                        "phi", "--to", "14", "--phase-condition", "axial", "--max-points", "60", "--out", csv.string()},
                       log),
            1);
  const auto lines = lines_of(log);
  ASSERT_FALSE(lines.empty());
  EXPECT_NE(lines.back().find("not an equilibrium"), std::string::npos) << lines.back();
  const auto rows = lines_of(csv);
  const auto column = csv_header(rows[0]);
  for (size_t i = 1; i < rows.size(); ++i)
    EXPECT_LE(std::abs(std::stod(csv_fields(rows[i])[column.at("unfolding")])), 1e-7) << rows[i];
}

// The wall's symmetric point contact continued through its flattening: at the located
// contact_flattens row g'' is 1e-13, where the index is not defined (docs/stability.md); the row
// said 0, judged on the fields' frame at a branch's 1e-8 (g'' = 1.8e-8 there). The points before
// it are stable, with an index each.
TEST_F(ContinueCli, TheRowWhereAContactFlattensHasNoIndex) {
  const fs::path csv = dir_ / "flat.csv";
  ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", std::string(KIRCHHOFF_CASES_DIR) + "/wall.toml", "--param", "Delta",
                        "--to", "0.0308", "--set", "Delta=0.0306", "--max-step", "2", "--out", csv.string()},
                       dir_ / "flat.log"),
            0);
  const auto rows = lines_of(csv);
  const auto column = csv_header(rows[0]);
  int flattens = 0;
  for (size_t i = 1; i < rows.size(); ++i) {
    const auto fields = csv_fields(rows[i]);
    if (fields[column.at("event")] == "contact_flattens") {
      ++flattens;
      EXPECT_LT(std::abs(std::stod(fields[column.at("kappa_contact")])), 1e-9) << rows[i];
      EXPECT_EQ(fields[column.at("stability_index")], "") << rows[i];
      break;
    }
    EXPECT_EQ(fields[column.at("stability_index")], "0") << rows[i];
  }
  EXPECT_EQ(flattens, 1);
}

TEST_F(ContinueCli, BranchPointsCanBeSkippedButNotSwitchedAt) {
  const std::vector<std::string> straight = {KIRCHHOFF_CLI, "continue",
                                             std::string(KIRCHHOFF_CASES_DIR) + "/euler_column.toml", "--param",
                                             "P", "--to", "12", "--set", "P=1", "--set", "theta_guess=0",
                                             "--max-step", "0.5", "--samples", "21", "--no-branch-points",
                                             "--out", (dir_ / "s.csv").string()};
  ASSERT_EQ(run_to_end(straight, dir_ / "s.log"), 0);
  std::string all;
  for (const auto& l : lines_of(dir_ / "s.csv")) all += l + "\n";
  EXPECT_EQ(all.find(",branch_point,"), std::string::npos);
  EXPECT_NE(all.find(",endpoint,"), std::string::npos);
  auto refused = continue_args(dir_ / "r.csv");
  refused.push_back("--no-branch-points");
  EXPECT_EQ(run_to_end(refused, dir_ / "r.log"), 2);
  const auto log = lines_of(dir_ / "r.log");
  ASSERT_FALSE(log.empty());
  EXPECT_NE(log.front().find("--no-branch-points"), std::string::npos);
}

// --profiles on a contact run: one profile per row, each solved with its leg's active set. The
// indenter rises into the rod; the last profile touches the disc at mid-span (where n_y jumps
// by the contact force) and stays outside it everywhere.
TEST_F(ContinueCli, ContactRunWritesEveryPointsProfile) {
  const fs::path csv = dir_ / "indenter.csv", profiles = dir_ / "profiles";
  const std::vector<std::string> args = {KIRCHHOFF_CLI, "continue", std::string(KIRCHHOFF_CASES_DIR) + "/indenter.toml",
                                         "--param", "rise", "--set", "rise=-0.02", "--to", "0.1969039464300978",
                                         "--max-step", "1", "--samples", "1001", "--profiles", profiles.string(),
                                         "--out", csv.string()};
  ASSERT_EQ(run_to_end(args, dir_ / "indenter.log"), 0);
  const auto rows = lines_of(csv);
  ASSERT_GT(rows.size(), 10u);
  size_t files = 0;
  for (const auto& entry : fs::directory_iterator(profiles)) files += entry.path().extension() == ".csv";
  EXPECT_EQ(files, rows.size() - 1);
  char name[32];
  std::snprintf(name, sizeof name, "point_%05zu.csv", rows.size() - 2);
  const auto profile = lines_of(profiles / name);
  ASSERT_EQ(profile.size(), 1002u);  // header and 1001 samples
  // Columns: s, x, y, ..., nx (13), ny (14). The disc: centre (half_span, rise - 0.05), radius 0.05.
  const double cx = 0.45072123252074, cy = 0.1969039464300978 - 0.05;
  double closest = INFINITY, ny_jump = 0.0;
  for (size_t i = 1; i < profile.size(); ++i) {
    closest = std::min(closest, std::hypot(csv_field(profile[i], 1) - cx, csv_field(profile[i], 2) - cy) - 0.05);
    if (i > 1) ny_jump = std::max(ny_jump, std::abs(csv_field(profile[i], 14) - csv_field(profile[i - 1], 14)));
  }
  EXPECT_GE(closest, -1e-10);
  EXPECT_LE(closest, 1e-6);                 // touching (the samples straddle the contact)
  EXPECT_NEAR(ny_jump, 11.2936742817, 1e-6);  // the closed-form contact force
}

// --start-from: a run in one parameter starts where another run (in another parameter) stopped.
// The straight twisted rod followed in phi to 8, then from there in tension: its first point is
// the first run's last one (twisting moment M = GJ phi / L at that phi).
TEST_F(ContinueCli, StartsFromAnotherRunsLastPoint) {
  const std::string twisted = std::string(KIRCHHOFF_CASES_DIR) + "/twisted_clamped.toml";
  const fs::path first = dir_ / "phi.csv", second = dir_ / "tension.csv";
  ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", twisted, "--param", "phi", "--to", "8", "--max-step", "0.5",
                        "--no-branch-points", "--samples", "21", "--out", first.string()},
                       dir_ / "phi.log"),
            0);
  const fs::path state = first.string() + ".state.json";
  ASSERT_TRUE(fs::exists(state));
  const std::vector<std::string> args = {KIRCHHOFF_CLI, "continue", twisted, "--param", "tension", "--to", "1",
                                         "--start-from", state.string(), "--no-branch-points", "--samples", "21",
                                         "--out", second.string()};
  ASSERT_EQ(run_to_end(args, dir_ / "tension.log"), 0);
  const auto log = lines_of(dir_ / "tension.log");
  ASSERT_FALSE(log.empty());
  ASSERT_GE(log.size(), 2u);
  EXPECT_NE(log[0].find("(endpoint) of the run in phi"), std::string::npos) << log[0];
  EXPECT_NE(log[1].find("phi = 8"), std::string::npos) << log[1];
  const double phi = std::stod(log[1].substr(log[1].find("phi = ") + 6));
  EXPECT_NEAR(phi, 8.0, 1e-12);  // the endpoint at --to, not the last point before it
  const auto rows = lines_of(second);
  ASSERT_GT(rows.size(), 2u);
  EXPECT_EQ(csv_field(rows[1], 2), 0.0);  // tension starts at the case's value
  EXPECT_NEAR(csv_field(rows[1], 4), 0.769230769230769 * phi, 1e-9);  // M of the straight rod there
  EXPECT_NE(rows.back().find(",endpoint,"), std::string::npos);
  // A state from another case is refused (its parameter is not this case's).
  const std::string plectoneme = std::string(KIRCHHOFF_CASES_DIR) + "/plectoneme.toml";
  EXPECT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", plectoneme, "--param", "turns", "--to", "1", "--start-from",
                        state.string(), "--out", (dir_ / "p.csv").string()},
                       dir_ / "p.log"),
            2);
  EXPECT_NE(lines_of(dir_ / "p.log").back().find("parameter 'phi' (the point's, row "), std::string::npos);
  EXPECT_NE(lines_of(dir_ / "p.log").back().find("is not a parameter of"), std::string::npos);
}

// The columns of a branch CSV row from column `first` on (the parameter is column 2), as numbers
// (an empty field, such as a stability index not defined there, as NaN; text fields as NaN).
std::vector<double> numbers_of(const std::string& row, int first, int count) {
  std::vector<double> out;
  for (int k = first; k < first + count; ++k) out.push_back(csv_field(row, k));
  return out;
}

// Whether `lines` has a line containing every one of `parts`.
bool has_line_with(const std::vector<std::string>& lines, const std::vector<std::string>& parts) {
  for (const auto& line : lines) {
    bool all = true;
    for (const auto& part : parts) all = all && line.find(part) != std::string::npos;
    if (all) return true;
  }
  return false;
}

// The issue's new-user scenario: soft_wall followed in Delta to 0.026 with --set log_b=-4, then
// from that run in log_b. The second run starts at the first run's endpoint (Delta = 0.026, not
// the last point before it, which is where the state file's resumable point is) with log_b = -4
// kept, so its first row is the first run's last row with log_b in place of Delta. A third run
// started from the second keeps Delta = 0.026 (which the second run had from the first) and the
// second run's endpoint log_b = -3.
TEST_F(ContinueCli, StartFromBeginsAtTheEndpointWithThatRunsSetValues) {
  const std::string soft_wall = std::string(KIRCHHOFF_CASES_DIR) + "/soft_wall.toml";
  const fs::path first = dir_ / "delta.csv", second = dir_ / "log_b.csv", third = dir_ / "back.csv";
  const std::string first_state = first.string() + ".state.json", second_state = second.string() + ".state.json";
  ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", soft_wall, "--set", "log_b=-4", "--set", "Delta=0.02", "--set",
                        "m_guess=1", "--param", "Delta", "--to", "0.026", "--out", first.string()},
                       dir_ / "delta.log"),
            0);
  const auto rows1 = lines_of(first);
  ASSERT_GT(rows1.size(), 3u);
  ASSERT_NE(rows1.back().find(",endpoint,"), std::string::npos);
  ASSERT_NEAR(csv_field(rows1.back(), 2), 0.026, 1e-12);

  // m_guess given again: the new command line wins over the kept value.
  ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", soft_wall, "--start-from", first_state, "--set", "m_guess=1.5",
                        "--param", "log_b", "--to", "-3", "--out", second.string()},
                       dir_ / "log_b.log"),
            0);
  const auto log = lines_of(dir_ / "log_b.log");
  EXPECT_TRUE(has_line_with(log, {"start: from row " + std::to_string(rows1.size() - 2), "(endpoint)"}));
  EXPECT_TRUE(has_line_with(log, {"Delta = 0.026", "the point's"}));
  EXPECT_TRUE(has_line_with(log, {"log_b = -4", "kept from"}));
  EXPECT_TRUE(has_line_with(log, {"m_guess = 1.5", "(--set)"}));
  EXPECT_TRUE(has_line_with(log, {"continuing in log_b from -4"}));
  const auto rows2 = lines_of(second);
  ASSERT_GT(rows2.size(), 3u);
  EXPECT_EQ(csv_field(rows2[1], 2), -4.0);
  // P, E_wall, gap, ny_jump, kappa_mid, H: the same equilibrium, corrected again only to round-off.
  const auto end1 = numbers_of(rows1.back(), 4, 6), start2 = numbers_of(rows2[1], 4, 6);
  for (size_t k = 0; k < end1.size(); ++k)
    EXPECT_NEAR(start2[k], end1[k], 1e-12 * std::max(1.0, std::abs(end1[k]))) << "column " << k + 4;
  ASSERT_NE(rows2.back().find(",endpoint,"), std::string::npos);

  ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", soft_wall, "--start-from", second_state, "--param", "Delta",
                        "--to", "0.025", "--out", third.string()},
                       dir_ / "back.log"),
            0);
  const auto back = lines_of(dir_ / "back.log");
  EXPECT_TRUE(has_line_with(back, {"Delta = 0.026", "kept from"}));
  EXPECT_TRUE(has_line_with(back, {"log_b = -3", "the point's"}));
  EXPECT_TRUE(has_line_with(back, {"m_guess = 1.5", "kept from"}));
  const auto rows3 = lines_of(third);
  ASSERT_GT(rows3.size(), 2u);
  EXPECT_NEAR(csv_field(rows3[1], 2), 0.026, 1e-12);
  const auto end2 = numbers_of(rows2.back(), 4, 6), start3 = numbers_of(rows3[1], 4, 6);
  for (size_t k = 0; k < end2.size(); ++k)
    EXPECT_NEAR(start3[k], end2[k], 1e-12 * std::max(1.0, std::abs(end2[k]))) << "column " << k + 4;

  // The parameter of the point cannot be set too: the point is a solution at its own value only.
  EXPECT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", soft_wall, "--start-from", first_state, "--set", "Delta=0.03",
                        "--param", "log_b", "--to", "-3", "--out", (dir_ / "x.csv").string()},
                       dir_ / "x.log"),
            2);
  EXPECT_TRUE(has_line_with(lines_of(dir_ / "x.log"), {"--set Delta conflicts with --start-from"}));
}

// A state file written before the last row and the --set values were recorded still starts a run:
// from its last saved point (said in a note), with the --set values read from its arguments line.
TEST_F(ContinueCli, StartFromAnOlderStateFileSaysWhatItCannotKnow) {
  const std::string soft_wall = std::string(KIRCHHOFF_CASES_DIR) + "/soft_wall.toml";
  const fs::path first = dir_ / "delta.csv", second = dir_ / "log_b.csv";
  ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", soft_wall, "--set", "log_b=-4", "--set", "Delta=0.02", "--set",
                        "m_guess=1", "--param", "Delta", "--to", "0.026", "--out", first.string()},
                       dir_ / "delta.log"),
            0);
  const fs::path state = first.string() + ".state.json";
  nlohmann::json j;
  {
    std::ifstream in(state);
    in >> j;
  }
  j.erase("written");
  j.erase("set_parameters");
  const int saved_row = j.at("row");
  {
    std::ofstream out(state);
    out << std::setprecision(17) << j.dump();
  }
  ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", soft_wall, "--start-from", state.string(), "--param", "log_b",
                        "--to", "-3.5", "--out", second.string()},
                       dir_ / "log_b.log"),
            0);
  const auto log = lines_of(dir_ / "log_b.log");
  EXPECT_TRUE(has_line_with(log, {"note:", "predates", "row " + std::to_string(saved_row)}));
  EXPECT_TRUE(has_line_with(log, {"log_b = -4", "kept from"}));
  const auto rows1 = lines_of(first), rows2 = lines_of(second);
  ASSERT_GT(rows2.size(), 2u);
  const std::string& saved = rows1[static_cast<size_t>(saved_row) + 1];
  EXPECT_NEAR(csv_field(rows2[1], 4), csv_field(saved, 4), 1e-10 * csv_field(saved, 4));  // P there
}

// Contact: the state carries the point's active set. wall.toml followed in Delta to 0.028 (a
// point contact since 0.02507), continued from its endpoint in Delta to 0.034 (the contact
// flattens at 0.03075 on the way), then from there in the wall's height a: each run's first row
// is the previous one's last, its contact included.
TEST_F(ContinueCli, StartFromKeepsTheActiveContactSet) {
  const std::string wall = std::string(KIRCHHOFF_CASES_DIR) + "/wall.toml";
  const fs::path point = dir_ / "point.csv", flat = dir_ / "flat.csv", height = dir_ / "height.csv";
  auto state_of = [](const fs::path& csv) { return csv.string() + ".state.json"; };
  ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", wall, "--param", "Delta", "--to", "0.028", "--set", "Delta=0.005",
                        "--set", "m_guess=0.9", "--max-step", "2", "--max-points", "3000", "--out", point.string()},
                       dir_ / "point.log"),
            0);
  ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", wall, "--start-from", state_of(point), "--param", "Delta", "--to",
                        "0.034", "--max-step", "2", "--max-points", "3000", "--out", flat.string()},
                       dir_ / "flat.log"),
            0);
  EXPECT_TRUE(has_line_with(lines_of(dir_ / "flat.log"), {"(endpoint)", "1 active contact"}));
  EXPECT_TRUE(has_line_with(lines_of(dir_ / "flat.log"), {"flattens into an extended contact"}));
  ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", wall, "--start-from", state_of(flat), "--param", "a", "--to",
                        "0.095", "--max-step", "2", "--max-points", "3000", "--out", height.string()},
                       dir_ / "height.log"),
            0);
  const auto rows_point = lines_of(point), rows_flat = lines_of(flat), rows_height = lines_of(height);
  ASSERT_GT(rows_flat.size(), 2u);
  ASSERT_GT(rows_height.size(), 2u);
  // Columns: P, contact_force, kappa_contact, contact_s, contact_length, H (4 to 9).
  // The point contact's row: P is ~3e4 times as sensitive to the residual as the residual itself
  // (the case's tolerance note), so the corrected start agrees to ~1e-12 of P's scale.
  const auto end_point = numbers_of(rows_point.back(), 4, 6), start_flat = numbers_of(rows_flat[1], 4, 6);
  EXPECT_NEAR(csv_field(rows_flat[1], 2), 0.028, 1e-12);
  for (size_t k = 0; k < end_point.size(); ++k)
    EXPECT_NEAR(start_flat[k], end_point[k], 1e-12 * std::max(100.0, std::abs(end_point[k]))) << "column " << k + 4;
  EXPECT_EQ(csv_field(rows_flat[1], 8), 0.0);  // still a point contact
  // The flat contact's row: P, the forces and H as closely; where the flat part starts only to
  // ~1e-9, since the solution is isolated at second order only there (contact.cpp: the arc
  // between clamp and flat part can slide along itself to first order).
  const auto end_flat = numbers_of(rows_flat.back(), 4, 6), start_height = numbers_of(rows_height[1], 4, 6);
  EXPECT_NEAR(csv_field(rows_height[1], 2), 0.1, 0.0);  // the case's a
  for (size_t k : {0, 1, 5})
    EXPECT_NEAR(start_height[k], end_flat[k], 1e-12 * std::max(100.0, std::abs(end_flat[k]))) << "column " << k + 4;
  // (To second order: a residual of the tolerance, 1e-12, moves it by ~sqrt(1e-12 / c), c the
  // second-order coefficient, of order one: 1.4e-6 measured on the flat part's end; 5e-6 allows
  // c down to 0.04, while a start off the flat contact's branch would be off by 1e-3 or more.)
  EXPECT_NEAR(start_height[3], end_flat[3], 5e-6);
  EXPECT_NEAR(start_height[4], end_flat[4], 5e-6);
  EXPECT_GT(start_height[4], 0.09);  // the extended contact it ended with
  EXPECT_NE(rows_height.back().find(",endpoint,"), std::string::npos);
}

// No shipped case with obstacles has a branch point on the branches `continue` follows from it
// (wall.toml and cavity.toml in Delta to 0.1, twisted_ribbon_pole.toml in phi): this one does.
// The Euler column (pinned, sliding end under P) with a wall at y = a above it: the straight
// column is clear of the wall, its branch point at P = pi^2 is where the buckled Elastica
// bifurcates, and that branch reaches the wall where y_max = k L / K(k) = a (k = sin(theta0/2),
// P = 4 K(k)^2 EI / L^2 on the way).
const char* kColumnUnderWall = R"toml(title = "Euler column below a wall"
model = "planar"
[parameters]
P = 1.0
L = 1.0
EI = 1.0
a = 0.2
[rod]
length = "L"
B = "EI"
[start]
type = "pinned"
position = [0, 0]
[end]
type = "sliding"
axis = [1, 0, 0]
position = [0, 0]
force = ["-P", 0]
[guess]
force = ["-P", 0]
[[obstacles]]
type = "plane"
name = "wall"
point = [0, "a"]
normal = [0, -1, 0]
[output]
derived = ["theta0", "y_max", "contact_force", "contact_length"]
)toml";

// The branch switched at a branch point starts from that point as its own branch settled it (the
// smaller of its neighbours' indices, the crossing eigenvalue a zero mode). The soft wall's branch
// point at log_b = -4, Delta = 0.029511 counts 2 with one zero mode by itself (a conjugate point of
// the clamped problem within 4e-8 of its end counts negative; stability.md) between neighbours of
// 0 and 1: its row on the first branch said 0, the switched branch's first row 2.
// It is the pitchfork where the symmetric arch (P rising with Delta) loses stability to
// asymmetric ones. The switched branch is theirs: it leaves with P falling as Delta grows, stable
// (the symmetric arch has index 1 past the branch point), and comes back to the all but straight
// rod (Delta < 1e-8) where that rod meets its antisymmetric clamped-clamped mode,
// P = 4 x^2 with tan x = x, x = 4.4934094579: 80.763. The barrier's foundation stiffness
// 2b/a^3 = 0.2 raises that by about 0.2 times the mode's int w^2 / int w'^2 (~1/80): 0.0025, so
// within 0.01. (The symmetric arch meets the straight rod at the first mode's 4 pi^2 = 39.5.) The
// branch point's bordered tangent had come out along the asymmetric branch, and the switch went
// back down the symmetric arch (branch_crossing.hpp).
TEST_F(ContinueCli, ASwitchedBranchStartsWithItsBranchPointsSettledIndex) {
  const fs::path csv = dir_ / "switched.csv";
  ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", std::string(KIRCHHOFF_CASES_DIR) + "/soft_wall.toml", "--set",
                        "log_b=-4", "--set", "Delta=0.02", "--param", "Delta", "--to", "0.04", "--switch-at-bp", "1",
                        "--max-points", "420", "--out", csv.string()},
                       dir_ / "run.log"),
            0);
  const auto rows = lines_of(csv);
  const auto column = csv_header(rows.at(0));
  std::vector<std::vector<std::string>> branch_points, switched;
  for (size_t i = 1; i < rows.size(); ++i) {
    auto fields = csv_fields(rows[i]);
    if (fields[column.at("type")] == "branch_point") branch_points.push_back(fields);
    if (fields[column.at("branch")] == "1") switched.push_back(fields);
  }
  ASSERT_GE(branch_points.size(), 2u);
  const auto& found = branch_points[0];
  const auto& started = branch_points[1];
  EXPECT_EQ(found[column.at("branch")], "0");
  EXPECT_EQ(started[column.at("branch")], "1");
  EXPECT_EQ(started[column.at("Delta")], found[column.at("Delta")]);
  EXPECT_NEAR(std::stod(found[column.at("Delta")]), 0.029511, 1e-6);
  for (const auto* row : {&found, &started}) {
    EXPECT_EQ((*row)[column.at("stability_index")], "0");
    EXPECT_EQ((*row)[column.at("zero_modes")], "1");
  }
  const double Delta_bp = std::stod(found[column.at("Delta")]), P_bp = std::stod(found[column.at("P")]);
  ASSERT_GE(switched.size(), 12u);
  for (size_t i = 1; i < 12; ++i) {
    EXPECT_GT(std::stod(switched[i][column.at("Delta")]), Delta_bp) << i;
    EXPECT_LT(std::stod(switched[i][column.at("P")]), P_bp) << i;
    EXPECT_EQ(switched[i][column.at("stability_index")], "0") << i;
  }
  const auto straight = std::find_if(switched.begin(), switched.end(), [&](const auto& fields) {
    return std::stod(fields[column.at("Delta")]) < 1e-8;
  });
  ASSERT_NE(straight, switched.end());
  EXPECT_NEAR(std::stod((*straight)[column.at("P")]), 4.0 * 4.4934094579 * 4.4934094579, 0.01);
}

// The soft wall's all but straight rod (Delta ~ 8e-10), reached from Delta = 0.02 down the
// symmetric arch, folds at P = 112.1: the eigenvalue of D (the chord's response to the loads) that
// crosses zero there is ~1e-10, out of terms of ~1e-9. A discretisation of the energy (200-800
// elements) gives index 1 without a zero mode up to the fold and 2 past it; against the absolute
// zero tolerance the rows from P = 104.7 to 119.2 said 1 with a zero mode.
TEST_F(ContinueCli, TheAllButStraightRodUnderABarrierFoldsWithItsIndexChanging) {
  const fs::path csv = dir_ / "down.csv";
  ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", std::string(KIRCHHOFF_CASES_DIR) + "/soft_wall.toml", "--set",
                        "log_b=-4", "--set", "Delta=0.02", "--param", "Delta", "--to", "0", "--max-points", "240",
                        "--out", csv.string()},
                       dir_ / "run.log"),
            0);
  const auto rows = lines_of(csv);
  const auto column = csv_header(rows.at(0));
  std::vector<std::vector<std::string>> folds;
  for (size_t i = 1; i < rows.size(); ++i) {
    auto fields = csv_fields(rows[i]);
    if (fields[column.at("type")] == "fold" && std::stod(fields[column.at("Delta")]) < 1e-8) folds.push_back(fields);
  }
  // P within 0.1 of the discretisation's 112.1 (the rows are ~0.5 apart in P there), the crossing
  // eigenvalue its zero mode, index 1 before and 2 after it.
  ASSERT_EQ(folds.size(), 1u);
  const double fold_P = std::stod(folds[0][column.at("P")]);
  EXPECT_NEAR(fold_P, 112.1, 0.1);
  EXPECT_EQ(folds[0][column.at("stability_index")], "1");
  EXPECT_EQ(folds[0][column.at("zero_modes")], "1");
  int before = 0, after = 0;
  for (size_t i = 1; i < rows.size(); ++i) {
    const auto fields = csv_fields(rows[i]);
    const double P = std::stod(fields[column.at("P")]);
    if (fields[column.at("type")] != "regular" || std::stod(fields[column.at("Delta")]) > 1e-8) continue;
    if (P > 104 && P < fold_P - 0.1) {
      ++before;
      EXPECT_EQ(fields[column.at("stability_index")], "1") << rows[i];
      EXPECT_EQ(fields[column.at("zero_modes")], "0") << rows[i];
    } else if (P > fold_P + 0.1 && P < 120) {
      ++after;
      EXPECT_EQ(fields[column.at("stability_index")], "2") << rows[i];
      EXPECT_EQ(fields[column.at("zero_modes")], "0") << rows[i];
    }
  }
  EXPECT_GE(before, 10);
  EXPECT_GE(after, 10);
}

// --switch-at-bp on a case with obstacles: the straight column to its branch point, then the
// buckled branch through first contact (the closed form above) and the flattening of the
// contact, with the active set changing on the switched branch. Killed on it (on the point
// contact's leg and on the flat contact's) and resumed, it writes the same rows.
TEST_F(ContinueCli, SwitchesAtABranchPointOfACaseWithObstacles) {
  const fs::path case_path = dir_ / "column_wall.toml";
  std::ofstream(case_path) << kColumnUnderWall;
  auto args_for = [&](const fs::path& csv) {
    return std::vector<std::string>{KIRCHHOFF_CLI, "continue", case_path.string(), "--param", "P", "--to", "12",
                                    "--switch-at-bp", "1", "--event", "P=40", "--max-step", "0.5",
                                    "--max-points", "400", "--out", csv.string()};
  };
  const fs::path full = dir_ / "full.csv";
  ASSERT_EQ(run_to_end(args_for(full), dir_ / "full.log"), 0);
  const auto log = lines_of(dir_ / "full.log");
  EXPECT_TRUE(has_line_with(log, {"switching branches at P = 9.8696"}));
  EXPECT_TRUE(has_line_with(log, {"a contact appears with obstacle 0 at s = 0.5"}));
  EXPECT_TRUE(has_line_with(log, {"flattens into an extended contact"}));
  const auto rows = lines_of(full);
  int bp_row = -1, reached_row = -1, flat_row = -1;
  for (size_t i = 1; i < rows.size(); ++i) {
    if (bp_row < 0 && rows[i].find(",branch_point,") != std::string::npos) bp_row = static_cast<int>(i);
    if (rows[i].find("obstacle") != std::string::npos && rows[i].find(",event,") != std::string::npos)
      reached_row = static_cast<int>(i);
    if (rows[i].find("flattens") != std::string::npos) flat_row = static_cast<int>(i);
  }
  ASSERT_GT(bp_row, 0);
  ASSERT_GT(reached_row, bp_row);
  ASSERT_GT(flat_row, reached_row);
  // Columns: index, branch, P, arclength, theta0, y_max, contact_force, contact_length.
  EXPECT_NEAR(csv_field(rows[bp_row], 2), M_PI * M_PI, 1e-9);
  EXPECT_EQ(csv_field(rows[bp_row], 1), 0.0);
  EXPECT_EQ(csv_field(rows[bp_row + 1], 1), 1.0);  // the switched branch starts at the branch point
  EXPECT_EQ(csv_field(rows[bp_row + 1], 2), csv_field(rows[bp_row], 2));
  const double theta0 = csv_field(rows[reached_row], 4), k = std::sin(theta0 / 2), K = std::comp_ellint_1(k);
  EXPECT_NEAR(csv_field(rows[reached_row], 5), 0.2, 1e-8);  // y_max = a
  EXPECT_NEAR(k / K, 0.2, 1e-8);
  EXPECT_NEAR(csv_field(rows[reached_row], 2), 4 * K * K, 1e-6);
  EXPECT_EQ(csv_field(rows[reached_row], 1), 1.0);
  EXPECT_GT(csv_field(rows.back(), 6), 0.0);  // pressing on the wall at P = 40
  EXPECT_GT(csv_field(rows.back(), 7), 0.0);  // over an interval
  EXPECT_NEAR(csv_field(rows.back(), 2), 40.0, 1e-9);

  const fs::path csv = dir_ / "killed.csv";
  // (Line i of the file is row i - 1.)
  ASSERT_GT(rows.size(), static_cast<size_t>(flat_row + 10));
  for (int row : {reached_row + 4, flat_row + 8}) {
    SCOPED_TRACE("killed after row " + std::to_string(row));
    fs::remove(csv);
    fs::remove(csv.string() + ".state.json");
    setenv("KIRCHHOFF_TEST_KILL_AFTER_ROW", std::to_string(row).c_str(), 1);
    run_to_end(args_for(csv), dir_ / "killed.log");
    unsetenv("KIRCHHOFF_TEST_KILL_AFTER_ROW");
    ASSERT_EQ(lines_of(csv).size(), static_cast<size_t>(row + 2));
    auto resume = args_for(csv);
    resume.push_back("--resume");
    ASSERT_EQ(run_to_end(resume, dir_ / "resume.log"), 0);
    EXPECT_EQ(lines_of(csv), rows);
  }
}

// A column clamped at both ends, the far clamp sliding under a dead load P: its first buckled
// branch (from 4 pi^2) reaches the point where the ends meet at P = 16 K(k)^2 with 2 E(k) = K(k),
// 86.19634977407 (elliptic integrals, scipy), a branch point where the index goes from 0 to 1.
// The count there is undefined (the chord's constraint degenerates exactly where the ends meet),
// and the row said nothing; its neighbours settle it: 0 with the crossing zero mode (from a probe).
TEST_F(ContinueCli, TheClampedColumnsEndsMeetWithTheIndexItsNeighboursSettle) {
  const fs::path case_path = dir_ / "clamped_column.toml";
  std::ofstream(case_path) << R"toml(title = "Clamped column, the far clamp sliding under a dead load"
model = "planar"
[parameters]
P = 1.0
[rod]
length = 1.0
B = 1.0
[start]
type = "clamped"
position = [0, 0]
[end]
type = "sliding"
axis = [1, 0, 0]
position = [0, 0]
force = ["-P", 0]
orientation = { axis = [0, 0, 1], angle = 0 }
[guess]
force = ["-P", 0]
[output]
derived = ["end_to_end"]
)toml";
  const fs::path csv = dir_ / "clamped.csv";
  ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", case_path.string(), "--param", "P", "--to", "170", "--switch-at-bp",
                        "1", "--max-step", "2", "--max-points", "120", "--out", csv.string()},
                       dir_ / "run.log"),
            0);
  const auto rows = lines_of(csv);
  const auto column = csv_header(rows.at(0));
  size_t meet = 0;
  for (size_t i = 1; i < rows.size() && meet == 0; ++i) {
    const auto fields = csv_fields(rows[i]);
    if (fields[column.at("branch")] == "1" && fields[column.at("type")] == "branch_point" &&
        std::stod(fields[column.at("end_to_end")]) < 1e-6)
      meet = i;
  }
  ASSERT_GT(meet, 1u);
  const auto at = csv_fields(rows[meet]);
  // Located to the corrector's tolerance: 1e-10 of P at least (measured 1e-12).
  EXPECT_NEAR(std::stod(at[column.at("P")]), 86.19634977407, 1e-8);
  EXPECT_EQ(csv_fields(rows[meet - 1])[column.at("stability_index")], "0");
  EXPECT_EQ(csv_fields(rows[meet + 1])[column.at("stability_index")], "1");
  EXPECT_EQ(at[column.at("stability_index")], "0");
  EXPECT_EQ(at[column.at("zero_modes")], "1");
}

// wall.toml with a disc of radius 0.5 for its wall, centred over the middle of the chord: the
// symmetric point contact at s = 0.5 loses stability at the pitchfork Delta = 0.0271376 to a pair
// of asymmetric contacts, mirror images of each other (s and 1 - s, the same contact force; P is
// not mirror-invariant, the disc's force having a horizontal part off the middle). Switching
// there followed the symmetric contact back (s = 0.5 on both sides): the branch point's bordered
// tangent was along the asymmetric branch (branch_crossing.hpp).
const char* kArchUnderDisc = R"toml(title = "Clamped-clamped arch below a disc"
model = "planar"
[parameters]
Delta = 0.026
a = 0.1
L = 1.0
[rod]
length = "L"
B = 1.0
[start]
type = "clamped"
position = [0, 0]
[end]
type = "clamped"
position = ["L - Delta", 0]
[[obstacles]]
type = "cylinder"
name = "disc"
centre = ["(L - Delta)/2", "a + 0.5"]
radius = 0.5
[solver]
tolerance = 1e-12
[guess]
force = [-40, 0]
moment = [0, 0, 2]
[output]
derived = ["P", "contact_force", "contact_s"]
)toml";

// The value of `key` at Delta on a branch's rows, by the cubic through the four nearest rows (its
// error, measured against the rows between, is below 1e-6 in s from Delta = 0.035 on, where s
// no longer grows like the square root of Delta - Delta_bp).
double at_Delta(const std::vector<std::vector<std::string>>& rows, const std::map<std::string, int>& column,
                const std::string& key, double Delta) {
  auto nearest = rows;
  std::sort(nearest.begin(), nearest.end(), [&](const auto& a, const auto& b) {
    return std::abs(std::stod(a[column.at("Delta")]) - Delta) < std::abs(std::stod(b[column.at("Delta")]) - Delta);
  });
  double value = 0.0;
  for (size_t i = 0; i < 4; ++i) {
    double weight = 1.0;
    const double xi = std::stod(nearest[i][column.at("Delta")]);
    for (size_t j = 0; j < 4; ++j)
      if (j != i) weight *= (Delta - std::stod(nearest[j][column.at("Delta")])) / (xi - std::stod(nearest[j][column.at("Delta")]));
    value += weight * std::stod(nearest[i][column.at(key)]);
  }
  return value;
}

TEST_F(ContinueCli, SwitchingAtADiscContactsPitchforkFollowsTheAsymmetricContacts) {
  const fs::path case_path = dir_ / "arch_disc.toml";
  std::ofstream(case_path) << kArchUnderDisc;
  std::map<std::string, std::vector<std::vector<std::string>>> switched;
  std::map<std::string, int> column;
  for (const std::string side : {"1", "-1"}) {
    const fs::path csv = dir_ / ("side" + side + ".csv");
    ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", case_path.string(), "--param", "Delta", "--to", "0.029",
                          "--switch-at-bp", "1", "--side", side, "--max-points", "80", "--out", csv.string()},
                         dir_ / "run.log"),
              0);
    const auto rows = lines_of(csv);
    column = csv_header(rows.at(0));
    bool branch_point = false;
    // The branch's first leg: the asymmetric contacts up to their lift-off.
    for (size_t i = 1; i < rows.size(); ++i) {
      auto fields = csv_fields(rows[i]);
      if (fields[column.at("branch")] != "1") continue;
      if (fields[column.at("type")] == "event") break;
      if (fields[column.at("type")] == "branch_point") {
        branch_point = true;
        EXPECT_NEAR(std::stod(fields[column.at("Delta")]), 0.0271376, 1e-7);
      } else if (fields[column.at("type")] == "regular") {
        // The asymmetric contacts take over the symmetric one's stability.
        EXPECT_EQ(fields[column.at("stability_index")], "0") << rows[i];
        switched[side].push_back(fields);
      }
    }
    EXPECT_TRUE(branch_point);
    ASSERT_GE(switched[side].size(), 30u);
  }
  // The asymmetric contact lifts off the disc at Delta = 0.1644. A run whose points are spent
  // exactly there stopped with "max_points must be in [1, 1e7]" (exit 1) when it set up the next
  // leg with none left; it stops at the event as max_points.
  // (Past the lift-off the free rod turns into the disc at once, and the run stops as
  // inadmissible, exit 1: contact.md, not modelled.)
  const fs::path through = dir_ / "through.csv";
  run_to_end({KIRCHHOFF_CLI, "continue", case_path.string(), "--param", "Delta", "--to", "0.029", "--switch-at-bp", "1",
              "--max-points", "150", "--out", through.string()},
             dir_ / "through.log");
  const auto rows = lines_of(through);
  int on_switched = 0, to_lift_off = 0;
  for (size_t i = 1; i < rows.size() && to_lift_off == 0; ++i) {
    const auto fields = csv_fields(rows[i]);
    if (fields[column.at("branch")] != "1") continue;
    ++on_switched;
    if (fields[column.at("event")].find("contact_lifts_off") != std::string::npos) to_lift_off = on_switched;
  }
  ASSERT_GT(to_lift_off, 0);
  const fs::path spent = dir_ / "spent.csv";
  ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", case_path.string(), "--param", "Delta", "--to", "0.029",
                        "--switch-at-bp", "1", "--max-points", std::to_string(to_lift_off), "--out",
                        spent.string()},
                       dir_ / "spent.log"),
            0);
  const auto spent_rows = lines_of(spent);
  EXPECT_NE(spent_rows.back().find("contact_lifts_off"), std::string::npos) << spent_rows.back();
  EXPECT_EQ(read_text(dir_ / "spent.log").find("max_points must be"), std::string::npos);
  for (const double Delta : {0.035, 0.05}) {
    const double s_plus = at_Delta(switched["1"], column, "contact_s", Delta);
    const double s_minus = at_Delta(switched["-1"], column, "contact_s", Delta);
    EXPECT_GT(std::abs(s_plus - 0.5), 0.05) << Delta;
    EXPECT_NEAR(s_plus + s_minus, 1.0, 1e-5) << Delta;
    EXPECT_NEAR(at_Delta(switched["1"], column, "contact_force", Delta),
                at_Delta(switched["-1"], column, "contact_force", Delta), 1e-4)
        << Delta;
  }
}

// --max-points N gives N rows on each branch, whatever ends the run. The Euler column switched
// at P = pi^2 reaches its touching-ends branch point, found inside a step besides the step's own
// point, about 40 rows on; the wall's contact run starts a hanging-fold leg (run_along) at row
// 676 and finds a fold at row 712. Each of those gave one row more than N: the switched branch
// did not count the branch point it starts at, and a step's special point was not counted
// against the budget before its candidate was added.
TEST_F(ContinueCli, MaxPointsGivesThatManyRowsOnEachBranch) {
  const std::string euler = std::string(KIRCHHOFF_CASES_DIR) + "/euler_column.toml";
  bool ended_on_a_special_point = false;
  for (int n = 33; n <= 48; ++n) {
    const fs::path csv = dir_ / ("euler" + std::to_string(n) + ".csv");
    ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", euler, "--param", "P", "--set", "P=1", "--set", "theta_guess=0",
                          "--to", "20", "--switch-at-bp", "1", "--max-points", std::to_string(n), "--out",
                          csv.string()},
                         dir_ / "euler.log"),
              0)
        << n;
    const auto rows = lines_of(csv);
    const auto column = csv_header(rows[0]);
    int on_switched = 0;
    for (size_t i = 1; i < rows.size(); ++i) on_switched += csv_fields(rows[i])[column.at("branch")] == "1";
    EXPECT_EQ(on_switched, n);
    const auto last = csv_fields(rows.back());
    if (last[column.at("type")] == "branch_point" && last[column.at("branch")] == "1") ended_on_a_special_point = true;
  }
  EXPECT_TRUE(ended_on_a_special_point);  // (else the loop no longer covers a step's special point)
  const std::string wall = std::string(KIRCHHOFF_CASES_DIR) + "/wall.toml";
  for (const int n : {677, 678, 713}) {
    const fs::path csv = dir_ / ("wall" + std::to_string(n) + ".csv");
    ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", wall, "--param", "Delta", "--to", "0.06", "--max-points",
                          std::to_string(n), "--out", csv.string()},
                         dir_ / "wall.log"),
              0)
        << n;
    EXPECT_EQ(lines_of(csv).size(), static_cast<size_t>(n) + 1) << n;  // (the header)
  }
  const auto rows = lines_of(dir_ / "wall713.csv");
  EXPECT_EQ(csv_fields(rows.back())[csv_header(rows[0]).at("type")], "fold");
  EXPECT_NE(read_text(dir_ / "wall.log").find("hanging fold"), std::string::npos);
}

// A wall-clock limit that passes before the start has converged (or at a new contact leg's
// start) stops the run as time_limit, which a driver resumes, not start_failed; the resumed run
// starts from the beginning (no point was saved) and ends as the uninterrupted one.
TEST_F(ContinueCli, ALimitReachedAtTheStartIsATimeLimit) {
  const std::string wall = std::string(KIRCHHOFF_CASES_DIR) + "/wall.toml";
  const fs::path csv = dir_ / "limited.csv", full = dir_ / "full.csv";
  auto args = [&](const fs::path& out) {
    return std::vector<std::string>{KIRCHHOFF_CLI, "continue", wall, "--param", "Delta", "--to", "0.04",
                                    "--max-step", "2", "--out", out.string()};
  };
  auto limited = args(csv);
  limited.insert(limited.end(), {"--max-seconds", "1e-6"});
  EXPECT_EQ(run_to_end(limited, dir_ / "limited.log"), 1);
  EXPECT_NE(read_text(dir_ / "limited.log").find("stopped: time_limit"), std::string::npos)
      << read_text(dir_ / "limited.log");
  auto resumed = args(csv);
  resumed.push_back("--resume");
  ASSERT_EQ(run_to_end(resumed, dir_ / "resumed.log"), 0);
  ASSERT_EQ(run_to_end(args(full), dir_ / "full.log"), 0);
  EXPECT_EQ(lines_of(csv), lines_of(full));
}

// A row whose index is undefined has an empty cell and the CSV no column for why: the first such
// row is noted with the reason (the Reissner rod's dead 3D end couple is not conservative), once.
TEST_F(ContinueCli, TheFirstRowWithoutAnIndexIsNotedWithWhy) {
  const fs::path csv = dir_ / "reissner.csv";
  ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", std::string(KIRCHHOFF_CASES_DIR) + "/reissner.toml", "--param", "F",
                        "--to", "2.5", "--out", csv.string()},
                       dir_ / "reissner.log"),
            0);
  const std::string log = read_text(dir_ / "reissner.log");
  EXPECT_NE(log.find("row 0 (F = 2): stability index undefined: the end's loads are not conservative"), std::string::npos)
      << log;
  EXPECT_EQ(log.find("index undefined"), log.rfind("index undefined")) << log;  // (once)
  const auto rows = lines_of(csv);
  ASSERT_GT(rows.size(), 3u);
  EXPECT_EQ(csv_fields(rows[2])[csv_header(rows[0]).at("stability_index")], "");
}

TEST_F(ContinueCli, ContinuingAnUnknownParameterIsRefused) {
  const std::vector<std::string> args = {KIRCHHOFF_CLI, "continue",
                                         std::string(KIRCHHOFF_CASES_DIR) + "/simply_supported.toml", "--param",
                                         "Q", "--to", "2", "--out", (dir_ / "x.csv").string()};
  EXPECT_EQ(run_to_end(args, dir_ / "x.log"), 2);
  const auto log = lines_of(dir_ / "x.log");
  ASSERT_FALSE(log.empty());
  EXPECT_NE(log.front().find("Q"), std::string::npos);
}

}  // namespace

namespace {

// --deflate: the five equilibria of the Euler column at P = 50 (straight, mode 1 and mode 2 up and
// down), each followed to P = 60 as its own branch; at P = 60 the buckled ends lie on the elliptic
// closed form P = (2 n K(k))^2 EI / L^2, k = sin(theta0 / 2), n = 1 or 2 (CSV values to 15
// digits; the endpoint located at P = 60 to ~1e-10, so 1e-8 relative).
TEST_F(ContinueCli, DeflateFollowsEveryBranchFromTheStart) {
  const fs::path csv = dir_ / "d.csv";
  const std::vector<std::string> args = {KIRCHHOFF_CLI, "continue", std::string(KIRCHHOFF_CASES_DIR) + "/euler_column.toml",
                                         "--set", "P=50", "--param", "P", "--to", "60", "--deflate", "--deflate-max", "5",
                                         "--no-stability", "--out", csv.string()};
  ASSERT_EQ(run_to_end(args, dir_ / "d.log"), 0);
  const auto lines = lines_of(csv);
  ASSERT_GT(lines.size(), 10u);
  const auto header = csv_header(lines[0]);
  const size_t branch_col = header.at("branch"), P_col = header.at("P"), theta_col = header.at("theta0"),
               type_col = header.at("type");
  std::vector<double> theta_at_60;
  std::vector<int> branches;
  for (size_t i = 1; i < lines.size(); ++i) {
    const std::vector<std::string> f = csv_fields(lines[i]);
    const int branch = std::stoi(f[branch_col]);
    if (std::find(branches.begin(), branches.end(), branch) == branches.end()) {
      branches.push_back(branch);
      EXPECT_EQ(std::stod(f[P_col]), 50.0) << lines[i];  // every branch starts at the start
    }
    if (f[type_col] == "endpoint") {
      EXPECT_NEAR(std::stod(f[P_col]), 60.0, 1e-9);
      theta_at_60.push_back(std::stod(f[theta_col]));
    }
  }
  EXPECT_EQ(branches, (std::vector<int>{0, 1, 2, 3, 4}));
  ASSERT_EQ(theta_at_60.size(), 5u);
  int straight = 0, mode1 = 0, mode2 = 0;
  for (double angle : theta_at_60) {
    // The mirror image of a mode-1 rod may carry its angle 2 pi on (3.309 for -2.974): the same rod.
    const double theta0 = std::remainder(angle, 2.0 * M_PI);
    if (std::abs(theta0) < 1e-9) {
      ++straight;
      continue;
    }
    const double first_mode_load = kirchhoff::analytic::PinnedElastica{1.0, 1.0, std::abs(theta0)}.load();
    if (std::abs(first_mode_load / 60.0 - 1.0) < 1e-8) ++mode1;
    if (std::abs(4.0 * first_mode_load / 60.0 - 1.0) < 1e-8) ++mode2;  // two half-waves: 4 K^2 times 4
  }
  EXPECT_EQ(straight, 1);
  EXPECT_EQ(mode1, 2);
  EXPECT_EQ(mode2, 2);
  // Not resumable: refused with the options that need a saved state.
  auto resumed = args;
  resumed.push_back("--resume");
  EXPECT_EQ(run_to_end(resumed, dir_ / "r.log"), 2);
}

// plectoneme.toml's branch as docs/stability.md follows it, to the fold where the end loop closes
// (60 points, turns 0 -> 1.770 -> 1.149): index 0 up to the fold where the loop starts to form,
// 1 between the folds (their symmetric direction), 0 past the second, with the turn about the
// clamps' axis as a zero mode at every regular point. Where the loop is about to close (turns
// 1.1576) the barrier's spike is narrow: at the default observations of the Jacobi fields one row
// had index 2 (a whole turn of an eigenphase inside one step); confirmed by denser observations in
// a field, it has 1.
TEST_F(ContinueCli, PlectonemeIndexAlongTheLoopFormingFolds) {
  const fs::path csv = dir_ / "plectoneme.csv";
  ASSERT_EQ(run_to_end({KIRCHHOFF_CLI, "continue", std::string(KIRCHHOFF_CASES_DIR) + "/plectoneme.toml", "--param",
                        "turns", "--to", "4", "--max-step", "60", "--max-points", "60", "--out", csv.string()},
                       dir_ / "run.log"),
            0);
  const auto lines = lines_of(csv);
  ASSERT_EQ(lines.size(), 61u);
  const auto header = csv_header(lines.front());
  const int turns = header.at("turns"), type = header.at("type"), index = header.at("stability_index"),
            zero = header.at("zero_modes");
  int folds = 0, between = 0;
  for (size_t i = 1; i < lines.size(); ++i) {
    const auto fields = csv_fields(lines[i]);
    if (fields[type] == "fold") {
      ++folds;
      continue;
    }
    SCOPED_TRACE("turns = " + fields[turns]);
    ASSERT_FALSE(fields[index].empty());
    EXPECT_EQ(std::stoi(fields[index]), folds == 1 ? 1 : 0);
    EXPECT_EQ(std::stoi(fields[zero]), 1);
    between += folds == 1;
  }
  EXPECT_EQ(folds, 2);
  EXPECT_GE(between, 10);
}

}  // namespace
