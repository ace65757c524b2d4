// `kirchhoff vibrate`: the JSON file, the mode-shape CSVs, the table, and refusals. Runs the
// built binary.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "kirchhoff/analysis/analytic.hpp"

namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string case_path(const std::string& name) { return std::string(KIRCHHOFF_CASES_DIR) + "/" + name; }

std::string read_file(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

class VibrateCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "kirchhoff_vibrate_test_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }
  // Runs `kirchhoff ARGS` (no quoting needed for the paths used here); returns the exit status.
  int run(const std::string& args) {
    const std::string command = std::string(KIRCHHOFF_CLI) + " " + args + " >" + (dir_ / "out.txt").string() +
                                " 2>" + (dir_ / "err.txt").string();
    const int raw = std::system(command.c_str());
    out_ = read_file(dir_ / "out.txt");
    err_ = read_file(dir_ / "err.txt");
    return (raw != -1 && WIFEXITED(raw)) ? WEXITSTATUS(raw) : -1;
  }
  fs::path dir_;
  std::string out_, err_;
};

TEST_F(VibrateCliTest, PinnedColumnJsonAndProfiles) {
  const double P = 0.5 * M_PI * M_PI;
  const fs::path json_path = dir_ / "vib.json", profiles = dir_ / "modes";
  ASSERT_EQ(run("vibrate " + case_path("euler_column.toml") + " --set P=" + std::to_string(P) +
                " --set theta_guess=0 --modes 2 --rho-s 2 --out " + json_path.string() + " --profiles " +
                profiles.string()),
            0)
      << err_;
  EXPECT_THAT(out_, HasSubstr("omega"));
  const auto j = nlohmann::json::parse(read_file(json_path));
  ASSERT_EQ(j["frequencies"].size(), 2u);
  // std::to_string keeps 6 decimals of P: compare at 1e-6.
  for (int k = 1; k <= 2; ++k) {
    const double exact = kirchhoff::analytic::pinned_column_frequency(1.0, P, 2.0, 1.0, k);
    EXPECT_NEAR(j["frequencies"][k - 1].get<double>() / exact, 1.0, 1e-6);
    EXPECT_LE(j["modes"][k - 1]["H_vib_relative_spread"].get<double>(), 1e-9);
    EXPECT_TRUE(j["modes"][k - 1]["H_vib_invariant"].get<bool>());
  }
  EXPECT_TRUE(j["straight_equilibrium"].get<bool>());
  const std::string csv = read_file(profiles / "mode_1.csv");
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "s,xbar,ybar,thetabar,mbar,nbarx,nbary,H_vib");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 202);  // header + 201 samples
}

TEST_F(VibrateCliTest, BuckledElasticaJsonOnStdout) {
  ASSERT_EQ(run("vibrate " + case_path("simply_supported.toml") + " --set theta0=1 --modes 1 --json"), 0) << err_;
  const auto j = nlohmann::json::parse(out_);
  EXPECT_FALSE(j["straight_equilibrium"].get<bool>());
  EXPECT_GT(j["modes"][0]["H_vib_relative_spread"].get<double>(), 1e-3);
}

// The straight column above its second Euler load: two imaginary frequencies, in the JSON (omega2,
// negative_omega2_count, unstable_modes with their growth rates and profiles) and in the text.
// omega_k^2 = (k pi)^2 ((k pi)^2 - P); the search is exact to ~1e-10, and P = 50 is exact here.
TEST_F(VibrateCliTest, UnstableColumnReportsNegativeOmega2) {
  const fs::path profiles = dir_ / "modes";
  ASSERT_EQ(run("vibrate " + case_path("euler_column.toml") + " --set P=50 --set theta_guess=0 --modes 1 --json" +
                " --profiles " + profiles.string()),
            0)
      << err_;
  const auto j = nlohmann::json::parse(out_);
  ASSERT_EQ(j["negative_omega2_count"].get<int>(), 2);
  const double k2[] = {4 * M_PI * M_PI, M_PI * M_PI};  // most negative first: k = 2, then k = 1
  for (int i = 0; i < 2; ++i) {
    const double exact = k2[i] * (k2[i] - 50.0);
    const auto& mode = j["unstable_modes"][i];
    EXPECT_NEAR(mode["omega2"].get<double>() / exact, 1.0, 1e-9);
    EXPECT_NEAR(mode["growth_rate"].get<double>(), std::sqrt(-exact), 1e-8 * std::sqrt(-exact));
    EXPECT_FALSE(mode.contains("omega"));
    EXPECT_TRUE(fs::exists(mode["profile"].get<std::string>()));
    EXPECT_NEAR(j["omega2"][i].get<double>(), mode["omega2"].get<double>(), 0.0);
  }
  EXPECT_GT(j["omega2"][2].get<double>(), 0.0);  // then the vibrations
  EXPECT_TRUE(j["unstable_search"]["searched"].get<bool>());
  EXPECT_TRUE(fs::exists(profiles / "unstable_mode_2.csv"));
  ASSERT_EQ(run("vibrate " + case_path("euler_column.toml") + " --set P=50 --set theta_guess=0 --modes 1"), 0) << err_;
  EXPECT_THAT(out_, HasSubstr("unstable: 2 modes with omega^2 < 0"));
  ASSERT_EQ(run("vibrate " + case_path("euler_column.toml") + " --set P=12 --set theta_guess=1 --modes 1"), 0) << err_;
  EXPECT_THAT(out_, HasSubstr("no mode with omega^2 < 0"));
}

TEST_F(VibrateCliTest, RefusesSpatialCasesAndBadOptions) {
  EXPECT_EQ(run("vibrate " + case_path("twisted_clamped.toml")), 2);
  EXPECT_THAT(err_, HasSubstr("planar"));
  EXPECT_EQ(run("vibrate " + case_path("euler_column.toml") + " --rho-s -1"), 2);
  EXPECT_EQ(run("vibrate " + case_path("euler_column.toml") + " --modes 0"), 2);
  EXPECT_THAT(err_, HasSubstr("--modes must be >= 1, got 0"));  // (was "not in range 0 to 1.8e308")
  // Refused before the equilibrium is solved for, as Python's vibrate() refuses them: a spatial
  // case whose solve would stop short, and bad options on a case whose solve would fail
  // (an end inside the wall).
  EXPECT_EQ(run("vibrate " + case_path("twisted_ribbon_pole.toml") + " --set pole_x=0 --set pole_z=0"), 2);
  EXPECT_THAT(err_, HasSubstr("planar rods only"));
  EXPECT_EQ(run("vibrate " + case_path("wall.toml") + " --set a=-0.01 --rho-s nan"), 2);
  EXPECT_THAT(err_, HasSubstr("--rho-s must be > 0, got nan"));
  EXPECT_EQ(run("vibrate --help"), 0);
  EXPECT_THAT(out_, HasSubstr("dead load"));
}

}  // namespace
