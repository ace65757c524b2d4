// The kirchhoff command line: exit statuses (0 solved, 1 solver failure, 2 input refused), the
// JSON report, the profile CSV, and the messages on stderr. Runs the built binary.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "foundation_column_case.hpp"
#include "kirchhoff/analysis/analytic.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using ::testing::HasSubstr;
using ::testing::Not;

const std::string kCases = KIRCHHOFF_CASES_DIR;
std::string case_path(const std::string& name) { return kCases + "/" + name; }

std::string quoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

struct CliRun {
  int status = -1;  // exit status; 128 + signal when killed (e.g. 134 on abort)
  std::string out, err;
};

const std::set<std::string> kFailureWords = {"max_iterations",     "singular_jacobian",  "integration_failed",
                                             "line_search_failed", "unfolding_not_zero", "not_finite",
                                             "check_failed",       "time_limit"};

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "kirchhoff_cli_test_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }

  // Runs `kirchhoff ARGS` (ARGS already shell-quoted where needed).
  CliRun run(const std::string& args) {
    const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string command =
        quoted(KIRCHHOFF_CLI) + " " + args + " >" + quoted(out.string()) + " 2>" + quoted(err.string());
    const int raw = std::system(command.c_str());
    CliRun r;
    if (raw != -1 && WIFEXITED(raw)) r.status = WEXITSTATUS(raw);
    else if (raw != -1 && WIFSIGNALED(raw)) r.status = 128 + WTERMSIG(raw);
    r.out = read_file(out);
    r.err = read_file(err);
    return r;
  }

  // Parses stdout as one JSON object (fails the test otherwise).
  static json parse(const CliRun& r) {
    json j;
    try {
      j = json::parse(r.out);
    } catch (const json::exception& e) {
      ADD_FAILURE() << "stdout is not JSON (" << e.what() << "):\n" << r.out << "\nstderr:\n" << r.err;
      return json::object();
    }
    EXPECT_TRUE(j.is_object()) << r.out;
    return j;
  }

  // A copy of cases/NAME with `from` replaced by `to`, in the temp directory.
  std::string variant(const std::string& name, const std::string& from, const std::string& to,
                      const std::string& file = "variant.toml") {
    std::string text = read_file(case_path(name));
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << "'" << from << "' not in " << name;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    const std::string path = (dir_ / file).string();
    std::ofstream(path) << text;
    return path;
  }

  fs::path dir_;
};

double relative(double a, double b) { return std::abs(a - b) / std::max(std::abs(b), 1e-300); }

// ---- help ----------------------------------------------------------------------------------

TEST_F(CliTest, HelpMentionsTheCommands) {
  const CliRun r = run("--help");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("solve"));
  EXPECT_THAT(r.out, HasSubstr("check"));
}

TEST_F(CliTest, NoCommandIsRefused) {
  const CliRun r = run("");
  EXPECT_EQ(r.status, 2);
  const CliRun bogus = run("frobnicate");
  EXPECT_EQ(bogus.status, 2);
}

// ---- solve: the simply supported Elastica against Love's solution --------------------------

TEST_F(CliTest, SolveSimplySupportedJson) {
  const CliRun r = run("solve " + quoted(case_path("simply_supported.toml")) + " --json");
  ASSERT_EQ(r.status, 0) << r.err << r.out;
  const json j = parse(r);
  ASSERT_TRUE(j.is_object());
  EXPECT_EQ(j.value("status", ""), "converged");
  ASSERT_TRUE(j.contains("iterations") && j["iterations"].is_number_integer()) << j.dump(2);
  EXPECT_GE(j["iterations"].get<int>(), 1);  // the guess P = 12 is not the solution
  ASSERT_TRUE(j.contains("residual") && j["residual"].is_number()) << j.dump(2);
  EXPECT_LT(j["residual"].get<double>(), 1e-8);

  ASSERT_TRUE(j.contains("parameters")) << j.dump(2);
  ASSERT_TRUE(j["parameters"].contains("theta0"));
  ASSERT_TRUE(j["parameters"].contains("P"));
  EXPECT_EQ(j["parameters"]["theta0"].get<double>(), 1.0);

  ASSERT_TRUE(j.contains("derived")) << j.dump(2);
  for (const char* key : {"P", "y_max", "kappa_max", "end_to_end"})
    ASSERT_TRUE(j["derived"].contains(key) && j["derived"][key].is_number()) << key << "\n" << j["derived"].dump(2);

  const kirchhoff::analytic::PinnedElastica love{1.0, 1.0, 1.0};
  const double P = j["derived"]["P"].get<double>();
  EXPECT_LT(relative(P, love.load()), 1e-9) << P << " vs 4 K(k)^2 = " << love.load();
  EXPECT_LT(relative(j["parameters"]["P"].get<double>(), love.load()), 1e-9);
  EXPECT_LT(relative(j["derived"]["y_max"].get<double>(), love.y_max()), 1e-6);
  EXPECT_LT(relative(j["derived"]["kappa_max"].get<double>(), love.kappa_max()), 1e-6);
  EXPECT_LT(relative(j["derived"]["end_to_end"].get<double>(), love.end_to_end()), 1e-8);

  ASSERT_TRUE(j.contains("invariants")) << j.dump(2);
  const json& H = j["invariants"]["H"];
  for (const char* key : {"mean", "min", "max", "spread"}) ASSERT_TRUE(H.contains(key) && H[key].is_number()) << key;
  EXPECT_LT(relative(H["mean"].get<double>(), love.hamiltonian(0.0)), 1e-8);
  EXPECT_LE(H["min"].get<double>(), H["max"].get<double>());
  EXPECT_LT(H["spread"].get<double>(), 1e-9 * std::abs(H["mean"].get<double>()));
  EXPECT_TRUE(j["invariants"].contains("m3"));
  EXPECT_TRUE(j["invariants"].contains("n_dot_m"));

  ASSERT_TRUE(j.contains("ends")) << j.dump(2);
  for (const char* end : {"start", "end"})
    for (const char* key : {"r", "n", "m"}) {
      ASSERT_TRUE(j["ends"].contains(end) && j["ends"][end].contains(key)) << end << "." << key;
      ASSERT_TRUE(j["ends"][end][key].is_array() && j["ends"][end][key].size() == 3) << end << "." << key;
    }
  // Pinned at the origin, roller on the x axis at the chord length, compressed by P.
  const json& start = j["ends"]["start"];
  const json& end = j["ends"]["end"];
  EXPECT_NEAR(start["r"][0].get<double>(), 0.0, 1e-12);
  EXPECT_NEAR(start["r"][1].get<double>(), 0.0, 1e-12);
  EXPECT_NEAR(end["r"][0].get<double>(), love.end_to_end(), 1e-8);
  EXPECT_NEAR(end["r"][1].get<double>(), 0.0, 1e-9);
  EXPECT_NEAR(end["n"][0].get<double>(), -P, 1e-9 * P);
  EXPECT_NEAR(end["m"][2].get<double>(), 0.0, 1e-9);
}

TEST_F(CliTest, SetChangesTheImposedSlope) {
  const CliRun r = run("solve " + quoted(case_path("simply_supported.toml")) + " --json --set theta0=2");
  ASSERT_EQ(r.status, 0) << r.err << r.out;
  const json j = parse(r);
  ASSERT_TRUE(j.contains("parameters") && j.contains("derived")) << r.out;
  EXPECT_EQ(j["parameters"]["theta0"].get<double>(), 2.0);
  const kirchhoff::analytic::PinnedElastica love{1.0, 1.0, 2.0};
  const double P = j["derived"]["P"].get<double>();
  EXPECT_LT(relative(P, love.load()), 1e-9) << P << " vs " << love.load();
  // Not the theta0 = 1 answer.
  EXPECT_GT(relative(P, kirchhoff::analytic::PinnedElastica{1.0, 1.0, 1.0}.load()), 0.1);
}

TEST_F(CliTest, SetScalesTheLoadWithStiffness) {
  const CliRun r = run("solve " + quoted(case_path("simply_supported.toml")) + " --json --set EI=2 --set P=25");
  ASSERT_EQ(r.status, 0) << r.err << r.out;
  const json j = parse(r);
  ASSERT_TRUE(j.contains("derived")) << r.out;
  const kirchhoff::analytic::PinnedElastica love{1.0, 2.0, 1.0};
  EXPECT_LT(relative(j["derived"]["P"].get<double>(), love.load()), 1e-9);
}

TEST_F(CliTest, HumanOutputListsDerivedQuantities) {
  const CliRun r = run("solve " + quoted(case_path("simply_supported.toml")));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("converged"));
  EXPECT_THAT(r.out, HasSubstr("P = "));
  EXPECT_THAT(r.out, HasSubstr("H = "));
  EXPECT_THAT(r.out, Not(HasSubstr("{")));  // not JSON
}

// ---- the profile CSV ---------------------------------------------------------------------

struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  std::string first_line;
};

Csv read_csv(const fs::path& path) {
  Csv csv;
  std::ifstream in(path);
  std::string line;
  if (!std::getline(in, line)) return csv;
  csv.first_line = line;
  {
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) csv.header.push_back(cell);
  }
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::vector<double> row;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) row.push_back(std::stod(cell));
    csv.rows.push_back(row);
  }
  return csv;
}

TEST_F(CliTest, ProfileCsv) {
  const fs::path csv_path = dir_ / "profile.csv";
  const CliRun r = run("solve " + quoted(case_path("simply_supported.toml")) + " --profile " + quoted(csv_path.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_TRUE(fs::exists(csv_path));
  const Csv csv = read_csv(csv_path);
  EXPECT_EQ(csv.first_line.rfind("s,x,y,z", 0), 0u) << csv.first_line;
  ASSERT_EQ(csv.rows.size(), 201u);
  for (const auto& row : csv.rows) ASSERT_EQ(row.size(), csv.header.size());

  const auto H_at = std::find(csv.header.begin(), csv.header.end(), "H");
  ASSERT_NE(H_at, csv.header.end()) << csv.first_line;
  const size_t H = static_cast<size_t>(H_at - csv.header.begin());
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& row : csv.rows) {
    lo = std::min(lo, row[H]);
    hi = std::max(hi, row[H]);
  }
  const kirchhoff::analytic::PinnedElastica love{1.0, 1.0, 1.0};
  EXPECT_LE(hi - lo, 1e-9 * std::max(std::abs(lo), std::abs(hi))) << lo << " .. " << hi;
  EXPECT_LT(relative(lo, love.hamiltonian(0.0)), 1e-8);

  // s runs over [0, L], the ends on the supports.
  EXPECT_EQ(csv.rows.front()[0], 0.0);
  EXPECT_NEAR(csv.rows.back()[0], 1.0, 1e-12);
  EXPECT_NEAR(csv.rows.front()[2], 0.0, 1e-12);
  EXPECT_NEAR(csv.rows.back()[2], 0.0, 1e-9);
  EXPECT_NEAR(csv.rows.back()[1], love.end_to_end(), 1e-8);
}

TEST_F(CliTest, ProfileSamplesFromCaseFile) {
  const std::string path = variant("simply_supported.toml", "[output]\n", "[output]\nsamples = 11\n");
  const fs::path csv_path = dir_ / "profile.csv";
  const CliRun r = run("solve " + quoted(path) + " --profile " + quoted(csv_path.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(read_csv(csv_path).rows.size(), 11u);
}

TEST_F(CliTest, UnwritableProfileIsRefused) {
  const fs::path csv_path = dir_ / "no_such_dir" / "profile.csv";
  const CliRun r = run("solve " + quoted(case_path("simply_supported.toml")) + " --profile " + quoted(csv_path.string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr(csv_path.string()));
}

// ---- solver failures ---------------------------------------------------------------------

TEST_F(CliTest, NotConvergedExitsOneWithStatus) {
  const std::string path = variant("simply_supported.toml", "unknowns = [\"P\"]",
                                   "unknowns = [\"P\"]\nmax_iterations = 1\nfallback_search = false");
  // One Newton step from the guess P = 12 cannot reach P = 11.22 at the file's theta0 = 1,
  // where the homotopy to 2.5 starts (nor P = 26.6 at 2.5 directly).
  const std::string args = "solve " + quoted(path) + " --set theta0=2.5";
  const CliRun human = run(args);
  EXPECT_EQ(human.status, 1) << human.out << human.err;
  EXPECT_THAT(human.err, HasSubstr("not converged"));
  EXPECT_THAT(human.err, HasSubstr(path));

  const CliRun r = run(args + " --json");
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_THAT(r.err, HasSubstr("not converged"));
  const json j = parse(r);
  ASSERT_TRUE(j.contains("status")) << r.out;
  EXPECT_NE(j["status"].get<std::string>(), "converged");
  EXPECT_TRUE(kFailureWords.count(j["status"].get<std::string>())) << j["status"];
  ASSERT_TRUE(j.contains("residual")) << r.out;
  EXPECT_TRUE(j["residual"].is_number()) << j["residual"];
  if (j["residual"].is_number()) EXPECT_GT(j["residual"].get<double>(), 1e-8);
  ASSERT_TRUE(j.contains("iterations")) << r.out;
  EXPECT_LE(j["iterations"].get<int>(), 1);
  EXPECT_EQ(j["parameters"]["theta0"].get<double>(), 2.5);
  // Why, in the JSON as on stderr, also where Newton gave no message of its own (out of
  // iterations: the message was empty, from a probe).
  const CliRun direct = run(args + " --json --direct");
  EXPECT_EQ(direct.status, 1) << direct.out << direct.err;
  EXPECT_THAT(parse(direct)["message"].get<std::string>(), HasSubstr("iterations, residual"));

  // The same copy converges with enough iterations: the failure above is the iteration cap.
  const std::string relaxed = variant("simply_supported.toml", "unknowns = [\"P\"]",
                                      "unknowns = [\"P\"]\nmax_iterations = 50\nfallback_search = false",
                                      "relaxed.toml");
  EXPECT_EQ(run("solve " + quoted(relaxed) + " --set theta0=2.5").status, 0);
}

// The documented stepper gives the same Elastica as the default one (it gave P = nan, y_max =
// 0.0042, exit 0): Love's P = 11.2224184758 for theta0 = 1 (eq. 54), to the 1e-9 the residual and
// the integrator tolerance 1e-12 leave.
// The straight Euler column at P = 50 lies above the Euler loads pi^2 and 4 pi^2: index 2; the
// conjugate points of its load-controlled problem are the zeros of cos(sqrt(P) s).
TEST_F(CliTest, SolveReportsTheStabilityIndex) {
  const CliRun r = run("solve " + quoted(case_path("euler_column.toml")) + " --set P=50 --set theta_guess=0 --json");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const json st = parse(r)["stability"];
  EXPECT_EQ(st["index"], 2);
  EXPECT_EQ(st["stable"], false);
  EXPECT_EQ(st["zero_modes"], 0);
  EXPECT_EQ(st["method"], "conjugate_points");
  ASSERT_EQ(st["conjugate_points"].size(), 2u);
  EXPECT_NEAR(st["conjugate_points"][0].get<double>(), M_PI / (2 * std::sqrt(50.0)), 1e-5);
  // The planar cross-check (discretised energy, 400 elements) agrees, and its lowest eigenvalue
  // is pi^2 - 50 to its O(h^2) discretisation error (pi^4 h^2 / 12 = 5e-5 here).
  EXPECT_EQ(st["cross_check"]["agrees"], true);
  EXPECT_NEAR(st["lowest_eigenvalues"][0].get<double>(), M_PI * M_PI - 50.0, 1e-4);
  const CliRun text = run("solve " + quoted(case_path("euler_column.toml")) + " --set P=50 --set theta_guess=0");
  EXPECT_NE(text.out.find("unstable (index 2)"), std::string::npos) << text.out;
  // A sliding length (sleeve.toml): the discretised energy's check, with ell among its unknowns,
  // agrees, and its d^2 E*/d ell^2 is the conjugate-point method's S to its O(h^2) error at 400
  // elements (measured 0.029 of S = -565.5: 5e-5 relative; 1e-4 leaves a factor two).
  const CliRun sleeve = run("solve " + quoted(case_path("sleeve.toml")) + " --json");
  ASSERT_EQ(sleeve.status, 0) << sleeve.out << sleeve.err;
  const json sliding = parse(sleeve)["stability"];
  EXPECT_EQ(sliding["index"], 1);
  EXPECT_EQ(sliding["cross_check"]["index"], 1);
  EXPECT_EQ(sliding["cross_check"]["agrees"], true);
  const double S = sliding["reduced_energy_curvature"].get<double>();
  EXPECT_NEAR(sliding["cross_check"]["reduced_energy_curvature"].get<double>(), S, 1e-4 * std::abs(S));
  // Where the index is not defined it is null, with the reason: never a guessed number.
  const CliRun couple = run("solve " + quoted(case_path("reissner.toml")) + " --json");
  ASSERT_EQ(couple.status, 0) << couple.out << couple.err;
  const json undefined = parse(couple)["stability"];
  EXPECT_TRUE(undefined["index"].is_null());
  EXPECT_TRUE(undefined["stable"].is_null());
  EXPECT_TRUE(undefined["zero_modes"].is_null());  // was 0 (from a probe); continue's CSV leaves both empty
  EXPECT_NE(undefined["reason"].get<std::string>().find("not conservative"), std::string::npos);
}

// A pinned column on a stiff Winkler foundation k (a soft wall b / (a - y) balanced by a uniform
// weight b / a^2 towards it: the straight rod is an equilibrium and the foundation's stiffness is
// 2 b / a^3 = k). Its sine modes diagonalise the second variation: eigenvalues (j pi)^2 + k /
// (j pi)^2 - P per int theta'^2, the lowest at j = 10 for k = 1e6, 800.2 at P = 1200 (stable). The
// field's stiffness leaves the held end's lateral position changed by 7e-9 per unit field, below
// the conjugate points' absolute zero tolerance, which then call the constraint degenerate; the
// discretised energy, having passed its own tests, decides the index and is reported as the method.
TEST_F(CliTest, TheDiscretisedEnergyDecidesWhereTheConjugatePointsDoNot) {
  const std::string path = (dir_ / "foundation.toml").string();
  std::ofstream(path) << kirchhoff::testing::foundation_column_case(1200.0, 1e6);
  const CliRun r = run("solve " + quoted(path) + " --direct --json");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const json st = parse(r)["stability"];
  EXPECT_EQ(st["index"], 0);
  EXPECT_EQ(st["stable"], true);
  EXPECT_EQ(st["method"], "discretised_energy");
  EXPECT_NE(st["method_reason"].get<std::string>().find("degenerate constraint"), std::string::npos);
  EXPECT_TRUE(st["cross_check"]["agrees"].is_null());  // its own index: no agreement to claim
  const double lowest = kirchhoff::testing::foundation_column_critical_load(10, 1e6) - 1200.0;  // 800.17
  // The discretisation's O(h^2) error at 400 elements on the mode of wavenumber 10 pi, about
  // (10 pi / 400)^2 / 12 = 5e-4 of its terms of ~1000 each (measured 1.55): 5 leaves a factor 3.
  EXPECT_NEAR(st["lowest_eigenvalues"][0].get<double>(), lowest, 5.0);
  const CliRun text = run("solve " + quoted(path) + " --direct");
  EXPECT_NE(text.out.find("stable (by the discretised energy"), std::string::npos) << text.out;
}

TEST_F(CliTest, Dopri5StepperGivesTheElastica) {
  // (Marched: the Elastica's closed-form flow would take no steps of either stepper.)
  const std::string path =
      variant("simply_supported.toml", "[solver]", "[solver]\nstepper = \"dopri5\"\nclosed_form = false");
  const CliRun r = run("solve " + quoted(path) + " --json");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const json j = parse(r);
  EXPECT_EQ(j["status"], "converged");
  EXPECT_NEAR(j["derived"]["P"].get<double>(), 11.2224184758, 1e-8);
  EXPECT_NEAR(j["derived"]["y_max"].get<double>(), 0.286225241775, 1e-8);
}

// A solve that cannot converge (theta0 = 1e6, its flows marched, spends ~35 s in Newton and the
// NLopt search; in closed form it converges to a high mode in milliseconds) ends at its
// wall-clock limit with status time_limit, exit 1, the best residual reported.
TEST_F(CliTest, MaxSecondsEndsASolveWithTimeLimit) {
  const auto start = std::chrono::steady_clock::now();
  const CliRun r = run("solve " + quoted(case_path("simply_supported.toml")) +
                       " --set theta0=1e6 --solver closed_form=false --max-seconds 1 --json --direct");
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  const json j = parse(r);
  EXPECT_EQ(j["status"], "time_limit") << r.out;
  EXPECT_TRUE(j["residual"].is_number());
  EXPECT_LT(elapsed, 20.0);  // the limit plus one evaluation, with a wide margin for a loaded machine
  EXPECT_EQ(run("solve " + quoted(case_path("simply_supported.toml")) + " --max-seconds -1").status, 2);
  // The library's checks, with Python's words (EquilibriaOptions::validate).
  const CliRun equilibria = run("equilibria " + quoted(case_path("clamped_clamped.toml")) + " --max-seconds -1");
  EXPECT_EQ(equilibria.status, 2);
  EXPECT_THAT(equilibria.err, HasSubstr("max_seconds must be in [0, 1e9]"));
  // By homotopy the branch approaches the closed loop at theta0 = pi (P -> infinity), where its
  // steps shrink: the path ends there at the limit or with its step too small, whichever comes
  // first, says where it got to, and reports no residual at 1e6 (none was computed).
  const auto path_start = std::chrono::steady_clock::now();
  const CliRun path = run("solve " + quoted(case_path("simply_supported.toml")) + " --set theta0=1e6 --max-seconds 1 --json");
  const double path_elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - path_start).count();
  EXPECT_EQ(path.status, 1) << path.out << path.err;
  const json k = parse(path);
  const std::string stop = k["status"].get<std::string>();
  EXPECT_TRUE(stop == "time_limit" || stop == "step_too_small") << path.out;
  EXPECT_EQ(k["path"]["stop"], stop);
  EXPECT_TRUE(k["residual"].is_null());
  EXPECT_LT(k["path"]["reached"]["theta0"].get<double>(), M_PI);
  EXPECT_GT(k["path"]["reached"]["theta0"].get<double>(), 3.0);
  EXPECT_LT(path_elapsed, 20.0);
}

// The soft wall at a range 1e-20 once converged with the rod beyond the wall (gap < 0, exit 0).
TEST_F(CliTest, RodBeyondItsSoftWallIsNotConverged) {
  // Directly: Newton converges beyond the wall and the check refuses it. (By homotopy the path
  // stalls as the wall stiffens, step_too_small, also exit 1.)
  const CliRun r = run("solve " + quoted(case_path("soft_wall.toml")) + " --set log_b=-20 --json --direct");
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  const json j = parse(r);
  EXPECT_EQ(j["status"], "check_failed") << r.out;
  EXPECT_THAT(j["message"].get<std::string>(), HasSubstr("soft wall"));
}

// An end imposed inside an obstacle: the status word Python's solve() also gives (one library
// solve behind both), exit 1, no iterate and so no residual.
TEST_F(CliTest, EndImposedInsideAnObstacleIsInfeasible) {
  const CliRun r = run("solve " + quoted(case_path("wall.toml")) + " --set a=-0.01 --json --direct");
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  const json j = parse(r);
  EXPECT_EQ(j["status"], "infeasible") << r.out;
  EXPECT_EQ(j["iterations"], 0);
  EXPECT_TRUE(j["residual"].is_null());
  EXPECT_EQ(j["path"]["method"], "direct");
  EXPECT_THAT(j["message"].get<std::string>(), HasSubstr("inside obstacle 'wall'"));
  EXPECT_THAT(r.err, HasSubstr("infeasible: the rod's start is imposed inside obstacle"));
}

// A cases folder without the case files reproduce reads is bad input (exit 2), as Python's
// CaseError; it was reported as a failed computation (exit 1).
TEST_F(CliTest, ReproduceWithoutItsCaseFilesIsBadInput) {
  const CliRun r = run("reproduce --cases " + quoted(dir_.string()) + " --out " + quoted((dir_ / "out").string()));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_THAT(r.err, HasSubstr("cannot open the file"));
}

TEST_F(CliTest, IpoptSeedSolvesWhatTheGuessCannot) {
  const std::string args = "solve " + quoted(case_path("cavity.toml")) + " --set Delta=0.05";
  const CliRun plain = run(args + " --direct");
  EXPECT_EQ(plain.status, 1) << plain.err;  // from the free arch: not converged
  const CliRun seeded = run(args + " --seed ipopt --json");
  EXPECT_EQ(seeded.status, 0) << seeded.err;
  EXPECT_THAT(seeded.err, HasSubstr("seed: Ipopt on 200 segments"));
  const json j = parse(seeded);
  EXPECT_EQ(j["status"], "converged");
  ASSERT_EQ(j["contacts"].size(), 1u);
  const json& contact = j["contacts"][0];
  EXPECT_EQ(contact["obstacle_name"], "upper wall");
  EXPECT_FALSE(contact["extended"].get<bool>());
  EXPECT_EQ(contact["s_end"].get<double>(), contact["s"].get<double>());
  EXPECT_EQ(contact["force_end"].get<double>(), 0.0);
  // H on both sides of the contact: the same (section 6.3), and the rod's H.
  const double H = j["derived"]["H"].get<double>();
  EXPECT_NEAR(contact["H_before"].get<double>(), H, 1e-9 * std::abs(H));
  EXPECT_NEAR(contact["H_after"].get<double>(), H, 1e-9 * std::abs(H));
  // A spatial case is refused with the reason; a bad segment count by the parser.
  const CliRun spatial = run("solve " + quoted(case_path("twisted_ribbon_pole.toml")) + " --seed ipopt");
  EXPECT_EQ(spatial.status, 2);
  EXPECT_THAT(spatial.err, HasSubstr("the case is spatial"));
  EXPECT_EQ(run(args + " --seed ipopt --seed-segments 2").status, 2);
  EXPECT_EQ(run(args + " --seed ipop").status, 2);
  // A continuation starts from the seed as well.
  const std::string csv = (dir_ / "cavity.csv").string();
  const CliRun branch = run("continue " + quoted(case_path("cavity.toml")) +
                            " --param Delta --set Delta=0.05 --to 0.06 --seed ipopt --out " + quoted(csv));
  EXPECT_EQ(branch.status, 0) << branch.err;
  EXPECT_THAT(branch.err, HasSubstr("seed: Ipopt"));
  EXPECT_THAT(branch.err, HasSubstr("reached_target"));
  const CliRun unseeded = run("continue " + quoted(case_path("cavity.toml")) + " --param Delta --set Delta=0.05 --to 0.06 --out " +
                              quoted((dir_ / "unseeded.csv").string()));
  EXPECT_EQ(unseeded.status, 1) << unseeded.err;  // no admissible starting point from the guess
}

TEST_F(CliTest, AxialPhaseConditionOnTheStraightTwistedRodIsNotConverged) {
  // At the straight guess the axial phase condition is degenerate: the solver must not claim
  // an isolated solution there.
  const CliRun r =
      run("solve " + quoted(case_path("twisted_clamped.toml")) + " --set phi=12 --phase-condition axial --json");
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  const json j = parse(r);
  ASSERT_TRUE(j.contains("status")) << r.out;
  EXPECT_NE(j["status"].get<std::string>(), "converged");
}

// ---- input refused -----------------------------------------------------------------------

TEST_F(CliTest, BadCaseFileExitsTwoNamingFileAndKey) {
  const std::string path = variant("simply_supported.toml", "length = \"L\"", "lenght = \"L\"");
  for (const char* command : {"solve", "check"}) {
    SCOPED_TRACE(command);
    const CliRun r = run(std::string(command) + " " + quoted(path));
    EXPECT_EQ(r.status, 2);
    EXPECT_THAT(r.err, HasSubstr(path));
    EXPECT_THAT(r.err, HasSubstr("rod.lenght"));
    EXPECT_THAT(r.err, HasSubstr("unknown key"));
  }
  const CliRun j = run("solve " + quoted(path) + " --json");
  EXPECT_EQ(j.status, 2);
  EXPECT_THAT(j.out, Not(HasSubstr("converged")));
}

TEST_F(CliTest, BadOverridesExitTwo) {
  const std::string path = case_path("simply_supported.toml");
  const CliRun unknown = run("solve " + quoted(path) + " --set Q=1");
  EXPECT_EQ(unknown.status, 2);
  EXPECT_THAT(unknown.err, HasSubstr(path));
  EXPECT_THAT(unknown.err, HasSubstr("Q"));

  const CliRun not_number = run("solve " + quoted(path) + " --set P=abc");
  EXPECT_EQ(not_number.status, 2);
  EXPECT_THAT(not_number.err, HasSubstr("--set"));
  EXPECT_THAT(not_number.err, HasSubstr("abc"));

  const CliRun no_equals = run("solve " + quoted(path) + " --set noequals");
  EXPECT_EQ(no_equals.status, 2);
  EXPECT_THAT(no_equals.err, HasSubstr("noequals"));

  const CliRun check = run("check " + quoted(path) + " --set Q=1");
  EXPECT_EQ(check.status, 2);
  EXPECT_THAT(check.err, HasSubstr("Q"));
}

TEST_F(CliTest, NonFiniteOverrideExitsTwo) {
  // A NaN parameter is bad input, not a solver failure.
  // Refused by the library when the case is loaded, in the words Python's load_case gives for the
  // same value (python_bindings_test.py), for every command that takes --set.
  for (const char* command : {"solve", "check", "equilibria"}) {
    const CliRun r = run(std::string(command) + " " + quoted(case_path("simply_supported.toml")) + " --set theta0=nan");
    EXPECT_EQ(r.status, 2) << command << ": " << r.err;
    EXPECT_THAT(r.err, HasSubstr("simply_supported.toml: --set theta0: nan is not a finite number with magnitude <= 1e+100"))
        << command;
  }
  const CliRun overflow = run("solve " + quoted(case_path("simply_supported.toml")) + " --set theta0=1e400");
  EXPECT_EQ(overflow.status, 2) << overflow.err;
  EXPECT_THAT(overflow.err, HasSubstr("--set theta0: inf is not a finite number"));
}

// The wall's clamps at y = 0 below a wall moved to y = a = -0.1 lie inside it: `check` said "ok",
// `solve` reported the fold its homotopy met on the way, `equilibria` "seeds exhausted". Now
// check refuses it (exit 2), and solve and equilibria stop at once as infeasible (exit 1).
TEST_F(CliTest, AnEndImposedInsideAnObstacleIsNamed) {
  const std::string wall = quoted(case_path("wall.toml")) + " --set a=-0.1";
  const CliRun check = run("check " + wall);
  EXPECT_EQ(check.status, 2) << check.out;
  EXPECT_THAT(check.err, HasSubstr("is imposed inside obstacle 'wall'"));
  for (const char* command : {"solve", "equilibria"}) {
    const CliRun r = run(std::string(command) + " " + wall);
    EXPECT_EQ(r.status, 1) << command << ": " << r.err;
    EXPECT_THAT(r.out + r.err, HasSubstr("infeasible")) << command;
    EXPECT_THAT(r.out + r.err, HasSubstr("inside obstacle 'wall'")) << command;
  }
}

TEST_F(CliTest, UnknownVariableInExpressionExitsTwo) {
  // Must be refused as input (exit 2, naming the key), not abort the program.
  for (const auto& [from, to, key] : {std::tuple<std::string, std::string, std::string>{"length = \"L\"", "length = \"Q\"", "rod.length"},
                                      {"force = [\"-P\", 0]         # internal", "force = [\"-Q\", 0] #", "guess.force"}}) {
    SCOPED_TRACE(to);
    const std::string path = variant("simply_supported.toml", from, to);
    for (const char* command : {"solve", "check"}) {
      SCOPED_TRACE(command);
      const CliRun r = run(std::string(command) + " " + quoted(path));
      EXPECT_EQ(r.status, 2) << r.err;
      EXPECT_THAT(r.err, HasSubstr(path));
      EXPECT_THAT(r.err, HasSubstr(key));
    }
  }
}

// A parameter computed from another ([parameters] EI = "pi*r^2"): the JSON shows it at its
// computed value, the solution is the Elastica of that stiffness, and --set of it is refused.
TEST_F(CliTest, ComputedParameterFollowsItsInputAndCannotBeSet) {
  const std::string path = variant("simply_supported.toml", "EI = 1.0", "r = 0.5\nEI = \"pi*r^2\"");
  const CliRun r = run("solve " + quoted(path) + " --json --set r=0.6");
  ASSERT_EQ(r.status, 0) << r.err << r.out;
  const json j = parse(r);
  const double EI = M_PI * 0.36;
  EXPECT_NEAR(j["parameters"]["EI"].get<double>(), EI, 1e-15 * EI);
  EXPECT_EQ(j["parameters"]["r"].get<double>(), 0.6);
  const kirchhoff::analytic::PinnedElastica love{1.0, EI, 1.0};
  EXPECT_LT(relative(j["derived"]["P"].get<double>(), love.load()), 1e-9);  // Newton's 1e-10, as above

  for (const char* command : {"solve", "check"}) {
    SCOPED_TRACE(command);
    const CliRun refused = run(std::string(command) + " " + quoted(path) + " --set EI=2");
    EXPECT_EQ(refused.status, 2) << refused.err;
    EXPECT_THAT(refused.err, HasSubstr(path + ": --set EI: EI is computed from r"));
    EXPECT_THAT(refused.err, HasSubstr("set r instead"));
  }
}

TEST_F(CliTest, MissingFileAndBadOptionsExitTwo) {
  const std::string missing = (dir_ / "missing.toml").string();
  const CliRun r = run("solve " + quoted(missing));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr(missing));
  EXPECT_EQ(run("check " + quoted(missing)).status, 2);
  EXPECT_EQ(run("solve " + quoted(case_path("twisted_clamped.toml")) + " --phase-condition radial").status, 2);
  EXPECT_EQ(run("solve " + quoted(case_path("simply_supported.toml")) + " --no-such-flag").status, 2);
  // 'axial' on a planar rod is refused by the loader.
  const CliRun planar = run("solve " + quoted(case_path("simply_supported.toml")) + " --phase-condition axial");
  EXPECT_EQ(planar.status, 2);
  EXPECT_THAT(planar.err, HasSubstr("phase_condition"));
}

// ---- check -------------------------------------------------------------------------------

TEST_F(CliTest, CheckAcceptsEveryShippedCase) {
  int seen = 0;
  for (const auto& entry : fs::directory_iterator(kCases)) {
    if (entry.path().extension() != ".toml") continue;
    ++seen;
    const std::string path = entry.path().string();
    SCOPED_TRACE(path);
    const CliRun r = run("check " + quoted(path));
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_THAT(r.out, HasSubstr(path + ": ok"));
    EXPECT_TRUE(r.err.empty()) << r.err;
  }
  EXPECT_GE(seen, 6);
}

TEST_F(CliTest, CheckRefusesBadFile) {
  const std::string path = variant("tapered.toml", "B = \"EI0*(1 + taper*s/L)\"", "B = \"EI0*(1 - 2*taper*s/L)\"");
  const CliRun r = run("check " + quoted(path));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr(path));
  EXPECT_THAT(r.err, HasSubstr("rod.B"));
  EXPECT_THAT(r.err, HasSubstr("stiffness must be > 0"));
  EXPECT_THAT(r.out, Not(HasSubstr("ok")));
}

// --solver KEY=VALUE overrides [solver] keys for every command that loads a case, checked as the
// file's value is, the message naming the option.
TEST_F(CliTest, SolverSettingsFromTheCommandLine) {
  const std::string ss = quoted(case_path("simply_supported.toml"));
  const CliRun r = run("solve " + ss + " --json --solver tolerance=1e-11 --solver stepper=dopri5");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_LT(parse(r)["residual"].get<double>(), 1e-11);
  const std::string out = " --out " + quoted((dir_ / "b.csv").string());
  for (const std::string command : {"solve " + ss, "check " + ss, "continue " + ss + " --param theta0 --to 1.1" + out,
                                    "vibrate " + ss, "equilibria " + ss}) {
    SCOPED_TRACE(command);
    const CliRun bad = run(command + " --solver tolerance=1");
    EXPECT_EQ(bad.status, 2) << bad.err;
    EXPECT_THAT(bad.err, HasSubstr("--solver tolerance=1: key 'solver.tolerance': must be in (0, 0.01]"));
  }
  const CliRun typo = run("check " + ss + " --solver tolernace=1e-9");
  EXPECT_EQ(typo.status, 2);
  EXPECT_THAT(typo.err, HasSubstr("key 'solver.tolernace': unknown key"));
  EXPECT_EQ(run("check " + ss + " --solver tolerance").status, 2);
}

// Where the conjugate points leave the index undefined (here a chord held nearly degenerate:
// the clamped ends 1e-5 apart, docs/stability.md) and the discretised energy's check passed its
// own tests, the index is the check's, and the output says so and why (the symmetric loop is
// stable for D > 0).
TEST_F(CliTest, UndefinedIndexShowsTheDiscretisedCheck) {
  const CliRun r = run("solve " + quoted(case_path("clamped_clamped.toml")) + " --set D=1e-5");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("stable (by the discretised energy: the conjugate points do not decide it: a "
                               "degenerate constraint"));
  const json st = parse(run("solve " + quoted(case_path("clamped_clamped.toml")) + " --set D=1e-5 --json"))["stability"];
  EXPECT_EQ(st["index"], 0);
  EXPECT_EQ(st["method"], "discretised_energy");
}

// --to at the starting value would never be crossed (the run marched off to its point budget):
// exit 2 saying so, and no CSV (python_bindings_test.py expects the same text).
TEST_F(CliTest, TargetAtTheStartingValueIsRefused) {
  const fs::path csv = dir_ / "b.csv";
  const CliRun r = run("continue " + quoted(case_path("euler_column.toml")) + " --param P --to 12 --out " +
                       quoted(csv.string()));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_THAT(r.err, HasSubstr("--to 12 is P's starting value: nothing to continue"));
  EXPECT_FALSE(fs::exists(csv));
}

// --to nan was taken for no target (NaN is the engine's "none"), --to inf and 1e300 as targets
// never reached: each run marched to its point budget with exit 0 (a probe). A --to is now
// finite and within +-1e100, as every number a case holds; Python's to= is the same request.
TEST_F(CliTest, TargetThatIsNotAFiniteNumberIsRefused) {
  for (const char* to : {"nan", "inf", "-inf", "1e300"}) {
    SCOPED_TRACE(to);
    const fs::path csv = dir_ / "b.csv";
    const CliRun r = run("continue " + quoted(case_path("euler_column.toml")) + " --param P --to " + to + " --out " +
                         quoted(csv.string()));
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_THAT(r.err, HasSubstr("--to must be a finite number within +-1e100"));
    EXPECT_FALSE(fs::exists(csv));
  }
}

// --side is 1 or -1 and picks a side of a switched branch: 0, 2, 0.5 and nan ran the +1 side with
// exit 0, and --side -1 without --switch-at-bp was ignored (from a probe).
TEST_F(CliTest, SideThatIsNotOneOrMinusOneIsRefused) {
  const std::string head = "continue " + quoted(case_path("euler_column.toml")) + " --param P --to 12 --set P=1";
  for (const char* side : {"0", "2", "0.5", "nan", "-0.001"}) {
    SCOPED_TRACE(side);
    const fs::path csv = dir_ / "b.csv";
    const CliRun r = run(head + " --switch-at-bp 1 --side " + side + " --out " + quoted(csv.string()));
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_THAT(r.err, HasSubstr("--side must be 1 or -1"));
    EXPECT_FALSE(fs::exists(csv));
  }
  const CliRun r = run(head + " --side -1 --out " + quoted((dir_ / "b.csv").string()));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_THAT(r.err, HasSubstr("it needs --switch-at-bp K"));
}

// continue in a computed parameter: exit 2 naming the one to continue in.
TEST_F(CliTest, ContinueInAComputedParameterIsRefused) {
  const std::string path = variant("simply_supported.toml", "EI = 1.0", "r = 0.5\nEI = \"pi*r^2\"");
  const CliRun r = run("continue " + quoted(path) + " --param EI --to 2 --out " + quoted((dir_ / "b.csv").string()));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_THAT(r.err, HasSubstr("--param EI: EI is computed from r"));
  EXPECT_THAT(r.err, HasSubstr("continue in r instead"));
}

// solve --profile: a planar rod's curvature column is kappa.
TEST_F(CliTest, PlanarProfileHasKappa) {
  const fs::path csv = dir_ / "p.csv";
  ASSERT_EQ(run("solve " + quoted(case_path("euler_column.toml")) + " --profile " + quoted(csv.string())).status, 0);
  const Csv c = read_csv(csv);
  EXPECT_THAT(c.first_line, HasSubstr(",mz,kappa,H,"));
}

}  // namespace
