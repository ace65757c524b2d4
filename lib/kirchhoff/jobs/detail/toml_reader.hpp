// Internal (not installed): typed values read out of a parsed TOML file, every problem an error
// that names the file, the line, the key and the reason, in one wording for the files users write:
// case files (case_reader.hpp's Reader adds expressions of the parameters) and sweep files
// (sweeps/sweep.cpp adds ranges and overrides).
#pragma once

#include <cmath>
#include <cstddef>
#include <set>
#include <sstream>
#include <string>
#include <toml.hpp>
#include <vector>

#include "kirchhoff/jobs/case_file.hpp"

namespace kirchhoff::toml_reading {

using Value = toml::value;

// A number in a message: "1e+100" rather than std::to_string's "10000000000...", and whole
// numbers up to 1e15 exactly (4294967297, not 4.29497e+09).
inline std::string shown(double v) {
  std::ostringstream os;
  os.precision(15);
  os << v;
  return os.str();
}

// "a, b, c".
inline std::string join(const std::set<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

// What a value is, in messages: "must be a number, got a string".
inline std::string type_name(const Value& v) {
  switch (v.type()) {
    case toml::value_t::boolean: return "a boolean";
    case toml::value_t::integer: return "an integer";
    case toml::value_t::floating: return "a float";
    case toml::value_t::string: return "a string";
    case toml::value_t::array: return "an array";
    case toml::value_t::table: return "a table";
    default: return "a date or time";
  }
}

// Values given on the command line (--solver KEY=VALUE) are parsed under this source name, so
// that messages name the option instead of a line of the file.
inline constexpr const char* kSolverOption = "--solver ";
inline bool is_command_line(const Value& v) { return v.location().file_name().rfind(kSolverOption, 0) == 0; }

// Reads typed values out of the TOML tree of the file at `path`, turning every problem into an
// Error (CaseError, SweepError: what the file's loader promises its callers) whose message names
// the file, the line, the key and the reason.
template <class Error>
class KeyReader {
 public:
  explicit KeyReader(std::string path) : path_(std::move(path)) {}

  [[noreturn]] void fail(const Value& v, const std::string& key, const std::string& reason) const {
    std::ostringstream os;
    os << path_;
    const auto line = v.location().line();
    if (is_command_line(v)) os << ": " << v.location().file_name();  // "--solver tolerance=..."
    else if (line > 0) os << ":" << line;
    os << ": key '" << key << "': " << reason;
    throw Error(os.str());
  }
  [[noreturn]] void fail(const std::string& key, const std::string& reason) const {
    throw Error(path_ + ": key '" + key + "': " + reason);
  }

  void allow_keys(const Value& table, const std::string& name, const std::set<std::string>& allowed) const {
    if (!table.is_table()) fail(table, name, "must be a table, got " + type_name(table));
    for (const auto& [key, value] : table.as_table())
      if (!allowed.count(key))
        fail(value, qualified(name, key), "unknown key (expected one of: " + join(allowed) + ")");
  }

  static std::string qualified(const std::string& table, const std::string& key) {
    return table.empty() ? key : table + "." + key;
  }

  // The value at `key` of `table`; null when there is none, or `table` is not a table.
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
    if (std::abs(x) > case_limits::kMaxMagnitude)
      fail(v, key, "must have a magnitude <= " + shown(case_limits::kMaxMagnitude) + " (so that the equations' "
                   "products do not overflow), got " + shown(x) + where);
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
    for (const auto& e : array(v, key, case_limits::kMaxNames, "strings")) out.push_back(string(e, key));
    return out;
  }

  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace kirchhoff::toml_reading
