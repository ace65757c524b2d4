#include "kirchhoff/shooting.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <functional>
#include <optional>
#include <stdexcept>
#include <thread>

#include "kirchhoff/jacobian_lu.hpp"

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
  if (!(initial_step > 0) || initial_step > 1) return "initial_step must be in (0, 1]";
  if (max_steps < 1) return "max_steps must be >= 1";
  return {};
}

ShootingProblem::ShootingProblem(ProblemDefinition definition) : definition_(std::move(definition)) {
  if (std::string e = definition_.options.validate(); !e.empty()) throw std::invalid_argument(e);
  if (!definition_.model) throw std::invalid_argument("no rod model given");
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
  definition_.start.append_residuals(*eq, true, y, definition_.parameters, &rows, nullptr);
  start_condition_count_ = static_cast<int>(rows.size());
  definition_.end.append_residuals(*eq, false, y, definition_.parameters, &rows, nullptr);
  residual_count_ += static_cast<int>(rows.size()) + (segments() - 1) * state_size_;
  if (!definition_.contacts.empty()) {
    if (segments() != 1) throw std::invalid_argument("solver: point contacts need single shooting (segments = 1)");
    for (const auto& c : definition_.contacts)
      if (c.obstacle < 0 || c.obstacle >= static_cast<int>(definition_.obstacles.size()))
        throw std::invalid_argument("contact on obstacle " + std::to_string(c.obstacle) + ", which does not exist");
    for (const auto& c : definition_.contacts) residual_count_ += c.unknowns();
  }
  // Moving obstacles decide: `obstacles` is kept as their value at the current parameters.
  if (definition_.moving_obstacles) definition_.obstacles = definition_.moving_obstacles(definition_.parameters);
  for (const auto& c : definition_.contacts)
    if (c.extended)
      if (std::string e = extended_contact_unsupported(*eq, definition_.obstacles[c.obstacle]); !e.empty())
        throw std::invalid_argument(e);
  if (residual_count_ != size())
    throw std::invalid_argument("boundary conditions give " + std::to_string(residual_count_) +
                                " equations for " + std::to_string(size()) + " unknowns");
}

int ShootingProblem::size() const {
  int n = segments() * state_size_ + static_cast<int>(unknown_index_.size());
  for (const auto& c : definition_.contacts) n += c.unknowns();
  return n;
}

std::vector<Obstacle> ShootingProblem::obstacles(const Parameters& p) const {
  return definition_.moving_obstacles ? definition_.moving_obstacles(p) : definition_.obstacles;
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

std::shared_ptr<const RodEquations> ShootingProblem::equations(const Parameters& p) const {
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

void ShootingProblem::for_each_segment(const Parameters& p, const std::function<void(int, const RodEquations&)>& work,
                                       bool parallel) const {
  const auto eq = equations(p);
  const int M = segments();
  const int requested = definition_.options.threads > 0 ? definition_.options.threads
                                                        : static_cast<int>(std::thread::hardware_concurrency());
  const int workers = parallel && M >= 8 ? std::clamp(requested, 1, M / 4) : 1;
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
  return p;
}

void ShootingProblem::set_parameter(const std::string& name, double value) {
  definition_.parameters.set(name, value);
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
  Parameters plus = parameters_at(x), minus = plus;
  plus.set(name, value + h);
  minus.set(name, value - h);
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
  const int gauge = residual_count_ - static_cast<int>(rows.size()) - (segments() - 1) * state_size_;
  column->segment(gauge, start_condition_count_) = rows.head(start_condition_count_);
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
  if (!definition_.contacts.empty()) return residual_with_contacts(x, p, F, J, failure, y_end);
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
  for (size_t k = 0; k < points.size(); ++k) {
    const double previous = k == 0 ? 0.0 : points[k - 1].s;
    // Strictly increasing, except that an extended contact may have zero length (when it forms),
    // and a wrap a negative one (traversed backwards: not a rod, but the residual stays smooth
    // where a wrap shrinks to a point, so that event is located by crossing). Flat contacts are
    // kept >= 0: their legs are degenerate (see run_legs in contact.cpp), and allowed a negative
    // length the first step after flattening goes that way.
    const bool wrap_end = points[k].kind == Breakpoint::ExtendedEnd && !obstacles_here[points[k].obstacle].is_flat();
    const double before_contact = k >= 2 ? points[k - 2].s : 0.0;
    const bool ok = wrap_end ? points[k].s > before_contact
                    : points[k].kind == Breakpoint::ExtendedEnd ? points[k].s >= previous
                                                                : points[k].s > previous;
    if (!ok || !(points[k].s < L)) {
      if (failure) *failure = "contact arclengths must increase inside (0, L)";
      return false;
    }
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
      auto conditions = [&](const Eigen::VectorXd& state, double at) {
        return o.contact_conditions(position * state, position * eq->derivative(state, at));
      };
      const Obstacle::ContactConditions here = conditions(y, s1);
      const Eigen::VectorXd jump = -force.transpose() * here.normal;  // n jumps by -force * nu
      // Their state derivatives by central differences.
      Eigen::MatrixXd d_rows(2, n), d_normal = Eigen::MatrixXd::Zero(3, n);
      if (J) {
        for (int i = 0; i < n; ++i) {
          const double h = 1e-7 * (1.0 + std::abs(y[i]));
          Eigen::VectorXd yp = y, ym = y;
          yp[i] += h;
          ym[i] -= h;
          const auto plus = conditions(yp, s1), minus = conditions(ym, s1);
          d_rows(0, i) = (plus.gap - minus.gap) / (2 * h);
          d_rows(1, i) = (plus.tangency - minus.tangency) / (2 * h);
          d_normal.col(i) = (plus.normal - minus.normal) / (2 * h);
        }
        // A plane's gap is linear in the position: exact (the cavity's hanging fold runs so close
        // to branch points that rounding in this row alone can send it onto another branch).
        if (o.is_flat()) d_rows.row(0) = o.gradient(position * y).transpose() * position;
      }
      if (b.kind != Breakpoint::ExtendedEnd) {
        // On the obstacle and tangent to it.
        (*F)[row] = here.gap;
        (*F)[row + 1] = here.tangency;
        if (J) {
          J->row(row) = d_rows.row(0) * S;
          J->row(row + 1) = d_rows.row(1) * S;
          // r' depends on s itself where the natural strains do.
          const auto after = conditions(y, s1 + 1e-7), before = conditions(y, s1 - 1e-7);
          J->row(row)[b.s_column] += (after.gap - before.gap) / 2e-7;
          J->row(row + 1)[b.s_column] += (after.tangency - before.tangency) / 2e-7;
        }
        row += 2;
      }
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
        if (!o.is_flat()) S -= b.force * force.transpose() * d_normal * S;
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
  ConditionRows end;
  definition_.end.append_residuals(*eq, false, y, p, &end.values, J ? &end.jacobian : nullptr);
  for (size_t k = 0; k < end.values.size(); ++k, ++row) {
    (*F)[row] = end.values[k];
    if (J) J->row(row) = end.jacobian[k] * S;
  }
  return true;
}

Eigen::VectorXd ShootingProblem::initial_unknowns(const RodPoint& start_guess) const {
  const auto eq = equations(definition_.parameters);
  RodPoint p0 = start_guess;
  definition_.start.impose_on(*eq, true, definition_.parameters, &p0);
  const int n = state_size_, M = segments();
  Eigen::VectorXd x(size());
  Eigen::VectorXd y = eq->state(p0);
  const double L = eq->model().length;
  for (int i = 0; i < M; ++i) {
    x.segment(i * n, n) = y;
    if (i + 1 < M) y = eq->flow(y, L * i / M, L * (i + 1) / M, false, definition_.options.integrator).y;
  }
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

std::vector<RodPoint> ShootingProblem::sample(const Eigen::VectorXd& x, const std::vector<double>& s) const {
  const Parameters p = parameters_at(x);
  const auto eq = equations(p);
  const int n = state_size_, M = segments();
  const double L = eq->model().length;
  std::vector<RodPoint> out;
  out.reserve(s.size());
  size_t k = 0;
  if (!definition_.contacts.empty()) {
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
  // Each segment samples the arclengths in it, from its own start state.
  std::vector<std::vector<double>> local(M);
  for (int i = 0; i < M; ++i) {
    const double s0 = L * i / M, s1 = L * (i + 1) / M;
    local[i] = {s0};
    while (k < s.size() && (s[k] < s1 || i + 1 == M)) local[i].push_back(std::min(s[k++], s1));
  }
  std::vector<std::vector<RodPoint>> points(M);
  for_each_segment(p, [&](int i, const RodEquations& equations) {
    if (local[i].size() == 1) return;
    const auto states = equations.sample(x.segment(i * n, n), local[i], definition_.options.integrator);
    for (size_t j = 1; j < states.size(); ++j) points[i].push_back(equations.point(states[j], local[i][j]));
  }, s.size() >= 64);
  for (auto& segment : points) out.insert(out.end(), segment.begin(), segment.end());
  return out;
}

std::string extended_contact_unsupported(const RodEquations& equations, const Obstacle& obstacle) {
  if (!equations.is_planar())
    return "extended contact is modelled for planar rods only (a spatial rod lying on an obstacle is not implemented)";
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
  const std::string name = "unfolding";
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

ShootingResult solve(const ShootingProblem& problem, const Eigen::VectorXd& x0) {
  ShootingResult result;
  result.x = x0;
  result.summary = solve_with_fallback(problem, result.x, problem.definition().options.newton);
  result.parameters = problem.parameters_at(result.x);
  if (!result.summary.converged() || !result.parameters.contains("unfolding")) return result;
  if (std::abs(result.parameters.get("unfolding")) > kUnfoldingTolerance) {
    result.summary.status = SolverStatus::UnfoldingNotZero;
    result.summary.message = "unfolding = " + std::to_string(result.parameters.get("unfolding")) +
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
