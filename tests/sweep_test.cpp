// kirchhoff sweep (sweep_run.hpp, sweep_mpi.hpp): serial and under mpirun -n 2 give the same
// index and job files byte for byte; a sweep killed half-way and resumed (under MPI) gives the
// same files as one never interrupted. Not labelled fast: the sanitizer build would run OpenMPI
// under LeakSanitizer; the sweep file's own tests are sweep_file_test.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>

#include "cli_run_support.hpp"

namespace kirchhoff {
namespace {

namespace fs = std::filesystem;
using testing::ScratchFolderTest;

const std::string kCases = KIRCHHOFF_CASES_DIR;

// The files a sweep leaves, but times.csv (wall times), each with its content.
std::map<std::string, std::string> files_of(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (!entry.is_regular_file() || entry.path().filename() == "times.csv") continue;
    std::ifstream in(entry.path(), std::ios::binary);
    std::ostringstream os;
    os << in.rdbuf();
    out[fs::relative(entry.path(), dir).string()] = os.str();
  }
  return out;
}

class SweepRunTest : public ScratchFolderTest {
 protected:
  // 16 jobs: solves of Fig. 3 by homotopy (the last ones beyond its branch point), equilibria of
  // the column, the straight column continued in P from 5 through its branch point to 12, and the
  // plectoneme case's branch from the untwisted rod to a quarter turn.
  fs::path write_spec() {
    const fs::path spec = dir_ / "sweep.toml";
    std::ofstream(spec) << "title = \"test sweep\"\n"
                           "case = \"" << kCases << "/simply_supported.toml\"\n"
                           "[[jobs]]\nname = \"fig3\"\nkind = \"solve\"\n"
                           "grid = { theta0 = { from = 0.25, to = 3.0, count = 12 } }\n"
                           "[[jobs]]\nname = \"column\"\nkind = \"equilibria\"\ncase = \"" << kCases
                        << "/euler_column.toml\"\nmax_equilibria = 3\nlist = [{ P = 5 }, { P = 12 }]\n"
                        << "[[jobs]]\nname = \"branch\"\nkind = \"continue\"\ncase = \"" << kCases
                        << "/euler_column.toml\"\nset = { theta_guess = 0 }\nparam = \"P\"\nto = 12\nmax_points = 100\n"
                           "list = [{ P = 5 }]\n"
                           "[[jobs]]\nname = \"ply\"\nkind = \"plectonemes\"\ncase = \"" << kCases
                        << "/plectoneme.toml\"\nlist = [{ slenderness = 100, turns = 0.25 }]\n";
    return spec;
  }
  std::vector<std::string> sweep(const fs::path& spec, const fs::path& out) {
    return {KIRCHHOFF_CLI, "sweep", spec.string(), "--out", out.string()};
  }
};

TEST_F(SweepRunTest, IndexHasOneRowPerJobInJobOrder) {
  const fs::path spec = write_spec();
  ASSERT_EQ(testing::run_to_end(sweep(spec, dir_ / "a"), dir_ / "a.log"), 0);
  const auto rows = testing::lines_of(dir_ / "a" / "index.csv");
  ASSERT_EQ(rows.size(), 17u);
  EXPECT_EQ(rows[0].rfind("job,kind,theta0,P,slenderness,turns,status,reason,contact_state,stable_states,stability_index,zero_modes,equilibria,"
                          "energy,derived_P,y_max,kappa_max,end_to_end,derived_theta0",
                          0),
            0u)
      << rows[0];
  EXPECT_EQ(rows[1].rfind("fig3-001,solve,0.25,,,,ok,,none,none,0,0,1,", 0), 0u) << rows[1];
  EXPECT_EQ(rows[13].rfind("column-001,equilibria,,5.0,,,ok,,none,none,0,0,3,", 0), 0u) << rows[13];
  EXPECT_TRUE(fs::exists(dir_ / "a" / "jobs" / "fig3-012" / "profile.csv"));
  EXPECT_TRUE(fs::exists(dir_ / "a" / "jobs" / "column-002" / "equilibrium_3.csv"));
  EXPECT_EQ(rows[15].rfind("branch,continue,,5.0,,,ok,", 0), 0u) << rows[15];
  EXPECT_TRUE(fs::exists(dir_ / "a" / "jobs" / "branch" / "branch.csv"));
  EXPECT_EQ(rows[16].rfind("ply,plectonemes,,,100.0,0.25,ok,", 0), 0u) << rows[16];
  EXPECT_TRUE(fs::exists(dir_ / "a" / "jobs" / "ply" / "plectoneme_100.csv"));
  // The plectonemes job's own progress lines (as `kirchhoff plectonemes` prints them) among the
  // sweep's, after the job's id.
  const auto log = testing::lines_of(dir_ / "a.log");
  EXPECT_NE(std::find(log.begin(), log.end(), "ply: L/2R = 100: turns 0 -> 0.25"), log.end());
  EXPECT_EQ(testing::lines_of(dir_ / "a" / "times.csv").size(), 17u);
  // Again into the same folder without --resume: refused, nothing touched.
  EXPECT_EQ(testing::run_to_end(sweep(spec, dir_ / "a"), dir_ / "b.log"), 2);
}

// A solve job whose index the conjugate points leave undefined (the clamped-clamped rod with its
// ends 1e-5 apart: a chord held nearly degenerate, docs/stability.md) gets the discretised
// energy's, as `kirchhoff solve` reports it (index 0, method discretised_energy); the index was
// empty.
TEST_F(SweepRunTest, ASolveJobTakesTheDiscretisedIndexAsSolveDoes) {
  const fs::path spec = dir_ / "ends_meet.toml";
  std::ofstream(spec) << "title = \"ends meet\"\ncase = \"" << kCases
                      << "/clamped_clamped.toml\"\n[[jobs]]\nname = \"meet\"\nkind = \"solve\"\n"
                         "list = [{ D = 1e-5 }]\n";
  ASSERT_EQ(testing::run_to_end(sweep(spec, dir_ / "m"), dir_ / "m.log"), 0);
  const auto rows = testing::lines_of(dir_ / "m" / "index.csv");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[1].rfind("meet,solve,1e-05,ok,,none,none,0,0,1,", 0), 0u) << rows[1];
  std::ifstream in(dir_ / "m" / "jobs" / "meet" / "result.json");
  const std::string result((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(result.find("\"stability_method\": \"discretised_energy\""), std::string::npos) << result;
}

#ifdef KIRCHHOFF_MPIEXEC
std::vector<std::string> under_mpi(std::vector<std::string> args) {
  args.insert(args.begin(), {KIRCHHOFF_MPIEXEC, "-n", "2", "--oversubscribe", "--allow-run-as-root"});
  return args;
}

TEST_F(SweepRunTest, SerialAndTwoRanksGiveTheSameFiles) {
  const fs::path spec = write_spec();
  ASSERT_EQ(testing::run_to_end(sweep(spec, dir_ / "serial"), dir_ / "serial.log"), 0);
  ASSERT_EQ(testing::run_to_end(under_mpi(sweep(spec, dir_ / "mpi")), dir_ / "mpi.log"), 0);
  const auto serial = files_of(dir_ / "serial");
  EXPECT_EQ(serial.size(), 1u + 12 * 2 + 2 * 4 + 2 + 3);
  EXPECT_EQ(files_of(dir_ / "mpi"), serial);
  // Both ranks ran jobs (the manager too, on its thread).
  const auto times = testing::lines_of(dir_ / "mpi" / "times.csv");
  EXPECT_TRUE(std::any_of(times.begin(), times.end(), [](const std::string& l) { return l.substr(l.size() - 2) == ",0"; }));
  EXPECT_TRUE(std::any_of(times.begin(), times.end(), [](const std::string& l) { return l.substr(l.size() - 2) == ",1"; }));
}

TEST_F(SweepRunTest, KilledHalfWayAndResumedUnderMpiEqualsUninterrupted) {
  const fs::path spec = write_spec();
  ASSERT_EQ(testing::run_to_end(sweep(spec, dir_ / "whole"), dir_ / "whole.log"), 0);
  const fs::path jobs = dir_ / "cut" / "jobs";
  const bool killed = testing::run_and_kill(sweep(spec, dir_ / "cut"), dir_ / "cut.log", [&jobs] {
    std::error_code ec;
    int finished = 0;
    for (const auto& e : fs::directory_iterator(jobs, ec))
      if (e.path().filename().string()[0] != '.') ++finished;
    return finished >= 4;
  });
  ASSERT_TRUE(killed) << "the sweep ended before it could be killed";
  EXPECT_FALSE(fs::exists(dir_ / "cut" / "index.csv"));
  ASSERT_EQ(testing::run_to_end(under_mpi(sweep(spec, dir_ / "cut")), dir_ / "resume.log"), 2);  // no --resume
  auto resume = under_mpi(sweep(spec, dir_ / "cut"));
  resume.push_back("--resume");
  ASSERT_EQ(testing::run_to_end(resume, dir_ / "resume.log"), 0);
  EXPECT_EQ(files_of(dir_ / "cut"), files_of(dir_ / "whole"));
}
#endif

TEST_F(SweepRunTest, ResumeRefusesResultsOfAnotherSweepFile) {
  const fs::path spec = write_spec();
  ASSERT_EQ(testing::run_to_end(sweep(spec, dir_ / "a"), dir_ / "a.log"), 0);
  std::ofstream(spec) << "case = \"" << kCases << "/simply_supported.toml\"\n"
                      << "[[jobs]]\nname = \"fig3\"\nkind = \"solve\"\ngrid = { theta0 = [0.3, 0.4] }\n";
  auto args = sweep(spec, dir_ / "a");
  args.push_back("--resume");
  EXPECT_EQ(testing::run_to_end(args, dir_ / "b.log"), 2);
  std::ifstream log(dir_ / "b.log");
  const std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("fig3-001/result.json: computed for another job"), std::string::npos) << text;
}

}  // namespace
}  // namespace kirchhoff
