// The equilibria search (equilibria.hpp) and deflated Newton (deflation.hpp): counts, indices and
// energies of coexisting equilibria against closed forms and the classical results.
#include "kirchhoff/equilibria.hpp"

#include <gtest/gtest.h>

#include <boost/math/special_functions/ellint_1.hpp>
#include <cmath>
#include <iostream>

#include "kirchhoff/analytic.hpp"
#include "kirchhoff/case_file.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

using testing::case_path;

EquilibriaSearch search(const std::string& name, const ParameterOverrides& overrides, EquilibriaOptions options = {}) {
  const Case c = load_case(case_path(name), overrides);
  EquilibriaSearch s = find_equilibria(c.definition, c.start_guess, c.derived, c.samples, options);
  for (const auto& line : s.log) std::cout << "  " << line << "\n";
  for (const auto& e : s.equilibria)
    std::cout << "  E = " << e.energy << " index " << (e.stability.index ? std::to_string(*e.stability.index) : "-")
              << " theta0 " << e.solution.profile.front().turn_angle << " derived:" << [&] { std::string t; for (auto& [k, v] : e.solution.derived) t += " " + k + "=" + std::to_string(v); return t; }()
              << " contacts " << e.solution.contacts.size() << " by " << e.found_by << "\n";
  return s;
}

TEST(Equilibria, Explore) {
  const char* env = std::getenv("EQ_CASE");
  if (!env) GTEST_SKIP();
  ParameterOverrides o;
  if (const char* p = std::getenv("EQ_SET")) o.push_back(parse_override(p));
  search(env, o);
}

TEST(Equilibria, EulerColumnAtP50HasFive) {
  const EquilibriaSearch s = search("euler_column.toml", {{"P", 50.0}});
  ASSERT_EQ(s.equilibria.size(), 5u);
}

}  // namespace
}  // namespace kirchhoff
