// The derived quantities as one table (analysis/derived_quantities.cpp): every name the catalogue
// lists evaluates on solved shipped cases, NaN only where its meaning says so; the evaluator knows
// exactly the catalogue's names.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include "kirchhoff/analysis/detail/derived_quantities.hpp"
#include "kirchhoff/contact/plectoneme.hpp"
#include "kirchhoff/jobs/case_solve.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

bool is_plectoneme_quantity(const std::string& name) {
  const auto& family = plectoneme_quantities();
  return std::any_of(family.begin(), family.end(), [&](const PlectonemeQuantity& q) { return q.name == name; });
}

// The catalogue's names a case can ask for: all of them, the plectoneme's only with self-contact.
std::vector<std::string> names_for(bool self_contact) {
  std::vector<std::string> names;
  for (const auto& [name, meaning] : derived_catalogue())
    if (self_contact || !is_plectoneme_quantity(name)) names.push_back(name);
  return names;
}

// Cases chosen so that between them every rod quantity has a finite value somewhere: no
// obstacle (reissner: spatial, extensible), a soft wall (field), a point contact on a plane (wall)
// and on a disc (indenter), a flat extended contact (cavity at Delta = 0.04, past the contact's
// flattening), a wrap around a disc (wrapped_indenter), half-turn self-contact (plectoneme, with
// the contact region still empty: its own quantities on a real ply are hard_ply_test's).
const std::vector<std::pair<std::string, ParameterOverrides>> kCases = {
    {"reissner.toml", {}},
    {"soft_wall.toml", {}},
    {"wall.toml", {}},
    {"indenter.toml", {}},
    {"cavity.toml", {{"Delta", 0.04}}},
    {"wrapped_indenter.toml", {}},
    {"plectoneme.toml", {}},
};

// The case solved as `kirchhoff solve` solves it (homotopy to the overrides, the active-set loop
// for the contacts), without the stability analysis.
CaseSolve solved(const Case& c) {
  CaseSolveOptions options;
  options.solution = false;
  options.stability = false;
  options.stability_check = false;
  return solve_case(c, options);
}

TEST(DerivedQuantities, EveryCatalogueNameEvaluatesFiniteOrDocumentedNaN) {
  std::set<std::string> finite_somewhere;
  for (const auto& [file, overrides] : kCases) {
    const Case c = load_case(testing::case_path(file), overrides);
    const CaseSolve s = solved(c);
    ASSERT_TRUE(s.converged()) << file << ": " << s.failure << " " << s.message;
    const ShootingProblem& problem = *s.solved.problem;
    const ShootingResult& r = s.solved.result;
    const bool self_contact = half_turn_geometry(problem, r.parameters).has_value();
    const std::vector<std::string> names = names_for(self_contact);
    const Solution sol = make_solution(problem, r, 201, names);
    ASSERT_EQ(sol.derived.size(), names.size()) << file;
    for (const auto& name : names) {
      const double value = sol.derived.at(name);
      if (std::isfinite(value)) {
        finite_somewhere.insert(name);
        continue;
      }
      // Not finite: only a NaN its meaning announces.
      EXPECT_TRUE(std::isnan(value)) << file << ": " << name << " = " << value;
      EXPECT_NE(derived_catalogue().at(name).find("NaN"), std::string::npos)
          << file << ": " << name << " is NaN, which its meaning does not say: " << derived_catalogue().at(name);
    }
  }
  // A quantity that is NaN everywhere would pass the loop above without ever being computed. The
  // plectoneme's contact-region measures are NaN on plectoneme.toml's untwisted rod (a ply takes
  // a continuation of ~30 s, hard_ply_test's), so the family is held to the test below instead.
  for (const auto& [name, meaning] : derived_catalogue())
    if (!is_plectoneme_quantity(name))
      EXPECT_TRUE(finite_somewhere.count(name)) << name << " is finite on none of the cases";
}

// The catalogue and the evaluator read one table: each name in the catalogue evaluates (above), and
// make_solution refuses a name not in it as unknown (case files and events refuse it on loading).
TEST(DerivedQuantities, EvaluatorRefusesExactlyTheNamesTheCatalogueLacks) {
  const testing::Solved s = testing::solve_case("euler_column.toml", {}, "", 21);
  for (const std::string name : {"not_a_quantity", "p", "theta", "helix"}) {
    ASSERT_FALSE(derived_catalogue().count(name)) << name;
    try {
      make_solution(*s.problem, s.solution.result, 21, {name});
      ADD_FAILURE() << name << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()), "unknown derived quantity '" + name + "'");
    }
  }
  // The family rule: every plectoneme quantity is in the catalogue with its table's meaning, and no
  // two of them read the same measure (a row copied and left half-edited).
  std::vector<double PlectonemeMeasures::*> measures;  // (member pointers compare only for equality)
  for (const auto& q : plectoneme_quantities()) {
    ASSERT_TRUE(derived_catalogue().count(q.name)) << q.name;
    EXPECT_EQ(derived_catalogue().at(q.name), q.meaning);
    EXPECT_EQ(std::find(measures.begin(), measures.end(), q.value), measures.end())
        << q.name << " reads a measure another name reads";
    measures.push_back(q.value);
  }
  // A plectoneme quantity of a rod without self-contact is not unknown but unavailable.
  EXPECT_THROW(make_solution(*s.problem, s.solution.result, 21, {"T_ext"}), std::invalid_argument);
}

// The quantities the table marks as reading the start alone come out of a solution described at
// s = 0 (make_start_solution, no integration) bit for bit as out of the whole profile: the same
// start state, the same function. A mark on a quantity that reads more would differ (the end,
// a maximum) or throw here. Every other quantity is refused on such a solution, and
// derived_read_start_only says which lists a continuation may describe so.
TEST(DerivedQuantities, StartOnlyQuantitiesAreTheSameFromTheStartAlone) {
  std::vector<std::string> start_names, other_names;
  for (const auto& [name, meaning] : derived_catalogue())
    (derived_read_start_only({name}) ? start_names : other_names).push_back(name);
  ASSERT_GE(start_names.size(), 5u);  // P, theta0, n_x, ... (the table's marks)
  for (const auto& [file, overrides] : kCases) {
    const Case c = load_case(testing::case_path(file), overrides);
    const CaseSolve s = solved(c);
    ASSERT_TRUE(s.converged()) << file << ": " << s.failure << " " << s.message;
    const ShootingProblem& problem = *s.solved.problem;
    const Solution whole = make_solution(problem, s.solved.result, 21, start_names);
    const Solution start = make_start_solution(problem, s.solved.result, start_names);
    ASSERT_EQ(start.profile.size(), 1u);
    EXPECT_EQ(start.contacts.size(), whole.contacts.size()) << file;
    for (const auto& name : start_names) {
      const double a = start.derived.at(name), b = whole.derived.at(name);
      EXPECT_TRUE(a == b || (std::isnan(a) && std::isnan(b))) << file << ": " << name << " " << a << " vs " << b;
    }
    for (const auto& name : other_names) {
      if (is_plectoneme_quantity(name)) continue;
      EXPECT_THROW(make_start_solution(problem, s.solved.result, {name}), std::logic_error) << file << ": " << name;
    }
  }
  EXPECT_TRUE(derived_read_start_only({}));
  EXPECT_TRUE(derived_read_start_only({"theta0", "P"}));
  EXPECT_FALSE(derived_read_start_only({"theta0", "end_to_end"}));
  EXPECT_FALSE(derived_read_start_only({"not_a_quantity"}));
}

}  // namespace
}  // namespace kirchhoff
