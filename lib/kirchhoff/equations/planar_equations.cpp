// The planar Elastica/Reissner rod: the 3D equations restricted to motions in the (x, y) plane
// with d2 = e_z, d3 = (cos theta, sin theta, 0), d1 = (-sin theta, cos theta, 0) (section 7 of the
// reference paper). Then u = (0, theta', 0), the moment is m e_z, and the 3D equations reduce to
//   r' = v1 d1 + v3 d3,  theta' = u_hat2 + m / B2,  n' = -f_ext,  m' = (n x r') . e_z,
// which for an inextensible rod is EI theta'' = n_x sin theta - n_y cos theta (eq. 52).
// It reads the same RodModel as SpatialEquations (B2, u_hat2, A1, A3, v_hat1, v_hat3, the field),
// so there is one physics and two state layouts; a test checks both give the same rod to 1e-10.
//
// State layout (6): x, y, theta, n_x, n_y, m. theta tracks whole turns by itself.
#include <array>
#include <cmath>
#include <optional>

#include "kirchhoff/equations/detail/compliances.hpp"
#include "kirchhoff/equations/detail/elastica_flow.hpp"
#include "kirchhoff/equations/detail/field_eval.hpp"
#include "kirchhoff/equations/detail/integrator_impl.hpp"
#include "kirchhoff/equations/detail/planar_state.hpp"
#include "kirchhoff/equations/rod_equations.hpp"

namespace kirchhoff {
namespace {

// The state layout (planar_state.hpp).
using detail::kPlanarStateSize, detail::kX, detail::kY, detail::kTheta, detail::kNx, detail::kNy, detail::kMoment;
constexpr int kStateSize = kPlanarStateSize;
// The turn of theta (rad) that bounds a step where theta turns at the march's start: a ring of
// curvature 2 pi closed by pinning, marched in steps of 0.39 rad, closes to 2e-14 (0.79 rad:
// 1e-11; RKF78's error falls as the eighth power of the step).
constexpr double kMaxTurnPerStep = 0.35;

class PlanarEquations final : public RodEquations {
 public:
  explicit PlanarEquations(RodModel model)
      : model_(std::move(model)),
        compliances_(model_),
        jumps_(std::make_shared<const std::vector<ProfileJump>>(model_.jumps())),
        pendulum_(pendulum_of(model_)) {}

  int state_size() const override { return kStateSize; }
  const RodModel& model() const override { return model_; }
  bool is_planar() const override { return true; }

  template <class T>
  void rhs(const T* y, T* dy, double s) const {
    using std::cos;
    using std::sin;
    const T c = cos(y[kTheta]), sn = sin(y[kTheta]);
    T v1 = T(model_.v_hat[0](s)), v3 = T(model_.v_hat[2](s));
    if (model_.extensible) {
      const T n1 = -y[kNx] * sn + y[kNy] * c;
      const T n3 = y[kNx] * c + y[kNy] * sn;
      v1 = v1 + n1 * compliances_.stretching(model_, 0, s);
      v3 = v3 + n3 * compliances_.stretching(model_, 2, s);
    }
    const T dx = -v1 * sn + v3 * c;
    const T dyy = v1 * c + v3 * sn;
    dy[kX] = dx;
    dy[kY] = dyy;
    dy[kTheta] = model_.u_hat[1](s) + y[kMoment] * compliances_.bending(model_, 1, s);
    if (model_.field) {
      const T r[3] = {y[kX], y[kY], T(0.0)};
      T f[3];
      detail::field_force(*model_.field, s, r, f);
      dy[kNx] = -f[0];
      dy[kNy] = -f[1];
    } else {
      dy[kNx] = T(0.0);
      dy[kNy] = T(0.0);
    }
    dy[kMoment] = y[kNx] * dyy - y[kNy] * dx;
  }

  // The caller's options with the rod's jumps and, where theta turns at s0, a step no longer than
  // kMaxTurnPerStep of its turn there (IntegratorOptions::max_step: RKF78 cannot see its error
  // where theta is linear in s, a rod without force of constant curvature). A rod whose theta is
  // not linear shows its error, and its steps stay below that (the Euler column's turn at most
  // 0.2 a step); one whose theta does not turn at s0 is not capped.
  IntegratorOptions options_from(const IntegratorOptions& given, const Eigen::VectorXd& y0, double s0) const {
    IntegratorOptions options = detail::with_jumps(given, jumps_);
    double dy[kStateSize];
    rhs(y0.data(), dy, s0);
    const double turn_rate = std::abs(dy[kTheta]);
    if (turn_rate > 0 && std::isfinite(turn_rate) && options.max_step == 0.0)
      options.max_step = kMaxTurnPerStep / turn_rate;
    return options;
  }

  // The state in closed form wherever its limits allow (detail::kStateLimits), Phi too where its
  // own do (kMatrixLimits), else by the march's variational equations beside the closed-form
  // state: F is then the same number with or without Phi, and as accurate near the separatrix.
  void flow_into(const Eigen::VectorXd& y0, double s0, double s1, bool sensitivities, const IntegratorOptions& given,
                 SegmentFlow* out) const override {
    std::array<double, kStateSize> y1;
    if (!given.closed_form || !closed_form_state(y0, s1 - s0, detail::kStateLimits, &y1))
      return march_into(y0, s0, s1, sensitivities, given, out);
    if (!sensitivities) {
      out->Phi.resize(0, 0);
    } else if (!closed_form_matrix(y0, s1 - s0, detail::kMatrixLimits, &out->Phi)) {
      // (Phi's pass alone: the march's own state pass would only be replaced.)
      IntegratorOptions phi_only = given;
      phi_only.sensitivities_only = true;
      march_into(y0, s0, s1, true, phi_only, out);
      out->y = Eigen::Map<const Eigen::Matrix<double, kStateSize, 1>>(y1.data());
      return;
    }
    out->y = Eigen::Map<const Eigen::Matrix<double, kStateSize, 1>>(y1.data());
    out->dy_dunfolding.resize(0);
    out->rhs_evaluations = 0;  // (no right-hand side is evaluated)
    out->steps = 1;
  }

  // The flow by the march (the stepper of `given`), Phi from the variational equations.
  void march_into(const Eigen::VectorXd& y0, double s0, double s1, bool sensitivities, const IntegratorOptions& given,
                  SegmentFlow* out) const {
    const IntegratorOptions options = options_from(given, y0, s0);
    auto f = [this](const auto* y, auto* dy, double s) { rhs(y, dy, s); };
    if (!sensitivities) return detail::flow_state_into<kStateSize>(f, y0, s0, s1, options, out);
    if (model_.field) {
      constexpr std::array<int, kStateSize> kAll{kX, kY, kTheta, kNx, kNy, kMoment};
      return detail::flow_with_seeded_sensitivities_into<kStateSize, kStateSize>(f, y0, s0, s1, options, kAll, out);
    }
    if (options.sensitivity_tol > options.abs_tol)
      return detail::flow_with_loose_pass_into<kStateSize>(
          f, y0, s0, s1, options,
          [&](const IntegratorOptions& loose, SegmentFlow* o) { variations_pass_into(y0, s0, s1, loose, o); }, out);
    // Without a field nothing depends on x(s0), y(s0): their columns of Phi are unit vectors.
    constexpr std::array<int, 4> kSeeds{kTheta, kNx, kNy, kMoment};
    detail::flow_with_seeded_sensitivities_into<kStateSize, 4>(f, y0, s0, s1, options, kSeeds, out);
  }

  DirectionalFlow flow_directions(const Eigen::VectorXd& y0, const Eigen::MatrixXd& directions, double s0, double s1,
                                  const IntegratorOptions& given, CarriedSteps* carried) const override {
    // In closed form: Phi directions, Phi at the interval's end (the carried step sizes are the
    // march's, left as they are for the next interval that needs one).
    // The state is the dual numbers' values (the fields' limits are inside the state's): their
    // rounding, a few ulps, is nothing to the fields, and a second pass on double costs a third.
    std::array<double, kStateSize> y1;
    Eigen::MatrixXd Phi;
    if (given.closed_form && closed_form_matrix(y0, s1 - s0, detail::kFieldLimits, &Phi, &y1)) {
      DirectionalFlow out;
      out.y = Eigen::Map<const Eigen::Matrix<double, kStateSize, 1>>(y1.data());
      out.directions = Phi * directions;
      out.steps = 1;
      return out;
    }
    const IntegratorOptions options = options_from(given, y0, s0);
    auto f = [this](const auto* y, auto* dy, double s) { rhs(y, dy, s); };
    // The seeds of flow(): all of them with a field, else those x(s0), y(s0) do not enter.
    static const std::vector<int> kAll{kX, kY, kTheta, kNx, kNy, kMoment};
    static const std::vector<int> kSeeds{kTheta, kNx, kNy, kMoment};
    return detail::flow_directions_through_seeds<kStateSize, 1, 2, 3, 4, 5, 6>(
        f, y0, directions, model_.field ? kAll : kSeeds, s0, s1, options, carried);
  }

  std::vector<Eigen::VectorXd> sample(const Eigen::VectorXd& y0, const std::vector<double>& s,
                                      const IntegratorOptions& given) const override {
    if (given.closed_form && pendulum_) {
      std::vector<Eigen::VectorXd> states;
      if (closed_form_samples(y0, s, given, &states)) return states;
    }
    const IntegratorOptions options = options_from(given, y0, s.empty() ? 0.0 : s.front());
    auto f = [this](const auto* y, auto* dy, double s) { rhs(y, dy, s); };
    return detail::sample_states<kStateSize>(f, y0, s, options);
  }

  Eigen::VectorXd derivative(const Eigen::VectorXd& y, double s) const override {
    Eigen::VectorXd dy(kStateSize);
    rhs(y.data(), dy.data(), s);
    return dy;
  }

  RodPoint point(const Eigen::VectorXd& y, double s) const override {
    RodPoint p;
    p.s = s;
    p.r = Vec3(y[kX], y[kY], 0.0);
    const double theta = y[kTheta], c = std::cos(theta), sn = std::sin(theta);
    p.R.col(0) = Vec3(-sn, c, 0.0);
    p.R.col(1) = Vec3::UnitZ();
    p.R.col(2) = Vec3(c, sn, 0.0);
    p.n = Vec3(y[kNx], y[kNy], 0.0);
    p.m = Vec3(0.0, 0.0, y[kMoment]);
    p.u = Vec3(model_.u_hat[0](s), model_.u_hat[1](s) + y[kMoment] / model_.B[1](s), model_.u_hat[2](s));
    const Vec3 n_body = p.R.transpose() * p.n;
    p.v = Vec3(model_.v_hat[0](s), model_.v_hat[1](s), model_.v_hat[2](s));
    if (model_.extensible) p.v += Vec3(n_body[0] / model_.A[0](s), 0.0, n_body[2] / model_.A[2](s));
    p.turn_angle = theta;
    return p;
  }

  int turn_angle_index() const override { return kTheta; }

  Eigen::VectorXd state(const RodPoint& p) const override {
    Eigen::VectorXd y(kStateSize);
    y << p.r.x(), p.r.y(), std::atan2(p.R(1, 2), p.R(0, 2)), p.n.x(), p.n.y(), p.m.z();
    return y;
  }

  SlotMap slot_map(Slot slot) const override {
    SlotMap M = SlotMap::Zero(3, kStateSize);
    switch (slot) {
      case Slot::Position: M(0, kX) = 1; M(1, kY) = 1; break;
      case Slot::Force: M(0, kNx) = 1; M(1, kNy) = 1; break;
      case Slot::Moment: M(2, kMoment) = 1; break;
      case Slot::Orientation: M(2, kTheta) = 1; break;
    }
    return M;
  }

  // In the plane every admissible target is a rotation about e_z, and theta - angle is the exact
  // rotation error, turns included.
  Vec3 orientation_error(const Eigen::VectorXd& y, const OrientationTarget& target, bool,
                         SlotMap* jacobian) const override {
    const double sign = target.axis.z() < 0 ? -1.0 : 1.0;
    if (jacobian) {
      jacobian->setZero(3, kStateSize);
      (*jacobian)(2, kTheta) = 1.0;
    }
    return Vec3(0.0, 0.0, y[kTheta] - sign * target.angle);
  }

  GaugeRows gauge_residual(const Eigen::VectorXd&, Eigen::MatrixXd* jacobian) const override {
    if (jacobian) jacobian->resize(0, kStateSize);
    return GaugeRows(0);
  }

  LabDirections admissible_directions(Slot slot) const override {
    if (slot == Slot::Orientation || slot == Slot::Moment) return Vec3::UnitZ();
    LabDirections E = LabDirections::Zero(3, 2);
    E(0, 0) = 1.0;
    E(1, 1) = 1.0;
    return E;
  }

 private:
  // The pendulum this rod's moment obeys, where its flow is closed form (detail/elastica_flow.hpp):
  // no field, inextensible, and every property that enters constant (then nothing jumps either).
  static std::optional<detail::ElasticaConstants> pendulum_of(const RodModel& m) {
    if (m.field || m.extensible) return std::nullopt;
    for (const Profile* p : {&m.B[1], &m.u_hat[1], &m.v_hat[0], &m.v_hat[2]})
      if (!p->is_constant()) return std::nullopt;
    return detail::ElasticaConstants{m.B[1](0.0), m.u_hat[1](0.0), m.v_hat[0](0.0), m.v_hat[2](0.0)};
  }

  // The state at s0 + ds in closed form into *y1; false where `limits` do not allow it (no
  // pendulum, an orbit outside the oscillating regime, too near the separatrix, too short a phase).
  bool closed_form_state(const Eigen::VectorXd& y0, double ds, const detail::ClosedFormLimits& limits,
                         std::array<double, kStateSize>* y1, detail::JacobiMemo* memo = nullptr) const {
    return pendulum_ && detail::elastica_flow(y0.data(), ds, *pendulum_, y1->data(), limits, memo) &&
           all_finite(*y1);
  }

  // Phi over ds by the same formulas on dual numbers seeded with theta, n_x, n_y and m (x, y
  // enter nothing) into *Phi, and their values into *values if asked; false where `limits` do not
  // allow it. (Shooting's state is closed_form_state's, on double: the dual numbers' divisions
  // round otherwise, and F must be the same number with or without Phi.)
  bool closed_form_matrix(const Eigen::VectorXd& y0, double ds, const detail::ClosedFormLimits& limits,
                          Eigen::MatrixXd* Phi, std::array<double, kStateSize>* values = nullptr) const {
    using D = Dual<4>;
    constexpr std::array<int, 4> kSeeds{kTheta, kNx, kNy, kMoment};
    std::array<D, kStateSize> x0, x1;
    for (int i = 0; i < kStateSize; ++i) x0[i] = D(y0[i]);
    for (int j = 0; j < 4; ++j) x0[kSeeds[j]].d[j] = 1.0;
    if (!pendulum_ || !detail::elastica_flow(x0.data(), ds, *pendulum_, x1.data(), limits)) return false;
    Phi->setIdentity(kStateSize, kStateSize);
    for (int i = 0; i < kStateSize; ++i)
      for (int j = 0; j < 4; ++j) (*Phi)(i, kSeeds[j]) = x1[i].d[j];
    if (values)
      for (int i = 0; i < kStateSize; ++i) (*values)[i] = x1[i].v;
    return Phi->allFinite() && (!values || all_finite(*values));
  }

  // The states at s (sorted) in closed form, interval by interval; false where an orbit is outside
  // the state's limits (the caller marches the whole then). An interval of no length (a profile's
  // first sample is its start) keeps the state, and one too short a phase for the closed form
  // (detail::kStateLimits) is marched alone: neither says anything about the orbit.
  bool closed_form_samples(const Eigen::VectorXd& y0, const std::vector<double>& s, const IntegratorOptions& given,
                           std::vector<Eigen::VectorXd>* states) const {
    states->clear();
    if (s.empty()) return true;
    states->reserve(s.size());
    states->push_back(y0);
    constexpr detail::ClosedFormLimits kAnyPhase{detail::kStateLimits.separatrix_margin, 0.0};
    std::array<double, kStateSize> y1;
    detail::JacobiMemo memo;  // (equal intervals share their Jacobi functions)
    for (size_t i = 1; i < s.size(); ++i) {
      const Eigen::VectorXd& y = states->back();
      const double ds = s[i] - s[i - 1];
      if (ds == 0.0) {
        states->push_back(Eigen::VectorXd(y));
      } else if (closed_form_state(y, ds, detail::kStateLimits, &y1, &memo)) {
        states->push_back(Eigen::Map<const Eigen::Matrix<double, kStateSize, 1>>(y1.data()));
      } else if (closed_form_state(y, ds, kAnyPhase, &y1)) {
        SegmentFlow short_interval;
        march_into(y, s[i - 1], s[i], false, given, &short_interval);
        states->push_back(short_interval.y);
      } else {
        return false;
      }
    }
    return true;
  }

  static bool all_finite(const std::array<double, kStateSize>& y) {
    for (double v : y)
      if (!std::isfinite(v)) return false;
    return true;
  }

  // Without a field nothing depends on x(s0), y(s0), and n is constant: the columns x, y of Phi
  // are unit vectors and its rows n_x, n_y those of the identity. The variational equations of
  // the other columns (theta, n_x, n_y, m) are written out for the rows x, y, theta and m: 16
  // entries beside the state, sin and cos shared, where Dual<4> carries four derivatives through
  // every operation and its sin and cos. Used for the looser matrices only (sensitivity_tol, the
  // state in its own pass: detail::flow_with_loose_pass_into); the exact pass keeps the dual numbers,
  // whose round-off the contact legs and their tests were computed with.
  static constexpr int kRows = 4;     // rows x, y, theta, m of Phi
  static constexpr int kColumns = 4;  // columns theta, n_x, n_y, m
  static constexpr std::array<int, kRows> kRowOf{kX, kY, kTheta, kMoment};
  static constexpr std::array<int, kColumns> kColumnOf{kTheta, kNx, kNy, kMoment};
  static constexpr int kAugmented = kStateSize + kRows * kColumns;  // y, then the 4 x 4 block row-major

  // d/ds of the state (as rhs<double>) and of the block: delta r' = d(r')/dtheta delta theta +
  // d(r')/dv delta v with d(r')/dtheta = (-r'_y, r'_x); delta theta' = delta m / B2;
  // delta m' = delta(n_x r'_y - n_y r'_x).
  void rhs_with_variations(const double* y, double* dy, double s) const {
    const double c = std::cos(y[kTheta]), sn = std::sin(y[kTheta]);
    double v1 = model_.v_hat[0](s), v3 = model_.v_hat[2](s);
    double n1 = 0.0, n3 = 0.0, compliance1 = 0.0, compliance3 = 0.0;
    if (model_.extensible) {
      n1 = -y[kNx] * sn + y[kNy] * c;
      n3 = y[kNx] * c + y[kNy] * sn;
      compliance1 = compliances_.stretching(model_, 0, s);
      compliance3 = compliances_.stretching(model_, 2, s);
      v1 += n1 * compliance1;
      v3 += n3 * compliance3;
    }
    const double dx = -v1 * sn + v3 * c, dyy = v1 * c + v3 * sn;
    const double flexibility = compliances_.bending(model_, 1, s);
    dy[kX] = dx;
    dy[kY] = dyy;
    dy[kTheta] = model_.u_hat[1](s) + y[kMoment] * flexibility;
    dy[kNx] = 0.0;
    dy[kNy] = 0.0;
    dy[kMoment] = y[kNx] * dyy - y[kNy] * dx;
    const double* P = y + kStateSize;
    double* dP = dy + kStateSize;
    for (int j = 0; j < kColumns; ++j) {
      const double d_theta = P[2 * kColumns + j], d_m = P[3 * kColumns + j];
      const double d_nx = kColumnOf[j] == kNx ? 1.0 : 0.0, d_ny = kColumnOf[j] == kNy ? 1.0 : 0.0;
      double d_v1 = 0.0, d_v3 = 0.0;
      if (model_.extensible) {  // d(n1, n3)/dtheta = (-n3, n1)
        d_v1 = (-d_nx * sn + d_ny * c - n3 * d_theta) * compliance1;
        d_v3 = (d_nx * c + d_ny * sn + n1 * d_theta) * compliance3;
      }
      const double d_dx = -d_v1 * sn + d_v3 * c - dyy * d_theta;
      const double d_dy = d_v1 * c + d_v3 * sn + dx * d_theta;
      dP[0 * kColumns + j] = d_dx;
      dP[1 * kColumns + j] = d_dy;
      dP[2 * kColumns + j] = d_m * flexibility;
      dP[3 * kColumns + j] = d_nx * dyy + y[kNx] * d_dy - d_ny * dx - y[kNy] * d_dx;
    }
  }

  // Phi by rhs_with_variations (every component under error control, as the dual numbers have
  // it) at `options`: the looser pass of detail::flow_with_loose_pass_into.
  void variations_pass_into(const Eigen::VectorXd& y0, double s0, double s1, const IntegratorOptions& options,
                            SegmentFlow* out) const {
    std::array<double, kAugmented> x{};
    for (int i = 0; i < kStateSize; ++i) x[i] = y0[i];
    for (int r = 0; r < kRows; ++r)
      for (int j = 0; j < kColumns; ++j) x[kStateSize + r * kColumns + j] = kRowOf[r] == kColumnOf[j] ? 1.0 : 0.0;
    out->rhs_evaluations = 0;
    auto system = [&](const std::array<double, kAugmented>& y, std::array<double, kAugmented>& dy, double s) {
      ++out->rhs_evaluations;
      rhs_with_variations(y.data(), dy.data(), s);
    };
    out->steps = detail::march(x, s0, s1, system, options);
    out->y = Eigen::Map<const Eigen::Matrix<double, kStateSize, 1>>(x.data());  // (to these options' tolerance)
    out->Phi.setIdentity(kStateSize, kStateSize);
    for (int r = 0; r < kRows; ++r)
      for (int j = 0; j < kColumns; ++j) out->Phi(kRowOf[r], kColumnOf[j]) = x[kStateSize + r * kColumns + j];
    out->dy_dunfolding.resize(0);
  }

  RodModel model_;
  detail::Compliances compliances_;  // of model_ (declared after it: built from it)
  std::shared_ptr<const std::vector<ProfileJump>> jumps_;  // of model_: where its properties jump
  std::optional<detail::ElasticaConstants> pendulum_;       // of model_: where its flow is closed form
};

}  // namespace

Mat3 planar_reference_frame() {
  Mat3 R;
  R.col(0) = Vec3::UnitY();
  R.col(1) = Vec3::UnitZ();
  R.col(2) = Vec3::UnitX();
  return R;
}

std::shared_ptr<const RodEquations> make_planar_equations(RodModel model) {
  model.validate();
  return std::make_shared<PlanarEquations>(std::move(model));
}

}  // namespace kirchhoff
