// [solver] of a case file (the shooting options, the unknowns, the phase condition) and the
// --solver KEY=VALUE overrides merged into it before it is read.
#include "kirchhoff/jobs/detail/case_reader.hpp"

namespace kirchhoff {
namespace case_reading {
namespace {

// A --solver value as TOML ("1e-10", "true", "[\"P\"]"); text that is not one TOML value (rk78)
// is the string it spells. Either carries the option as its source, for messages.
Value solver_value(const std::string& path, const std::string& key, const std::string& text) {
  const std::string source = kSolverOption + key + "=" + text;
  auto parsed = [&](const std::string& toml_text) -> std::optional<Value> {
    try {
      std::istringstream in("value = " + toml_text);
      const Value table = toml::parse(in, source);
      if (table.as_table().size() == 1) return table.as_table().at("value");
    } catch (const std::exception&) {
    }
    return std::nullopt;
  };
  if (auto v = parsed(text)) return *v;
  std::string quoted = "\"";
  for (const char ch : text) {
    if (ch == '"' || ch == '\\') quoted += '\\';
    if (static_cast<unsigned char>(ch) < 0x20) throw CaseError(path + ": " + source + ": control characters in the value");
    quoted += ch;
  }
  if (auto v = parsed(quoted + "\"")) return *v;
  throw CaseError(path + ": " + source + ": neither a TOML value nor a string");
}

// [solver].segments: an integer, or an expression of the parameters rounded (e.g. "slenderness
// / 5": long slender rods need more segments, and a sweep's slenderness need not be a multiple of
// 5) evaluated at load time. An expression of no parameter is a number written as a string, and
// must be an integer as a number must. Either is range-checked before it becomes an int ("1e10"
// once wrapped to -129542143).
int read_segments(const Reader& reader, const Value& v, const ProblemDefinition& d) {
  const std::string why = " (Newton's Jacobian is dense: 13 x segments unknowns squared)";
  int segments = 1;
  if (v.is_string()) {
    const Expression e = reader.expression(v, "solver.segments");
    const double x = reader.value(e, v, "solver.segments");
    segments = reader.in_range(v, "solver.segments", std::round(x), 1, kMaxSegments, why);
    if (e.used_parameters().empty() && x != std::round(x))
      reader.fail(v, "solver.segments",
                  "must be an integer, got \"" + v.as_string().str + "\" (an expression of the parameters is rounded)");
  } else {
    segments = reader.integer(v, "solver.segments", 1, kMaxSegments, why);
  }
  if (segments > 1 && !d.obstacles.empty())
    reader.fail(v, "solver.segments", "contact with obstacles needs single shooting (segments = 1)");
  return segments;
}

// [solver].unknowns: parameters of the file (not computed ones) solved for with the state.
std::vector<std::string> read_unknowns(const Reader& reader, const Value& v, const Parameters& parameters,
                                       const std::vector<DependentParameter>& dependents) {
  std::vector<std::string> unknowns = reader.strings(v, "solver.unknowns");
  for (const auto& name : unknowns) {
    if (!parameters.contains(name))
      reader.fail(v, "solver.unknowns", "'" + name + "' is not in [parameters] (give it there with a guess)");
    if (find_dependent(dependents, name))
      reader.fail(v, "solver.unknowns", dependent_parameter_refusal(dependents, name, "solve for"));
  }
  return unknowns;
}

}  // namespace

void apply_phase_condition(const Reader& reader, const Value* where, const std::string& name, ProblemDefinition& d) {
  if (name == "axial") {
    if (d.kind != RodKind::Spatial) reader.fail(*where, "solver.phase_condition", "'axial' is for spatial rods");
    if (d.parameters.contains(kUnfoldingParameter))
      reader.fail(*where, "solver.phase_condition", "needs the parameter name 'unfolding' free");
    add_axial_phase_condition(d);
  } else if (name != "none") {
    reader.fail(*where, "solver.phase_condition", "'" + name + "' is not 'none' or 'axial'");
  }
}

void merge_solver_overrides(Value& root, const SolverOverrides& solver, const std::string& path) {
  if (solver.empty()) return;
  auto& table = root.as_table();
  if (!table.count("solver")) table["solver"] = toml::table{};
  Value& solver_table = table["solver"];
  if (!solver_table.is_table()) return;  // refused as the file's [solver] when read
  for (const auto& [key, text] : solver) solver_table.as_table()[key] = solver_value(path, key, text);
}

void read_solver(const Reader& reader, const Value& s, const Parameters& parameters,
                 const std::vector<DependentParameter>& dependents, const std::string& phase_condition,
                 ProblemDefinition* d) {
  reader.allow_keys(s, "solver", {"unknowns", "segments", "stepper", "abs_tol", "rel_tol", "sensitivity_tol",
                                  "tolerance", "max_iterations", "jacobian", "fallback_search", "phase_condition",
                                  "threads", "coarse_tolerance", "closed_form"});
  ShootingOptions& o = d->options;
  if (const Value* v = Reader::find(s, "unknowns")) d->unknown_parameters = read_unknowns(reader, *v, parameters, dependents);
  if (const Value* v = Reader::find(s, "segments")) o.segments = read_segments(reader, *v, *d);
  if (const Value* v = Reader::find(s, "threads")) {
    o.threads = reader.integer(*v, "solver.threads", 0, kMaxThreads, " (0: the machine's hardware concurrency)");
  }
  if (const Value* v = Reader::find(s, "stepper")) {
    const std::string name = reader.string(*v, "solver.stepper");
    if (name == "rk78") o.integrator.stepper = IntegratorOptions::Stepper::RungeKutta78;
    else if (name == "dopri5") o.integrator.stepper = IntegratorOptions::Stepper::Dopri5;
    else reader.fail(*v, "solver.stepper", "'" + name + "' is not 'rk78' or 'dopri5'");
  }
  auto positive = [&](const char* key, double* target) {
    if (const Value* v = Reader::find(s, key)) *target = reader.tolerance(*v, std::string("solver.") + key);
  };
  positive("abs_tol", &o.integrator.abs_tol);
  positive("rel_tol", &o.integrator.rel_tol);
  positive("sensitivity_tol", &o.integrator.sensitivity_tol);
  positive("tolerance", &o.newton.residual_tolerance);
  if (const Value* v = Reader::find(s, "coarse_tolerance")) {
    const double x = reader.number(*v, "solver.coarse_tolerance");
    if (!(x >= 0.0 && x <= kMaxCoarseTolerance))
      reader.fail(*v, "solver.coarse_tolerance",
                  "must be 0 (no coarse iterations) or in (0, " + shown(kMaxCoarseTolerance) +
                      "] (Newton's far iterations integrated to it), got " + shown(x));
    o.newton.coarse_tolerance = x;
  }
  if (const Value* v = Reader::find(s, "max_iterations")) {
    o.newton.max_iterations = reader.integer(*v, "solver.max_iterations", 1, kMaxIterations,
                                             " (each iteration forms a Jacobian; Newton converges in tens)");
  }
  if (const Value* v = Reader::find(s, "jacobian")) {
    const std::string name = reader.string(*v, "solver.jacobian");
    if (name == "finite_differences") o.newton.finite_difference_jacobian = true;
    else if (name != "variational") reader.fail(*v, "solver.jacobian", "'" + name + "' is not 'variational' or 'finite_differences'");
  }
  if (const Value* v = Reader::find(s, "closed_form")) o.integrator.closed_form = reader.boolean(*v, "solver.closed_form");
  if (const Value* v = Reader::find(s, "fallback_search")) o.newton.fallback_search = reader.boolean(*v, "solver.fallback_search");
  if (const Value* v = Reader::find(s, "phase_condition"); v && phase_condition.empty())
    apply_phase_condition(reader, v, reader.string(*v, "solver.phase_condition"), *d);
}

}  // namespace case_reading

std::pair<std::string, std::string> parse_solver_override(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size())
    throw std::invalid_argument("'" + text + "' is not KEY=VALUE (a [solver] key and its value, e.g. tolerance=1e-10)");
  const std::string key = text.substr(0, eq);
  if (!case_reading::is_identifier(key))
    throw std::invalid_argument("'" + key + "' in '" + text + "' is not a [solver] key");
  return {key, text.substr(eq + 1)};
}

SolverOverrides parse_solver_overrides(const std::vector<std::string>& texts) {
  SolverOverrides out;
  for (const auto& t : texts) {
    try {
      out.push_back(parse_solver_override(t));
    } catch (const std::invalid_argument& e) {
      throw CaseError(std::string("--solver ") + e.what());
    }
  }
  return out;
}

}  // namespace kirchhoff
