#include "kirchhoff/model/detail/expression.hpp"

#include <muParser.h>

#include <algorithm>
#include <functional>
#include <stdexcept>

namespace kirchhoff {
namespace {

// muParser knows pi only as _pi, and as 3.141592653589 (2.5e-13 off): case files say pi, as
// every reader of them would, and both names are the double nearest to pi.
constexpr double kPi = 3.14159265358979323846;
void define_constants(mu::Parser& parser) {
  parser.DefineConst("pi", kPi);
  parser.DefineConst("_pi", kPi);
}

}  // namespace

const std::vector<std::string>& reserved_constant_names() {
  static const std::vector<std::string> names{"pi", "_pi", "_e"};
  return names;
}

// One parser with its variable storage. muParser binds variables by address, so the storage
// lives beside the parser and is refilled before each evaluation.
struct Expression::Compiled {
  mu::Parser parser;
  std::vector<std::string> names;  // parameter names in storage order
  std::vector<double> storage;     // values of names, then s
};

Expression::Expression(const std::string& text, const std::vector<std::string>& parameter_names, bool uses_s)
    : text_(text), compiled_(std::make_shared<Compiled>()) {
  auto& c = *compiled_;
  c.names = parameter_names;
  c.storage.assign(parameter_names.size() + 1, 0.0);
  try {
    define_constants(c.parser);
    for (size_t i = 0; i < parameter_names.size(); ++i) c.parser.DefineVar(parameter_names[i], &c.storage[i]);
    if (uses_s) c.parser.DefineVar("s", &c.storage.back());
    c.parser.SetExpr(text);
    // muParser lists undefined names here too, so every name is checked against ours.
    for (const auto& [name, address] : c.parser.GetUsedVar()) {
      (void)address;
      if (name == "s" && uses_s) {
        depends_on_s_ = true;
      } else if (std::find(parameter_names.begin(), parameter_names.end(), name) != parameter_names.end()) {
        used_.push_back(name);
      } else {
        throw std::invalid_argument("cannot read expression '" + text + "': " +
                                    (name == "s" ? std::string("s is only allowed in material properties (it is the arclength)")
                                                 : "unknown variable '" + name + "' (not in [parameters])"));
      }
    }
  } catch (const mu::Parser::exception_type& e) {
    throw std::invalid_argument("cannot read expression '" + text + "': " + e.GetMsg() +
                                (uses_s ? "" : " (s is only allowed in material properties)"));
  }
}

Expression Expression::constant(double value) {
  Expression e;
  e.text_ = std::to_string(value);
  e.constant_ = value;
  return e;
}

double Expression::operator()(const Parameters& p, double s) const {
  if (!compiled_) return constant_;
  auto& c = *compiled_;
  for (size_t i = 0; i < c.names.size(); ++i) c.storage[i] = p.get(c.names[i]);
  c.storage.back() = s;
  try {
    return c.parser.Eval();
  } catch (const mu::Parser::exception_type& e) {
    throw std::invalid_argument("cannot evaluate '" + text_ + "': " + e.GetMsg());
  }
}

std::function<double(double)> Expression::bind(const Parameters& p) const {
  if (!compiled_) return [v = constant_](double) { return v; };
  // A private copy of the parser so that profiles built for different parameter values (e.g.
  // the two sides of a finite difference) never share variable storage.
  auto c = std::make_shared<Compiled>();
  c->names = compiled_->names;
  c->storage.assign(c->names.size() + 1, 0.0);
  define_constants(c->parser);
  for (size_t i = 0; i < c->names.size(); ++i) {
    c->storage[i] = p.get(c->names[i]);
    c->parser.DefineVar(c->names[i], &c->storage[i]);
  }
  c->parser.DefineVar("s", &c->storage.back());
  c->parser.SetExpr(text_);
  return [c](double s) {
    c->storage.back() = s;
    return c->parser.Eval();
  };
}

}  // namespace kirchhoff
