// `kirchhoff plectonemes` killed with SIGKILL half-way through a branch and run again with
// --resume: the rows written before the kill stay as they were, indices run on without a gap or a
// repeat, the branch ends where the uninterrupted one ends, and a finished branch is left alone.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

namespace {

namespace fs = std::filesystem;

std::vector<std::string> lines_of(const fs::path& p) {
  std::ifstream in(p);
  std::vector<std::string> out;
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) out.push_back(line);
  return out;
}

double column(const std::string& line, int k) {
  size_t pos = 0;
  for (int i = 0; i < k; ++i) pos = line.find(',', pos) + 1;
  return std::stod(line.substr(pos, line.find(',', pos) - pos));
}

// L/2R = 100 from the untwisted rod to 3 turns: through both folds and the loop's closing, a few
// hundred points in ~10 s.
std::vector<std::string> sweep_args(const fs::path& dir) {
  return {KIRCHHOFF_CLI, "plectonemes", "--slenderness", "100", "--turns", "3", "--out", dir.string()};
}

int run_to_end(const std::vector<std::string>& args, const fs::path& log) {
  std::string cmd;
  for (const auto& a : args) cmd += "'" + a + "' ";
  return WEXITSTATUS(std::system((cmd + " > '" + log.string() + "' 2>&1").c_str()));
}

class PlectonemesCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("kirchhoff_plectonemes_" + std::to_string(getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(PlectonemesCli, KilledSweepResumesOnTheSameBranch) {
  const fs::path full = dir_ / "full", killed = dir_ / "killed";
  ASSERT_EQ(run_to_end(sweep_args(full), dir_ / "full.log"), 0);
  const auto expected = lines_of(full / "plectoneme_100.csv");
  ASSERT_GT(expected.size(), 60u);
  EXPECT_EQ(expected[0].substr(0, 27), "index,turns,type,T_ext,heli");

  const fs::path csv = killed / "plectoneme_100.csv";
  const pid_t pid = fork();
  if (pid == 0) {
    const auto args = sweep_args(killed);
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    FILE* err = std::freopen((dir_ / "killed.log").c_str(), "w", stderr);
    (void)err;
    execv(argv[0], argv.data());
    _exit(127);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (lines_of(csv).size() < expected.size() / 2 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the sweep finished before it could be killed";
  const auto before = lines_of(csv);

  auto resume = sweep_args(killed);
  resume.push_back("--resume");
  ASSERT_EQ(run_to_end(resume, dir_ / "resume.log"), 0);
  const auto after = lines_of(csv);
  // Rows up to the last resumable point are untouched. The resumed march recomputes the matrix
  // of its first point (the state keeps none), so its steps differ from the uninterrupted run's
  // and the two reach turns = 3 by different corrector paths: measured 1.5e-6 apart in T_ext,
  // with the residual 1e-8 on forces ~1e2. The bar, 1e-5, still tells another branch (O(1) apart).
  for (size_t i = 0; i + 3 < before.size(); ++i) EXPECT_EQ(after[i], before[i]) << "line " << i;
  for (size_t i = 1; i < after.size(); ++i)
    EXPECT_EQ(std::stoi(after[i].substr(0, after[i].find(','))), static_cast<int>(i - 1)) << "line " << i;
  ASSERT_NE(after.back().find(",endpoint,"), std::string::npos);
  EXPECT_NEAR(column(after.back(), 1), 3.0, 3e-9);  // the located end point, to 1e-9 relative
  EXPECT_NEAR(column(after.back(), 3) / column(expected.back(), 3), 1.0, 1e-5);  // T_ext at 3 turns

  // A finished branch is left as it is.
  ASSERT_EQ(run_to_end(resume, dir_ / "again.log"), 0);
  EXPECT_EQ(lines_of(csv), after);
  const auto log = lines_of(dir_ / "again.log");
  std::string all;
  for (const auto& l : log) all += l + "\n";
  EXPECT_NE(all.find("already complete"), std::string::npos) << all;
}

}  // namespace
