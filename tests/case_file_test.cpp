// The case-file loader refuses every class of bad input with a message that names the file, the
// key (with its line where the TOML parser knows it) and the reason. Each bad case is a small
// TOML file derived from a valid one (the simply supported Elastica) by changing one thing.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "kirchhoff/analysis/analytic.hpp"
#include "kirchhoff/analysis/solution.hpp"
#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

// A valid planar case (cases/simply_supported.toml without comments), the base of every
// bad case below. Keep one statement per line: the tests locate keys by line.
const char* const kBase = R"(title = "simply supported, base of the bad cases"
model = "planar"

[parameters]
theta0 = 1.0
L = 1.0
EI = 1.0
P = 12.0

[rod]
length = "L"
B = "EI"

[start]
type = "pinned"
position = [0, 0]
extra_angle = "theta0"

[end]
type = "sliding"
axis = [1, 0, 0]
position = [0, 0]
force = ["-P", 0]

[solver]
unknowns = ["P"]

[guess]
force = ["-P", 0]

[output]
derived = ["P", "y_max"]
)";

// A spatial case (twisted clamped rod), for the checks that only apply to spatial rods.
const char* const kSpatialBase = R"(model = "spatial"

[parameters]
phi = 6.0
L = 1.0

[rod]
length = "L"
B = 1.0
B3 = 0.8

[start]
type = "clamped"
position = [0, 0, 0]

[end]
type = "sliding"
axis = [0, 0, 1]
position = [0, 0, 0]
force = [0, 0, 0]
orientation = { axis = [0, 0, 1], angle = "phi" }
track_turns = true

[guess]
moment = [0, 0, "0.8*phi/L"]
)";

// 1-based line of the first line containing needle, 0 when absent.
int line_of(const std::string& text, const std::string& needle) {
  const auto at = text.find(needle);
  if (at == std::string::npos) return 0;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
}

// text with `from` replaced by `to`; fails the test when `from` is not in the text (so that a
// mutation that silently does nothing cannot make a test pass).
std::string replaced(const std::string& text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "'" << from << "' is not in the base case";
  if (at == std::string::npos) return text;
  EXPECT_EQ(text.find(from, at + 1), std::string::npos) << "'" << from << "' is ambiguous in the base case";
  std::string out = text;
  out.replace(at, from.size(), to);
  return out;
}

class CaseFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "kirchhoff_case_file_test_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }

  std::string write(const std::string& text) {
    const std::string path = (dir_ / ("case_" + std::to_string(++count_) + ".toml")).string();
    std::ofstream(path) << text;
    return path;
  }

  // Loads text and expects a CaseError naming the file, the key (as 'key'), every reason
  // fragment and, when line > 0, "FILE:LINE:" at the start of the message.
  void expect_refused(const std::string& text, const std::string& key, std::initializer_list<std::string> reason,
                      int line = 0, const ParameterOverrides& overrides = {}, const std::string& phase = "") {
    const std::string path = write(text);
    std::string message;
    try {
      load_case(path, overrides, phase);
      ADD_FAILURE() << "accepted (expected a CaseError naming '" << key << "'):\n" << text;
      return;
    } catch (const CaseError& e) {
      message = e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << "threw another exception than CaseError (expected one naming '" << key << "'): " << e.what();
      return;
    }
    EXPECT_THAT(message, HasSubstr(path));
    EXPECT_THAT(message, HasSubstr("key '" + key + "'"));
    for (const auto& r : reason) EXPECT_THAT(message, HasSubstr(r));
    if (line > 0) {
      EXPECT_EQ(message.rfind(path + ":" + std::to_string(line) + ":", 0), 0u)
          << "expected line " << line << " in: " << message;
    }
  }

  fs::path dir_;
  int count_ = 0;
};

// ---- the bases are valid: every refusal below is due to the one change -------------------

TEST_F(CaseFileTest, BaseCasesLoad) {
  const Case c = load_case(write(kBase));
  EXPECT_EQ(c.definition.kind, RodKind::Planar);
  EXPECT_EQ(c.definition.unknown_parameters, std::vector<std::string>{"P"});
  EXPECT_EQ(c.definition.parameters.get("P"), 12.0);
  EXPECT_EQ(c.derived, (std::vector<std::string>{"P", "y_max"}));
  EXPECT_NO_THROW(ShootingProblem{c.definition});

  const Case s = load_case(write(kSpatialBase));
  EXPECT_EQ(s.definition.kind, RodKind::Spatial);
  EXPECT_NO_THROW(ShootingProblem{s.definition});
}

TEST_F(CaseFileTest, OverridesReplaceParameters) {
  const Case c = load_case(write(kBase), {{"theta0", 2.0}, {"P", 30.0}});
  EXPECT_EQ(c.definition.parameters.get("theta0"), 2.0);
  EXPECT_EQ(c.definition.parameters.get("P"), 30.0);
  EXPECT_EQ(c.definition.parameters.get("EI"), 1.0);
}

// ---- typo'd keys ---------------------------------------------------------------------------

TEST_F(CaseFileTest, TypoInRodKey) {
  const std::string text = replaced(kBase, "length = \"L\"", "lenght = \"L\"");
  expect_refused(text, "rod.lenght", {"unknown key", "length"}, line_of(text, "lenght"));
}

TEST_F(CaseFileTest, TypoInEndTypeKey) {
  // The misspelt key itself should be named, not only the missing 'type'.
  const std::string text = replaced(kBase, "type = \"sliding\"", "typ = \"sliding\"");
  expect_refused(text, "end.typ", {}, line_of(text, "typ = "));
}

TEST_F(CaseFileTest, TypoInEndKeyBesideType) {
  const std::string text = replaced(kBase, "axis = [1, 0, 0]", "axis = [1, 0, 0]\naxsi = [1, 0, 0]");
  expect_refused(text, "end.axsi", {"unknown key", "axis"}, line_of(text, "axsi"));
}

TEST_F(CaseFileTest, UnknownTopLevelTable) {
  const std::string text = replaced(kBase, "[solver]", "[solvr]");
  expect_refused(text, "solvr", {"unknown key", "solver"});
}

TEST_F(CaseFileTest, TypoInSolverKey) {
  const std::string text = replaced(kBase, "unknowns = [\"P\"]", "unknowns = [\"P\"]\nmax_iteration = 3");
  expect_refused(text, "solver.max_iteration", {"unknown key", "max_iterations"}, line_of(text, "max_iteration"));
}

// ---- wrong types ---------------------------------------------------------------------------

TEST_F(CaseFileTest, LengthIsBoolean) {
  const std::string text = replaced(kBase, "length = \"L\"", "length = true");
  expect_refused(text, "rod.length", {"must be a number or an expression", "boolean"}, line_of(text, "length = "));
}

TEST_F(CaseFileTest, StiffnessIsArray) {
  const std::string text = replaced(kBase, "B = \"EI\"", "B = [1, 2]");
  expect_refused(text, "rod.B", {"must be a number or an expression", "array"}, line_of(text, "B = "));
}

TEST_F(CaseFileTest, SegmentsIsFloat) {
  const std::string text = replaced(kBase, "unknowns = [\"P\"]", "unknowns = [\"P\"]\nsegments = 1.5");
  expect_refused(text, "solver.segments", {"must be an integer", "got a float"}, line_of(text, "segments"));
}

TEST_F(CaseFileTest, UnknownsIsString) {
  const std::string text = replaced(kBase, "unknowns = [\"P\"]", "unknowns = \"P\"");
  expect_refused(text, "solver.unknowns", {"must be an array of strings", "string"}, line_of(text, "unknowns"));
}

TEST_F(CaseFileTest, ModelIsMisspelt) {
  const std::string text = replaced(kBase, "model = \"planar\"", "model = \"planer\"");
  expect_refused(text, "model", {"'planer'", "not 'planar' or 'spatial'"}, line_of(text, "model"));
}

TEST_F(CaseFileTest, ParameterIsBoolean) {
  const std::string text = replaced(kBase, "EI = 1.0", "EI = true");
  expect_refused(text, "parameters.EI", {"must be a number", "boolean"}, line_of(text, "EI = true"));
}

// A string is an expression of the parameters above it; a word that is none of them is refused.
TEST_F(CaseFileTest, ParameterIsAWord) {
  const std::string text = replaced(kBase, "EI = 1.0", "EI = \"one\"");
  expect_refused(text, "parameters.EI", {"unknown variable 'one'"}, line_of(text, "EI = \"one\""));
}

// ---- non-physical values -------------------------------------------------------------------

TEST_F(CaseFileTest, ZeroLength) {
  const std::string text = replaced(kBase, "length = \"L\"", "length = 0");
  expect_refused(text, "rod.length", {"must be > 0"}, line_of(text, "length = "));
}

TEST_F(CaseFileTest, ZeroLengthThroughParameter) {
  // The check applies at the parameter values, overrides included.
  expect_refused(kBase, "rod.length", {"must be > 0"}, line_of(kBase, "length = "), {{"L", -1.0}});
}

TEST_F(CaseFileTest, NegativeStiffness) {
  const std::string text = replaced(kBase, "B = \"EI\"", "B = -1");
  expect_refused(text, "rod.B", {"stiffness must be > 0", "-1"}, line_of(text, "B = "));
}

TEST_F(CaseFileTest, NegativeStiffnessThroughOverride) {
  expect_refused(kBase, "rod.B", {"stiffness must be > 0"}, line_of(kBase, "B = "), {{"EI", -2.0}});
}

TEST_F(CaseFileTest, TaperedStiffnessGoesNegative) {
  // 1 - 2 s is positive at s = 0 and reaches 0 at s = 0.5: only a check along the rod sees it.
  const std::string text = replaced(kBase, "B = \"EI\"", "B = \"1 - 2*s\"");
  expect_refused(text, "rod.B", {"stiffness must be > 0", "at s = 0.5"}, line_of(text, "B = "));
}

// A stretch 1e-4 of the rod long where the stiffness is -1 fell between the 101 points it was
// checked at (a probe's case), and the solve returned the uniform rod's answer; both sides of
// each located jump are checked now.
TEST_F(CaseFileTest, AShortStretchOfNegativeStiffnessIsRefused) {
  const std::string text = replaced(kBase, "B = \"EI\"", "B = \"EI*(1 - 2*(s > 0.4013 && s < 0.4014))\"");
  expect_refused(text, "rod.B", {"stiffness must be > 0", "-1", "at s = 0.4013"}, line_of(text, "B = "));
}

TEST_F(CaseFileTest, TaperedStiffnessPositiveIsAccepted) {
  const std::string text = replaced(kBase, "B = \"EI\"", "B = \"1 + 2*s\"");
  EXPECT_NO_THROW(load_case(write(text)));
}

TEST_F(CaseFileTest, BarrierRangeNotPositive) {
  for (const char* b : {"0", "-0.1"}) {
    const std::string text =
        replaced(kBase, "B = \"EI\"", std::string("B = \"EI\"\nbarrier = { b = ") + b + ", a = 1 }");
    SCOPED_TRACE(b);
    expect_refused(text, "rod.barrier.b", {"must be > 0"}, line_of(text, "barrier"));
  }
  // ... while a positive range is accepted.
  const std::string ok = replaced(kBase, "B = \"EI\"", "B = \"EI\"\nbarrier = { b = 0.1, a = 1 }");
  EXPECT_NO_THROW(load_case(write(ok)));
}

TEST_F(CaseFileTest, ShearStiffnessWithoutExtensible) {
  const std::string text = replaced(kBase, "B = \"EI\"", "B = \"EI\"\nA3 = 50");
  expect_refused(text, "rod.A3", {"rod.extensible is false"}, line_of(text, "A3"));
}

TEST_F(CaseFileTest, BothIsotropicAndDirectionalStiffness) {
  const std::string text = replaced(kBase, "B = \"EI\"", "B = \"EI\"\nB1 = 2");
  expect_refused(text, "rod.B1", {"either B or B1/B2"}, line_of(text, "B1"));
}

// ---- impossible or inconsistent boundary conditions ----------------------------------------

TEST_F(CaseFileTest, UnknownParameterWithoutExtraCondition) {
  const std::string text = replaced(kBase, "extra_angle = \"theta0\"\n", "");
  expect_refused(text, "solver", {"0 extra condition(s) but 1 unknown parameter(s)"});
}

TEST_F(CaseFileTest, ExtraConditionWithoutUnknownParameter) {
  const std::string text = replaced(kBase, "[solver]\nunknowns = [\"P\"]\n", "");
  expect_refused(text, "solver", {"1 extra condition(s) but 0 unknown parameter(s)"});
}

TEST_F(CaseFileTest, SlidingEndWithoutAxis) {
  const std::string text = replaced(kBase, "axis = [1, 0, 0]\n", "");
  expect_refused(text, "end.axis", {"sliding end needs the axis"});
}

TEST_F(CaseFileTest, SlidingAxisOutOfThePlane) {
  // The planar rod cannot carry a force along e_z.
  const std::string text = replaced(kBase, "axis = [1, 0, 0]", "axis = [0, 0, 1]");
  expect_refused(text, "end", {"end:", "planar"});
}

TEST_F(CaseFileTest, BogusEndType) {
  const std::string text = replaced(kBase, "type = \"sliding\"", "type = \"bogus\"");
  expect_refused(text, "end.type", {"'bogus' is not one of", "clamped, pinned, free, loaded, sliding"},
                 line_of(text, "bogus"));
}

TEST_F(CaseFileTest, KeyDoesNotApplyToEndType) {
  const std::string text = replaced(kBase, "type = \"pinned\"", "type = \"clamped\"\nforce = [0, 1]");
  expect_refused(text, "start.force", {"does not apply to a clamped end"}, line_of(text, "force = [0, 1]"));
}

TEST_F(CaseFileTest, PlanarClampOrientationOutOfThePlane) {
  // A planar rod can only turn about e_z; a clamp turned about e_x cannot be honoured and must
  // not be read as a turn about e_z.
  const std::string text = replaced(kBase, "type = \"pinned\"\nposition = [0, 0]\nextra_angle = \"theta0\"",
                                    "type = \"clamped\"\nposition = [0, 0]\norientation = { axis = [1, 0, 0], angle = 0.5 }");
  const std::string no_unknowns = replaced(text, "[solver]\nunknowns = [\"P\"]\n", "");
  expect_refused(no_unknowns, "start.orientation.axis", {"planar"});
}

TEST_F(CaseFileTest, PlanarPositionOutOfThePlane) {
  // The planar rod lies in z = 0: imposing z = 1 at a support is impossible, not ignorable.
  const std::string text = replaced(kBase, "type = \"pinned\"\nposition = [0, 0]", "type = \"pinned\"\nposition = [0, 0, 1]");
  expect_refused(text, "start.position", {"planar"});
}

// A planar rod reads B2, u_hat[1], A1, A3, v_hat[0] and v_hat[2] only. The others were accepted
// and ignored: u_hat = [0, 0, k] left the rod straight (the Euler column's buckled solve gave the
// same theta0 to every digit with and without it). Refused, naming the key, line and component;
// the in-plane curvature (and a zero written as a parameter-free 0) is accepted.
TEST_F(CaseFileTest, PlanarRodRefusesPropertiesItsEquationsDoNotRead) {
  for (const char* key : {"B1", "B3"}) {
    const std::string text = replaced(kBase, "B = \"EI\"", std::string("B2 = \"EI\"\n") + key + " = 2");
    expect_refused(text, std::string("rod.") + key, {"planar rod bends about d2 only", "model = \"spatial\""},
                   line_of(text, std::string(key) + " = 2"));
  }
  const std::string shear = replaced(kBase, "B = \"EI\"", "B = \"EI\"\nextensible = true\nA1 = 10\nA2 = 10\nA3 = 10");
  expect_refused(shear, "rod.A2", {"A2 does not enter"}, line_of(shear, "A2"));
  const std::string twist = replaced(kBase, "B = \"EI\"", "B = \"EI\"\nu_hat = [0, 0, \"EI\"]");
  expect_refused(twist, "rod.u_hat", {"component 3 must be 0 for a planar rod", "u_hat = [0, kappa, 0]"},
                 line_of(twist, "u_hat"));
  const std::string first = replaced(kBase, "B = \"EI\"", "B = \"EI\"\nu_hat = [0.5, 0, 0]");
  expect_refused(first, "rod.u_hat", {"component 1 must be 0"}, line_of(first, "u_hat"));
  const std::string shear_strain = replaced(kBase, "B = \"EI\"", "B = \"EI\"\nv_hat = [0, \"s\", 1]");
  expect_refused(shear_strain, "rod.v_hat", {"component 2 must be 0"}, line_of(shear_strain, "v_hat"));
  EXPECT_NO_THROW(load_case(write(replaced(kBase, "B = \"EI\"", "B2 = \"EI\"\nu_hat = [0, \"EI\", 0.0]\nv_hat = [0.1, 0, 1]"))));
  // A zero written as an expression ("0"): it was evaluated without the case's parameters, and
  // the load failed with "unknown parameter" and no file or key.
  EXPECT_NO_THROW(load_case(write(replaced(kBase, "B = \"EI\"", "B = \"EI\"\nu_hat = [\"0\", 0.5, \"0\"]"))));
}

// An unknown that no expression of the problem reads (here: the load is a number, so P balances
// nothing) could take any value: Newton's Jacobian has a zero column, and a solve stopped wherever
// it started. Refused where the unknowns are named; a parameter used only through another
// (computed) parameter is used.
TEST_F(CaseFileTest, UnknownUsedByNoExpressionIsRefused) {
  const std::string text = replaced(kBase, "force = [\"-P\", 0]\n\n[solver]", "force = [-12.0, 0]\n\n[solver]");
  expect_refused(text, "solver.unknowns", {"'P' is used by no expression"}, line_of(text, "unknowns"));
  const std::string through_computed =
      replaced(replaced(kBase, "P = 12.0", "P = 12.0\nload = \"2*P\""), "force = [\"-P\", 0]\n\n[solver]",
               "force = [\"-load/2\", 0]\n\n[solver]");
  EXPECT_NO_THROW(load_case_text(through_computed, "computed.toml"));
}

TEST_F(CaseFileTest, UnknownsNameMissingParameter) {
  const std::string text = replaced(kBase, "unknowns = [\"P\"]", "unknowns = [\"Q\"]");
  expect_refused(text, "solver.unknowns", {"'Q' is not in [parameters]"}, line_of(text, "unknowns"));
}

TEST_F(CaseFileTest, TurnTrackingAboutAnotherAxisNamesTheEnd) {
  // Turn counting works about e3 only; the refusal must point at the end that asks for it.
  const std::string text =
      replaced(kSpatialBase, "orientation = { axis = [0, 0, 1]", "orientation = { axis = [1, 0, 0]");
  expect_refused(text, "end.orientation.axis", {"turn"});
}

TEST_F(CaseFileTest, AxialPhaseConditionOnPlanarRod) {
  expect_refused(kBase, "solver.phase_condition", {"'axial' is for spatial rods"}, 0, {}, "axial");
  const std::string text = replaced(kBase, "unknowns = [\"P\"]", "unknowns = [\"P\"]\nphase_condition = \"axial\"");
  expect_refused(text, "solver.phase_condition", {"'axial' is for spatial rods"}, line_of(text, "phase_condition"));
}

TEST_F(CaseFileTest, BogusPhaseCondition) {
  const std::string text =
      replaced(kSpatialBase, "[guess]", "[solver]\nphase_condition = \"radial\"\n\n[guess]");
  expect_refused(text, "solver.phase_condition", {"'radial' is not 'none' or 'axial'"},
                 line_of(text, "phase_condition"));
  // The spatial base accepts the real one.
  EXPECT_NO_THROW(load_case(write(kSpatialBase), {}, "axial"));
}

TEST_F(CaseFileTest, UnknownDerivedQuantity) {
  const std::string text = replaced(kBase, "derived = [\"P\", \"y_max\"]", "derived = [\"P\", \"ymax\"]");
  expect_refused(text, "output.derived", {"'ymax' is not a derived quantity", "y_max"}, line_of(text, "derived"));
}

// ---- bad expressions -----------------------------------------------------------------------

TEST_F(CaseFileTest, ExpressionWithUnknownVariable) {
  const std::string text = replaced(kBase, "force = [\"-P\", 0]\n\n[solver]", "force = [\"-Q\", 0]\n\n[solver]");
  expect_refused(text, "end.force", {"cannot read expression '-Q'", "Q"}, line_of(text, "\"-Q\""));
}

TEST_F(CaseFileTest, UnknownVariableIsACaseErrorWherever) {
  // Unknown names must be refused as a CaseError naming the key, wherever the expression is
  // (not escape as another exception type, which would abort the CLI).
  struct Mutation {
    const char* from;
    const char* to;
    const char* key;
  };
  for (const Mutation& m : {Mutation{"length = \"L\"", "length = \"Q\"", "rod.length"},
                            Mutation{"B = \"EI\"", "B = \"EI*Q\"", "rod.B"},
                            Mutation{"extra_angle = \"theta0\"", "extra_angle = \"Q\"", "start.extra_angle"},
                            Mutation{"[guess]\nforce = [\"-P\", 0]", "[guess]\nforce = [\"-Q\", 0]", "guess.force"},
                            Mutation{"B = \"EI\"", "B = \"EI\"\ngravity = { weight = \"Q\" }", "rod.gravity.weight"}}) {
    SCOPED_TRACE(m.to);
    const std::string text = replaced(kBase, m.from, m.to);
    expect_refused(text, m.key, {"Q"}, line_of(text, "Q"));
  }
}

// A planar rod's field acts in its plane: gravity with up = [0, 0, 1] was accepted and did
// nothing (a probe); in-plane directions are normalised, not refused.
TEST_F(CaseFileTest, AFieldAcrossAPlanarRodsPlaneIsRefused) {
  for (const char* field : {"gravity = { weight = 1.0, up = [0, 0, 1] }", "gravity = { weight = 1.0, up = [0, 1, 0.5] }",
                            "barrier = { b = 0.01, a = 0.2, normal = [0, 0, 1] }"}) {
    SCOPED_TRACE(field);
    const std::string text = replaced(kBase, "B = \"EI\"", std::string("B = \"EI\"\n") + field);
    const std::string key = std::string(field).rfind("gravity", 0) == 0 ? "rod.gravity.up" : "rod.barrier.normal";
    expect_refused(text, key, {"the z component must be 0"}, line_of(text, field));
  }
  EXPECT_NO_THROW(load_case_text(replaced(kBase, "B = \"EI\"", "B = \"EI\"\ngravity = { weight = 1.0, up = [1, 1, 0] }"),
                                 "tilted.toml"));
}

TEST_F(CaseFileTest, ExpressionWithSyntaxError) {
  const std::string text = replaced(kBase, "length = \"L\"", "length = \"L*\"");
  expect_refused(text, "rod.length", {"cannot read expression 'L*'"}, line_of(text, "length = "));
}

TEST_F(CaseFileTest, ArclengthOutsideMaterialProperties) {
  const std::string text = replaced(kBase, "axis = [1, 0, 0]\nposition = [0, 0]", "axis = [1, 0, 0]\nposition = [\"s\", 0]");
  expect_refused(text, "end.position", {"cannot read expression 's'", "s is only allowed in material properties"},
                 line_of(text, "\"s\""));
}

TEST_F(CaseFileTest, ArclengthCannotBeAParameter) {
  const std::string text = replaced(kBase, "EI = 1.0", "EI = 1.0\ns = 0.5");
  expect_refused(text, "parameters.s", {"reserved for the arclength"}, line_of(text, "s = 0.5"));
}

// ---- [parameters] expressions ---------------------------------------------------------------

// kBase with EI computed from E and I, given above it.
std::string with_computed_stiffness() { return replaced(kBase, "EI = 1.0", "E = 2.0\nI = 0.25\nEI = \"E*I\""); }

TEST_F(CaseFileTest, ParameterExpressionIsComputedFromTheParametersAboveIt) {
  const Case c = load_case(write(with_computed_stiffness()), {{"E", 8.0}});
  EXPECT_EQ(c.definition.parameters.get("EI"), 2.0);  // 8 * 0.25, the override included
  EXPECT_EQ(c.file_parameters.get("EI"), 0.5);        // the file's own values
  ASSERT_EQ(c.definition.dependent_parameters.size(), 1u);
  EXPECT_EQ(c.definition.dependent_parameters[0].name, "EI");
  EXPECT_EQ(c.definition.dependent_parameters[0].uses, (std::vector<std::string>{"E", "I"}));

  // The rod follows E wherever the problem takes its parameters: set by hand, as continuation does.
  ShootingProblem problem(c.definition);
  problem.set_parameter("E", 12.0);
  EXPECT_EQ(problem.parameters().get("EI"), 3.0);
  EXPECT_EQ(problem.equations(problem.parameters())->model().B[1](0.0), 3.0);
  EXPECT_THROW(problem.set_parameter("EI", 1.0), std::invalid_argument);
}

TEST_F(CaseFileTest, ComputedStiffnessGivesTheElasticaOfThatStiffness) {
  const Case c = load_case(write(with_computed_stiffness()), {{"E", 8.0}});
  ShootingProblem problem(c.definition);
  const ShootingResult r = solve(problem, problem.initial_unknowns(c.start_guess));
  ASSERT_TRUE(r.summary.converged()) << r.summary.brief_report();
  // P = 4 K(k)^2 EI / L^2 (eq. 54) with EI = 2: the load scales with the computed stiffness
  // (Newton's tolerance 1e-10 and the analytic solution's 1e-12 leave 1e-9 of margin).
  const double P = r.parameters.get("P");
  const double expected = analytic::PinnedElastica{1.0, 2.0, 1.0}.load();
  EXPECT_NEAR(P, expected, 1e-9 * expected);
  EXPECT_EQ(r.parameters.get("EI"), 2.0);
}

TEST_F(CaseFileTest, PiIsAConstantAndAnExpressionOfNoParameterIsAParameterOfItsOwn) {
  const std::string text = replaced(kBase, "theta0 = 1.0", "theta0 = \"pi/3\"");
  const Case c = load_case(write(text));
  EXPECT_DOUBLE_EQ(c.definition.parameters.get("theta0"), std::acos(0.5));
  EXPECT_TRUE(c.definition.dependent_parameters.empty());
  EXPECT_EQ(load_case(write(text), {{"theta0", 2.0}}).definition.parameters.get("theta0"), 2.0);
  // pi in any expression; _pi, muParser's name, is the same double (muParser's own is 3.141592653589).
  const Case d = load_case(write(replaced(kBase, "length = \"L\"", "length = \"L*pi/_pi\"")));
  EXPECT_EQ(d.definition.model(d.definition.parameters).length, 1.0);
  const Case e = load_case(write(replaced(kBase, "B = \"EI\"", "B = \"EI*(1 + s*(pi - _pi))\"")));
  EXPECT_EQ(e.definition.model(e.definition.parameters).B[1](0.5), 1.0);  // a profile in s: bound apart
}

TEST_F(CaseFileTest, ParameterUsingOneBelowItIsRefusedByName) {
  const std::string text = replaced(kBase, "theta0 = 1.0", "theta0 = \"EI/2\"");
  expect_refused(text, "parameters.theta0",
                 {"uses 'EI', which is given below it (line " + std::to_string(line_of(text, "EI = 1.0")) + ")",
                  "only the parameters above it"},
                 line_of(text, "theta0 = "));
}

TEST_F(CaseFileTest, CycleOfParametersIsRefusedByName) {
  const std::string text = replaced(kBase, "L = 1.0\nEI = 1.0", "L = \"EI\"\nEI = \"L\"");
  expect_refused(text, "parameters.L", {"uses 'EI', which is given below it"}, line_of(text, "L = \"EI\""));
  const std::string self = replaced(kBase, "EI = 1.0", "EI = \"2*EI\"");
  expect_refused(self, "parameters.EI", {"uses itself"}, line_of(self, "EI = \"2*EI\""));
}

TEST_F(CaseFileTest, ParameterNamedLikeAConstantIsRefused) {
  const std::string text = replaced(kBase, "EI = 1.0", "EI = 1.0\npi = 3.14");
  expect_refused(text, "parameters.pi", {"is a constant in expressions"}, line_of(text, "pi = 3.14"));
}

TEST_F(CaseFileTest, ComputedParameterCannotBeSetOrSolvedFor) {
  const std::string path = write(with_computed_stiffness());
  try {
    load_case(path, {{"EI", 3.0}});
    ADD_FAILURE() << "--set of a computed parameter was accepted";
  } catch (const CaseError& e) {
    EXPECT_THAT(e.what(), HasSubstr(path + ": --set EI: EI is computed from E, I"));
    EXPECT_THAT(e.what(), HasSubstr("set E, I instead"));
  }
  const std::string text = replaced(with_computed_stiffness(), "unknowns = [\"P\"]", "unknowns = [\"EI\"]");
  expect_refused(text, "solver.unknowns", {"EI is computed from E, I", "solve for E, I instead"},
                 line_of(text, "unknowns"));
  // Chains name the parameters a user can set.
  std::vector<DependentParameter> chain{{"A", {}, {"r"}}, {"B", {}, {"A", "t"}}};
  EXPECT_THAT(dependent_parameter_refusal(chain, "B", "continue in"), HasSubstr("B is computed from r, t"));
  EXPECT_EQ(dependent_parameter_refusal(chain, "r", "set"), "");
}

// Rules sharing inputs: each of 200 parameters the sum of the two above it. Loading, computing
// and refusing a --set stay linear in the rules (a walk of the rules per path took 2^200 steps).
TEST_F(CaseFileTest, LongChainsOfComputedParametersStayCheap) {
  std::string chain = "p0 = 1.0\np1 = 1.0\n";
  for (int k = 2; k < 200; ++k)
    chain += "p" + std::to_string(k) + " = \"p" + std::to_string(k - 1) + " + p" + std::to_string(k - 2) + "\"\n";
  const std::string path = write(replaced(kBase, "P = 12.0\n", "P = 12.0\n" + chain));
  const Case c = load_case(path, {{"p1", 2.0}});
  EXPECT_EQ(c.definition.parameters.get("p5"), 13.0);  // 1, 2, 3, 5, 8, 13
  EXPECT_EQ(c.definition.dependent_parameters.size(), 198u);
  try {
    load_case(path, {{"p199", 1.0}});
    ADD_FAILURE() << "--set of a computed parameter was accepted";
  } catch (const CaseError& e) {
    EXPECT_THAT(e.what(), HasSubstr("p199 is computed from p0, p1 "));
  }
}

// ---- --set overrides -----------------------------------------------------------------------

TEST_F(CaseFileTest, OverrideOfUnknownParameter) {
  const std::string path = write(kBase);
  try {
    load_case(path, {{"Q", 1.0}});
    FAIL() << "override of a parameter that does not exist was accepted";
  } catch (const CaseError& e) {
    const std::string message = e.what();
    EXPECT_THAT(message, HasSubstr(path));
    EXPECT_THAT(message, HasSubstr("--set Q"));
    EXPECT_THAT(message, HasSubstr("no parameter 'Q'"));
    EXPECT_THAT(message, HasSubstr("theta0"));  // the names it has
  }
}

// ---- frames: axis and angle, a rotation matrix, or directors ----------------------------------

// F at the unknowns the first problem's guess gives, for both problems: equal when their ends
// impose the same frames.
double residual_difference(const Case& a, const Case& b) {
  const ShootingProblem pa(a.definition), pb(b.definition);
  const Eigen::VectorXd x = pa.initial_unknowns(a.start_guess);
  Eigen::VectorXd Fa, Fb;
  std::string failure;
  EXPECT_TRUE(pa.evaluate(x, &Fa, nullptr, &failure)) << failure;
  EXPECT_TRUE(pb.evaluate(x, &Fb, nullptr, &failure)) << failure;
  return (Fa - Fb).cwiseAbs().maxCoeff();
}

std::string shipped(const std::string& name) {
  std::ifstream in(std::string(KIRCHHOFF_CASES_DIR) + "/" + name);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST_F(CaseFileTest, PlanarClampFrameAsDirectorsOrMatrixIsTheAxisAngleFrame) {
  // heavy_cantilever clamped at 0.3 rad: d3 = (cos, sin, 0) the tangent, d1 = (-sin, cos, 0).
  auto clamped = [&](const std::string& orientation) {
    return load_case(write(replaced(shipped("heavy_cantilever.toml"), "position = [0, 0]\n",
                                    "position = [0, 0]\norientation = " + orientation + "\n")));
  };
  const Case angle = clamped("{ axis = [0, 0, 1], angle = 0.3 }");
  // Written out to 1e-16, the frame reproduces the rotation to rounding (F is O(1)).
  EXPECT_LT(residual_difference(angle, clamped("{ d3 = [\"cos(0.3)\", \"sin(0.3)\", 0], d2 = [0, 0, 1] }")), 1e-14);
  EXPECT_LT(residual_difference(angle, clamped("{ d1 = [\"-sin(0.3)\", \"cos(0.3)\", 0], d3 = [\"cos(0.3)\", "
                                               "\"sin(0.3)\", 0] }")), 1e-14);
  EXPECT_LT(residual_difference(angle, clamped("{ matrix = [[\"-sin(0.3)\", 0, \"cos(0.3)\"], "
                                               "[\"cos(0.3)\", 0, \"sin(0.3)\"], [0, 1, 0]] }")), 1e-14);
  // And differs from another angle's (the comparison can fail).
  EXPECT_GT(residual_difference(angle, clamped("{ axis = [0, 0, 1], angle = 0.31 }")), 1e-3);
}

TEST_F(CaseFileTest, SpatialClampFrameAsDirectorsIsTheAxisAngleFrame) {
  auto clamped = [&](const std::string& orientation) {
    return load_case(write(replaced(kSpatialBase, "position = [0, 0, 0]\n\n[end]",
                                    "position = [0, 0, 0]\norientation = " + orientation + "\n\n[end]")));
  };
  // A quarter turn about e1 + e3 ... as directors: the rotation's columns.
  const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 0, 1).normalized()).toRotationMatrix();
  auto row = [&](int i, const Mat3& M) {
    std::ostringstream os;
    os.precision(17);
    os << "[" << M(i, 0) << ", " << M(i, 1) << ", " << M(i, 2) << "]";
    return os.str();
  };
  const Mat3 Rt = R.transpose();  // rows of R^T: the directors
  const Case angle = clamped("{ axis = [1, 0, 1], angle = 0.7 }");
  EXPECT_LT(residual_difference(angle, clamped("{ d1 = " + row(0, Rt) + ", d2 = " + row(1, Rt) + " }")), 1e-14);
  EXPECT_LT(residual_difference(angle, clamped("{ matrix = [" + row(0, R) + ", " + row(1, R) + ", " + row(2, R) + "] }")),
            1e-14);
  EXPECT_GT(residual_difference(angle, clamped("{ axis = [1, 0, 1], angle = 0.71 }")), 1e-3);
}

TEST_F(CaseFileTest, GuessFrameAsDirectors) {
  const std::string text = replaced(kBase, "[guess]\n", "[guess]\norientation = { d3 = [0, 1, 0], d2 = [0, 0, 1] }\n");
  const Case c = load_case(write(text));
  // A planar guess turned a quarter turn: the tangent along e_y.
  EXPECT_LT((c.start_guess.R.col(2) - Vec3::UnitY()).norm(), 1e-15);
  EXPECT_NEAR(c.start_guess.turn_angle, std::acos(0.0), 1e-15);
}

TEST_F(CaseFileTest, FramesThatAreNoRotationAreRefused) {
  auto guess = [&](const std::string& orientation) {
    return replaced(kBase, "[guess]\n", "[guess]\norientation = " + orientation + "\n");
  };
  std::string text = guess("{ d3 = [1, 0.001, 0], d2 = [0, 0, 1] }");
  expect_refused(text, "guess.orientation", {"not orthonormal", "1e-09"}, line_of(text, "orientation"));
  text = guess("{ matrix = [[0, 0, 1], [1, 0, 0], [0, -1, 0]] }");
  expect_refused(text, "guess.orientation", {"left-handed", "det = -1"}, line_of(text, "orientation"));
  text = guess("{ d3 = [1, 0, 0] }");
  expect_refused(text, "guess.orientation", {"two or three of d1, d2, d3"}, line_of(text, "orientation"));
  text = guess("{ d3 = [1, 0, 0], d2 = [0, 0, 1], angle = 1 }");
  expect_refused(text, "guess.orientation", {"give one of"}, line_of(text, "orientation"));
  text = guess("{ d3 = [\"cos(theta0)\", \"sin(theta0)\", 0], d2 = [0, 0, 1] }");
  expect_refused(text, "guess.orientation.d3", {"is fixed", "'theta0'", "axis and angle"}, line_of(text, "orientation"));
  text = guess("{ d3 = [1, 0, 0], d2 = [0, 1, 0] }");  // spatial frame on a planar rod
  expect_refused(text, "guess.orientation", {"a planar rod's frame has d2 = e_z"}, line_of(text, "orientation"));
  text = guess("{ matrix = [[1, 0], [0, 1, 0], [0, 0, 1]] }");
  expect_refused(text, "guess.orientation.matrix", {"each row has 3 numbers"}, line_of(text, "orientation"));
  // Whole turns are counted about an axis: a frame cannot say how many.
  text = replaced(kSpatialBase, "orientation = { axis = [0, 0, 1], angle = \"phi\" }",
                  "orientation = { d1 = [1, 0, 0], d2 = [0, 1, 0] }");
  expect_refused(text, "end.orientation", {"with track_turns, give axis and angle"}, line_of(text, "orientation"));
}

// ---- --solver overrides ----------------------------------------------------------------------

TEST_F(CaseFileTest, SolverOverridesReplaceAndAddSolverKeys) {
  const Case c = load_case(write(kBase), {}, "",
                           {{"tolerance", "1e-11"}, {"stepper", "dopri5"}, {"fallback_search", "true"},
                            {"max_iterations", "7"}, {"unknowns", "[\"P\"]"}});
  const ShootingOptions& o = c.definition.options;
  EXPECT_EQ(o.newton.residual_tolerance, 1e-11);
  EXPECT_EQ(o.integrator.stepper, IntegratorOptions::Stepper::Dopri5);
  EXPECT_TRUE(o.newton.fallback_search);
  EXPECT_EQ(o.newton.max_iterations, 7);
  EXPECT_EQ(c.definition.unknown_parameters, std::vector<std::string>{"P"});
  // Newton's coarse phase: off with 0, or another tolerance; refused beyond 1e-4 or negative.
  EXPECT_EQ(load_case(write(kBase), {}, "", {{"coarse_tolerance", "0"}}).definition.options.newton.coarse_tolerance,
            0.0);
  EXPECT_EQ(load_case(write(kBase), {}, "", {{"coarse_tolerance", "1e-6"}}).definition.options.newton.coarse_tolerance,
            1e-6);
  for (const char* bad : {"1e-3", "-1e-7", "nan"})
    EXPECT_THROW(load_case(write(kBase), {}, "", {{"coarse_tolerance", bad}}), CaseError) << bad;
  // A case without [solver] gains one; a reload keeps the overrides.
  const Case s = load_case(write(kSpatialBase), {}, "", {{"abs_tol", "1e-9"}});
  EXPECT_EQ(s.definition.options.integrator.abs_tol, 1e-9);
  EXPECT_EQ(reload_case(s, {}).definition.options.integrator.abs_tol, 1e-9);
  // A string value may be quoted as in the file.
  const Case q = load_case(write(kBase), {}, "", {{"stepper", "\"dopri5\""}});
  EXPECT_EQ(q.definition.options.integrator.stepper, IntegratorOptions::Stepper::Dopri5);
}

// Refused as the file's value would be, the message naming the option instead of a line.
TEST_F(CaseFileTest, BadSolverOverridesAreRefusedAsInTheFile) {
  const std::string path = write(kBase);
  auto message = [&](const std::string& key, const std::string& value) -> std::string {
    try {
      load_case(path, {}, "", {{key, value}});
    } catch (const CaseError& e) {
      return e.what();
    }
    ADD_FAILURE() << "--solver " << key << "=" << value << " was accepted";
    return "";
  };
  const std::string tolerance = message("tolerance", "1");
  EXPECT_THAT(tolerance, HasSubstr(path + ": --solver tolerance=1: key 'solver.tolerance': must be in (0, 0.01]"));
  EXPECT_THAT(message("tolerance", "small"), HasSubstr("key 'solver.tolerance': must be a number, got a string"));
  EXPECT_THAT(message("tolernace", "1e-9"), HasSubstr("--solver tolernace=1e-9: key 'solver.tolernace': unknown key"));
  EXPECT_THAT(message("stepper", "rk4"), HasSubstr("key 'solver.stepper': 'rk4' is not 'rk78' or 'dopri5'"));
  EXPECT_THAT(message("segments", "1.5"), HasSubstr("key 'solver.segments': must be an integer, got a float"));
  EXPECT_THAT(message("unknowns", "P"), HasSubstr("key 'solver.unknowns': must be an array of strings"));
  EXPECT_THAT(message("max_iterations", "0"), HasSubstr("must be in [1, 10000]"));
}

TEST(ParseSolverOverride, SplitsKeyAndValueText) {
  EXPECT_EQ(parse_solver_override("tolerance=1e-10"), (std::pair<std::string, std::string>{"tolerance", "1e-10"}));
  EXPECT_EQ(parse_solver_override("unknowns=[\"P\", \"Q\"]"),
            (std::pair<std::string, std::string>{"unknowns", "[\"P\", \"Q\"]"}));
  for (const char* bad : {"tolerance", "=1", "tolerance=", "solver.tolerance=1"})
    EXPECT_THROW(parse_solver_override(bad), std::invalid_argument) << bad;
  EXPECT_EQ(parse_solver_overrides({"tolerance=1e-10", "stepper=rk78"}),
            (SolverOverrides{{"tolerance", "1e-10"}, {"stepper", "rk78"}}));
  try {
    parse_solver_overrides({"tolerance=1e-10", "tolerance"});
    ADD_FAILURE() << "accepted";
  } catch (const CaseError& e) {
    EXPECT_THAT(e.what(), HasSubstr("--solver 'tolerance' is not KEY=VALUE"));
  }
}

TEST(ParseOverride, AcceptsNameEqualsNumber) {
  EXPECT_EQ(parse_override("theta0=2.5"), (std::pair<std::string, double>{"theta0", 2.5}));
  EXPECT_EQ(parse_override("P=-1e-3"), (std::pair<std::string, double>{"P", -1e-3}));
}

TEST(ParseOverride, RefusesNonNumericValue) {
  try {
    parse_override("P=abc");
    FAIL() << "'P=abc' was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("'abc'"));
    EXPECT_THAT(std::string(e.what()), HasSubstr("not a number"));
  }
  EXPECT_THROW(parse_override("P=1.5x"), std::invalid_argument);
  EXPECT_THROW(parse_override("P="), std::invalid_argument);
  // A number out of range is still a number: load_case refuses it (input_limits_test.cpp).
  EXPECT_TRUE(std::isinf(parse_override("P=1e999").second));
}

TEST(ParseOverride, RefusesMissingEquals) {
  try {
    parse_override("noequals");
    FAIL() << "'noequals' was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("'noequals'"));
    EXPECT_THAT(std::string(e.what()), HasSubstr("NAME=VALUE"));
  }
  EXPECT_THROW(parse_override("=3"), std::invalid_argument);
}

TEST_F(CaseFileTest, NonFiniteOverrideIsRefused) {
  // stod reads "nan" and "inf"; neither is a usable parameter value. Either parse_override or
  // load_case must refuse it (theta0 has no physical range check of its own).
  const std::string path = write(kBase);
  for (const char* text : {"theta0=nan", "theta0=inf"}) {
    SCOPED_TRACE(text);
    EXPECT_ANY_THROW({
      const auto o = parse_override(text);
      load_case(path, {o});
    });
  }
}

// ---- TOML syntax and files -----------------------------------------------------------------

TEST_F(CaseFileTest, TomlSyntaxError) {
  const std::string text = replaced(kBase, "length = \"L\"", "length = ");
  const std::string path = write(text);
  try {
    load_case(path);
    FAIL() << "a TOML syntax error was accepted";
  } catch (const CaseError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind(path + ": TOML syntax error", 0), 0u) << message;
    // toml11 shows the offending line as " NN | text".
    EXPECT_THAT(message, HasSubstr(std::to_string(line_of(text, "length = ")) + " | length ="));
  }
}

TEST_F(CaseFileTest, DuplicateKeyIsASyntaxError) {
  const std::string text = replaced(kBase, "B = \"EI\"", "B = \"EI\"\nB = 2");
  const std::string path = write(text);
  try {
    load_case(path);
    FAIL() << "a duplicate key was accepted";
  } catch (const CaseError& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr(path + ": TOML syntax error"));
  }
}

TEST_F(CaseFileTest, MissingFile) {
  const std::string path = (dir_ / "does_not_exist.toml").string();
  try {
    load_case(path);
    FAIL() << "a missing file was accepted";
  } catch (const CaseError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind(path + ":", 0), 0u) << message;
    EXPECT_THAT(message, HasSubstr("open"));
  }
}

TEST_F(CaseFileTest, MissingTables) {
  expect_refused(replaced(kBase, "model = \"planar\"\n", ""), "model", {"missing"});
  const std::string no_rod = replaced(kBase, "[rod]\nlength = \"L\"\nB = \"EI\"\n", "");
  expect_refused(no_rod, "rod", {"missing table [rod]"});
  const std::string no_end = replaced(
      kBase, "[end]\ntype = \"sliding\"\naxis = [1, 0, 0]\nposition = [0, 0]\nforce = [\"-P\", 0]\n", "");
  expect_refused(no_end, "end", {"missing table [end]"});
}

// ---- obstacles and the starting active set --------------------------------------------------

// The base with a disc obstacle and a starting contact on it, appended after [output].
std::string with_disc(const std::string& disc = "type = \"cylinder\"\nname = \"pin\"\ncentre = [0.5, \"0.1 - 0.05\"]\nradius = 0.05\n",
                      const std::string& contact = "") {
  return std::string(kBase) + "\n[[obstacles]]\n" + disc + contact;
}

TEST_F(CaseFileTest, DiscObstacleAndStartingContactLoad) {
  const std::string contact = "\n[[guess.contacts]]\nobstacle = \"pin\"\ns = \"L / 2\"\nforce = 3\n";
  // [[guess.contacts]] after [output] is a sub-table of [guess]: the base's [guess] is extended.
  const Case c = load_case(write(with_disc(replaced(
                               "type = \"cylinder\"\nname = \"pin\"\ncentre = [0.5, \"0.1 - 0.05\"]\nradius = 0.05\n",
                               "radius = 0.05", "radius = \"0.05 * L\""), contact)));
  ASSERT_EQ(c.definition.obstacles.size(), 1u);
  EXPECT_EQ(c.definition.obstacles[0].shape(), Obstacle::Shape::Cylinder);
  EXPECT_DOUBLE_EQ(c.definition.obstacles[0].gap(Vec3(0.5, 0.2, 0)), 0.1);
  // The radius uses L: the obstacle moves with it.
  EXPECT_EQ(c.definition.obstacle_parameters, std::set<std::string>{"L"});
  ASSERT_TRUE(c.definition.moving_obstacles);
  Parameters longer = c.definition.parameters;
  longer.set("L", 2.0);
  EXPECT_DOUBLE_EQ(c.definition.moving_obstacles(longer)[0].radius(), 0.1);
  ASSERT_EQ(c.definition.contacts.size(), 1u);
  EXPECT_DOUBLE_EQ(c.definition.contacts[0].s, 0.5);
  EXPECT_DOUBLE_EQ(c.definition.contacts[0].force, 3.0);
}

TEST_F(CaseFileTest, PlectonemeQuantitiesNeedSelfContact) {
  expect_refused(replaced(kBase, "derived = [\"P\", \"y_max\"]", "derived = [\"P\", \"m3\"]"), "output.derived",
                 {"'m3' is a plectoneme quantity", "[rod.self_contact]"});
}

TEST_F(CaseFileTest, BadObstaclesAreRefused) {
  const std::string disc = "type = \"cylinder\"\nname = \"pin\"\ncentre = [0.5, \"0.1 - 0.05\"]\nradius = 0.05\n";
  expect_refused(with_disc(replaced(disc, "cylinder", "sphere")), "obstacles.type", {"plane", "cylinder", "level_set"});
  expect_refused(with_disc(replaced(disc, "radius = 0.05", "radius = 0")), "obstacles.radius", {"must be > 0"});
  expect_refused(with_disc(replaced(disc, "radius = 0.05", "radius = \"-EI\"")), "obstacles.radius", {"must be > 0"});
  expect_refused(with_disc(replaced(disc, "radius = 0.05\n", "")), "obstacles.radius", {"needs a radius"});
  expect_refused(with_disc(disc + "axis = [1, 0, 0]\n"), "obstacles.axis", {"e_z"});
  expect_refused(with_disc(disc + "normal = [0, 1, 0]\n"), "obstacles.normal", {"not a key of a cylinder"});
  expect_refused(with_disc(disc + "radiu = 1\n"), "obstacles.radiu", {"unknown key"});
  expect_refused(with_disc("type = \"level_set\"\ngap = \"y - q\"\n"), "obstacles.gap", {"unknown variable 'q'"});
  expect_refused(with_disc("type = \"level_set\"\ngap = 3\n"), "obstacles.gap", {"expression string in x, y, z"});
  expect_refused(with_disc("type = \"level_set\"\ngap = \"y\"\nstep = -1\n"), "obstacles.step", {"must be > 0"});
  expect_refused(replaced(with_disc("type = \"level_set\"\ngap = \"y\"\n"), "theta0 = 1.0", "x = 1.0\ntheta0 = 1.0"),
                 "obstacles.gap", {"rename the parameter 'x'"});
  expect_refused(with_disc("type = \"plane\"\npoint = [0, 1]\nnormal = [0, 0, 1]\n"), "obstacles.normal",
                 {"lies in the plane"});
  expect_refused(with_disc(disc, "\n[[guess.contacts]]\nobstacle = \"peg\"\ns = 0.5\n"), "guess.contacts.obstacle",
                 {"no obstacle named 'peg'"});
  expect_refused(with_disc(disc, "\n[[guess.contacts]]\nobstacle = \"pin\"\ns = 1.5\n"), "guess.contacts.s",
                 {"inside (0, L)"});
  expect_refused(with_disc(disc, "\n[[guess.contacts]]\nobstacle = \"pin\"\n"), "guess.contacts", {"arclength s"});
  // Extended contacts: s_end after s, force_end only with s_end, and only where they are modelled.
  expect_refused(with_disc(disc, "\n[[guess.contacts]]\nobstacle = \"pin\"\ns = 0.5\ns_end = 0.4\n"),
                 "guess.contacts.s_end", {"inside (s, L)"});
  expect_refused(with_disc(disc, "\n[[guess.contacts]]\nobstacle = \"pin\"\ns = 0.5\nforce_end = 1\n"),
                 "guess.contacts.force_end", {"give s_end too"});
  expect_refused(with_disc("type = \"level_set\"\nname = \"bump\"\ngap = \"y + 0.2\"\n",
                           "\n[[guess.contacts]]\nobstacle = \"bump\"\ns = 0.4\ns_end = 0.6\n"),
                 "guess.contacts.s_end", {"not implemented", "discs"});
}

// ---- every shipped case loads and its problem constructs -----------------------------------

TEST(ShippedCases, EveryCaseLoadsAndConstructs) {
  std::set<std::string> seen;
  for (const auto& entry : fs::directory_iterator(KIRCHHOFF_CASES_DIR)) {
    if (entry.path().extension() != ".toml") continue;
    const std::string path = entry.path().string();
    SCOPED_TRACE(path);
    seen.insert(entry.path().stem().string());
    Case c;
    ASSERT_NO_THROW(c = load_case(path)) << path;
    EXPECT_EQ(c.path, path);
    EXPECT_FALSE(c.title.empty());
    EXPECT_FALSE(c.derived.empty());
    EXPECT_GE(c.samples, 2);
    std::unique_ptr<ShootingProblem> problem;
    ASSERT_NO_THROW(problem = std::make_unique<ShootingProblem>(c.definition));
    EXPECT_GT(problem->size(), static_cast<int>(c.definition.unknown_parameters.size()));
  }
  for (const char* name :
       {"simply_supported", "euler_column", "tapered", "twisted_clamped", "heavy_cantilever", "reissner"})
    EXPECT_TRUE(seen.count(name)) << name << ".toml missing from " << KIRCHHOFF_CASES_DIR;
}

// The guess is the internal n(0), m(0): for the cantilever the clamp holds the weight w L up,
// so n(0) = -w L e_y exactly (statics of the whole rod) and m(0) = -|m(0)| e_z; the guess has
// those signs, and Newton from it reaches the equilibrium hanging down.
TEST(ShippedCases, HeavyCantileverGuessHasTheSignsOfItsEquilibrium) {
  const Case c = load_case(std::string(KIRCHHOFF_CASES_DIR) + "/heavy_cantilever.toml");
  const double w = c.definition.parameters.get("w"), L = c.definition.parameters.get("L");
  EXPECT_EQ(c.start_guess.n.y(), -w * L);
  EXPECT_EQ(c.start_guess.m.z(), -w * L * L / 2);
  ShootingProblem problem(c.definition);
  const ShootingResult r = solve(problem, problem.initial_unknowns(c.start_guess));
  ASSERT_TRUE(r.summary.converged()) << r.summary.brief_report();
  const auto ends = problem.sample(r.x, {0.0, L});
  const RodPoint &start = ends.front(), &tip = ends.back();
  // n(L) = 0 holds to Newton's tolerance (1e-10) and n' = w e_y integrates exactly.
  EXPECT_NEAR(start.n.y(), -w * L, 1e-9);
  EXPECT_LT(start.m.z(), 0.0);
  EXPECT_LT(tip.r.y(), 0.0);
}

// The profile CSV names the planar curvature kappa (= theta' = u2); spatial profiles keep u1, u2, u3.
TEST(ShippedCases, PlanarProfileCsvHasKappaSpatialKeepsU) {
  const fs::path dir = fs::temp_directory_path() / "kirchhoff_profile_csv_test";
  fs::create_directories(dir);
  // The header and the fields of the row at s = L/2 (written as solve --profile writes them).
  auto written = [&](const std::string& name) {
    const Case c = load_case(std::string(KIRCHHOFF_CASES_DIR) + "/" + name);
    ShootingProblem problem(c.definition);
    const ShootingResult r = solve(problem, problem.initial_unknowns(c.start_guess));
    EXPECT_TRUE(r.summary.converged()) << name;
    const double L = problem.length(r.parameters);
    const auto profile = problem.sample(r.x, {0.0, L / 2, L});
    const std::string path = (dir / (name + ".csv")).string();
    write_profile_csv(path, problem.equations(r.parameters)->model(), profile, c.definition.kind);
    std::ifstream in(path);
    std::string header, row;
    std::getline(in, header);
    std::getline(in, row);
    std::getline(in, row);
    auto split = [](const std::string& line) {
      std::vector<std::string> out;
      std::stringstream ss(line);
      for (std::string field; std::getline(ss, field, ',');) out.push_back(field);
      return out;
    };
    return std::make_tuple(header, split(header), split(row), profile[1].u[1]);
  };
  const auto [planar, names, fields, u2] = written("simply_supported.toml");
  EXPECT_THAT(planar, HasSubstr(",mz,kappa,H,"));
  EXPECT_THAT(planar, Not(HasSubstr("u2")));
  ASSERT_EQ(names.size(), fields.size());
  const auto kappa = std::find(names.begin(), names.end(), "kappa") - names.begin();
  EXPECT_EQ(std::stod(fields[static_cast<std::size_t>(kappa)]), u2);  // 17 digits: the double itself
  EXPECT_LT(u2, -1.0);  // theta0 = 1, pinned: curved most at mid-span (kappa_M of eq. 54)
  EXPECT_THAT(std::get<0>(written("twisted_clamped.toml")), HasSubstr(",mz,u1,u2,u3,H,"));
  fs::remove_all(dir);
}

TEST(ShippedCases, TwistedClampedAcceptsTheAxialPhaseCondition) {
  const Case c = load_case(std::string(KIRCHHOFF_CASES_DIR) + "/twisted_clamped.toml", {{"phi", 11.58}}, "axial");
  EXPECT_TRUE(c.definition.parameters.contains("unfolding"));
  EXPECT_NE(std::find(c.definition.unknown_parameters.begin(), c.definition.unknown_parameters.end(), "unfolding"),
            c.definition.unknown_parameters.end());
  EXPECT_NO_THROW(ShootingProblem{c.definition});
}

}  // namespace
}  // namespace kirchhoff
