#include "kirchhoff/shooting/shooting.hpp"

#include <algorithm>
#include <sstream>
#include <cmath>
#include <exception>
#include <functional>
#include <optional>
#include <stdexcept>
#include <thread>

#include "kirchhoff/equations/detail/rod_on_cylinder.hpp"
#include "kirchhoff/shooting/detail/contact_conditions.hpp"
#include "kirchhoff/shooting/detail/jacobian_lu.hpp"
#include "kirchhoff/shooting/verification.hpp"

namespace kirchhoff {

using detail::Breakpoint;
using detail::DiscWrap;
using detail::SegmentSpan;
using detail::breakpoints;
using detail::disc_wrap;
using detail::point_contact_terms;
using detail::segment_spans;
using detail::support_of;

namespace {

// Central-difference step for parameter columns, relative to 1 + |p|: the truncation error
// ~h^2 and round-off ~eps/h balance near 1e-6 for the smooth closed-form targets.
constexpr double kParameterStep = 1e-6;

}  // namespace

std::string ShootingOptions::validate() const {
  if (segments < 1) return "segments must be >= 1";
  if (threads < 0) return "threads must be >= 0 (0: the hardware concurrency)";
  if (std::string e = integrator.validate(); !e.empty()) return e;
  return newton.validate();
}

std::string IntegratorOptions::validate() const {
  if (!(abs_tol > 0) || !(rel_tol >= 0)) return "integrator tolerances must be > 0";
  if (!(sensitivity_tol >= 0)) return "sensitivity_tol must be >= 0 (0: the state's tolerances)";
  if (!(initial_step > 0) || initial_step > 1) return "initial_step must be in (0, 1]";
  if (max_steps < 1) return "max_steps must be >= 1";
  if (!(max_step >= 0)) return "max_step must be >= 0 (0: none)";
  return {};
}

ShootingProblem::ShootingProblem(ProblemDefinition definition) : definition_(std::move(definition)) {
  if (std::string e = definition_.options.validate(); !e.empty()) throw std::invalid_argument(e);
  if (!definition_.model) throw std::invalid_argument("no rod model given");
  // A rod with obstacles marches its flows (IntegratorOptions::closed_form): the contact runs'
  // choices at degenerate points were validated on the march's flows only. Where a flat contact
  // buckles into a hanging fold, the fold's direction is a combination of two null vectors
  // (contact.cpp, fold_direction), and with the closed form's flows `continue cavity.toml` took
  // another branch than the one docs/contact.md gives.
  if (!without_obstacles()) definition_.options.integrator.closed_form = false;
  adopt_dependent_parameters();
  const auto eq = equations(definition_.parameters);
  state_size_ = eq->state_size();
  if (std::string e = definition_.start.check(*eq); !e.empty()) throw std::invalid_argument("start: " + e);
  if (std::string e = definition_.end.check(*eq); !e.empty()) throw std::invalid_argument("end: " + e);
  for (const auto& name : definition_.unknown_parameters) {
    const int i = definition_.parameters.index_of(name);
    if (i < 0) throw std::invalid_argument("unknown parameter '" + name + "' is not among the parameters");
    unknown_index_.push_back(i);
  }
  const int extras = definition_.start.extra_count() + definition_.end.extra_count();
  if (extras != static_cast<int>(unknown_index_.size()))
    throw std::invalid_argument(std::to_string(extras) + " extra condition(s) but " +
                                std::to_string(unknown_index_.size()) +
                                " unknown parameter(s): each unknown parameter needs exactly one extra condition");
  // Count residual rows once, at the guess, to make sure the system is square.
  std::vector<double> rows;
  const Eigen::VectorXd y = eq->state(RodPoint{});
  residual_count_ = static_cast<int>(eq->gauge_residual(y, nullptr).size());
  gauge_count_ = residual_count_;
  definition_.start.append_residuals(*eq, true, y, definition_.parameters, &rows, nullptr);
  start_condition_count_ = static_cast<int>(rows.size());
  definition_.end.append_residuals(*eq, false, y, definition_.parameters, &rows, nullptr);
  residual_count_ += static_cast<int>(rows.size()) + (segments() - 1) * state_size_;
  if (!definition_.contacts.empty()) {
    for (const auto& c : definition_.contacts)
      if (c.obstacle < 0 || c.obstacle >= static_cast<int>(definition_.obstacles.size()))
        throw std::invalid_argument("contact on obstacle " + std::to_string(c.obstacle) + ", which does not exist");
    for (const auto& c : definition_.contacts) residual_count_ += c.unknowns();
  }
  // Moving obstacles decide: `obstacles` is kept as their value at the current parameters.
  if (definition_.moving_obstacles) definition_.obstacles = definition_.moving_obstacles(definition_.parameters);
  for (const auto& c : definition_.contacts) {
    if (!c.extended) continue;
    if (std::string e = extended_contact_unsupported(*eq, definition_.obstacles[c.obstacle]); !e.empty())
      throw std::invalid_argument(e);
    // Each way of shooting through a wrap is written once: the closed-form planar ones through a
    // single segment, the spatial rod on a cylinder as a piece of multiple shooting.
    if (eq->is_planar() && segments() > 1)
      throw std::invalid_argument("solver: extended contacts of planar rods need single shooting (segments = 1)");
    if (!eq->is_planar() && segments() == 1)
      throw std::invalid_argument(
          "solver: a spatial rod lying on a cylinder is shot piece by piece: set segments to at least the number of "
          "pieces the contacts cut the rod into");
  }
  if (!definition_.contacts.empty() && segments() > 1) set_piece_segments();
  if (residual_count_ != size())
    throw std::invalid_argument("boundary conditions give " + std::to_string(residual_count_) +
                                " equations for " + std::to_string(size()) + " unknowns");
}

int ShootingProblem::size() const {
  int n = segments() * state_size_ + static_cast<int>(unknown_index_.size());
  for (const auto& c : definition_.contacts) n += c.unknowns();
  return n;
}

void ShootingProblem::adopt_dependent_parameters() {
  const auto& dependents = definition_.dependent_parameters;
  for (const auto& name : definition_.unknown_parameters)
    if (find_dependent(dependents, name))
      throw std::invalid_argument("unknown parameter '" + name + "' is computed from other parameters");
  // Later rules may use earlier ones: walking backwards reaches every parameter a chain uses.
  for (auto d = dependents.rbegin(); d != dependents.rend(); ++d) {
    for (auto* depends : {&definition_.model_parameters, &definition_.obstacle_parameters})
      if (depends->count(d->name)) depends->insert(d->uses.begin(), d->uses.end());
  }
  complete(&definition_.parameters, dependents);
  if (definition_.moving_obstacles) definition_.obstacles = definition_.moving_obstacles(definition_.parameters);
}

Parameters ShootingProblem::completed(Parameters p) const {
  complete(&p, definition_.dependent_parameters);
  return p;
}

std::vector<Obstacle> ShootingProblem::obstacles(const Parameters& p) const {
  if (!definition_.moving_obstacles) return definition_.obstacles;
  return definition_.dependent_parameters.empty() ? definition_.moving_obstacles(p)
                                                  : definition_.moving_obstacles(completed(p));
}

std::shared_ptr<const RodEquations> ShootingProblem::build_equations(const Parameters& p) const {
  RodModel model = definition_.model(p);
  return definition_.kind == RodKind::Planar ? make_planar_equations(std::move(model))
                                             : make_spatial_equations(std::move(model));
}

std::shared_ptr<const RodEquations> ShootingProblem::equations(const Parameters& given) const {
  // Callers that changed a parameter by hand may pass values whose dependents are stale.
  Parameters recomputed;
  if (!definition_.dependent_parameters.empty()) recomputed = completed(given);
  const Parameters& p = definition_.dependent_parameters.empty() ? given : recomputed;
  const auto model_values = [&](auto&& visit) {
    for (const auto& name : definition_.model_parameters)
      if (const int i = p.index_of(name); i >= 0) visit(p.values()[i]);
  };
  return workspace_.equations(model_values, [&] { return build_equations(p); });
}

namespace {

// The machine's hardware concurrency, read once per process: std::thread::hardware_concurrency()
// reads /sys/devices/system/cpu/online on every call, and asked at every evaluation it was 15 % of
// a planar branch's CPU time, in the kernel.
int hardware_threads() {
  static const int threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  return threads;
}

}  // namespace

void ShootingProblem::for_each_segment(const Parameters& p, const std::function<void(int, const RodEquations&)>& work,
                                       bool parallel) const {
  const auto eq = equations(p);
  const int M = segments();
  if (!parallel || M < 8) {
    // Serially, on this thread: no threads, no error slots (an exception reaches the caller as is).
    for (int i = 0; i < M; ++i) work(i, *eq);
    return;
  }
  const int requested = definition_.options.threads > 0 ? definition_.options.threads : hardware_threads();
  const int workers = std::clamp(requested, 1, M / 4);
  const auto& copies = workspace_.workers(workers - 1, [&] { return build_equations(p); });
  // Worker w takes the segments w, w + workers, ... (neighbouring segments cost alike).
  std::vector<std::exception_ptr> errors(workers);
  auto run = [&](int w) {
    const RodEquations& equations = w == 0 ? *eq : *copies[w - 1];
    try {
      for (int i = w; i < M; i += workers) work(i, equations);
    } catch (...) {
      errors[w] = std::current_exception();
    }
  };
  std::vector<std::thread> threads;
  for (int w = 1; w < workers; ++w) threads.emplace_back(run, w);
  run(0);
  for (auto& t : threads) t.join();
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}

bool ShootingProblem::integrate_segments(const Eigen::VectorXd& x, const Parameters& p, bool sensitivities,
                                         const IntegratorOptions& integrator, std::vector<SegmentFlow>* flows,
                                         std::string* failure) const {
  const int n = state_size_, M = segments();
  // Each segment's start state and flow in the workspace's buffers (resized, not rebuilt: their
  // storage is reused), and the work handed to for_each_segment as one pointer, which a
  // std::function holds without allocating.
  auto& starts = workspace_.buffers().starts;
  starts.resize(M);
  for (int i = 0; i < M; ++i) starts[i] = x.segment(i * n, n);
  flows->resize(M);
  struct Work {
    const std::vector<Eigen::VectorXd>& starts;
    std::vector<SegmentFlow>& flows;
    double L;
    int M;
    bool sensitivities;
    const IntegratorOptions& integrator;
  } work{starts, *flows, length(p), M, sensitivities, integrator};
  try {
    for_each_segment(p, [w = &work](int i, const RodEquations& equations) {
      const double s0 = w->L * i / w->M, s1 = w->L * (i + 1) / w->M;
      equations.flow_into(w->starts[i], s0, s1, w->sensitivities, w->integrator, &w->flows[i]);
    });
  } catch (const IntegrationError& e) {
    if (failure) *failure = e.what();
    return false;
  }
  for (const auto& flow : *flows) workspace_.count_rhs(flow.rhs_evaluations);
  return true;
}

Parameters ShootingProblem::parameters_at(const Eigen::VectorXd& x) const {
  Parameters p;
  parameters_into(x, &p);
  return p;
}

void ShootingProblem::parameters_into(const Eigen::VectorXd& x, Parameters* p, int moved, double by) const {
  *p = definition_.parameters;  // (the values' storage reused when *p has as many)
  const int offset = segments() * state_size_;
  for (size_t j = 0; j < unknown_index_.size(); ++j) p->value_at(unknown_index_[j]) = x[offset + j];
  if (moved >= 0) p->value_at(unknown_index_[moved]) = x[offset + moved] + by;
  complete(p, definition_.dependent_parameters);
}

void ShootingProblem::set_parameter(const std::string& name, double value) {
  if (find_dependent(definition_.dependent_parameters, name))
    throw std::invalid_argument("parameter '" + name + "' is computed from other parameters: set those instead");
  definition_.parameters.set(name, value);
  complete(&definition_.parameters, definition_.dependent_parameters);
  if (definition_.moving_obstacles && definition_.obstacle_parameters.count(name))
    definition_.obstacles = definition_.moving_obstacles(definition_.parameters);
}

bool ShootingProblem::moves_beyond_conditions(int unknown) const {
  const std::string& name = definition_.parameters.names()[unknown_index_[unknown]];
  return definition_.model_parameters.count(name) > 0 || definition_.obstacle_parameters.count(name) > 0;
}

bool ShootingProblem::evaluate(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J,
                               std::string* failure) const {
  return evaluate_with_end(x, F, J, &workspace_.buffers().y_end, failure);
}

bool ShootingProblem::without_obstacles() const {
  return definition_.contacts.empty() && definition_.obstacles.empty() && !definition_.moving_obstacles;
}

bool ShootingProblem::has_step_matrices(double tolerance) const {
  const IntegratorOptions& own = definition_.options.integrator;
  return tolerance > std::max(own.sensitivity_tol, own.abs_tol) && without_obstacles();
}

bool ShootingProblem::evaluate_for_step(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J,
                                        double tolerance, std::string* failure) const {
  Eigen::VectorXd& y_end = workspace_.buffers().y_end;
  if (!J || !has_step_matrices(tolerance)) return evaluate_with_end(x, F, J, &y_end, failure);
  IntegratorOptions loose = definition_.options.integrator;
  loose.sensitivity_tol = tolerance;
  return evaluate_with(x, F, J, &y_end, loose, failure);
}

bool ShootingProblem::has_coarse_evaluations(double tolerance) const {
  const IntegratorOptions& own = definition_.options.integrator;
  return tolerance > std::max(own.abs_tol, own.rel_tol) && without_obstacles();
}

bool ShootingProblem::evaluate_coarse(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J,
                                      double tolerance, std::string* failure) const {
  Eigen::VectorXd& y_end = workspace_.buffers().y_end;
  if (!has_coarse_evaluations(tolerance)) return evaluate_with_end(x, F, J, &y_end, failure);
  IntegratorOptions coarse = definition_.options.integrator;
  coarse.abs_tol = coarse.rel_tol = tolerance;
  // The variational equations in their own, looser pass (written out where the equations have
  // them, cheaper than dual numbers): a far step needs its matrix to a few digits.
  coarse.sensitivity_tol = 10.0 * tolerance;
  return evaluate_with(x, F, J, &y_end, coarse, failure);
}

// The looser pass of evaluate_for_step and evaluate_coarse alone, the variational equations with
// the state at `tolerance` (IntegratorOptions::sensitivities_only: the equations' cheaper
// written-out variations where they have them); F is not returned.
bool ShootingProblem::matrix_in_one_pass(const Eigen::VectorXd& x, Eigen::MatrixXd* J, double tolerance,
                                         Eigen::VectorXd* y_end, std::string* failure) const {
  IntegratorOptions one_pass = definition_.options.integrator;
  one_pass.sensitivity_tol = tolerance;
  one_pass.sensitivities_only = one_pass.sensitivity_tol > one_pass.abs_tol;
  return evaluate_with(x, &workspace_.buffers().F_unused, J, y_end, one_pass, failure);
}

bool ShootingProblem::step_matrix(const Eigen::VectorXd& x, Eigen::MatrixXd* J, double tolerance,
                                  std::string* failure) const {
  Eigen::VectorXd& y_end = workspace_.buffers().y_end;
  if (!has_step_matrices(tolerance)) return evaluate_with_end(x, &workspace_.buffers().F_unused, J, &y_end, failure);
  return matrix_in_one_pass(x, J, tolerance, &y_end, failure);
}

bool ShootingProblem::coarse_matrix(const Eigen::VectorXd& x, Eigen::MatrixXd* J, double tolerance,
                                    std::string* failure) const {
  Eigen::VectorXd& y_end = workspace_.buffers().y_end;
  if (!has_coarse_evaluations(tolerance))
    return evaluate_with_end(x, &workspace_.buffers().F_unused, J, &y_end, failure);
  return matrix_in_one_pass(x, J, 10.0 * tolerance, &y_end, failure);  // (evaluate_coarse's matrices' tolerance)
}

bool ShootingProblem::matrix_at_sensitivity_tolerance(const Eigen::VectorXd& x, Eigen::MatrixXd* J,
                                                      Eigen::VectorXd* y_end, std::string* failure) const {
  // (Where sensitivity_tol is not looser than abs_tol the one pass is evaluate_with_end's.)
  return matrix_in_one_pass(x, J, definition_.options.integrator.sensitivity_tol, y_end, failure);
}

bool ShootingProblem::parameter_derivative(const Eigen::VectorXd& x, const std::string& name, Eigen::VectorXd* dF,
                                           std::string* failure, const Eigen::VectorXd* y_end) const {
  const double value = definition_.parameters.get(name);
  const double h = kParameterStep * (1.0 + std::abs(value));
  if (find_dependent(definition_.dependent_parameters, name))
    throw std::invalid_argument("parameter '" + name + "' is computed from other parameters");
  Parameters plus = parameters_at(x), minus = plus;
  plus.set(name, value + h);
  minus.set(name, value - h);
  complete(&plus, definition_.dependent_parameters);
  complete(&minus, definition_.dependent_parameters);
  if (definition_.model_parameters.count(name) || definition_.obstacle_parameters.count(name)) {
    Eigen::VectorXd Fp, Fm, F0;
    std::string plus_failure, minus_failure;
    const bool has_plus = residual(x, plus, &Fp, nullptr, &plus_failure);
    const bool has_minus = residual(x, minus, &Fm, nullptr, &minus_failure);
    if (has_plus && has_minus) {
      *dF = (Fp - Fm) / (2.0 * h);
      return true;
    }
    // One side outside the model's domain (a homotopy from EI = 1 to 2e11 probes EI = 1 - 2e5 h
    // < 0 at its start): the one-sided difference, O(h) where the central one is O(h^2).
    if (has_plus != has_minus && residual(x, parameters_at(x), &F0, nullptr, failure)) {
      *dF = has_plus ? Eigen::VectorXd((Fp - F0) / h) : Eigen::VectorXd((F0 - Fm) / h);
      return true;
    }
    if (failure) *failure = has_plus ? minus_failure : plus_failure;
    return false;
  }
  Eigen::VectorXd end_state;
  if (!y_end) {
    Eigen::VectorXd F;
    if (!residual(x, parameters_at(x), &F, nullptr, failure, &end_state)) return false;
    y_end = &end_state;
  }
  dF->resize(residual_count_);
  condition_column(x, *y_end, plus, minus, h, *dF);
  return true;
}

bool ShootingProblem::evaluate_with_end(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J,
                                        Eigen::VectorXd* y_end_out, std::string* failure) const {
  return evaluate_with(x, F, J, y_end_out, definition_.options.integrator, failure);
}

bool ShootingProblem::evaluate_with(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J,
                                    Eigen::VectorXd* y_end_out, const IntegratorOptions& integrator,
                                    std::string* failure) const {
  Parameters& p = workspace_.buffers().parameters;
  parameters_into(x, &p);
  Eigen::VectorXd& y_end = *y_end_out;
  if (!residual(x, p, F, J, failure, &y_end, &integrator)) return false;
  if (!J) return true;
  // (Before any differencing below integrates again over the flows it reads.)
  const int from_flows = unfolding_column_from_flows(x, p, y_end, J);
  // Parameter columns by central differences (see the header for why this is accurate enough).
  // A parameter that only enters the boundary conditions moves only their rows, which are
  // closed-form in the end states: no re-integration is needed for it.
  const int offset = segments() * state_size_;
  for (size_t j = 0; j < unknown_index_.size(); ++j) {
    if (static_cast<int>(j) == from_flows) continue;
    if (moves_beyond_conditions(static_cast<int>(j))) {
      const double h = kParameterStep * (1.0 + std::abs(x[offset + j]));
      Eigen::VectorXd xp = x, xm = x, Fp, Fm;
      xp[offset + j] += h;
      xm[offset + j] -= h;
      if (!residual(xp, parameters_at(xp), &Fp, nullptr, failure)) return false;
      if (!residual(xm, parameters_at(xm), &Fm, nullptr, failure)) return false;
      J->col(offset + j) = (Fp - Fm) / (2.0 * h);
    } else {
      unknown_condition_column(x, y_end, static_cast<int>(j), J->col(offset + static_cast<Eigen::Index>(j)));
    }
  }
  return true;
}

void ShootingProblem::unknown_condition_column(const Eigen::VectorXd& x, const Eigen::VectorXd& y_end, int unknown,
                                               Eigen::Ref<Eigen::VectorXd> column) const {
  auto& b = workspace_.buffers();
  const double h = kParameterStep * (1.0 + std::abs(x[segments() * state_size_ + unknown]));
  parameters_into(x, &b.plus, unknown, h);
  parameters_into(x, &b.minus, unknown, -h);
  condition_column(x, y_end, b.plus, b.minus, h, column);
}

int ShootingProblem::unfolding_column_from_flows(const Eigen::VectorXd& x, const Parameters& p,
                                                 const Eigen::VectorXd& y_end, Eigen::MatrixXd* J) const {
  if (!definition_.contacts.empty()) return -1;
  const int n = state_size_, M = segments(), offset = M * n;
  int j = -1;
  for (size_t k = 0; k < unknown_index_.size(); ++k)
    if (is_unfolding_parameter(definition_.parameters.names()[unknown_index_[k]])) j = static_cast<int>(k);
  const std::vector<SegmentFlow>& flows = workspace_.buffers().sensitivity_flows;  // (the Jacobian's, just made)
  if (j < 0 || static_cast<int>(flows.size()) != M) return -1;
  for (const SegmentFlow& flow : flows)
    if (flow.dy_dunfolding.size() != n) return -1;
  // Where the conditions name the parameter: their rows' closed-form difference, the states held.
  Eigen::Ref<Eigen::VectorXd> column = J->col(offset + j);
  unknown_condition_column(x, y_end, j, column);
  // Through the flows: the continuity rows y_i(s_{i+1}) - x_{i+1}, then the end rows G(y(L)).
  int row = gauge_count_ + start_condition_count_;
  for (int i = 0; i + 1 < M; ++i, row += n) column.segment(row, n) += flows[i].dy_dunfolding;
  const auto& rows = condition_rows_at(*equations(p), false, flows.back().y, p, true);
  const int end_count = static_cast<int>(rows.end_values.size());
  for (int k = 0; k < end_count; ++k)
    column[residual_count_ - end_count + k] += rows.end_jacobian[k].dot(flows.back().dy_dunfolding);
  return j;
}

void ShootingProblem::condition_column(const Eigen::VectorXd& x, const Eigen::VectorXd& y_end, const Parameters& plus,
                                       const Parameters& minus, double h, Eigen::Ref<Eigen::VectorXd> column) const {
  auto& b = workspace_.buffers();
  b.y0 = x.head(state_size_);
  condition_rows_into(b.y0, y_end, plus, &b.rows_plus);
  condition_rows_into(b.y0, y_end, minus, &b.rows_minus);
  column.setZero();
  // Start rows follow the gauge rows; end rows are the last ones (contact rows lie between).
  const int count = static_cast<int>(b.rows_plus.size());
  for (int k = 0; k < count; ++k)
    column[k < start_condition_count_ ? gauge_count_ + k : residual_count_ - count + k] =
        (b.rows_plus[k] - b.rows_minus[k]) / (2.0 * h);
}

void ShootingProblem::condition_rows_into(const Eigen::VectorXd& y0, const Eigen::VectorXd& y_end,
                                          const Parameters& p, std::vector<double>* rows) const {
  const auto eq = equations(p);
  rows->clear();
  definition_.start.append_residuals(*eq, true, y0, p, rows, nullptr);
  definition_.end.append_residuals(*eq, false, y_end, p, rows, nullptr);
}

int ShootingProblem::start_rows(const RodEquations& eq, const Eigen::VectorXd& y0, const Parameters& p,
                                Eigen::VectorXd* F, Eigen::MatrixXd* J) const {
  const int n = state_size_;
  F->resize(residual_count_);
  if (J) J->setZero(residual_count_, size());
  Eigen::MatrixXd& Jg = workspace_.buffers().gauge_jacobian;
  const GaugeRows g = eq.gauge_residual(y0, J ? &Jg : nullptr);
  F->head(g.size()) = g;
  if (J) J->block(0, 0, g.size(), n) = Jg;
  int row = static_cast<int>(g.size());
  const auto& b = condition_rows_at(eq, true, y0, p, J != nullptr);
  for (size_t k = 0; k < b.start_values.size(); ++k, ++row) {
    (*F)[row] = b.start_values[k];
    if (J) J->block(row, 0, 1, n) = b.start_jacobian[k];
  }
  return row;
}

const ShootingWorkspace::Buffers& ShootingProblem::condition_rows_at(const RodEquations& eq, bool at_start,
                                                                     const Eigen::VectorXd& y, const Parameters& p,
                                                                     bool with_jacobian) const {
  auto& b = workspace_.buffers();
  auto& values = at_start ? b.start_values : b.end_values;
  auto& jacobian = at_start ? b.start_jacobian : b.end_jacobian;
  values.clear();
  jacobian.clear();
  (at_start ? definition_.start : definition_.end)
      .append_residuals(eq, at_start, y, p, &values, with_jacobian ? &jacobian : nullptr);
  return b;
}

void ShootingProblem::end_rows(const RodEquations& eq, const Eigen::VectorXd& y_end, const Parameters& p,
                               const Eigen::MatrixXd* S, Eigen::VectorXd* F, Eigen::MatrixXd* J, int row) const {
  const auto& b = condition_rows_at(eq, false, y_end, p, J != nullptr);
  for (size_t k = 0; k < b.end_values.size(); ++k, ++row) {
    (*F)[row] = b.end_values[k];
    if (J) J->row(row).noalias() = b.end_jacobian[k] * *S;
  }
}

bool ShootingProblem::residual(const Eigen::VectorXd& x, const Parameters& p, Eigen::VectorXd* F,
                               Eigen::MatrixXd* J, std::string* failure, Eigen::VectorXd* y_end,
                               const IntegratorOptions* integrator) const {
  // A Newton or corrector iterate may take a parameter outside the model's domain (a slenderness
  // whose radius is <= 0): that point cannot be evaluated, like one that cannot be integrated.
  std::shared_ptr<const RodEquations> eq;
  try {
    eq = equations(p);
  } catch (const std::invalid_argument& e) {
    if (failure) *failure = std::string("the rod model is not defined there: ") + e.what();
    return false;
  }
  if (!definition_.contacts.empty())
    return segments() > 1 ? residual_pieces(x, p, F, J, failure, y_end)
                          : residual_with_contacts(x, p, F, J, failure, y_end);
  const int n = state_size_, M = segments();
  std::vector<SegmentFlow>& flows = J ? workspace_.buffers().sensitivity_flows : workspace_.buffers().flows;
  if (!integrate_segments(x, p, J != nullptr, integrator ? *integrator : definition_.options.integrator, &flows,
                          failure))
    return false;
  int row = start_rows(*eq, workspace_.buffers().starts.front(), p, F, J);  // (the start state: x's first n)
  for (int i = 0; i + 1 < M; ++i) {
    F->segment(row, n) = flows[i].y - x.segment((i + 1) * n, n);
    if (J) {
      J->block(row, i * n, n, n) = flows[i].Phi;
      J->block(row, (i + 1) * n, n, n) = -Eigen::MatrixXd::Identity(n, n);
    }
    row += n;
  }
  const SegmentFlow& last = flows.back();

  if (y_end) *y_end = last.y;
  const auto& b = condition_rows_at(*eq, false, last.y, p, J != nullptr);
  for (size_t k = 0; k < b.end_values.size(); ++k, ++row) {
    (*F)[row] = b.end_values[k];
    if (J) J->block(row, (M - 1) * n, 1, n).noalias() = b.end_jacobian[k] * last.Phi;
  }
  return true;
}

std::vector<double> ShootingProblem::node_arclengths(const Eigen::VectorXd& x) const {
  const double L = length(parameters_at(x));
  std::vector<double> out;
  if (piece_segments_.empty()) {
    for (int i = 0; i < segments(); ++i) out.push_back(L * i / segments());
    return out;
  }
  for (const auto& span : segment_spans(breakpoints(contacts_at(x), contact_columns()), piece_segments_, L))
    out.push_back(span.s0);
  return out;
}

Eigen::VectorXd ShootingProblem::unknowns_from(const std::vector<RodPoint>& nodes) const {
  if (static_cast<int>(nodes.size()) != segments())
    throw std::invalid_argument("unknowns_from: one point per segment needed");
  const auto eq = equations(definition_.parameters);
  Eigen::VectorXd x = unknowns_without_states();
  // Each node's state continues its neighbour's representation: from the second node on along the
  // rod, and the first (a clamp's frame may leave its representation to round-off) the second's.
  std::vector<Eigen::VectorXd> states(nodes.size());
  for (size_t i = 1; i < nodes.size(); ++i)
    states[i] = i == 1 ? eq->state(nodes[i]) : eq->state_beside(nodes[i], states[i - 1]);
  states[0] = nodes.size() > 1 ? eq->state_beside(nodes[0], states[1]) : eq->state(nodes[0]);
  // The turn angle counts whole turns along the rod; at s = 0 the gauge wants it in [-pi, pi].
  const int turns = eq->turn_angle_index();
  const double offset = states.front()[turns] - nodes.front().turn_angle;
  for (int i = 0; i < segments(); ++i) {
    states[i][turns] = nodes[i].turn_angle + offset;
    x.segment(i * state_size_, state_size_) = states[i];
  }
  return x;
}

Eigen::VectorXd ShootingProblem::unknowns_without_states() const {
  const int n = state_size_, M = segments();
  Eigen::VectorXd x = Eigen::VectorXd::Zero(size());
  for (size_t j = 0; j < unknown_index_.size(); ++j)
    x[M * n + j] = definition_.parameters.values()[unknown_index_[j]];
  for (size_t k = 0; k < definition_.contacts.size(); ++k) {
    const auto& c = definition_.contacts[k];
    const int column = contact_column(k);
    x[column] = c.s;
    x[column + 1] = c.force;
    if (c.extended) {
      x[column + 2] = c.s_end;
      x[column + 3] = c.force_end;
    }
  }
  return x;
}

Eigen::VectorXd ShootingProblem::initial_unknowns(const RodPoint& start_guess) const {
  const auto eq = equations(definition_.parameters);
  RodPoint p0 = start_guess;
  definition_.start.impose_on(*eq, true, definition_.parameters, &p0);
  const int n = state_size_, M = segments();
  Eigen::VectorXd x = unknowns_without_states();
  Eigen::VectorXd y = eq->state(p0);
  if (piece_segments_.empty()) {
    const double L = eq->model().length;
    for (int i = 0; i < M; ++i) {
      x.segment(i * n, n) = y;
      if (i + 1 < M) y = eq->flow(y, L * i / M, L * (i + 1) / M, false, definition_.options.integrator).y;
    }
    return x;
  }
  // Piece by piece, each jump applied with its guessed force.
  const auto points = breakpoints(definition_.contacts, contact_columns());
  const auto spans = segment_spans(points, piece_segments_, eq->model().length);
  const auto on_piece = piece_equations(x, definition_.parameters);
  const auto obstacles_here = obstacles(definition_.parameters);
  const Eigen::MatrixXd force = eq->slot_map(Slot::Force);
  for (int i = 0; i < M; ++i) {
    x.segment(i * n, n) = y;
    if (i + 1 == M) break;
    const RodEquations& e = on_piece[spans[i].piece] ? *on_piece[spans[i].piece] : *eq;
    y = e.flow(y, spans[i].s0, spans[i].s1, false, definition_.options.integrator).y;
    if (spans[i + 1].piece == spans[i].piece) continue;
    const Breakpoint& b = points[spans[i].piece];
    const Obstacle& o = obstacles_here[b.obstacle];
    const Vec3 normal = b.kind == Breakpoint::Point ? point_contact_terms(*eq, o, y, b.s, false).here.normal
                                                    : cylinder_normal(support_of(o), y);
    y -= b.force * force.transpose() * normal;
  }
  return x;
}

std::vector<RodPoint> ShootingProblem::sample(const Eigen::VectorXd& x, const std::vector<double>& s,
                                              const IntegratorOptions* integrator) const {
  const IntegratorOptions& options = integrator ? *integrator : definition_.options.integrator;
  const Parameters p = parameters_at(x);
  const auto eq = equations(p);
  const int n = state_size_, M = segments();
  const double L = eq->model().length;
  std::vector<RodPoint> out;
  out.reserve(s.size());
  size_t k = 0;
  if (!definition_.contacts.empty() && piece_segments_.empty()) {
    // Piece by piece between breakpoints, applying the jump of n at each.
    const auto points = breakpoints(contacts_at(x), contact_columns());
    const std::vector<Obstacle> obstacles_here = obstacles(p);
    const Eigen::MatrixXd force = eq->slot_map(Slot::Force);
    Eigen::VectorXd y = x.head(n);
    double s0 = 0.0;
    std::optional<DiscWrap> wrap;  // set when [s0, next breakpoint] lies on a disc
    for (size_t c = 0; c <= points.size(); ++c) {
      const bool last = c == points.size();
      const double s1 = last ? L : points[c].s;
      std::vector<double> local{s0};
      // The last piece takes every remaining point: an arclength computed as L * i / n can exceed
      // L by an ulp.
      while (k < s.size() && (s[k] < s1 || last)) local.push_back(std::min(s[k++], s1));
      if (wrap) {
        for (size_t j = 1; j < local.size(); ++j) out.push_back(eq->point(wrap->advance(*eq, y, local[j] - s0), local[j]));
        y = wrap->advance(*eq, y, s1 - s0);
        wrap.reset();
      } else {
        if (local.size() > 1) {
          const auto states = eq->sample(y, local, options);
          for (size_t j = 1; j < states.size(); ++j) out.push_back(eq->point(states[j], local[j]));
        }
        if (!last) y = eq->flow(y, s0, s1, false, options).y;
      }
      if (last) break;
      const Obstacle& o = obstacles_here[points[c].obstacle];
      const Eigen::MatrixXd position = eq->slot_map(Slot::Position);
      const Vec3 tangent = position * eq->derivative(y, s1);
      const Vec3 normal = o.contact_conditions(position * y, tangent).normal;
      if (points[c].kind == Breakpoint::ExtendedStart && !o.is_flat()) wrap = disc_wrap(o, tangent, normal);
      y -= points[c].force * force.transpose() * normal;
      s0 = s1;
    }
    return out;
  }
  // Each segment samples the arclengths in it, from its own start state (with contacts, on the
  // equations of its piece: a node after a breakpoint holds the state after the jump).
  std::vector<SegmentSpan> spans;
  std::vector<std::shared_ptr<const RodEquations>> on_piece{nullptr};
  if (piece_segments_.empty()) {
    for (int i = 0; i < M; ++i) {
      SegmentSpan span;
      span.s0 = L * i / M;
      span.s1 = L * (i + 1) / M;
      spans.push_back(span);
    }
  } else {
    spans = segment_spans(breakpoints(contacts_at(x), contact_columns()), piece_segments_, L);
    on_piece = piece_equations(x, p);
  }
  std::vector<std::vector<double>> local(M);
  for (int i = 0; i < M; ++i) {
    local[i] = {spans[i].s0};
    while (k < s.size() && (s[k] < spans[i].s1 || i + 1 == M)) local[i].push_back(std::min(s[k++], spans[i].s1));
  }
  std::vector<std::vector<RodPoint>> points(M);
  for_each_segment(p, [&](int i, const RodEquations& own) {
    if (local[i].size() == 1) return;
    const RodEquations& equations = on_piece[spans[i].piece] ? *on_piece[spans[i].piece] : own;
    const auto states = equations.sample(x.segment(i * n, n), local[i], options);
    for (size_t j = 1; j < states.size(); ++j) points[i].push_back(equations.point(states[j], local[i][j]));
  }, s.size() >= 64);
  for (auto& segment : points) out.insert(out.end(), segment.begin(), segment.end());
  return out;
}

std::string extended_contact_unsupported(const RodEquations& equations, const Obstacle& obstacle) {
  if (!equations.is_planar()) {
    if (obstacle.shape() != Obstacle::Shape::Cylinder)
      return "a spatial rod lying on " + obstacle.describe() +
             " is not implemented: of the obstacles, only cylinders are modelled for spatial rods";
    return rod_on_cylinder_unsupported(equations.model());
  }
  if (obstacle.is_flat()) return "";
  const std::string what = "wrapping around " + obstacle.describe();
  if (obstacle.shape() != Obstacle::Shape::Cylinder || std::abs(std::abs(obstacle.direction().z()) - 1.0) > 1e-12)
    return what + " is not implemented: of the curved obstacles, only discs (cylinders along e_z) are modelled";
  const RodModel& model = equations.model();
  if (model.extensible || !model.is_uniform() || model.field)
    return what + " is modelled for uniform, inextensible rods without an external field (its closed form); "
                  "not implemented for this rod";
  return "";
}

void add_axial_phase_condition(ProblemDefinition& d) {
  if (d.kind != RodKind::Spatial) throw std::invalid_argument("the axial phase condition is for spatial rods");
  const std::string name = kUnfoldingParameter;
  d.parameters.set(name, 0.0);
  d.model = [inner = d.model, name](const Parameters& p) {
    RodModel m = inner(p);
    m.symmetry_unfolding = p.get(name);
    m.unfolding_sensitivity = true;
    return m;
  };
  d.model_parameters.insert(name);
  SlotCondition phase;
  phase.slot = Slot::Moment;
  phase.directions = Directions::AlongAxis;
  phase.axis = Vec3::UnitY();
  phase.value = constant(Vec3::Zero());
  phase.extra = true;
  d.start.add(phase);
  d.unknown_parameters.push_back(name);
}

void limit_wall_clock(ShootingOptions& options, double seconds) { options.newton.deadline = deadline_after(seconds); }

namespace {

// How far above its tolerance a step matrix's reciprocal condition estimate must be for the exact
// Jacobian to be certainly far from singular. The step matrix differs from the exact one by about
// its tolerance (relative), which moves a reciprocal condition number by about as much, and LU's
// estimate may exceed the true value by a factor of the order of the size (tens here): an
// estimate 1e4 times the tolerance (1e-4 at the default 1e-8) leaves the exact matrix's reciprocal
// condition at ~1e-6 or more, six orders above the singular thresholds (1e-12).
constexpr double kClearlyRegular = 1e4;

// Whether the Jacobian at x has a reciprocal condition number at or below `threshold`. The step
// matrix (NewtonOptions::step_matrix_tolerance, a quarter of the exact matrix's cost on a 3D rod)
// answers where it is clearly regular; otherwise the exact matrix decides.
bool singular_at_solution(const ShootingProblem& problem, const Eigen::VectorXd& x, double threshold) {
  Eigen::VectorXd F;
  Eigen::MatrixXd J;
  std::string failure;
  const double step_tolerance = problem.definition().options.newton.step_matrix_tolerance;
  if (problem.has_step_matrices(step_tolerance) && problem.evaluate_for_step(x, &F, &J, step_tolerance, &failure) &&
      JacobianLU(J).reciprocal_condition() > std::max(kClearlyRegular * step_tolerance, threshold))
    return false;
  return problem.evaluate(x, &F, &J, &failure) && !(JacobianLU(J).reciprocal_condition() > threshold);
}

// A single segment whose Jacobian is singular to the solver, or whose residual no step lowers,
// is most often a shooting problem too ill-conditioned for one segment: the fields grow like
// exp(sqrt(P) L) along a rod in tension (the Euler column in tension at P = 1000: singular at one
// segment, converged in 2 iterations at 8), or one whose units are far from 1 (scale_hint). The
// failure says what would help.
void note_single_shooting(const ShootingProblem& problem, const Eigen::VectorXd& x, NewtonSummary* summary) {
  const SolverStatus status = summary->status;
  if (problem.segments() != 1 || (status != SolverStatus::SingularJacobian && status != SolverStatus::LineSearchFailed))
    return;
  std::string hint = scale_hint(problem, x);
  if (hint.empty()) hint = single_segment_hint();
  summary->append_to_message(hint);
}

}  // namespace

// A case whose length or bending stiffness lies decades from 1 (of_unit_scale) is ill-conditioned
// by its units alone, and its residual tolerance (absolute) means something else there: a heavy
// column with EI = 1e6 and weight 7.8e6 came out singular at a residual of 3.5e-9 (4e-16 of its
// forces), where more segments do not help and units of order 1 do. Loads large against B / L^2
// are the rod's own state (a tension, which more segments help), not its units. x: where the
// solve stopped.
std::string scale_hint(const ShootingProblem& problem, const Eigen::VectorXd& x) {
  const RodModel& model = problem.equations(problem.parameters_at(x))->model();
  const double length = model.length, bending = model.B[1](0.0);
  if (of_unit_scale(length, bending)) return "";
  std::ostringstream os;
  os << "the case is far from unit scale (length " << length << ", bending stiffness " << bending
     << ") and the residual tolerance is absolute: give lengths, stiffnesses and loads in units that make them of "
     << "order 1";
  return os.str();
}

std::string single_segment_hint() {
  return "with a single shooting segment; where the rod is long or under a large tension its shooting is "
         "ill-conditioned, and more segments condition it better ([solver] segments in the case file, e.g. "
         "--solver segments=8 on the command line)";
}

std::string unfolding_failure(const Parameters& parameters) {
  if (!parameters.contains(kUnfoldingParameter)) return "";
  const double mu = parameters.get(kUnfoldingParameter);
  if (!(std::abs(mu) > kUnfoldingTolerance)) return "";
  std::ostringstream why;
  why << "unfolding = " << mu << ": not an equilibrium (on the straight rod the axial phase condition is degenerate)";
  return why.str();
}

ShootingResult solve(const ShootingProblem& problem, const Eigen::VectorXd& x0) {
  ShootingResult result;
  result.x = x0;
  result.summary = solve_with_fallback(problem, result.x, problem.definition().options.newton);
  result.parameters = problem.parameters_at(result.x);
  if (!result.summary.converged())
    if (const std::string turns = turn_count_hint(problem, result.x); !turns.empty())
      result.summary.append_to_message(turns);
  note_single_shooting(problem, result.x, &result.summary);
  if (result.summary.converged()) mark_check_failure(&result, unknowns_failure(problem, result));
  if (result.summary.converged()) mark_check_failure(&result, zero_iteration_failure(problem, result));
  if (!result.summary.converged() || !result.parameters.contains(kUnfoldingParameter)) return result;
  if (std::string why = unfolding_failure(result.parameters); !why.empty()) {
    result.summary.status = SolverStatus::UnfoldingNotZero;
    result.summary.message = why;
    return result;
  }
  // A guess that is already a straight solution converges in zero iterations; the phase
  // condition is degenerate there, which shows as a singular Jacobian.
  if (singular_at_solution(problem, result.x, problem.definition().options.newton.singular_rcond * 1e3)) {
    result.summary.status = SolverStatus::SingularJacobian;
    result.summary.message =
        "the axial phase condition is degenerate here (a straight rod): solve it without the phase condition";
  }
  return result;
}

}  // namespace kirchhoff
