#include "kirchhoff/model/parameters.hpp"

#include <stdexcept>

namespace kirchhoff {

void Parameters::set(const std::string& name, double value) {
  const int i = index_of(name);
  if (i >= 0) {
    values_[i] = value;
  } else {
    auto grown = names_ ? std::make_shared<std::vector<std::string>>(*names_)
                        : std::make_shared<std::vector<std::string>>();
    grown->push_back(name);
    names_ = std::move(grown);
    values_.push_back(value);
  }
}

const std::vector<std::string>& Parameters::names() const {
  static const std::vector<std::string> none;
  return names_ ? *names_ : none;
}

double Parameters::get(const std::string& name) const {
  const int i = index_of(name);
  if (i < 0) throw std::invalid_argument("unknown parameter '" + name + "'");
  return values_[i];
}

int Parameters::index_of(const std::string& name) const {
  const std::vector<std::string>& all = names();
  for (int i = 0; i < size(); ++i)
    if (all[i] == name) return i;
  return -1;
}

void complete(Parameters* p, const std::vector<DependentParameter>& dependents) {
  for (const auto& d : dependents) p->set(d.name, d.value(*p));
}

const DependentParameter* find_dependent(const std::vector<DependentParameter>& dependents, const std::string& name) {
  for (const auto& d : dependents)
    if (d.name == name) return &d;
  return nullptr;
}

}  // namespace kirchhoff
