// Named scalar parameters of a problem: the quantities the paper varies (theta0, P, phi, ...).
// Continuation moves one of them; shooting may treat some as unknowns.
#pragma once

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

  const std::vector<std::string>& names() const { return names_; }
  const std::vector<double>& values() const { return values_; }
  double& value_at(int index) { return values_[index]; }
  int size() const { return static_cast<int>(names_.size()); }

 private:
  std::vector<std::string> names_;
  std::vector<double> values_;
};

}  // namespace kirchhoff
