#include "kirchhoff/shooting.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <functional>
#include <optional>
#include <stdexcept>
#include <thread>

#include "kirchhoff/jacobian_lu.hpp"
#include "kirchhoff/rod_on_cylinder.hpp"
#include "kirchhoff/verification.hpp"

namespace kirchhoff {
namespace {

// Central-difference step for parameter columns, relative to 1 + |p|: the truncation error
// ~h^2 and round-off ~eps/h balance near 1e-6 for the smooth closed-form targets.
constexpr double kParameterStep = 1e-6;

struct ConditionRows {
  std::vector<double> values;
  std::vector<Eigen::RowVectorXd> jacobian;
};

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
  return {};
}

ShootingProblem::ShootingProblem(ProblemDefinition definition) : definition_(std::move(definition)) {
  if (std::string e = definition_.options.validate(); !e.empty()) throw std::invalid_argument(e);
  if (!definition_.model) throw std::invalid_argument("no rod model given");
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

double ShootingProblem::contact_bending(const Eigen::VectorXd& x, const PointContact& contact) const {
  const RodPoint p = sample(x, {contact.s}).front();
  const Obstacle o = obstacles(parameters_at(x))[contact.obstacle];
  const Vec3 tangent = p.R * p.v;
  return o.gradient(p.r).dot(p.R * p.u.cross(p.v)) + tangent.dot(o.hessian(p.r) * tangent);
}

double ShootingProblem::flat_contact_margin(const Eigen::VectorXd& x, const PointContact& contact) const {
  if (!contact.extended || !(contact.s_end > contact.s)) return NAN;
  if (!obstacles(parameters_at(x))[contact.obstacle].is_flat()) return NAN;
  const RodPoint p = sample(x, {0.5 * (contact.s + contact.s_end)}).front();
  const double l = contact.s_end - contact.s;
  return 4.0 * M_PI * M_PI * equations(parameters_at(x))->model().B[1](p.s) / (l * l) + p.n.dot(p.R.col(2));
}

double ShootingProblem::wrap_tension(const Eigen::VectorXd& x, const PointContact& contact) const {
  if (!contact.extended || obstacles(parameters_at(x))[contact.obstacle].is_flat()) return NAN;
  if (definition_.kind == RodKind::Spatial) return NAN;
  const RodPoint p = sample(x, {0.5 * (contact.s + contact.s_end)}).front();
  return p.n.dot(p.R.col(2));
}

int ShootingProblem::contact_column(size_t k) const {
  int column = contact_offset();
  for (size_t i = 0; i < k; ++i) column += definition_.contacts[i].unknowns();
  return column;
}

std::vector<PointContact> ShootingProblem::contacts_at(const Eigen::VectorXd& x) const {
  std::vector<PointContact> out = definition_.contacts;
  for (size_t k = 0; k < out.size(); ++k) {
    const int c = contact_column(k);
    out[k].s = x[c];
    out[k].force = x[c + 1];
    if (out[k].extended) {
      out[k].s_end = x[c + 2];
      out[k].force_end = x[c + 3];
    }
  }
  return out;
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
  std::vector<double> key;
  for (const auto& name : definition_.model_parameters)
    if (p.contains(name)) key.push_back(p.get(name));
  if (!cached_equations_ || key != cached_model_values_) {
    cached_equations_ = build_equations(p);
    cached_model_values_ = key;
    worker_equations_.clear();
  }
  return cached_equations_;
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
  while (static_cast<int>(worker_equations_.size()) < workers - 1) worker_equations_.push_back(build_equations(p));
  // Worker w takes the segments w, w + workers, ... (neighbouring segments cost alike).
  std::vector<std::exception_ptr> errors(workers);
  auto run = [&](int w) {
    const RodEquations& equations = w == 0 ? *eq : *worker_equations_[w - 1];
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
                                         std::vector<SegmentFlow>* flows, std::string* failure) const {
  const int n = state_size_, M = segments();
  const double L = length(p);
  flows->assign(M, SegmentFlow{});
  try {
    for_each_segment(p, [&](int i, const RodEquations& equations) {
      (*flows)[i] = equations.flow(x.segment(i * n, n), L * i / M, L * (i + 1) / M, sensitivities,
                                   definition_.options.integrator);
    });
  } catch (const IntegrationError& e) {
    if (failure) *failure = e.what();
    return false;
  }
  for (const auto& flow : *flows) rhs_evaluations_ += flow.rhs_evaluations;
  return true;
}

Parameters ShootingProblem::parameters_at(const Eigen::VectorXd& x) const {
  Parameters p = definition_.parameters;
  const int offset = segments() * state_size_;
  for (size_t j = 0; j < unknown_index_.size(); ++j) p.value_at(unknown_index_[j]) = x[offset + j];
  complete(&p, definition_.dependent_parameters);
  return p;
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
  Eigen::VectorXd y_end;
  return evaluate_with_end(x, F, J, &y_end, failure);
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
    Eigen::VectorXd Fp, Fm;
    if (!residual(x, plus, &Fp, nullptr, failure) || !residual(x, minus, &Fm, nullptr, failure)) return false;
    *dF = (Fp - Fm) / (2.0 * h);
    return true;
  }
  Eigen::VectorXd end_state;
  if (!y_end) {
    Eigen::VectorXd F;
    if (!residual(x, parameters_at(x), &F, nullptr, failure, &end_state)) return false;
    y_end = &end_state;
  }
  const Eigen::VectorXd y0 = x.head(state_size_);
  const Eigen::VectorXd column = (condition_rows(y0, *y_end, plus) - condition_rows(y0, *y_end, minus)) / (2.0 * h);
  dF->setZero(residual_count_);
  place_condition_rows(column, dF);
  return true;
}

void ShootingProblem::place_condition_rows(const Eigen::VectorXd& rows, Eigen::VectorXd* column) const {
  // Start rows follow the gauge rows; end rows are the last ones (contact rows lie between).
  column->segment(gauge_count_, start_condition_count_) = rows.head(start_condition_count_);
  column->tail(rows.size() - start_condition_count_) = rows.tail(rows.size() - start_condition_count_);
}

bool ShootingProblem::evaluate_with_end(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J,
                                        Eigen::VectorXd* y_end_out, std::string* failure) const {
  const Parameters p = parameters_at(x);
  Eigen::VectorXd& y_end = *y_end_out;
  if (!residual(x, p, F, J, failure, &y_end)) return false;
  if (!J) return true;
  // Parameter columns by central differences (see the header for why this is accurate enough).
  // A parameter that only enters the boundary conditions moves only their rows, which are
  // closed-form in the end states: no re-integration is needed for it.
  const int offset = segments() * state_size_;
  const Eigen::VectorXd y0 = x.head(state_size_);
  for (size_t j = 0; j < unknown_index_.size(); ++j) {
    const double h = kParameterStep * (1.0 + std::abs(x[offset + j]));
    Eigen::VectorXd xp = x, xm = x, Fp, Fm;
    xp[offset + j] += h;
    xm[offset + j] -= h;
    if (moves_beyond_conditions(static_cast<int>(j))) {
      if (!residual(xp, parameters_at(xp), &Fp, nullptr, failure)) return false;
      if (!residual(xm, parameters_at(xm), &Fm, nullptr, failure)) return false;
      J->col(offset + j) = (Fp - Fm) / (2.0 * h);
    } else {
      const Eigen::VectorXd rows =
          (condition_rows(y0, y_end, parameters_at(xp)) - condition_rows(y0, y_end, parameters_at(xm))) / (2.0 * h);
      Eigen::VectorXd column = Eigen::VectorXd::Zero(residual_count_);
      place_condition_rows(rows, &column);
      J->col(offset + j) = column;
    }
  }
  return true;
}

Eigen::VectorXd ShootingProblem::condition_rows(const Eigen::VectorXd& y0, const Eigen::VectorXd& y_end,
                                                const Parameters& p) const {
  const auto eq = equations(p);
  std::vector<double> rows;
  definition_.start.append_residuals(*eq, true, y0, p, &rows, nullptr);
  definition_.end.append_residuals(*eq, false, y_end, p, &rows, nullptr);
  return Eigen::Map<Eigen::VectorXd>(rows.data(), static_cast<Eigen::Index>(rows.size()));
}

int ShootingProblem::start_rows(const RodEquations& eq, const Eigen::VectorXd& y0, const Parameters& p,
                                Eigen::VectorXd* F, Eigen::MatrixXd* J) const {
  const int n = state_size_;
  F->resize(residual_count_);
  if (J) J->setZero(residual_count_, size());
  Eigen::MatrixXd Jg;
  const Eigen::VectorXd g = eq.gauge_residual(y0, J ? &Jg : nullptr);
  F->head(g.size()) = g;
  if (J) J->block(0, 0, g.size(), n) = Jg;
  int row = static_cast<int>(g.size());
  ConditionRows start;
  definition_.start.append_residuals(eq, true, y0, p, &start.values, J ? &start.jacobian : nullptr);
  for (size_t k = 0; k < start.values.size(); ++k, ++row) {
    (*F)[row] = start.values[k];
    if (J) J->block(row, 0, 1, n) = start.jacobian[k];
  }
  return row;
}

void ShootingProblem::end_rows(const RodEquations& eq, const Eigen::VectorXd& y_end, const Parameters& p,
                               const Eigen::MatrixXd* S, Eigen::VectorXd* F, Eigen::MatrixXd* J, int row) const {
  ConditionRows end;
  definition_.end.append_residuals(eq, false, y_end, p, &end.values, J ? &end.jacobian : nullptr);
  for (size_t k = 0; k < end.values.size(); ++k, ++row) {
    (*F)[row] = end.values[k];
    if (J) J->row(row) = end.jacobian[k] * *S;
  }
}

bool ShootingProblem::residual(const Eigen::VectorXd& x, const Parameters& p, Eigen::VectorXd* F,
                               Eigen::MatrixXd* J, std::string* failure, Eigen::VectorXd* y_end) const {
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
  const Eigen::VectorXd y0 = x.head(n);
  int row = start_rows(*eq, y0, p, F, J);

  std::vector<SegmentFlow> flows;
  if (!integrate_segments(x, p, J != nullptr, &flows, failure)) return false;
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
  ConditionRows end;
  definition_.end.append_residuals(*eq, false, last.y, p, &end.values, J ? &end.jacobian : nullptr);
  for (size_t k = 0; k < end.values.size(); ++k, ++row) {
    (*F)[row] = end.values[k];
    if (J) J->block(row, (M - 1) * n, 1, n) = end.jacobian[k] * last.Phi;
  }
  return true;
}

namespace {

// A place where n jumps: a point contact, or either end of an extended one.
struct Breakpoint {
  double s;
  double force;
  int obstacle;
  int s_column, force_column;  // their unknowns
  enum Kind { Point, ExtendedStart, ExtendedEnd } kind;
};

// The part of a planar rod wrapped around a disc (see PointContact): each section's state is the
// entry state turned rigidly about the disc's centre by phi = curvature * (s - s_entry) - position,
// tangent and internal force alike, the moment unchanged. That is the exact solution of the
// constrained equations for a uniform inextensible rod: constant curvature gives m' = 0, so n stays
// along the tangent (n = N t), and n' = N t' is the disc's pressure N / radius along its normal.
struct DiscWrap {
  Vec3 centre;
  double curvature = 0.0;  // theta' on the disc, +-1 / radius: the disc on the rod's concave side

  // The state `length` further along the disc, with its derivatives in the state and the length.
  Eigen::VectorXd advance(const RodEquations& eq, const Eigen::VectorXd& y, double length,
                          Eigen::MatrixXd* d_state = nullptr, Eigen::VectorXd* d_length = nullptr) const {
    const Eigen::MatrixXd position = eq.slot_map(Slot::Position), force = eq.slot_map(Slot::Force);
    const Eigen::VectorXd angle = eq.slot_map(Slot::Orientation).row(2).transpose();
    const double phi = curvature * length;
    const Mat3 turn = Eigen::AngleAxisd(phi, Vec3::UnitZ()).toRotationMatrix();
    const Vec3 arm = position * y - centre, n = force * y;
    Eigen::VectorXd out = y + position.transpose() * (turn * arm - arm) + force.transpose() * (turn * n - n) + angle * phi;
    if (d_state) {
      const Mat3 I = Mat3::Identity();
      *d_state = Eigen::MatrixXd::Identity(y.size(), y.size()) + position.transpose() * (turn - I) * position +
                 force.transpose() * (turn - I) * force;
    }
    if (d_length) {
      const auto spin = [&](const Vec3& w) { return Vec3(Vec3::UnitZ().cross(turn * w)); };  // d(turn w)/dphi
      *d_length = curvature * (position.transpose() * spin(arm) + force.transpose() * spin(n) + angle);
    }
    return out;
  }
};

// The wrap that starts where the rod, with tangent t, touches the disc o with reaction normal nu
// (pointing from the disc to the rod): the rod turns towards the centre, theta' = -(t x nu).e_z / radius.
DiscWrap disc_wrap(const Obstacle& o, const Vec3& tangent, const Vec3& normal) {
  return {o.point(), (tangent.cross(normal).z() > 0 ? -1.0 : 1.0) / o.radius()};
}

std::vector<Breakpoint> breakpoints(const std::vector<PointContact>& contacts, const std::vector<int>& columns) {
  std::vector<Breakpoint> out;
  for (size_t k = 0; k < contacts.size(); ++k) {
    const auto& c = contacts[k];
    if (!c.extended) {
      out.push_back({c.s, c.force, c.obstacle, columns[k], columns[k] + 1, Breakpoint::Point});
    } else {
      out.push_back({c.s, c.force, c.obstacle, columns[k], columns[k] + 1, Breakpoint::ExtendedStart});
      out.push_back({c.s_end, c.force_end, c.obstacle, columns[k] + 2, columns[k] + 3, Breakpoint::ExtendedEnd});
    }
  }
  return out;
}

// Whether the breakpoints increase inside (0, L): strictly, except that an extended contact may
// have zero length (when it forms), and a wrap a negative one (traversed backwards: not a rod, but
// the residual stays smooth where a wrap shrinks to a point, so that event is located by crossing).
// Flat contacts are kept >= 0: their legs are degenerate (see run_legs in contact.cpp), and allowed
// a negative length the first step after flattening goes that way.
bool contacts_in_order(const std::vector<Breakpoint>& points, const std::vector<Obstacle>& obstacles, double L) {
  for (size_t k = 0; k < points.size(); ++k) {
    const double previous = k == 0 ? 0.0 : points[k - 1].s;
    const bool wrap_end = points[k].kind == Breakpoint::ExtendedEnd && !obstacles[points[k].obstacle].is_flat();
    const double before_contact = k >= 2 ? points[k - 2].s : 0.0;
    const bool ok = wrap_end ? points[k].s > before_contact
                    : points[k].kind == Breakpoint::ExtendedEnd ? points[k].s >= previous
                                                                : points[k].s > previous;
    if (!ok || !(points[k].s < L)) return false;
  }
  return true;
}

// A segment of multiple shooting with contacts: segment j of the `count` equal ones of its piece
// [a, b] between breakpoints (a = 0 or a contact arclength, b = a contact arclength or L), so
// s0 = a + (b - a) j / count and s1 = a + (b - a) (j + 1) / count. The unknowns that a and b are
// (-1: fixed) and ds0/da, ds0/db, ds1/da, ds1/db.
struct SegmentSpan {
  int piece = 0;
  double s0 = 0.0, s1 = 0.0;
  int a_column = -1, b_column = -1;
  double s0_a = 0.0, s0_b = 0.0, s1_a = 0.0, s1_b = 0.0;
};

std::vector<SegmentSpan> segment_spans(const std::vector<Breakpoint>& points, const std::vector<int>& piece_segments,
                                       double L) {
  std::vector<SegmentSpan> out;
  for (size_t k = 0; k < piece_segments.size(); ++k) {
    const double a = k == 0 ? 0.0 : points[k - 1].s, b = k == points.size() ? L : points[k].s;
    const int count = piece_segments[k];
    for (int j = 0; j < count; ++j) {
      SegmentSpan span;
      span.piece = static_cast<int>(k);
      const double f0 = static_cast<double>(j) / count, f1 = static_cast<double>(j + 1) / count;
      span.s0 = a + (b - a) * f0;
      span.s1 = j + 1 == count ? b : a + (b - a) * f1;  // exactly on the breakpoint
      span.a_column = k == 0 ? -1 : points[k - 1].s_column;
      span.b_column = k == points.size() ? -1 : points[k].s_column;
      span.s0_a = 1.0 - f0;
      span.s0_b = f0;
      span.s1_a = 1.0 - f1;
      span.s1_b = f1;
      out.push_back(span);
    }
  }
  return out;
}

// What a point contact (or the entry of an extended one on a plane or disc) imposes, closed-form
// in the state y at arclength s, with the derivatives the Jacobian needs.
struct PointContactTerms {
  Obstacle::ContactConditions here;  // gap, tangency and the reaction's direction
  Eigen::MatrixXd d_rows;            // 2 x n: gap and tangency in the state
  Eigen::MatrixXd d_normal;          // 3 x n: the direction in the state
  Eigen::Vector2d d_s = Eigen::Vector2d::Zero();  // gap and tangency in s (r' depends on s where natural strains do)
};

PointContactTerms point_contact_terms(const RodEquations& eq, const Obstacle& o, const Eigen::VectorXd& y, double s,
                                      bool derivatives) {
  const Eigen::MatrixXd position = eq.slot_map(Slot::Position);
  auto conditions = [&](const Eigen::VectorXd& state, double at) {
    return o.contact_conditions(position * state, position * eq.derivative(state, at));
  };
  PointContactTerms t;
  t.here = conditions(y, s);
  if (!derivatives) return t;
  // The state derivatives by central differences.
  const int n = static_cast<int>(y.size());
  t.d_rows.resize(2, n);
  t.d_normal = Eigen::MatrixXd::Zero(3, n);
  for (int i = 0; i < n; ++i) {
    const double h = 1e-7 * (1.0 + std::abs(y[i]));
    Eigen::VectorXd yp = y, ym = y;
    yp[i] += h;
    ym[i] -= h;
    const auto plus = conditions(yp, s), minus = conditions(ym, s);
    t.d_rows(0, i) = (plus.gap - minus.gap) / (2 * h);
    t.d_rows(1, i) = (plus.tangency - minus.tangency) / (2 * h);
    t.d_normal.col(i) = (plus.normal - minus.normal) / (2 * h);
  }
  // A plane's gap is linear in the position: exact (the cavity's hanging fold runs so close
  // to branch points that rounding in this row alone can send it onto another branch).
  if (o.is_flat()) t.d_rows.row(0) = o.gradient(position * y).transpose() * position;
  const auto after = conditions(y, s + 1e-7), before = conditions(y, s - 1e-7);
  t.d_s << (after.gap - before.gap) / 2e-7, (after.tangency - before.tangency) / 2e-7;
  return t;
}

// A point contact's two rows at `row` (on the obstacle and tangent to it), with their Jacobian
// through S = dy/dx there and the contact arclength's own column (J null: the rows alone).
// Returns the next row.
int point_contact_rows(const PointContactTerms& t, const Eigen::MatrixXd& S, int s_column, Eigen::VectorXd* F,
                       Eigen::MatrixXd* J, int row) {
  (*F)[row] = t.here.gap;
  (*F)[row + 1] = t.here.tangency;
  if (J) {
    J->row(row) = t.d_rows.row(0) * S;
    J->row(row + 1) = t.d_rows.row(1) * S;
    J->row(row)[s_column] += t.d_s[0];
    J->row(row + 1)[s_column] += t.d_s[1];
  }
  return row + 2;
}

// The cylinder a spatial rod lies on over an extended contact.
CylinderSupport support_of(const Obstacle& o) {
  CylinderSupport c;
  c.point = o.point();
  c.axis = o.direction();
  c.radius = o.radius();
  return c;
}

}  // namespace

std::vector<int> ShootingProblem::contact_columns() const {
  std::vector<int> columns;
  for (size_t k = 0; k < definition_.contacts.size(); ++k) columns.push_back(contact_column(k));
  return columns;
}

bool ShootingProblem::residual_with_contacts(const Eigen::VectorXd& x, const Parameters& p, Eigen::VectorXd* F,
                                             Eigen::MatrixXd* J, std::string* failure, Eigen::VectorXd* y_end) const {
  const auto eq = equations(p);
  const int n = state_size_, N = size();
  const double L = eq->model().length;
  const auto points = breakpoints(contacts_at(x), contact_columns());
  const std::vector<Obstacle> obstacles_here = obstacles(p);
  if (!contacts_in_order(points, obstacles_here, L)) {
    if (failure) *failure = "contact arclengths must increase inside (0, L)";
    return false;
  }
  const Eigen::VectorXd y0 = x.head(n);
  int row = start_rows(*eq, y0, p, F, J);

  // S = dy/dx of the current state, carried through segments and jumps.
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(n, N);
  S.leftCols(n).setIdentity();
  const Eigen::MatrixXd position = eq->slot_map(Slot::Position), force = eq->slot_map(Slot::Force);
  const Eigen::RowVectorXd moment_z = eq->slot_map(Slot::Moment).row(2);
  Eigen::VectorXd y = y0;
  double s0 = 0.0;
  int s0_column = -1;  // the unknown that s0 is, if any
  std::optional<DiscWrap> wrap;  // set when [s0, next breakpoint] lies on a disc
  try {
    for (size_t k = 0; k <= points.size(); ++k) {
      const bool last = k == points.size();
      const double s1 = last ? L : points[k].s;
      if (wrap) {
        Eigen::MatrixXd d_state;
        Eigen::VectorXd d_length;
        y = wrap->advance(*eq, y, s1 - s0, J ? &d_state : nullptr, J ? &d_length : nullptr);
        if (J) {
          S = d_state * S;
          S.col(s0_column) -= d_length;
          S.col(points[k].s_column) += d_length;
        }
        wrap.reset();
      } else {
        SegmentFlow flow = eq->flow(y, s0, s1, J != nullptr, definition_.options.integrator);
        rhs_evaluations_ += flow.rhs_evaluations;
        if (J) {
          S = flow.Phi * S;
          if (s0_column >= 0) S.col(s0_column) -= flow.Phi * eq->derivative(y, s0);
          if (!last) S.col(points[k].s_column) += eq->derivative(flow.y, s1);
        }
        y = flow.y;
      }
      if (last) break;
      const Breakpoint& b = points[k];
      const Obstacle& o = obstacles_here[b.obstacle];
      // What the contact imposes, closed-form in the state here (and in s through r').
      const PointContactTerms terms = point_contact_terms(*eq, o, y, s1, J != nullptr);
      const Obstacle::ContactConditions& here = terms.here;
      const Eigen::VectorXd jump = -force.transpose() * here.normal;  // n jumps by -force * nu
      if (b.kind != Breakpoint::ExtendedEnd) row = point_contact_rows(terms, S, b.s_column, F, J, row);
      if (b.kind == Breakpoint::ExtendedStart) {
        // On the obstacle from here: its curvature (none on a plane), and no normal force once the
        // jump is applied.
        if (!o.is_flat()) wrap = disc_wrap(o, position * eq->derivative(y, s1), here.normal);
        const double kappa = wrap ? wrap->curvature : 0.0;
        const RodModel& model = eq->model();
        const Eigen::RowVectorXd normal_force = here.normal.transpose() * force;
        (*F)[row] = moment_z.dot(y) - model.B[1](s1) * (kappa - model.u_hat[1](s1));
        (*F)[row + 1] = normal_force.dot(y) - b.force;
        if (J) {
          J->row(row) = moment_z * S;
          J->row(row + 1) = normal_force * S;
          (*J)(row + 1, b.force_column) -= 1.0;
        }
        row += 2;
      }
      if (J) {
        // On a curved obstacle the jump's direction turns with the contact point.
        if (!o.is_flat()) S -= b.force * force.transpose() * terms.d_normal * S;
        S.col(b.force_column) += jump;
      }
      y += b.force * jump;
      s0 = s1;
      s0_column = b.s_column;
    }
  } catch (const IntegrationError& e) {
    if (failure) *failure = e.what();
    return false;
  }
  if (y_end) *y_end = y;
  end_rows(*eq, y, p, J ? &S : nullptr, F, J, row);
  return true;
}

void ShootingProblem::set_piece_segments() {
  const auto points = breakpoints(definition_.contacts, contact_columns());
  const int pieces = static_cast<int>(points.size()) + 1, M = segments();
  const std::string what = "solver: " + std::to_string(M) + " segments for the " + std::to_string(pieces) +
                           " pieces the contacts cut the rod into";
  if (M < pieces) throw std::invalid_argument(what + ": each piece needs at least one");
  if (!definition_.piece_segments.empty()) {
    const auto& given = definition_.piece_segments;
    int total = 0;
    for (int count : given) total += count;
    if (static_cast<int>(given.size()) != pieces || total != M ||
        *std::min_element(given.begin(), given.end()) < 1)
      throw std::invalid_argument(what + ": piece_segments must give each piece at least one, " +
                                  std::to_string(M) + " in all");
    piece_segments_ = given;
    return;
  }
  // One each, the rest in proportion to the pieces' lengths (largest remainders first).
  const double L = length(definition_.parameters);
  std::vector<double> quota(pieces);
  double total_length = 0.0;
  for (int k = 0; k < pieces; ++k) {
    const double a = k == 0 ? 0.0 : points[k - 1].s, b = k + 1 == pieces ? L : points[k].s;
    quota[k] = std::max(0.0, b - a);
    total_length += quota[k];
  }
  piece_segments_.assign(pieces, 1);
  const int spare = M - pieces;
  int given_out = 0;
  std::vector<std::pair<double, int>> remainders;
  for (int k = 0; k < pieces; ++k) {
    const double share = total_length > 0.0 ? spare * quota[k] / total_length : 0.0;
    const int whole = static_cast<int>(std::floor(share));
    piece_segments_[k] += whole;
    given_out += whole;
    remainders.push_back({share - whole, k});
  }
  std::sort(remainders.begin(), remainders.end(), std::greater<>());
  for (int i = 0; i < spare - given_out; ++i) ++piece_segments_[remainders[i % pieces].second];
}

std::vector<std::shared_ptr<const RodEquations>> ShootingProblem::piece_equations(const Eigen::VectorXd& x,
                                                                                const Parameters& p) const {
  const auto points = breakpoints(contacts_at(x), contact_columns());
  const auto obstacles_here = obstacles(p);
  std::vector<std::shared_ptr<const RodEquations>> out(points.size() + 1);  // null: the rod's own
  for (size_t k = 0; k < points.size(); ++k)
    if (points[k].kind == Breakpoint::ExtendedStart)
      out[k + 1] = make_spatial_equations_on_cylinder(equations(p)->model(), support_of(obstacles_here[points[k].obstacle]));
  return out;
}

bool ShootingProblem::residual_pieces(const Eigen::VectorXd& x, const Parameters& p, Eigen::VectorXd* F,
                                      Eigen::MatrixXd* J, std::string* failure, Eigen::VectorXd* y_end) const {
  const auto eq = equations(p);
  const int n = state_size_, M = segments(), N = size();
  const double L = eq->model().length;
  const auto points = breakpoints(contacts_at(x), contact_columns());
  const std::vector<Obstacle> obstacles_here = obstacles(p);
  if (!contacts_in_order(points, obstacles_here, L)) {
    if (failure) *failure = "contact arclengths must increase inside (0, L)";
    return false;
  }
  const auto spans = segment_spans(points, piece_segments_, L);
  std::vector<std::shared_ptr<const RodEquations>> on_piece;
  try {
    on_piece = piece_equations(x, p);
  } catch (const std::invalid_argument& e) {
    if (failure) *failure = e.what();
    return false;
  }
  auto equations_of = [&](int i, const RodEquations& own) -> const RodEquations& {
    const auto& special = on_piece[spans[i].piece];
    return special ? *special : own;
  };
  int row = start_rows(*eq, x.head(n), p, F, J);

  std::vector<SegmentFlow> flows(M);
  try {
    for_each_segment(p, [&](int i, const RodEquations& own) {
      flows[i] = equations_of(i, own).flow(x.segment(i * n, n), spans[i].s0, spans[i].s1, J != nullptr,
                                           definition_.options.integrator);
    });
  } catch (const IntegrationError& e) {
    if (failure) *failure = e.what();
    return false;
  }
  for (const auto& flow : flows) rhs_evaluations_ += flow.rhs_evaluations;

  // A segment's end state moves with the ends of its piece: d y1 / d s0 = -Phi y'(s0), d y1 / d s1 =
  // y'(s1), times how s0 and s1 move with the breakpoints.
  auto add_span_columns = [&](int i, const std::function<void(int, const Eigen::VectorXd&)>& add) {
    const SegmentSpan& span = spans[i];
    const RodEquations& e = equations_of(i, *eq);
    const Eigen::VectorXd d0 = -flows[i].Phi * e.derivative(x.segment(i * n, n), span.s0);
    const Eigen::VectorXd d1 = e.derivative(flows[i].y, span.s1);
    if (span.a_column >= 0) add(span.a_column, span.s0_a * d0 + span.s1_a * d1);
    if (span.b_column >= 0) add(span.b_column, span.s0_b * d0 + span.s1_b * d1);
  };
  const Eigen::MatrixXd force = eq->slot_map(Slot::Force);
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(n, n);
  for (int i = 0; i < M; ++i) {
    const bool last = i + 1 == M;
    if (!last && spans[i + 1].piece == spans[i].piece) {
      F->segment(row, n) = flows[i].y - x.segment((i + 1) * n, n);
      if (J) {
        J->block(row, i * n, n, n) = flows[i].Phi;
        J->block(row, (i + 1) * n, n, n) = -I;
        add_span_columns(i, [&](int c, const Eigen::VectorXd& v) { J->block(row, c, n, 1) += v; });
      }
      row += n;
      continue;
    }
    // The end of a piece: a breakpoint, or s = L. S = dy/dx there (dense: a few per evaluation).
    Eigen::VectorXd y = flows[i].y;
    Eigen::MatrixXd S;
    if (J) {
      S = Eigen::MatrixXd::Zero(n, N);
      S.block(0, i * n, n, n) = flows[i].Phi;
      add_span_columns(i, [&](int c, const Eigen::VectorXd& v) { S.col(c) += v; });
    }
    if (last) {
      if (y_end) *y_end = y;
      end_rows(*eq, y, p, J ? &S : nullptr, F, J, row);
      break;
    }
    const Breakpoint& b = points[spans[i].piece];
    const Obstacle& o = obstacles_here[b.obstacle];
    Eigen::VectorXd jump;
    if (b.kind == Breakpoint::Point) {
      const PointContactTerms terms = point_contact_terms(*eq, o, y, b.s, J != nullptr);
      row = point_contact_rows(terms, S, b.s_column, F, J, row);
      if (J && !o.is_flat()) S -= b.force * force.transpose() * terms.d_normal * S;
      jump = -force.transpose() * terms.here.normal;  // n jumps by -force * nu
    } else {
      // A spatial rod on a cylinder (the only extended contact of multiple shooting): entering, it
      // is on the cylinder with g = g' = g'' = 0, and g''' = 0 once the edge force is applied
      // (rod_on_cylinder.hpp); leaving, only the edge force. Both push along e.
      const CylinderSupport c = support_of(o);
      const RodModel& model = eq->model();
      Eigen::MatrixXd dG, de;
      if (b.kind == Breakpoint::ExtendedStart) {
        const Eigen::Vector4d G = cylinder_gap_derivatives(model, c, y, J ? &dG : nullptr);
        for (int k = 0; k < 3; ++k, ++row) {
          (*F)[row] = G[k];
          if (J) J->row(row) = dG.row(k) * S;
        }
      }
      const Vec3 e = cylinder_normal(c, y, J ? &de : nullptr);
      if (J) S -= b.force * force.transpose() * de * S;
      jump = -force.transpose() * e;
      if (b.kind == Breakpoint::ExtendedStart) {
        const Eigen::VectorXd after = y + b.force * jump;
        const Eigen::Vector4d G = cylinder_gap_derivatives(model, c, after, J ? &dG : nullptr);
        (*F)[row] = G[3];
        if (J) {
          Eigen::MatrixXd S_after = S;
          S_after.col(b.force_column) += jump;
          J->row(row) = dG.row(3) * S_after;
        }
        ++row;
      }
    }
    if (J) S.col(b.force_column) += jump;
    y += b.force * jump;
    // Into the next piece's first node.
    F->segment(row, n) = y - x.segment((i + 1) * n, n);
    if (J) {
      J->middleRows(row, n) = S;
      J->block(row, (i + 1) * n, n, n) -= I;
    }
    row += n;
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
  // The turn angle counts whole turns along the rod; at s = 0 the gauge wants it in (-pi, pi].
  const int turns = eq->turn_angle_index();
  const double offset = eq->state(nodes.front())[turns] - nodes.front().turn_angle;
  for (int i = 0; i < segments(); ++i) {
    Eigen::VectorXd y = eq->state(nodes[i]);
    y[turns] = nodes[i].turn_angle + offset;
    x.segment(i * state_size_, state_size_) = y;
  }
  return x;
}

double ShootingProblem::smallest_wrap_pressure(const Eigen::VectorXd& x, const PointContact& contact,
                                               int samples) const {
  if (!contact.extended) return NAN;
  const Parameters p = parameters_at(x);
  const Obstacle o = obstacles(p)[contact.obstacle];
  if (o.is_flat()) return NAN;
  const auto eq = equations(p);
  if (eq->is_planar()) return wrap_tension(x, contact) / o.radius();
  // Just inside the wrap at both ends: at the breakpoints themselves the samples lie on the free side.
  std::vector<double> s(samples);
  const double inset = 1e-12 * (1.0 + contact.s_end), span = contact.s_end - contact.s - 2.0 * inset;
  for (int i = 0; i < samples; ++i) s[i] = contact.s + inset + span * i / (samples - 1);
  double smallest = INFINITY;
  const CylinderSupport support = support_of(o);
  for (const auto& point : sample(x, s))
    smallest = std::min(smallest, cylinder_pressure(eq->model(), support, eq->state(point)));
  return smallest;
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

std::vector<RodPoint> ShootingProblem::sample(const Eigen::VectorXd& x, const std::vector<double>& s) const {
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
          const auto states = eq->sample(y, local, definition_.options.integrator);
          for (size_t j = 1; j < states.size(); ++j) out.push_back(eq->point(states[j], local[j]));
        }
        if (!last) y = eq->flow(y, s0, s1, false, definition_.options.integrator).y;
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
    const auto states = equations.sample(x.segment(i * n, n), local[i], definition_.options.integrator);
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

ShootingResult solve(const ShootingProblem& problem, const Eigen::VectorXd& x0) {
  ShootingResult result;
  result.x = x0;
  result.summary = solve_with_fallback(problem, result.x, problem.definition().options.newton);
  result.parameters = problem.parameters_at(result.x);
  if (result.summary.converged()) mark_check_failure(&result, unknowns_failure(problem, result));
  if (result.summary.converged()) mark_check_failure(&result, zero_iteration_failure(problem, result));
  if (!result.summary.converged() || !result.parameters.contains(kUnfoldingParameter)) return result;
  if (std::abs(result.parameters.get(kUnfoldingParameter)) > kUnfoldingTolerance) {
    result.summary.status = SolverStatus::UnfoldingNotZero;
    result.summary.message = "unfolding = " + std::to_string(result.parameters.get(kUnfoldingParameter)) +
                             ": not an equilibrium (on the straight rod the axial phase condition is degenerate)";
    return result;
  }
  // A guess that is already a straight solution converges in zero iterations; the phase
  // condition is degenerate there, which shows as a singular Jacobian.
  Eigen::VectorXd F;
  Eigen::MatrixXd J;
  std::string failure;
  if (problem.evaluate(result.x, &F, &J, &failure) &&
      !(JacobianLU(J).reciprocal_condition() > problem.definition().options.newton.singular_rcond * 1e3)) {
    result.summary.status = SolverStatus::SingularJacobian;
    result.summary.message =
        "the axial phase condition is degenerate here (a straight rod): solve it without the phase condition";
  }
  return result;
}

}  // namespace kirchhoff
