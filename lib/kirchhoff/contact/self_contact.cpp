#include "kirchhoff/contact/self_contact.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "kirchhoff/equations/integrator.hpp"

namespace kirchhoff {
namespace {
constexpr double kUnderflowExponent = 746.0;  // exp(-746) underflows to 0
}  // namespace

Vec3 HalfTurnGeometry::radial(const Vec3& r) const {
  const Vec3 d = r - origin;
  return d - axis * axis.dot(d);
}

std::vector<WholeRodSection> HalfTurnGeometry::whole_rod(const std::vector<RodPoint>& half) const {
  std::vector<WholeRodSection> out;
  out.reserve(2 * half.size());
  const double Lh = half.back().s;
  for (const auto& p : half) out.push_back({p.s, p.r});
  for (auto it = half.rbegin() + 1; it != half.rend(); ++it) out.push_back({2.0 * Lh - it->s, image(it->r)});
  return out;
}

HalfTurnSelfContact::HalfTurnSelfContact(const HalfTurnSelfContactOptions& options)
    : options_(options), geometry_{options.origin, options.axis.normalized(), options.radius, options.symmetry_s} {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument(what);
  };
  require(options.radius > 0.0, "self-contact radius must be > 0");
  require(options.strength > 0.0, "self-contact strength must be > 0");
  require(options.range > 0.0, "self-contact range must be > 0");
  require(options.adjacent > 0.0, "self-contact adjacent length must be > 0");
  require(options.axis.norm() > 0.0, "self-contact axis must be a non-zero vector");
  require(options.symmetry_s > 2.0 * options.adjacent,
          "self-contact: the rod is shorter than twice the adjacent length");
}

double HalfTurnSelfContact::weight(double s) const {
  const double off = options_.symmetry_s - options_.adjacent;
  const double on = options_.symmetry_s - 2.0 * options_.adjacent;
  if (s <= on) return 1.0;
  if (s >= off) return 0.0;
  const double t = (off - s) / (off - on);  // 0 at `off`, 1 at `on`
  return t * t * t * (10.0 + t * (-15.0 + 6.0 * t));  // C2 smoothstep
}

HalfTurnSelfContact::Barrier HalfTurnSelfContact::barrier(double s, const Vec3& r) const {
  Barrier b;
  b.w = weight(s);
  if (b.w == 0.0) return b;
  b.d = geometry_.radial(r);
  b.rho = b.d.norm();
  const double g = b.rho - options_.radius;
  if (!(g > 0.0))
    throw IntegrationError("the rod passes through itself at s = " + std::to_string(s) +
                           " (distance to the symmetry axis below the radius)");
  const double c = options_.range;
  // exp(-x) is exactly 0 for x > 745.2; computing it there takes libm's slow underflow path (a
  // tenth of a plectoneme run's time went there), so it is skipped, with the same result.
  const double exponent = (g * g) / (c * c);
  const double e = exponent < kUnderflowExponent ? options_.strength * std::exp(-exponent) : 0.0;
  b.phi = e / g;
  b.dphi = -e * (2.0 / (c * c) + 1.0 / (g * g));
  b.ddphi = e * (4.0 * g / (c * c * c * c) + 2.0 / (c * c * g) + 2.0 / (g * g * g));
  return b;
}

double HalfTurnSelfContact::potential(double s, const Vec3& r) const {
  const Barrier b = barrier(s, r);
  return b.w * b.phi;
}

Vec3 HalfTurnSelfContact::force(double s, const Vec3& r) const {
  const Barrier b = barrier(s, r);
  if (b.w == 0.0) return Vec3::Zero();
  return -b.w * b.dphi * b.d / b.rho;
}

Mat3 HalfTurnSelfContact::force_gradient(double s, const Vec3& r) const {
  const Barrier b = barrier(s, r);
  if (b.w == 0.0) return Mat3::Zero();
  const Vec3 e = b.d / b.rho;
  const Mat3 across = Mat3::Identity() - geometry_.axis * geometry_.axis.transpose() - e * e.transpose();
  return -b.w * (b.ddphi * e * e.transpose() + b.dphi * across / b.rho);
}

double HalfTurnSelfContact::gap(double s, const Vec3& r) const {
  if (weight(s) == 0.0) return std::numeric_limits<double>::quiet_NaN();
  return geometry_.distance_to_axis(r) - options_.radius;
}

const HalfTurnSelfContact* find_half_turn_self_contact(const RodModel& model) {
  if (!model.field) return nullptr;
  if (auto* direct = dynamic_cast<const HalfTurnSelfContact*>(model.field.get())) return direct;
  if (auto* sum = dynamic_cast<const FieldSum*>(model.field.get()))
    for (const auto& f : sum->fields())
      if (auto* found = dynamic_cast<const HalfTurnSelfContact*>(f.get())) return found;
  return nullptr;
}

}  // namespace kirchhoff
