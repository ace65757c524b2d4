// What `reproduce`'s groups share (reproduce_steps.hpp): a case solved from its guess with its
// stability, the options of their continuations, and the short number format of the notes.
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "kirchhoff/analysis/stability.hpp"
#include "kirchhoff/reproduce/detail/reproduce_steps.hpp"

namespace kirchhoff::reproduce_steps {

Solved solve_for_report(const fs::path& file, const ParameterOverrides& overrides, int samples) {
  const Case c = load_case(file.string(), overrides);
  Solved out;
  out.problem = std::make_unique<ShootingProblem>(c.definition);
  ShootingResult r = solve(*out.problem, out.problem->initial_unknowns(c.start_guess));
  if (!r.summary.converged()) throw std::runtime_error(file.string() + ": " + r.summary.brief_report());
  out.solution = make_solution(*out.problem, std::move(r), samples, c.derived);
  out.stability = describe(analyse_stability(*out.problem, out.solution.result.x));
  return out;
}

RodContinuationOptions report_continuation(const std::string& parameter, double target, double max_step,
                                        ReportPoints points, const std::vector<std::string>& derived) {
  RodContinuationOptions o;
  o.parameter = parameter;
  o.target = target;
  o.max_step = max_step;
  o.derived = derived;
  switch (points) {
    case ReportPoints::Located:
      o.samples = 21;
      break;
    case ReportPoints::Followed:
      o.compute_invariants = false;
      break;
  }
  return o;
}

std::string format_short(double v) {
  std::ostringstream os;
  os << std::setprecision(4) << v;
  return os.str();
}

void state_stability(std::vector<ReportRow>* rows, int count, const std::string& stability) {
  for (auto it = rows->end() - count; it != rows->end(); ++it) it->stability = stability;
}

}  // namespace kirchhoff::reproduce_steps
