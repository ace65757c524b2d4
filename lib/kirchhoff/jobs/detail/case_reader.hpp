// Internal (not installed): what the case-file loader's section readers share - the Reader that
// turns every problem in the TOML tree into a CaseError naming the file, line, key and reason -
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
#include "kirchhoff/model/detail/expression.hpp"

namespace kirchhoff::case_reading {

using namespace case_limits;
using Value = toml::value;

// "1e+100" rather than std::to_string's "10000000000...".
inline std::string shown(double v) {
  std::ostringstream os;
  os.precision(15);  // whole numbers up to 1e15 exactly (4294967297, not 4.29497e+09)
  os << v;
  return os.str();
}

// "a, b, c".
inline std::string join(const std::set<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

// Values given on the command line (--solver KEY=VALUE) are parsed under this source name, so
// that messages name the option instead of a line of the file.
inline constexpr const char* kSolverOption = "--solver ";
inline bool is_command_line(const Value& v) { return v.location().file_name().rfind(kSolverOption, 0) == 0; }

// Reads typed values out of the TOML tree, turning every problem into a CaseError that names
// the file, the line, the key and the reason.
class Reader {
 public:
  // Expressions may use the parameters, and are checked at their values.
  Reader(std::string path, Parameters parameters)
      : path_(std::move(path)), parameter_names_(parameters.names()), parameters_(std::move(parameters)) {}

  [[noreturn]] void fail(const Value& v, const std::string& key, const std::string& reason) const {
    std::ostringstream os;
    os << path_;
    const auto line = v.location().line();
    if (is_command_line(v)) os << ": " << v.location().file_name();  // "--solver tolerance=..."
    else if (line > 0) os << ":" << line;
    os << ": key '" << key << "': " << reason;
    throw CaseError(os.str());
  }
  [[noreturn]] void fail(const std::string& key, const std::string& reason) const {
    throw CaseError(path_ + ": key '" + key + "': " + reason);
  }

  void allow_keys(const Value& table, const std::string& name, const std::set<std::string>& allowed) const {
    if (!table.is_table()) fail(table, name, "must be a table");
    for (const auto& [key, value] : table.as_table())
      if (!allowed.count(key))
        fail(value, qualified(name, key), "unknown key (expected one of: " + join(allowed) + ")");
  }

  static std::string qualified(const std::string& table, const std::string& key) {
    return table.empty() ? key : table + "." + key;
  }

  static const Value* find(const Value& table, const std::string& key) {
    if (!table.is_table()) return nullptr;
    const auto& t = table.as_table();
    const auto it = t.find(key);
    return it == t.end() ? nullptr : &it->second;
  }

  // TOML allows inf and nan; no quantity of a rod may be either, or beyond kMaxMagnitude.
  double number(const Value& v, const std::string& key) const {
    double x = 0.0;
    if (v.is_floating()) x = v.as_floating();
    else if (v.is_integer()) x = static_cast<double>(v.as_integer());
    else fail(v, key, "must be a number, got " + type_name(v));
    check_magnitude(v, key, x);
    return x;
  }
  void check_magnitude(const Value& v, const std::string& key, double x, const std::string& where = "") const {
    if (!std::isfinite(x)) fail(v, key, "must be a finite number, got " + shown(x) + where);
    if (std::abs(x) > kMaxMagnitude)
      fail(v, key, "must have a magnitude <= " + shown(kMaxMagnitude) + " (so that the equations' products do not "
                   "overflow), got " + shown(x) + where);
  }
  // An integer in [low, high], checked before it is narrowed to int: a TOML integer has 64 bits,
  // and 9223372036854775807 must be refused, not wrapped. `why` says where the bound comes from.
  int integer(const Value& v, const std::string& key, long low, long high, const std::string& why = "") const {
    if (!v.is_integer()) fail(v, key, "must be an integer, got " + type_name(v));
    return in_range(v, key, static_cast<double>(v.as_integer()), low, high, why, std::to_string(v.as_integer()));
  }
  int in_range(const Value& v, const std::string& key, double x, long low, long high, const std::string& why,
               const std::string& as_given = "") const {
    if (!(x >= static_cast<double>(low) && x <= static_cast<double>(high)))
      fail(v, key, "must be in [" + std::to_string(low) + ", " + std::to_string(high) + "]" + why + ", got " +
                       (as_given.empty() ? shown(x) : as_given));
    return static_cast<int>(x);
  }
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
  // An array of at most `most` entries.
  const toml::array& array(const Value& v, const std::string& key, int most, const std::string& what) const {
    if (!v.is_array()) fail(v, key, "must be an array of " + what + ", got " + type_name(v));
    if (v.as_array().size() > static_cast<std::size_t>(most))
      fail(v, key, "has " + std::to_string(v.as_array().size()) + " entries, at most " + std::to_string(most) +
                       " are allowed");
    return v.as_array();
  }
  bool boolean(const Value& v, const std::string& key) const {
    if (v.is_boolean()) return v.as_boolean();
    fail(v, key, "must be true or false, got " + type_name(v));
  }
  std::string string(const Value& v, const std::string& key) const {
    if (v.is_string()) return v.as_string().str;
    fail(v, key, "must be a string, got " + type_name(v));
  }
  std::vector<std::string> strings(const Value& v, const std::string& key) const {
    std::vector<std::string> out;
    for (const auto& e : array(v, key, kMaxNames, "strings")) out.push_back(string(e, key));
    return out;
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

  const std::string& path() const { return path_; }

 private:
  static std::string type_name(const Value& v) {
    std::ostringstream os;
    os << v.type();
    return os.str();
  }
  std::string path_;
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
