#include "kirchhoff/analysis/detail/stability_free_length.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kirchhoff {
namespace {

constexpr const char* kMethod = "conjugate_points+reduced_energy";

// The end as stated without its H condition: the same slot conditions, added again.
EndCondition without_hamiltonian(const EndCondition& end) {
  EndCondition stripped;
  for (const SlotCondition& c : end.conditions()) stripped.add(c);
  return stripped;
}

// Why the sliding-length reduction does not apply to this problem, "" when it does.
std::string unsupported_reason(const ShootingProblem& problem, const std::string& name) {
  const ProblemDefinition& d = problem.definition();
  if (d.obstacle_parameters.count(name))
    return "the unknown parameter '" + name + "' moves an obstacle: it is not a degree of freedom of the energy";
  for (const std::string& other : d.unknown_parameters) {
    if (other == name) continue;
    if (is_unfolding_parameter(other))
      return "a sliding length solved with the axial phase condition's unfolding parameter: not implemented";
    if (d.model_parameters.count(other) || d.obstacle_parameters.count(other))
      return "several unknown parameters change the rod or an obstacle ('" + name + "', '" + other +
             "'): the reduction on one sliding length does not apply";
    return "the sliding length '" + name + "' is solved together with the unknown parameter '" + other +
           "': the reduced energy with a multiplier load is not implemented";
  }
  if (d.start.is_half_turn_symmetry() || d.end.is_half_turn_symmetry())
    return "a sliding length on half of a symmetric rod: not implemented";
  const bool at_start = has_hamiltonian_condition(d.start), at_end = has_hamiltonian_condition(d.end);
  if (at_start == at_end)
    return "the unknown parameter '" + name + "' changes the rod but is not balanced by the continuity of H at " +
           "exactly one end (a sleeve's exit): it is not a sliding length, and no energy is known of which it is "
           "a degree of freedom";
  return "";
}

// Why dE_outside/d ell = -H at the exit (what S rests on) may fail here, "" when it holds: it
// needs a Lagrangian without explicit s (a uniform rod, H conserved) whose only dependence on ell
// is the rod's length, and no field (the part inside the sleeve would feel it, and its energy is
// not part of the case).
std::string energy_slope_reason(const ShootingProblem& problem, const Eigen::VectorXd& x, const std::string& name) {
  const Parameters p = problem.parameters_at(x);
  const auto equations = problem.equations(p);  // held: the next call replaces the problem's cache
  const RodModel& model = equations->model();
  if (model.field)
    return "an external field acts on the sliding rod: the part inside the sleeve feels it too, and its energy is "
           "not part of the case";
  if (!model.is_uniform())
    return "the sliding rod's properties vary along it: the energy's slope in its length is not the jump of H across the exit";
  Parameters moved = p;
  moved.set(name, p.get(name) * (1 + 1e-3) + 1e-3);
  const auto other_equations = problem.equations(problem.completed(moved));
  const RodModel& other = other_equations->model();
  auto same = [](const std::array<Profile, 3>& a, const std::array<Profile, 3>& b) {
    for (int i = 0; i < 3; ++i)
      if (a[i](0.0) != b[i](0.0)) return false;
    return true;
  };
  if (other.extensible != model.extensible || !same(model.B, other.B) || !same(model.A, other.A) ||
      !same(model.u_hat, other.u_hat) || !same(model.v_hat, other.v_hat) || other.field)
    return "the unknown parameter '" + name + "' changes the rod's properties, not only its length: it is not a "
           "sliding length";
  return "";
}

// How many independent directions of `slot` the end holds (the rank of its conditions' bases).
int held_directions(const EndCondition& end, const RodEquations& eq, Slot slot) {
  Eigen::MatrixXd held(3, 0);
  for (const SlotCondition& c : end.conditions()) {
    if (c.slot != slot || c.extra) continue;
    const Eigen::MatrixXd b = c.basis(eq);
    held.conservativeResize(3, held.cols() + b.cols());
    held.rightCols(b.cols()) = b;
  }
  return held.cols() == 0 ? 0 : static_cast<int>(Eigen::FullPivLU<Eigen::MatrixXd>(held).rank());
}

// Why the part inside the sleeve has no known energy, "" when it has: H_inside ell (up to a
// constant) is its energy when it is straight along the exit's fixed tangent under the constant
// axial force H_inside that the H condition names, with a dead load at its inner end. That needs
// the named H not to change with ell, and the exit to hold the rod's position and direction (a
// sleeve free to turn carries the inside part and its load with it: another energy, which the
// case does not describe).
std::string sleeve_reason(const ShootingProblem& problem, const Eigen::VectorXd& x, const std::string& name) {
  const ProblemDefinition& d = problem.definition();
  const EndCondition& exit = has_hamiltonian_condition(d.start) ? d.start : d.end;
  const Parameters p = problem.parameters_at(x);
  Parameters moved = p;
  moved.set(name, p.get(name) * (1 + 1e-3) + 1e-3);
  const auto& inside_H = exit.hamiltonian_condition();
  if (inside_H(problem.completed(moved)) != inside_H(p))
    return "the H that the sleeve's exit is held to changes with the sliding length '" + name +
           "': not the constant H of a straight part under a dead load, so the part inside has no known energy";
  const auto equations = problem.equations(p);
  for (Slot slot : {Slot::Position, Slot::Orientation})
    if (held_directions(exit, *equations, slot) < equations->admissible_directions(slot).cols())
      return "the sleeve's exit does not hold the rod's position and direction: the part inside is not straight "
             "along a fixed line, and its energy is not known";
  return "";
}

// Row k of `full` whose removal, with column `column`, leaves `fixed`: the H row. -1 when none
// does (the two problems do not differ by that row and column alone).
int hamiltonian_row(const Eigen::MatrixXd& full, const Eigen::MatrixXd& fixed, int column) {
  if (full.rows() != fixed.rows() + 1 || full.cols() != fixed.cols() + 1) return -1;
  Eigen::MatrixXd states(full.rows(), fixed.cols());
  states << full.leftCols(column), full.rightCols(full.cols() - column - 1);
  // The same rows computed by the same code at the same state and parameters: equal to round-off.
  const double tol = 1e-9 * (1.0 + fixed.cwiseAbs().maxCoeff());
  for (int k = 0; k < full.rows(); ++k) {
    Eigen::MatrixXd rest(fixed.rows(), fixed.cols());
    rest << states.topRows(k), states.bottomRows(full.rows() - k - 1);
    if ((rest - fixed).cwiseAbs().maxCoeff() <= tol) return k;
  }
  return -1;
}

Eigen::VectorXd without_entry(const Eigen::VectorXd& v, int i) {
  Eigen::VectorXd out(v.size() - 1);
  out << v.head(i), v.tail(v.size() - i - 1);
  return out;
}

// S = -(r_ell - r_x J_fixed^-1 F_ell) and the sizes of its terms, or why it cannot be had.
std::string reduced_curvature(const ShootingProblem& problem, const Eigen::VectorXd& x,
                              const FixedLengthProblem& fixed, double* S, double* scale) {
  Eigen::VectorXd F_full, F_fixed;
  Eigen::MatrixXd J_full, J_fixed;
  std::string failure;
  if (!problem.evaluate(x, &F_full, &J_full, &failure) || !fixed.problem->evaluate(fixed.x, &F_fixed, &J_fixed, &failure))
    return "the shooting Jacobian could not be evaluated: " + failure;
  const int c = fixed.parameter_column;
  const int k = hamiltonian_row(J_full, J_fixed, c);
  if (k < 0) return "the problem with the length held does not differ from the whole one by its H row alone";
  Eigen::VectorXd F_ell = without_entry(J_full.col(c), k);
  Eigen::RowVectorXd r_x = without_entry(J_full.row(k).transpose(), c).transpose();
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(J_fixed);
  const Eigen::VectorXd dx = -lu.solve(F_ell);  // the fixed-length family's tangent dx/d ell
  if (!dx.allFinite() || (J_fixed * dx + F_ell).norm() > 1e-8 * (1.0 + F_ell.norm() + (J_fixed * dx).norm()))
    return "the problem with the length held has a singular Jacobian: the reduction on the length is not defined";
  // The sizes of the products S sums, over which cancellation may lose digits (each has the
  // units of S; r_ell itself vanishes where H is conserved along the rod).
  const double r_ell = J_full(k, c);
  *S = -(r_ell + r_x.dot(dx));
  *scale = std::abs(r_ell) + r_x.cwiseProduct(dx.transpose()).cwiseAbs().sum();
  return "";
}

FreeLengthStability undefined(FreeLengthStability out, const std::string& reason) {
  out.report = StabilityReport{};
  out.report.method = kMethod;
  out.report.reason = reason;
  out.report.rhs_evaluations = out.fixed_length.rhs_evaluations;
  out.report.field_flows = out.fixed_length.field_flows;
  return out;
}

}  // namespace

bool has_hamiltonian_condition(const EndCondition& end) { return static_cast<bool>(end.hamiltonian_condition()); }

std::string sliding_length_reason(const ShootingProblem& problem, const Eigen::VectorXd& x, const std::string& name) {
  if (std::string why = unsupported_reason(problem, name); !why.empty()) return why;
  try {
    if (std::string why = energy_slope_reason(problem, x, name); !why.empty()) return why;
    return sleeve_reason(problem, x, name);
  } catch (const std::exception& e) {
    return std::string("the rod could not be built at a nearby length: ") + e.what();
  }
}

std::string rod_changing_unknown(const ShootingProblem& problem) {
  const ProblemDefinition& d = problem.definition();
  for (const std::string& name : d.unknown_parameters) {
    if (is_unfolding_parameter(name)) continue;
    if (d.model_parameters.count(name) || d.obstacle_parameters.count(name)) return name;
  }
  return "";
}

FixedLengthProblem fixed_length_problem(const ShootingProblem& problem, const Eigen::VectorXd& x,
                                        const std::string& name) {
  if (std::string why = unsupported_reason(problem, name); !why.empty()) throw std::invalid_argument(why);
  const ProblemDefinition& d = problem.definition();
  ProblemDefinition fixed = d;
  fixed.unknown_parameters.clear();
  fixed.parameters.set(name, problem.parameters_at(x).get(name));
  if (has_hamiltonian_condition(d.start)) fixed.start = without_hamiltonian(d.start);
  else fixed.end = without_hamiltonian(d.end);
  FixedLengthProblem out;
  out.problem = std::make_unique<ShootingProblem>(std::move(fixed));
  out.parameter_column = problem.segments() * problem.state_size();  // the only unknown parameter
  out.x = without_entry(x, out.parameter_column);
  return out;
}

FreeLengthStability analyse_free_length(const ShootingProblem& problem, const Eigen::VectorXd& x,
                                        const StabilityOptions& options) {
  FreeLengthStability out;
  out.reduced_curvature = out.curvature_scale = NAN;
  out.parameter = rod_changing_unknown(problem);
  if (out.parameter.empty()) return undefined(out, "no unknown parameter changes the rod: not a sliding length");
  if (std::string why = sliding_length_reason(problem, x, out.parameter); !why.empty()) return undefined(out, why);
  FixedLengthProblem fixed;
  try {
    fixed = fixed_length_problem(problem, x, out.parameter);
  } catch (const std::exception& e) {
    return undefined(out, e.what());
  }
  const std::string held = "with the length '" + out.parameter + "' held: ";
  out.fixed_length = analyse_stability(*fixed.problem, fixed.x, options);
  if (!out.fixed_length.defined()) {
    out = undefined(out, held + out.fixed_length.reason);
    out.report.resolution_limited = out.fixed_length.resolution_limited;
    return out;
  }
  if (out.fixed_length.zero_modes > 0)
    return undefined(out, held + "a zero mode (the second variation is singular), so the reduction on the "
                                 "length is not defined");
  try {
    if (std::string why = reduced_curvature(problem, x, fixed, &out.reduced_curvature, &out.curvature_scale);
        !why.empty())
      return undefined(out, why);
  } catch (const std::exception& e) {
    return undefined(out, std::string("the shooting Jacobian could not be evaluated: ") + e.what());
  }
  out.report = out.fixed_length;
  out.report.method = kMethod;
  const bool fold = std::abs(out.reduced_curvature) <= kFreeLengthZeroTolerance * out.curvature_scale;
  if (fold) out.report.zero_modes += 1;
  *out.report.index += (!fold && out.reduced_curvature < 0) ? 1 : 0;
  out.report.constraint_correction = *out.report.index - out.report.dead_load_index;
  out.report.sliding_length = out.parameter;
  out.report.fixed_length_index = out.fixed_length.index;
  out.report.reduced_energy_curvature = out.reduced_curvature;
  return out;
}

StabilityReport analyse_free_length_stability(const ShootingProblem& problem, const Eigen::VectorXd& x,
                                              const StabilityOptions& options) {
  return analyse_free_length(problem, x, options).report;
}

}  // namespace kirchhoff
