// Input that used to crash, hang or silently produce nonsense is refused with the file, line,
// key and reason (issue 20): nesting that overflowed toml11's recursive parser, integer keys
// that wrapped when narrowed to int, numbers that overflow to inf, tolerances that make any
// answer "converged", --set values out of range, and non-finite positions in the spatial bins.
// Each case is also in fuzz/corpus/regressions/, which the fuzzer replays.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "kirchhoff/contact/detail/spatial_bins.hpp"
#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/jobs/detail/toml_nesting.hpp"

namespace kirchhoff {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const std::string kPlanar = std::string(KIRCHHOFF_CASES_DIR) + "/simply_supported.toml";
const std::string kSpatial = std::string(KIRCHHOFF_CASES_DIR) + "/twisted_clamped.toml";
const std::string kWall = std::string(KIRCHHOFF_CASES_DIR) + "/wall.toml";

std::string read(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// text with the first match of `pattern` (a regex, one line) replaced; fails the test when
// there is none, so that a mutation that does nothing cannot make a test pass.
std::string edited(const std::string& text, const std::string& pattern, const std::string& to) {
  const std::regex re(pattern);
  EXPECT_TRUE(std::regex_search(text, re)) << "'" << pattern << "' is not in the case";
  return std::regex_replace(text, re, to, std::regex_constants::format_first_only);
}

int line_of(const std::string& text, const std::string& needle) {
  const auto at = text.find(needle);
  if (at == std::string::npos) return 0;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
}

// Loads text as "limits.toml" and expects a CaseError starting "limits.toml:LINE:" (when line >
// 0), naming 'key' (when not empty) and every reason fragment.
void expect_refused(const std::string& text, const std::string& key, std::initializer_list<std::string> reason,
                    int line, const ParameterOverrides& overrides = {}) {
  const std::string path = "limits.toml";
  try {
    load_case_text(text, path, overrides);
    ADD_FAILURE() << "accepted (expected a CaseError naming '" << key << "')";
    return;
  } catch (const CaseError& e) {
    const std::string message = e.what();
    if (line > 0) EXPECT_EQ(message.rfind(path + ":" + std::to_string(line) + ":", 0), 0u) << message;
    else EXPECT_EQ(message.rfind(path + ":", 0), 0u) << message;
    if (!key.empty()) EXPECT_THAT(message, HasSubstr("key '" + key + "'"));
    for (const auto& r : reason) EXPECT_THAT(message, HasSubstr(r));
  }
}

// ---- nesting: refused before toml11's recursive parser sees it ------------------------------

TEST(Nesting, DeepArraysAndInlineTablesAreRefusedQuicklyWithTheLine) {
  const std::string deep_array = "title = \"t\"\n\nx = " + std::string(5000, '[') + std::string(5000, ']') + "\n";
  std::string deep_table = "title = \"t\"\nx = ";
  for (int i = 0; i < 5000; ++i) deep_table += "{a = ";
  deep_table += "1" + std::string(5000, '}') + "\n";
  const std::string unclosed = "model = \"planar\"\n[parameters]\nx = " + std::string(100000, '[') + "\n";
  std::string dotted = "[rod]\n";
  for (int i = 0; i < 20000; ++i) dotted += "a.";
  dotted += "a = 1\n";
  std::string header = "title = \"t\"\n[";
  for (int i = 0; i < 20000; ++i) header += "a.";
  header += "a]\n";
  const auto started = std::chrono::steady_clock::now();
  for (const auto& [text, line] : {std::pair{deep_array, 3}, std::pair{deep_table, 2}, std::pair{unclosed, 3},
                                   std::pair{dotted, 2}, std::pair{header, 2}}) {
    SCOPED_TRACE(line);
    expect_refused(text, "", {"nest deeper than 64 levels"}, line);
  }
  // Depth 2000 took toml11 6 s; the scan is linear.
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count(), 2.0);
}

TEST(Nesting, BracketsInStringsAndCommentsDoNotCount) {
  // 100 brackets in each kind of string and in a comment, then a real, shallow case.
  const std::string brackets(100, '[');
  std::string text = read(kPlanar);
  text = edited(text, "title = \"[^\"]*\"", "title = \"" + brackets + "\\\"" + brackets + "\"  # " + brackets);
  text = edited(text, "description = \"\"\"\n", "description = '''" + brackets + "\n" + brackets + "\n");
  text = edited(text, "\\.\"\"\"\n", ".'''\n");
  text += "\n# trailing " + brackets + "\n";
  EXPECT_NO_THROW(load_case_text(text, "strings.toml"));
  // A multi-line basic string with escaped quotes and a closing run of five quotes.
  const std::string quotes = edited(read(kPlanar), "title = \"[^\"]*\"", "title = \"\"\"a \\\"[[[\\\" b\"\"\"\"\"");
  EXPECT_NO_THROW(load_case_text(quotes, "quotes.toml"));
}

TEST(Nesting, SixtyFourLevelsAreAllowedSixtyFiveAreNot) {
  const std::string base = read(kPlanar);
  // An unknown top-level key nested `depth` deep: the nesting check comes first, the unknown key
  // second, so the message says which limit was met.
  auto nested = [&](int depth) { return "x = " + std::string(depth, '[') + std::string(depth, ']') + "\n" + base; };
  expect_refused(nested(64), "x", {"unknown key"}, 1);
  expect_refused(nested(65), "", {"nest deeper than 64"}, 1);
}

TEST(Nesting, TheScanCountsLinesInsideStringsAndDottedKeysAcrossBrackets) {
  // Lines inside multi-line strings (and after an escaped line end) are counted; the nesting is
  // on line 6.
  const std::string text = "a = \"\"\"\n[[[\\\n\"\"\"\nb = '''\n]]]'''\nc = [[[[1]]]]\n";
  EXPECT_EQ(toml_line_beyond_nesting(text, 3), 6);
  EXPECT_EQ(toml_line_beyond_nesting(text, 4), 0);
  // The dots of keys inside inline tables add to the levels around them: x.y = { z.w = [1] } counts
  // a dot, the table, a dot, the array (32 levels of {a.a.a... = } used to count only 64 dots).
  EXPECT_EQ(toml_line_beyond_nesting("x.y = { z.w = [1] }\n", 3), 1);
  EXPECT_EQ(toml_line_beyond_nesting("x.y = { z.w = [1] }\n", 4), 0);
  std::string dotted_tables = "x = ";
  for (int i = 0; i < 32; ++i) dotted_tables += "{" + std::string(30, 'a').replace(1, 28, std::string(28, '.')) + " = ";
  dotted_tables += "1" + std::string(32, '}') + "\n";
  EXPECT_EQ(toml_line_beyond_nesting(dotted_tables, 64), 1);
  // A one-line string ends at its line's end, as toml11 reads it (then refuses it).
  EXPECT_EQ(toml_line_beyond_nesting("a = \"[[[\n[[[\n", 2), 2);
}

// ---- UTF-8: toml11 overflows a heap buffer on invalid UTF-8 in literal strings ------------------

TEST(Utf8, InvalidUtf8IsRefusedWithTheLineBeforeToml11) {
  // The fuzzer's input, reduced: a byte 0x9D inside a multi-line literal string (and in a
  // one-line one, which has the same bug) made toml11 read past a buffer.
  const std::string base = read(kPlanar);
  for (const std::string value : {"'''ab\x9d'''", "'a\x9d'", "\"a\xc0\xaf\"", "\"\xed\xa0\x80\"", "\"\xf4\x90\x80\x80\""}) {
    const std::string text = edited(base, "model = \"planar\"", "model = " + value);
    expect_refused(text, "", {"not valid UTF-8"}, line_of(text, "model = "));
  }
  // Valid UTF-8 of every length passes (an e-acute, a euro sign, an emoji in the title).
  const std::string ok = edited(base, "title = \"", "title = \"\xc3\xa9 \xe2\x82\xac \xf0\x9f\x98\x80 ");
  EXPECT_NO_THROW(load_case_text(ok, "ok.toml"));
  EXPECT_EQ(toml_invalid_utf8_at("ab\xe2\x82"), 2u);  // a truncated sequence
  EXPECT_EQ(toml_invalid_utf8_at("ab"), 2u);
}

// ---- integer keys: range-checked before they become ints -----------------------------------

TEST(IntegerKeys, SegmentsAsAnExpressionOrIntegerAreBounded) {
  const std::string base = read(kPlanar);
  for (const std::string value : {"\"1e10\"", "100000", "9223372036854775807", "\"-3\"", "0", "\"0.4\""}) {
    SCOPED_TRACE(value);
    const std::string text = edited(base, "\\[solver\\]\n", "[solver]\nsegments = " + value + "\n");
    expect_refused(text, "solver.segments", {"must be in [1, 2000]"}, line_of(text, "segments ="));
  }
  // "1e10" is reported as such, not as the int it used to wrap to (-129542143).
  const std::string text = edited(base, "\\[solver\\]\n", "[solver]\nsegments = \"1e10\"\n");
  expect_refused(text, "solver.segments", {"got 10000000000"}, line_of(text, "segments ="));
  // A number written as a string is an integer or refused, not rounded in silence (a probe's
  // "2.5" became 3); an expression of the parameters is rounded (below).
  const std::string half = edited(base, "\\[solver\\]\n", "[solver]\nsegments = \"2.5\"\n");
  expect_refused(half, "solver.segments", {"must be an integer", "2.5"}, line_of(half, "segments ="));
  const std::string inf = edited(base, "\\[solver\\]\n", "[solver]\nsegments = \"1/0\"\n");
  expect_refused(inf, "solver.segments", {"finite"}, line_of(inf, "segments ="));
  // The bound itself is accepted (the plectoneme's expression form too).
  EXPECT_EQ(load_case_text(edited(base, "\\[solver\\]\n", "[solver]\nsegments = 2000\n"), "ok.toml")
                .definition.options.segments,
            2000);
  EXPECT_EQ(load_case_text(edited(base, "\\[solver\\]\n", "[solver]\nsegments = \"L * 7.6\"\n"), "ok.toml")
                .definition.options.segments,
            8);
}

TEST(IntegerKeys, SamplesIterationsAndThreadsAreBounded) {
  const std::string base = read(kPlanar);
  struct Case {
    const char* table;
    const char* key;
    const char* value;
    const char* range;
  };
  for (const Case& c : {Case{"output", "samples", "2000000000", "[2, 100000]"},
                        Case{"output", "samples", "9223372036854775807", "[2, 100000]"},
                        Case{"output", "samples", "1", "[2, 100000]"},
                        Case{"solver", "max_iterations", "4294967297", "[1, 10000]"},
                        Case{"solver", "max_iterations", "0", "[1, 10000]"},
                        Case{"solver", "threads", "4294967296", "[0, 1024]"},
                        Case{"solver", "threads", "-1", "[0, 1024]"}}) {
    SCOPED_TRACE(std::string(c.key) + " = " + c.value);
    const std::string text = edited(base, std::string("\\[") + c.table + "\\]\n",
                                    std::string("[") + c.table + "]\n" + c.key + " = " + c.value + "\n");
    expect_refused(text, std::string(c.table) + "." + c.key, {std::string("must be in ") + c.range, c.value},
                   line_of(text, std::string(c.key) + " ="));
  }
  const std::string ok = edited(base, "\\[output\\]\n", "[output]\nsamples = 100000\n");
  EXPECT_EQ(load_case_text(ok, "ok.toml").samples, 100000);
}

// ---- numbers: finite and within 1e100 wherever they come from ------------------------------

TEST(Numbers, InfiniteOrOverflowingValuesAreRefused) {
  const std::string planar = read(kPlanar), spatial = read(kSpatial);
  struct Mutation {
    const std::string* base;
    const char* pattern;
    const char* to;
    const char* key;
    const char* reason;
  };
  for (const Mutation& m : {
           Mutation{&planar, "length = .*", "length = \"1/0\"", "rod.length", "finite"},
           Mutation{&planar, "length = .*", "length = \"exp(1000)\"", "rod.length", "finite"},
           Mutation{&planar, "length = .*", "length = inf", "rod.length", "finite"},
           Mutation{&planar, "length = .*", "length = nan", "rod.length", "finite"},
           Mutation{&planar, "length = .*", "length = \"1e60 * 1e60\"", "rod.length", "magnitude <= 1e+100"},
           Mutation{&planar, "\nB = .*", "\nB = \"1/0\"", "rod.B", "finite"},
           Mutation{&planar, "\nB = .*", "\nB = \"1/(0.5 - s)\"", "rod.B", "at s = 0.5"},
           Mutation{&spatial, "\nB3 = .*", "\nB3 = \"C\"\nu_hat = [0, 0, \"exp(1000)\"]", "rod.u_hat", "finite"},
           Mutation{&spatial, "\nB3 = .*", "\nB3 = \"C\"\nu_hat = [0, 0, \"1/(s - 1)\"]", "rod.u_hat", "at s = 1"},
           Mutation{&planar, "\nP = .*", "\nP = 1e308", "parameters.P", "magnitude <= 1e+100"},
           Mutation{&planar, "\nP = .*", "\nP = -inf", "parameters.P", "finite"},
           Mutation{&planar, "force = \\[\"-P\", 0\\]\n\n", "force = [\"-P*1e99\", 0]\n\n", "end.force",
                    "magnitude <= 1e+100"},
           Mutation{&planar, "position = \\[0, 0\\]\nextra_angle", "position = [\"1/0\", 0]\nextra_angle",
                    "start.position", "finite"},
       }) {
    SCOPED_TRACE(m.to);
    const std::string text = edited(*m.base, m.pattern, m.to);
    std::string first_line_of_to = m.to;
    first_line_of_to = first_line_of_to.substr(first_line_of_to[0] == '\n' ? 1 : 0);
    if (std::string(m.key) == "rod.u_hat") first_line_of_to = "u_hat = ";
    expect_refused(text, m.key, {m.reason}, line_of(text, first_line_of_to.substr(0, first_line_of_to.find('\n'))));
  }
}

TEST(Numbers, TolerancesLieInZeroToOnePercent) {
  const std::string base = read(kPlanar);
  for (const char* key : {"tolerance", "abs_tol", "rel_tol", "sensitivity_tol"})
    for (const char* value : {"inf", "1e300", "0", "-1e-10", "0.5", "nan"}) {
      SCOPED_TRACE(std::string(key) + " = " + value);
      const std::string text = edited(base, "\\[solver\\]\n", std::string("[solver]\n") + key + " = " + value + "\n");
      expect_refused(text, std::string("solver.") + key, {"must be in (0, 0.01]"}, line_of(text, std::string(key) + " ="));
    }
  const std::string ok = edited(base, "\\[solver\\]\n", "[solver]\ntolerance = 1e-2\n");
  EXPECT_EQ(load_case_text(ok, "ok.toml").definition.options.newton.residual_tolerance, 1e-2);
}

TEST(Numbers, LevelSetGapMustBeFiniteAtTheSupports) {
  const std::string wall = read(kWall);
  const std::string text = edited(wall, "type = \"plane\"\nname = \"wall\"\npoint = .*\nnormal = .*",
                                  "type = \"level_set\"\nname = \"wall\"\ngap = \"1/0\"");
  expect_refused(text, "obstacles.gap", {"finite", "inf"}, line_of(text, "gap = "), {{"Delta", 1e6}});
  // A gap singular away from the rod is fine.
  const std::string far = edited(wall, "type = \"plane\"\nname = \"wall\"\npoint = .*\nnormal = .*",
                                 "type = \"level_set\"\nname = \"wall\"\ngap = \"a - y + 1/(x - 7)^2\"");
  EXPECT_NO_THROW(load_case_text(far, "far.toml"));
}

TEST(Numbers, HugeButFiniteWallHeightIsAcceptedAsSolveRunsIt) {
  // a = 2^63 - 1 (a TOML integer) is 9.2e18 as a double: a wall that far never touches the rod,
  // and solve finds the free arch. Accepted, like any value within 1e100.
  const std::string text = edited(read(kWall), "\na = 0.1", "\na = 9223372036854775807");
  const Case c = load_case_text(text, "far_wall.toml");
  EXPECT_EQ(c.definition.parameters.get("a"), 9223372036854775807.0);
}

// ---- lists and files -----------------------------------------------------------------------

TEST(Lists, ObstaclesContactsNamesAndParametersAreBounded) {
  const std::string base = read(kPlanar);
  std::string obstacles = base;
  for (int k = 0; k < 65; ++k) obstacles += "\n[[obstacles]]\ntype = \"plane\"\npoint = [0, 5]\nnormal = [0, -1, 0]\n";
  expect_refused(obstacles, "obstacles", {"has 65 entries, at most 64"}, 0);
  std::string derived = "[";
  for (int k = 0; k < 65; ++k) derived += std::string(k ? ", " : "") + "\"P\"";
  derived += "]";
  const std::string names = edited(base, "derived = .*", "derived = " + derived);
  expect_refused(names, "output.derived", {"has 65 entries, at most 64"}, line_of(names, "derived ="));
  std::string parameters;
  for (int k = 0; k < 257; ++k) parameters += "p" + std::to_string(k) + " = 1\n";
  const std::string many = edited(base, "\\[parameters\\]\n", "[parameters]\n" + parameters);
  expect_refused(many, "parameters", {"has 261 entries, at most 256"}, 0);
  const std::string bad_name = edited(base, "\\[parameters\\]\n", "[parameters]\n\"a b\" = 1\n");
  expect_refused(bad_name, "parameters.a b", {"not a name"}, line_of(bad_name, "\"a b\""));
}

TEST(Files, OversizedFileIsRefusedWithoutParsing) {
  const std::string text = read(kPlanar) + "\n#" + std::string(case_limits::kMaxFileBytes, 'x') + "\n";
  expect_refused(text, "", {"larger than 1 MiB"}, 0);
  const fs::path path = fs::temp_directory_path() / "kirchhoff_input_limits_big.toml";
  std::ofstream(path) << text;
  try {
    load_case(path.string());
    ADD_FAILURE() << "a 1 MiB file was accepted";
  } catch (const CaseError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path.string() + ": larger than 1 MiB", 0), 0u) << e.what();
  }
  fs::remove(path);
}

// ---- --set NAME=VALUE ----------------------------------------------------------------------

TEST(Overrides, ValuesMustBeFiniteAndInRangeAndNamesIdentifiers) {
  // The text's syntax is parse_override's to refuse.
  for (const char* text : {"P= 1", "P=0x", "1P=2", "a b=1", "P=", "=1", "P=abc"}) {
    SCOPED_TRACE(text);
    EXPECT_THROW(parse_override(text), std::invalid_argument);
  }
  // The value's range is load_case's, for the CLI's parsed values as for Python's (one message).
  for (const char* text : {"P=1e308", "P=-1e101", "P=inf", "P=nan", "P=1e999"}) {
    SCOPED_TRACE(text);
    const auto parsed = parse_override(text);
    expect_refused(read(kPlanar), "", {"--set P", "is not a finite number with magnitude <= 1e+100"}, 0, {parsed});
  }
  EXPECT_EQ(parse_override("P=1e100").second, 1e100);
  EXPECT_EQ(parse_override("P=1e-400").second, 0.0);  // underflow is a number: 0
  EXPECT_EQ(parse_override("_x2=-3.5").first, "_x2");
  // load_case checks overrides given to it directly too (the Python module passes a dict).
  expect_refused(read(kPlanar), "", {"--set P", "magnitude <= 1e+100"}, 0, {{"P", 1e200}});
  expect_refused(read(kPlanar), "", {"--set P", "finite"}, 0, {{"P", std::numeric_limits<double>::infinity()}});
}

// ---- the spatial bins: non-finite and far positions ----------------------------------------

TEST(SpatialBins, NonFiniteAndFarPointsNeverReachIntegerArithmetic) {
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Vec3> points{Vec3(0, 0, 0),      Vec3(inf, 0, 0),    Vec3(0.05, 0, 0),  Vec3(nan, 1, 1),
                                 Vec3(1e300, 0, 0), Vec3(1e300, 0, 0), Vec3(-1e300, 0, 0), Vec3(1e10, 1e10, 0),
                                 Vec3(1e10, 1e10, 0.05)};
  std::set<std::pair<std::size_t, std::size_t>> visited;
  for_each_near_pair(points, 0.1, 1, [&](std::size_t i, std::size_t j) { visited.insert({i, j}); });
  // Every pair closer than the cell is found (1e10 / 0.1 cells overflowed an int); no pair with
  // a non-finite point is visited.
  for (const auto& pair : {std::pair<std::size_t, std::size_t>{0, 2}, {4, 5}, {7, 8}})
    EXPECT_TRUE(visited.count(pair)) << pair.first << " " << pair.second;
  for (const auto& [i, j] : visited) {
    EXPECT_TRUE(points[i].allFinite());
    EXPECT_TRUE(points[j].allFinite());
  }
  // An infinite cell is one cube; a nan or non-positive one is a caller's bug.
  int pairs = 0;
  for_each_near_pair(points, inf, 1, [&](std::size_t, std::size_t) { ++pairs; });
  EXPECT_EQ(pairs, 7 * 6 / 2);
  EXPECT_THROW(CubeBins(points, nan, 1), std::invalid_argument);
  EXPECT_THROW(CubeBins(points, 0.0, 1), std::invalid_argument);
}

}  // namespace
}  // namespace kirchhoff
