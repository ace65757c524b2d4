// Scalar expressions in case files ("-P", "EI*(1 + taper*(s/L - 0.5))"), evaluated by muParser
// with the problem's parameters and, for material profiles, the arclength s as variables.
// Besides muParser's functions and constants (_pi, _e), `pi` is defined; a variable may not
// be named pi, _pi or _e (reserved_constant_names()).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "kirchhoff/model/parameters.hpp"

namespace kirchhoff {

// The constants every expression knows: no parameter may take these names.
const std::vector<std::string>& reserved_constant_names();

class Expression {
 public:
  // Throws std::invalid_argument with muParser's reason (unknown variable, syntax) when the text
  // does not compile against these variable names.
  Expression(const std::string& text, const std::vector<std::string>& parameter_names, bool uses_s);
  static Expression constant(double value);

  // Value with the parameters bound (and s when the expression uses it).
  double operator()(const Parameters& p, double s = 0.0) const;
  // A function of s alone, with the parameters frozen at p (for Profile).
  std::function<double(double)> bind(const Parameters& p) const;
  // Whether the text mentions s, i.e. whether the property varies along the rod.
  bool depends_on_s() const { return depends_on_s_; }
  // Parameter names the text mentions.
  const std::vector<std::string>& used_parameters() const { return used_; }
  const std::string& text() const { return text_; }

 private:
  struct Compiled;
  std::string text_;
  bool depends_on_s_ = false;
  std::vector<std::string> used_;
  std::shared_ptr<Compiled> compiled_;  // null for a constant
  double constant_ = 0.0;
  Expression() = default;
};

}  // namespace kirchhoff
