// Named scalar parameters of a problem: the quantities the paper varies (theta0, P, phi, ...).
// Continuation moves one of them; shooting may treat some as unknowns.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace kirchhoff {

class Parameters {
 public:
  // Adds or overwrites a parameter.
  void set(const std::string& name, double value);
  // Throws std::invalid_argument naming the parameter when it does not exist.
  double get(const std::string& name) const;
  double operator[](const std::string& name) const { return get(name); }
  bool contains(const std::string& name) const { return index_of(name) >= 0; }
  int index_of(const std::string& name) const;

  const std::vector<std::string>& names() const;
  const std::vector<double>& values() const { return values_; }
  double& value_at(int index) { return values_[index]; }
  int size() const { return static_cast<int>(values_.size()); }

 private:
  // The names are shared between copies and replaced, never changed, when one is added: a copy
  // (a problem's parameters at its unknowns, made at every evaluation) allocates for its values
  // only.
  std::shared_ptr<const std::vector<std::string>> names_;
  std::vector<double> values_;
};

// A parameter computed from others: a case's `A = "pi*r^2"`, or a homotopy's interpolation
// between two sets of values. It is never set directly: wherever a problem uses its parameters
// it recomputes these from the others, so that continuing in r moves A with it.
struct DependentParameter {
  std::string name;
  std::function<double(const Parameters&)> value;
  std::vector<std::string> uses;  // the parameters `value` reads (the rod model depends on them if on it)
};

// Recomputes each dependent parameter in order (a later one may use an earlier one).
void complete(Parameters* p, const std::vector<DependentParameter>& dependents);
// The rule computing `name`, or nullptr when `name` is not a dependent parameter.
const DependentParameter* find_dependent(const std::vector<DependentParameter>& dependents, const std::string& name);

}  // namespace kirchhoff
