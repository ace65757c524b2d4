// The 3D static Reissner rod (eqs. 21a, 25, 26 of the reference paper):
//   r' = R v,   R' = R [u]x,   n' = -f_ext(r),   m' = n x r',
// with the constitutive laws u = u_hat + B^-1 (R^T m) and v = v_hat + A^-1 (R^T n) (Kirchhoff
// limit: v = v_hat exactly).
//
// The frame is stored as a quaternion q and R is computed from q/|q|. Why quaternions: four
// unknowns instead of nine (the variational equations cost grows with the square of the state
// size), and R(q) is orthonormal to round-off for *any* q, so no drift of the frame away from
// SO(3) can build up along the rod; |q| itself is conserved by q' = q (0, u)/2 and pinned to 1
// at s = 0 by a gauge condition.
//
// State layout (14): r[0..2], q[3..6] = (w, x, y, z), n[7..9], m[10..12], turn angle chi[13].
// chi is the rotation of the frame about the turn axis e3 (the twist angle of q's swing-twist
// decomposition, 2 atan2(q.e3, w)) integrated continuously so that imposed end rotations count
// whole turns; it feeds nothing back into the mechanics.
#include <cmath>
#include <optional>
#include <stdexcept>

#include "kirchhoff/equations/detail/compliances.hpp"
#include "kirchhoff/equations/detail/field_eval.hpp"
#include "kirchhoff/equations/detail/integrator_impl.hpp"
#include "kirchhoff/equations/detail/rod_on_cylinder_impl.hpp"
#include "kirchhoff/equations/detail/spatial_state.hpp"
#include "kirchhoff/equations/detail/spatial_variations.hpp"
#include "kirchhoff/equations/rod_equations.hpp"

namespace kirchhoff {
namespace {

constexpr int kStateSize = detail::kSpatialStateSize;
using detail::kChi;
using detail::kM;
using detail::kN;
using detail::kQ;
using detail::kR;
using detail::rotation_from_quaternion;

Eigen::Vector4d quaternion_from_rotation(const Mat3& R) {
  const Eigen::Quaterniond q(R);
  return Eigen::Vector4d(q.w(), q.x(), q.y(), q.z());
}

class SpatialEquations final : public RodEquations {
 public:
  explicit SpatialEquations(RodModel model, std::optional<CylinderSupport> support = std::nullopt)
      : model_(std::move(model)),
        compliances_(model_),
        jumps_(std::make_shared<const std::vector<ProfileJump>>(model_.jumps())),
        support_(std::move(support)),
        tangent_stiffness_(model_.field && !support_ && model_.field->has_tangent_stiffness()) {}

  int state_size() const override { return kStateSize; }
  const RodModel& model() const override { return model_; }
  bool is_planar() const override { return false; }

  template <class T>
  void rhs(const T* y, T* dy, double s) const {
    T R[3][3];
    rotation_from_quaternion(y + kQ, R);
    T u[3], v[3];
    for (int i = 0; i < 3; ++i) {
      const T m_body = R[0][i] * y[kM] + R[1][i] * y[kM + 1] + R[2][i] * y[kM + 2];
      u[i] = model_.u_hat[i](s) + m_body * compliances_.bending(model_, i, s);
      if (model_.extensible) {
        const T n_body = R[0][i] * y[kN] + R[1][i] * y[kN + 1] + R[2][i] * y[kN + 2];
        v[i] = model_.v_hat[i](s) + n_body * compliances_.stretching(model_, i, s);
      } else {
        v[i] = T(model_.v_hat[i](s));
      }
    }
    T dr[3];
    for (int i = 0; i < 3; ++i) dr[i] = R[i][0] * v[0] + R[i][1] * v[1] + R[i][2] * v[2];
    for (int i = 0; i < 3; ++i) dy[kR + i] = dr[i];
    // q' = q (0, u) / 2 with the body angular velocity u (R' = R [u]x).
    const T w = y[kQ], qx = y[kQ + 1], qy = y[kQ + 2], qz = y[kQ + 3];
    dy[kQ] = -0.5 * (qx * u[0] + qy * u[1] + qz * u[2]);
    dy[kQ + 1] = 0.5 * (w * u[0] + qy * u[2] - qz * u[1]);
    dy[kQ + 2] = 0.5 * (w * u[1] + qz * u[0] - qx * u[2]);
    dy[kQ + 3] = 0.5 * (w * u[2] + qx * u[1] - qy * u[0]);
    if (support_) {
      // Lying on a cylinder: its pressure along e (rod_on_cylinder.hpp).
      detail::V3<T> e;
      const T p = detail::cylinder_pressure(*support_, model_.B[0](s), y, &e);
      for (int i = 0; i < 3; ++i) dy[kN + i] = -p * e[i];
    } else if (model_.field) {
      T f[3];
      detail::field_force(*model_.field, s, y + kR, f);
      for (int i = 0; i < 3; ++i) dy[kN + i] = -f[i];
    } else {
      for (int i = 0; i < 3; ++i) dy[kN + i] = T(0.0);
    }
    const T* n = y + kN;
    dy[kM] = n[1] * dr[2] - n[2] * dr[1];
    dy[kM + 1] = n[2] * dr[0] - n[0] * dr[2];
    dy[kM + 2] = n[0] * dr[1] - n[1] * dr[0];
    if (tangent_stiffness_) {
      // Only the linearisation changes (a stability analysis' term, rod_model.hpp): d3' = R (u x e3).
      const T* d3[3] = {&R[0][2], &R[1][2], &R[2][2]};
      double d3_prime[3];
      for (int i = 0; i < 3; ++i) d3_prime[i] = value(R[i][0] * u[1] - R[i][1] * u[0]);
      detail::add_tangent_stiffness(*model_.field, s, y + kR, d3, d3_prime, dy + kN, dy + kM);
    }
    if (model_.symmetry_unfolding != 0.0) {
      const double mu = model_.symmetry_unfolding;
      dy[kM] = dy[kM] + mu * R[0][2];
      dy[kM + 1] = dy[kM + 1] + mu * R[1][2];
      dy[kM + 2] = dy[kM + 2] - mu * (1.0 - R[2][2]);
    }
    // chi = 2 atan2(qz, w)  =>  chi' = 2 (w qz' - qz w') / (w^2 + qz^2), the denominator held off
    // zero where the tangent points along -e3 (turn_angle_denominator).
    dy[kChi] = 2.0 * (w * dy[kQ + 3] - qz * dy[kQ]) / detail::turn_angle_denominator(w, qx, qy, qz);
  }

  void flow_into(const Eigen::VectorXd& y0, double s0, double s1, bool sensitivities, const IntegratorOptions& given,
                 SegmentFlow* out) const override {
    const IntegratorOptions options = detail::with_jumps(given, jumps_);
    auto f = [this](const auto* y, auto* dy, double s) { rhs(y, dy, s); };
    if (!sensitivities) return detail::flow_state_into<kStateSize>(f, y0, s0, s1, options, out);
    // A rod without field or cylinder: the variational equations written out
    // (spatial_variations.hpp) instead of dual numbers, the looser matrices in a pass of their own.
    if (detail::has_written_out_variations(model_, support_.has_value())) {
      auto state_rhs = [this](const double* y, double* dy, double s) { rhs(y, dy, s); };
      auto pass = [&](const IntegratorOptions& at, SegmentFlow* o) {
        detail::written_out_variations_pass_into(model_, compliances_, state_rhs, y0, s0, s1, at, o);
      };
      if (options.sensitivity_tol > options.abs_tol)
        return detail::flow_with_loose_pass_into<kStateSize>(f, y0, s0, s1, options, pass, out);
      return pass(options, out);
    }
    // With a field (self-contact, gravity) or a cylinder, on dual numbers. Nothing depends on
    // chi(s0): its column of Phi is a unit vector, and the 13 others are carried.
    constexpr std::array<int, 13> kSeeds{kR,     kR + 1, kR + 2, kQ,     kQ + 1, kQ + 2, kQ + 3,
                                         kN,     kN + 1, kN + 2, kM,     kM + 1, kM + 2};
    detail::flow_with_seeded_sensitivities_into<kStateSize, 13>(f, y0, s0, s1, options, kSeeds, out);
  }

  DirectionalFlow flow_directions(const Eigen::VectorXd& y0, const Eigen::MatrixXd& directions, double s0, double s1,
                                  const IntegratorOptions& given, CarriedSteps* carried) const override {
    const IntegratorOptions options = detail::with_jumps(given, jumps_);
    if (detail::has_written_out_variations(model_, support_.has_value())) {
      auto state_rhs = [this](const double* y, double* dy, double s) { rhs(y, dy, s); };
      return detail::written_out_directional_flow<3, 4, 5, 6, 8, 10>(model_, compliances_, state_rhs, y0, directions,
                                                                     s0, s1, options, carried);
    }
    auto f = [this](const auto* y, auto* dy, double s) { rhs(y, dy, s); };
    // With a field or a cylinder: the seeds of flow(); the dual sizes those of the stability
    // index's Jacobi fields (a frame of 3 or 6 columns and a few particular ones), then all the seeds.
    static const std::vector<int> kSeeds{kR,     kR + 1, kR + 2, kQ,     kQ + 1, kQ + 2, kQ + 3,
                                         kN,     kN + 1, kN + 2, kM,     kM + 1, kM + 2};
    return detail::flow_directions_through_seeds<kStateSize, 3, 4, 5, 6, 8, 10, 13>(f, y0, directions, kSeeds, s0, s1,
                                                                                  options, carried);
  }

  std::vector<Eigen::VectorXd> sample(const Eigen::VectorXd& y0, const std::vector<double>& s,
                                      const IntegratorOptions& given) const override {
    const IntegratorOptions options = detail::with_jumps(given, jumps_);
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
    p.r = y.segment<3>(kR);
    double R[3][3];
    rotation_from_quaternion(y.data() + kQ, R);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) p.R(i, j) = R[i][j];
    p.n = y.segment<3>(kN);
    p.m = y.segment<3>(kM);
    const Vec3 m_body = p.R.transpose() * p.m, n_body = p.R.transpose() * p.n;
    for (int i = 0; i < 3; ++i) {
      p.u[i] = model_.u_hat[i](s) + m_body[i] / model_.B[i](s);
      p.v[i] = model_.v_hat[i](s) + (model_.extensible ? n_body[i] / model_.A[i](s) : 0.0);
    }
    p.turn_angle = y[kChi];
    return p;
  }

  int turn_angle_index() const override { return kChi; }

  Eigen::VectorXd state(const RodPoint& p) const override {
    Eigen::VectorXd y(kStateSize);
    y.segment<3>(kR) = p.r;
    Eigen::Vector4d q = quaternion_from_rotation(p.R);
    if (q[0] < 0) q = -q;
    y.segment<4>(kQ) = q;
    y.segment<3>(kN) = p.n;
    y.segment<3>(kM) = p.m;
    y[kChi] = 2.0 * std::atan2(q[3], q[0]);
    return y;
  }

  // A frame turned by pi about e3 (the plectoneme's clamp at -pi * turns, odd turns) has
  // q0 = 0: state() then chose q or -q, and chi = +pi or -pi, by the sign of a q0 of round-off,
  // and a guess whose first node took the other sign from its second was a whole segment's
  // quaternion and a turn of chi away from any solution (Newton from the hard ply's seed failed).
  // Below kTie, the sign that continues the neighbour's quaternion.
  Eigen::VectorXd state_beside(const RodPoint& p, const Eigen::VectorXd& neighbour) const override {
    constexpr double kTie = 1e-9;  // below the accuracy of any solved frame
    Eigen::VectorXd y = state(p);
    Eigen::Ref<Eigen::VectorXd> q = y.segment<4>(kQ);
    if (std::abs(q[0]) < kTie && q.dot(neighbour.segment<4>(kQ)) < 0) {
      q = -q;
      y[kChi] = 2.0 * std::atan2(q[3], q[0]);
    }
    return y;
  }

  SlotMap slot_map(Slot slot) const override {
    SlotMap M = SlotMap::Zero(3, kStateSize);
    const int offset = slot == Slot::Position ? kR : slot == Slot::Force ? kN : kM;
    M.block<3, 3>(0, offset).setIdentity();
    return M;
  }

  // Error rotation E = q conj(q_t), normalised: e = 2 sign(E_w) vec(E) is the lab-frame
  // rotation vector to first order. Linear in q/|q|, so its Jacobian is exact and cheap.
  Vec3 orientation_error(const Eigen::VectorXd& y, const OrientationTarget& target, bool track_turns,
                         SlotMap* jacobian) const override {
    const Eigen::Vector4d q = y.segment<4>(kQ);
    const double norm = q.norm();
    const Eigen::Vector4d p = q / norm;
    const Vec3 a = target.axis.normalized();
    const double c = std::cos(0.5 * target.angle), sn = std::sin(0.5 * target.angle);
    Eigen::Matrix<double, 3, 4> M;  // vec(p conj(q_t)) = M p
    M.col(0) = -sn * a;
    Mat3 a_cross;
    a_cross << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
    M.rightCols<3>() = c * Mat3::Identity() + sn * a_cross;
    const double scalar = p[0] * c + sn * p.tail<3>().dot(a);
    const double sign = scalar < 0 ? -1.0 : 1.0;
    Vec3 e = 2.0 * sign * M * p;
    Eigen::Matrix<double, 3, 4> de_dq =
        2.0 * sign * M * (Eigen::Matrix4d::Identity() - p * p.transpose()) / norm;
    if (track_turns) {
      // chi measures turns about e3 only (see the state layout above).
      if ((a - Vec3::UnitZ()).norm() > 1e-12)
        throw std::invalid_argument("turn tracking needs the rotation axis to be e3 = (0, 0, 1)");
      const Mat3 lateral = Mat3::Identity() - a * a.transpose();
      e = lateral * e + a * (y[kChi] - target.angle);
      de_dq = lateral * de_dq;
    }
    if (jacobian) {
      jacobian->setZero(3, kStateSize);
      jacobian->block<3, 4>(0, kQ) = de_dq;
      if (track_turns) jacobian->block<3, 1>(0, kChi) = a;
    }
    return e;
  }

  GaugeRows gauge_residual(const Eigen::VectorXd& y, Eigen::MatrixXd* jacobian) const override {
    const Eigen::Vector4d q = y.segment<4>(kQ);
    GaugeRows g(2);
    g[0] = q.squaredNorm() - 1.0;
    // (d held off zero as chi's equation holds it, turn_angle_denominator: a clamp pointing along
    // -e3 has w = qz = 0, where the gauge's derivatives were infinite.)
    const double w = q[0], qz = q[3], d = detail::turn_angle_denominator(w, q[1], q[2], qz);
    // chi(0) is the twist of R(0) up to whole turns: 2 atan2(qz, w) is it for q and -q alike
    // modulo 2 pi. The remainder keeps the residual continuous where the twist passes pi (w = 0):
    // a gauge in a fixed interval such as (-pi, pi] jumps by 2 pi there, and Newton could not
    // take a clamp turned by a parameter across half a turn (the plectoneme at turns = 1).
    // chi(0) thus follows the clamp's turns continuously from where the guess put it.
    g[1] = std::remainder(y[kChi] - 2.0 * std::atan2(qz, w), 2.0 * M_PI);
    if (jacobian) {
      jacobian->setZero(2, kStateSize);
      jacobian->block<1, 4>(0, kQ) = 2.0 * q.transpose();
      (*jacobian)(1, kChi) = 1.0;
      (*jacobian)(1, kQ) = 2.0 * qz / d;
      (*jacobian)(1, kQ + 3) = -2.0 * w / d;
    }
    return g;
  }

  LabDirections admissible_directions(Slot) const override { return LabDirections::Identity(3, 3); }

 private:
  RodModel model_;
  detail::Compliances compliances_;         // of model_ (declared after it: built from it)
  std::shared_ptr<const std::vector<ProfileJump>> jumps_;  // of model_: where its properties jump
  std::optional<CylinderSupport> support_;  // set: the rod lies on this cylinder
  bool tangent_stiffness_ = false;           // the field has a tangent stiffness (rod_model.hpp)
};

}  // namespace

const char* to_string(Slot slot) {
  switch (slot) {
    case Slot::Position: return "position";
    case Slot::Orientation: return "orientation";
    case Slot::Force: return "force";
    case Slot::Moment: return "moment";
  }
  return "?";
}

std::shared_ptr<const RodEquations> make_spatial_equations(RodModel model) {
  model.validate();
  return std::make_shared<SpatialEquations>(std::move(model));
}

std::shared_ptr<const RodEquations> make_spatial_equations_on_cylinder(RodModel model, CylinderSupport support) {
  model.validate();
  if (std::string why = rod_on_cylinder_unsupported(model); !why.empty()) throw std::invalid_argument(why);
  if (!(support.radius > 0.0)) throw std::invalid_argument("a supporting cylinder needs a radius > 0");
  if (!(support.axis.norm() > 0.0)) throw std::invalid_argument("a supporting cylinder needs a non-zero axis");
  support.axis.normalize();
  return std::make_shared<SpatialEquations>(std::move(model), std::move(support));
}

}  // namespace kirchhoff
