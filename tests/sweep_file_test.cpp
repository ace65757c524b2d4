// Sweep files (sweep.hpp): expansion of grids, lists, ranges and log ranges into jobs with
// deterministic ids, and errors that name the file, the line, the key and the reason.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "kirchhoff/sweeps/sweep.hpp"

namespace kirchhoff {
namespace {

const std::string kCases = KIRCHHOFF_CASES_DIR;

std::string error_of(const std::string& text) {
  try {
    load_sweep_text(text, "bad.toml");
  } catch (const SweepError& e) {
    return e.what();
  }
  return "";
}

std::string head() { return "case = \"" + kCases + "/simply_supported.toml\"\n"; }

TEST(SweepFile, GridExpandsFirstKeySlowestWithRangesAndLogRanges) {
  const SweepSpec spec = load_sweep_text(head() +
                                             "[[jobs]]\nname = \"g\"\nkind = \"solve\"\n"
                                             "grid = { theta0 = [1, 2], P = { from = 1, to = 100, count = 3, log = true } }\n"
                                             "[[jobs]]\nkind = \"equilibria\"\nlist = [{ theta0 = 0.5 }, { theta0 = 0.25 }]\n",
                                         "sweep.toml");
  ASSERT_EQ(spec.jobs.size(), 8u);
  EXPECT_EQ(spec.jobs[0].id, "g-001");
  EXPECT_EQ(spec.jobs[5].id, "g-006");
  EXPECT_EQ(spec.jobs[6].id, "equilibria-001");
  EXPECT_EQ(spec.jobs[6].kind, SweepJobKind::Equilibria);
  EXPECT_EQ(spec.parameter_columns, (std::vector<std::string>{"theta0", "P"}));
  // theta0 slowest; P = 1, 10, 100 (log: the ends exactly, 10 to rounding).
  EXPECT_EQ(spec.jobs[2].values[0].second, 1.0);
  EXPECT_EQ(spec.jobs[3].values[0].second, 2.0);
  EXPECT_EQ(spec.jobs[0].values[1].second, 1.0);
  EXPECT_NEAR(spec.jobs[1].values[1].second, 10.0, 1e-13);
  EXPECT_EQ(spec.jobs[2].values[1].second, 100.0);
  EXPECT_GT(spec.jobs[6].cost, spec.jobs[0].cost);  // searches are handed out before solves
  EXPECT_EQ(spec.jobs[7].values[0].second, 0.25);
}

// A linear range's interior values are the decimals meant: -0.5 .. 0.7 in three is 0.1, which
// from + (to - from) / 2 misses by an ulp (0.09999999999999998, in index.csv and every output).
TEST(SweepFile, LinearRangesRunTheDecimalsMeant) {
  const SweepSpec spec = load_sweep_text(
      head() + "[[jobs]]\nname = \"a\"\nkind = \"solve\"\ngrid = { theta0 = { from = -0.5, to = 0.7, count = 3 } }\n"
               "[[jobs]]\nname = \"b\"\nkind = \"solve\"\ngrid = { theta0 = { from = -0.7, to = 0.5, count = 7 } }\n",
      "sweep.toml");
  ASSERT_EQ(spec.jobs.size(), 10u);
  EXPECT_EQ(spec.jobs[1].values[0].second, 0.1);
  const double meant[] = {-0.7, -0.5, -0.3, -0.1, 0.1, 0.3, 0.5};
  for (int k = 0; k < 7; ++k) EXPECT_EQ(spec.jobs[3 + k].values[0].second, meant[k]) << k;
}

// A name that is another table's job id ("x-001" beside "x" of two points): one folder and row
// stood for two jobs, the second's result under the first's values, and --resume refused the file
// (a probe's). Refused up front, at the name.
TEST(SweepFile, AJobIdMadeTwiceIsRefused) {
  const std::string text = head() +
                           "[[jobs]]\nname = \"x\"\nkind = \"solve\"\nlist = [{ theta0 = 1 }, { theta0 = 2 }]\n"
                           "[[jobs]]\nname = \"x-001\"\nkind = \"solve\"\n";
  EXPECT_EQ(error_of(text).rfind("bad.toml:7: key 'jobs[2].name': its job id 'x-001' is another table's job id too", 0), 0u)
      << error_of(text);
}

// The file's own `set` and `solver` are named where they are refused (a probe's: both were
// reported at line 1, key 'case').
TEST(SweepFile, TheFilesSetAndSolverAreNamedWhereTheyAreRefused) {
  const std::string job = "[[jobs]]\nkind = \"solve\"\n";
  EXPECT_EQ(error_of(head() + "set = { Q = 1 }\n" + job),
            "bad.toml:2: key 'set.Q': no parameter 'Q' in " + kCases + "/simply_supported.toml (have: theta0, L, EI, P)");
  EXPECT_EQ(error_of(head() + "solver = { tolerence = 1e-3 }\n" + job).rfind("bad.toml:2: key 'solver'", 0), 0u)
      << error_of(head() + "solver = { tolerence = 1e-3 }\n" + job);
  EXPECT_EQ(error_of(head() + job + "set = { Q = 1 }\n").rfind("bad.toml:4: key 'jobs[1].set.Q'", 0), 0u)
      << error_of(head() + job + "set = { Q = 1 }\n");
}

// A continue job's steps that `continue` would refuse are refused with the file (a probe's
// min_step = 1, max_step = 0.1 ran and became a bad_input row, exit 0).
TEST(SweepFile, AContinueJobsStepsAreCheckedWithTheFile) {
  const std::string text = head() +
                           "[[jobs]]\nkind = \"continue\"\nparam = \"theta0\"\nto = 1.5\nmin_step = 1\nmax_step = 0.1\n";
  EXPECT_EQ(error_of(text).rfind("bad.toml:6: key 'jobs[1].min_step': min_step (1) must not exceed max_step (0.1)", 0), 0u)
      << error_of(text);
}

TEST(SweepFile, ErrorsNameFileLineKeyAndReason) {
  EXPECT_EQ(error_of(head() + "[[jobs]]\nkind = \"solve\"\ngrid = { theta0 = [1, 2], thetaX = 3 }\n"),
            "bad.toml:4: key 'jobs[1].grid.thetaX': no parameter 'thetaX' in " + kCases +
                "/simply_supported.toml (have: theta0, L, EI, P)");
  EXPECT_EQ(error_of(head() + "[[jobs]]\nkind = \"solve\"\nfoo = 1\n").rfind("bad.toml:4: key 'jobs[1].foo': unknown key", 0),
            0u);
  EXPECT_EQ(error_of(head() + "[[jobs]]\nkind = \"solve\"\ngrid = { theta0 = { from = 1, to = 2 } }\n"),
            "bad.toml:4: key 'jobs[1].grid.theta0': a range needs from, to and count (count is missing)");
  EXPECT_EQ(error_of(head() + "[[jobs]]\nkind = \"solve\"\ngrid = { theta0 = { from = 0, to = 2, count = 3, log = true } }\n"),
            "bad.toml:4: key 'jobs[1].grid.theta0': a log range needs from > 0 and to > 0");
  EXPECT_EQ(error_of(head() + "[[jobs]]\nkind = \"solve\"\ngrid = { theta0 = \"1\" }\n"),
            "bad.toml:4: key 'jobs[1].grid.theta0': must be a number, got a string");
  EXPECT_EQ(error_of(head() + "[[jobs]]\nkind = \"solve\"\n[[jobs]]\nkind = \"solve\"\n")
                .find("'solve' names another [[jobs]] table too"),
            error_of(head() + "[[jobs]]\nkind = \"solve\"\n[[jobs]]\nkind = \"solve\"\n").find("'solve' names"));
  EXPECT_NE(error_of(head() + "[[jobs]]\nkind = \"solve\"\n[[jobs]]\nkind = \"solve\"\n").find("bad.toml:4: key 'jobs[2].name'"),
            std::string::npos);
  EXPECT_EQ(error_of(head() + "[[jobs]]\nkind = \"solv\"\n"),
            "bad.toml:3: key 'jobs[1].kind': unknown job kind 'solv' (expected one of: solve, equilibria, continue, "
            "plectonemes)");
  EXPECT_EQ(error_of(head() + "[[jobs]]\nkind = \"solve\"\nmax_equilibria = 3\n"),
            "bad.toml:4: key 'jobs[1].max_equilibria': only equilibria jobs take it");
  EXPECT_EQ(error_of(head() + "[[jobs]]\nkind = \"solve\"\nset = { nope = 1 }\n")
                .rfind("bad.toml:4: key 'jobs[1].set.nope': no parameter 'nope'", 0),
            0u);
  EXPECT_EQ(error_of(head() + "[[jobs]]\nkind = \"continue\"\n"),
            "bad.toml:2: key 'jobs[1].param': missing: the parameter a continue job follows its branch in");
  EXPECT_EQ(error_of(head() + "[[jobs]]\nkind = \"continue\"\nparam = \"Q\"\n"),
            "bad.toml:4: key 'jobs[1].param': no parameter 'Q' in " + kCases + "/simply_supported.toml");
  EXPECT_EQ(error_of(head() + "[[jobs]]\nkind = \"solve\"\nparam = \"P\"\n"),
            "bad.toml:4: key 'jobs[1].param': only continue jobs take it");
  EXPECT_EQ(error_of(head() + "[[jobs]]\nkind = \"plectonemes\"\nlist = [{ P = 1 }]\n"),
            "bad.toml:2: key 'jobs[1]': a plectonemes job needs 'slenderness' in its grid or list (the branch's L/2R "
            "and its largest turns)");
  EXPECT_EQ(error_of(head() + "[[jobs]]\nkind = \"solve\"\nfrom_ply = 500\n"),
            "bad.toml:4: key 'jobs[1].from_ply': only plectonemes jobs take it");
  EXPECT_EQ(error_of("[[jobs]]\nkind = \"solve\"\n"),
            "bad.toml:1: key 'jobs[1].case': no case: give `case` at the top or in the [[jobs]] table");
  EXPECT_EQ(error_of(head()), "bad.toml: key 'jobs': no [[jobs]] tables: nothing to run");
  EXPECT_EQ(error_of("case = [\n").rfind("bad.toml: TOML syntax error: ", 0), 0u);
}

// Sweep files are read by the case files' reader (toml_reader.hpp): numbers, integers and types
// are refused in the case files' words, with values shown to 15 digits.
TEST(SweepFile, ValuesAreRefusedInTheCaseFilesWords) {
  const std::string job = head() + "[[jobs]]\nkind = \"solve\"\n";
  EXPECT_EQ(error_of(job + "grid = { theta0 = inf }\n"),
            "bad.toml:4: key 'jobs[1].grid.theta0': must be a finite number, got inf");
  EXPECT_EQ(error_of(job + "grid = { theta0 = [0.1, 1.2345678901234567e300] }\n"),
            "bad.toml:4: key 'jobs[1].grid.theta0[1]': must have a magnitude <= 1e+100 (so that the equations' "
            "products do not overflow), got 1.23456789012346e+300");
  EXPECT_EQ(error_of(job + "grid = { theta0 = { from = 1, to = 2, count = 2.5 } }\n"),
            "bad.toml:4: key 'jobs[1].grid.theta0.count': must be an integer, got a float");
  EXPECT_EQ(error_of(job + "grid = { theta0 = { from = 1, to = 2, count = 0 } }\n"),
            "bad.toml:4: key 'jobs[1].grid.theta0.count': must be in [1, 1000000], got 0");
  EXPECT_EQ(error_of(job + "profiles = 1\n"),
            "bad.toml:4: key 'jobs[1].profiles': must be true or false, got an integer");
  EXPECT_EQ(error_of(job + "grid = 3\n"),
            "bad.toml:4: key 'jobs[1].grid': must be a table NAME = values, got an integer");
}

// The fingerprint (which a resumed sweep compares) and the [solver] texts handed to the case loader
// keep 17 digits, so that 0.1 and the next double are told apart and read back exactly.
TEST(SweepFile, FingerprintsAndSolverTextsKeepSeventeenDigits) {
  const std::string text = head() + "solver = { tolerance = 1e-11 }\n[[jobs]]\nkind = \"solve\"\n" +
                           "grid = { theta0 = [0.1, 0.10000000000000002] }\n";
  const SweepSpec spec = load_sweep_text(text, "sweep.toml");
  ASSERT_EQ(spec.jobs.size(), 2u);
  EXPECT_EQ(spec.jobs[0].fingerprint(), "solve case=" + kCases + "/simply_supported.toml theta0=0.10000000000000001 "
                                        "set: solver: tolerance=9.9999999999999994e-12 direct=0 max_seconds=120 "
                                        "max_equilibria=16 profiles=1");
  EXPECT_NE(spec.jobs[0].fingerprint(), spec.jobs[1].fingerprint());
  ASSERT_EQ(spec.jobs[0].solver.size(), 1u);
  EXPECT_EQ(spec.jobs[0].solver[0].second, "9.9999999999999994e-12");
}

}  // namespace
}  // namespace kirchhoff
