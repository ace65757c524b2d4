// Internal (not installed): what the case-file loader's section readers share - the Reader that
// turns every problem in the TOML tree into a CaseError naming the file, line, key and reason
// (toml_reader.hpp's KeyReader, which sweep files use too, with expressions added) -
// and the sections read in files of their own: [rod] (case_file_rod.cpp) and [solver] with the
// --solver overrides (case_file_solver.cpp). case_file.cpp reads the rest and load_case_text
// calls them in the order of the file's sections.
#pragma once

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <toml.hpp>
#include <vector>

#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/jobs/detail/toml_reader.hpp"
#include "kirchhoff/model/detail/expression.hpp"

namespace kirchhoff::case_reading {

using namespace case_limits;
using Value = toml::value;

using toml_reading::join;
using toml_reading::kSolverOption;
using toml_reading::shown;
using toml_reading::type_name;

// Reads typed values out of the TOML tree, turning every problem into a CaseError that names
// the file, the line, the key and the reason (toml_reader.hpp); adds what only case files hold:
// expressions of the parameters, checked at the case's values, and tolerances.
class Reader : public toml_reading::KeyReader<CaseError> {
 public:
  // Expressions may use the parameters, and are checked at their values.
  Reader(std::string path, Parameters parameters)
      : KeyReader(std::move(path)), parameter_names_(parameters.names()), parameters_(std::move(parameters)) {}

  // A value in (0, kMaxTolerance].
  double tolerance(const Value& v, const std::string& key) const {
    double x = 0.0;
    if (v.is_floating()) x = v.as_floating();
    else if (v.is_integer()) x = static_cast<double>(v.as_integer());
    else fail(v, key, "must be a number, got " + type_name(v));
    if (!(x > 0 && x <= kMaxTolerance))  // also refuses nan and inf
      fail(v, key, "must be in (0, " + shown(kMaxTolerance) + "] (a looser tolerance gives answers wrong in the "
                   "second digit), got " + shown(x));
    return x;
  }
  // An expression of the parameters (and of s when uses_s). One that does not use s is also
  // evaluated here, at the case's parameter values, and refused unless finite and within
  // kMaxMagnitude ("1/0", "exp(1000)", "1e60 * 1e60"); material profiles are checked along the
  // rod once its length is known.
  Expression expression(const Value& v, const std::string& key, bool uses_s = false) const {
    if (v.is_floating() || v.is_integer()) return Expression::constant(number(v, key));
    if (!v.is_string()) fail(v, key, "must be a number or an expression string, got " + type_name(v));
    std::optional<Expression> e;
    try {
      e.emplace(v.as_string().str, parameter_names_, uses_s);
    } catch (const std::invalid_argument& error) {
      fail(v, key, error.what());
    }
    if (!e->depends_on_s()) (void)value(*e, v, key);
    note_uses(*e, key);
    return *e;
  }

  // The parameters the problem itself (not its [guess]) depends on, as far as read so far.
  const std::set<std::string>& problem_uses() const { return problem_uses_; }

  // e at the case's parameter values and arclength s: finite and within kMaxMagnitude.
  double value(const Expression& e, const Value& v, const std::string& key, double s = 0.0) const {
    double x = 0.0;
    try {
      x = e(parameters_, s);
    } catch (const std::invalid_argument& error) {
      fail(v, key, error.what());
    }
    check_magnitude(v, key, x, e.depends_on_s() ? " at s = " + shown(s) : "");
    return x;
  }

  // An expression of the parameters and the position x, y, z (a level set).
  Expression position_expression(const Value& v, const std::string& key) const {
    if (!v.is_string()) fail(v, key, "must be an expression string in x, y, z, got " + type_name(v));
    std::vector<std::string> names = parameter_names_;
    for (const char* axis : {"x", "y", "z"}) {
      if (std::find(names.begin(), names.end(), axis) != names.end())
        fail(v, key, std::string("x, y and z are the position here; rename the parameter '") + axis + "'");
      names.push_back(axis);
    }
    try {
      Expression e(v.as_string().str, names, false);
      note_uses(e, key);
      return e;
    } catch (const std::invalid_argument& e) {
      fail(v, key, e.what());
    }
  }

  void note_uses(const Expression& e, const std::string& key) const {
    if (key.rfind("guess", 0) == 0) return;
    problem_uses_.insert(e.used_parameters().begin(), e.used_parameters().end());
  }

  std::array<Expression, 3> vector(const Value& v, const std::string& key, bool uses_s = false) const {
    if (!v.is_array() || (v.as_array().size() != 3 && v.as_array().size() != 2))
      fail(v, key, "must be an array of 2 or 3 numbers/expressions");
    const auto& a = v.as_array();
    return {expression(a[0], key, uses_s), expression(a[1], key, uses_s),
            a.size() == 3 ? expression(a[2], key, uses_s) : Expression::constant(0.0)};
  }

  Vec3 unit_vector(const Value& v, const std::string& key) const {
    if (!v.is_array() || v.as_array().size() != 3) fail(v, key, "must be an array of 3 numbers");
    const auto& a = v.as_array();
    const Vec3 out(number(a[0], key), number(a[1], key), number(a[2], key));
    if (!(out.norm() > 0)) fail(v, key, "must be a non-zero vector");
    return out.normalized();
  }

 private:
  std::vector<std::string> parameter_names_;
  Parameters parameters_;
  mutable std::set<std::string> problem_uses_;  // see uses()
};

inline VectorTarget vector_target(const std::array<Expression, 3>& e) {
  return [e](const Parameters& p) { return Vec3(e[0](p), e[1](p), e[2](p)); };
}

// A parameter name muParser can bind: a letter or '_', then letters, digits and '_'.
inline bool is_identifier(const std::string& name) {
  if (name.empty() || std::isdigit(static_cast<unsigned char>(name[0]))) return false;
  return std::all_of(name.begin(), name.end(),
                     [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

// [rod]: its length, material profiles and external fields, checked along the rod at the case's
// parameter values, become d->model (and d->model_parameters). case_file_rod.cpp.
void read_rod(const Reader& reader, const Value& root, const Parameters& parameters, ProblemDefinition* d);

// --solver KEY=VALUE in place of [solver] KEY, so that each is validated, and refused, exactly
// as the file's own value would be. case_file_solver.cpp.
void merge_solver_overrides(Value& root, const SolverOverrides& solver, const std::string& path);

// The phase condition "none" or "axial" (spatial rods), named at `where` when refused.
void apply_phase_condition(const Reader& reader, const Value* where, const std::string& name, ProblemDefinition& d);

// [solver]: d->options and unknowns; its phase_condition unless the caller gives one.
void read_solver(const Reader& reader, const Value& s, const Parameters& parameters,
                 const std::vector<DependentParameter>& dependents, const std::string& phase_condition,
                 ProblemDefinition* d);

}  // namespace kirchhoff::case_reading
