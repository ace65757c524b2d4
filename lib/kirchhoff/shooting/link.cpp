#include "kirchhoff/shooting/link.hpp"

#include <cmath>
#include <optional>
#include <sstream>

namespace kirchhoff {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Samples of the rod (of each half of a symmetric one) at the finest resolution of Wr: the pair
// sum is O(n^2), ~0.3 s at 2 x 8192 points.
constexpr int kMaxSamples = 8192;

// The angle of an imposed frame as a rotation about e3 (the reference frame has d3 = e3, so
// such a frame keeps d3 on the axis); nothing when the end's frame is not imposed that way.
std::optional<double> angle_about_e3(const EndCondition& end, const Parameters& p) {
  for (const SlotCondition& c : end.conditions()) {
    if (c.slot != Slot::Orientation || c.directions != Directions::All || !c.orientation) continue;
    const OrientationTarget t = c.orientation(p);
    const Vec3 axis = t.axis.normalized();
    if (std::abs(t.angle) < 1e-300) return 0.0;  // the identity, whatever its axis
    if ((axis - Vec3::UnitZ()).norm() < 1e-12) return t.angle;
    if ((axis + Vec3::UnitZ()).norm() < 1e-12) return -t.angle;
    return std::nullopt;
  }
  return std::nullopt;
}

// A polyline of the whole rod: points and unit tangents at the midpoints of its pieces, with
// the pieces' lengths (midpoint rule for both integrals).
struct Polyline {
  std::vector<Vec3> mid, tangent;
  std::vector<double> length;
  Vec3 start, end, axis_tangent;  // the ends on the axis and the common tangent there
};

Polyline whole_rod(const std::vector<RodPoint>& half, const Vec3& half_turn_axis) {
  std::vector<Vec3> r;
  for (const RodPoint& p : half) r.push_back(p.r);
  if (half_turn_axis.squaredNorm() > 0) {
    const Eigen::AngleAxisd image(kPi, half_turn_axis);
    for (size_t i = half.size() - 1; i-- > 0;) r.push_back(image * half[i].r);
  }
  Polyline line;
  for (size_t i = 0; i + 1 < r.size(); ++i) {
    const Vec3 d = r[i + 1] - r[i];
    const double l = d.norm();
    if (l == 0.0) continue;
    line.mid.push_back(0.5 * (r[i] + r[i + 1]));
    line.tangent.push_back(d / l);
    line.length.push_back(l);
  }
  line.start = r.front();
  line.end = r.back();
  return line;
}

// Gauss integrand summed over a ray from `origin` along `direction` (|direction| = 1) in closed
// form, for the piece at w = point - origin with tangent tau:
//   int_0^inf (tau x direction).(w - lambda direction) / |w - lambda direction|^3 dlambda
//   = (tau x direction).w_perp (1 + w_par / |w|) / rho^2,  rho = |w_perp|, w_par = w.direction.
double ray_term(const Vec3& w, const Vec3& tau, const Vec3& direction) {
  const double w_par = w.dot(direction);
  const Vec3 w_perp = w - w_par * direction;
  const double rho2 = w_perp.squaredNorm();
  const double norm = w.norm();
  if (rho2 <= 1e-28 * norm * norm) return 0.0;  // on the ray's line: its own extension
  return tau.cross(direction).dot(w_perp) * (1.0 + w_par / norm) / rho2;
}

// Wr of the polyline closed by the axis rays below its start and above its end.
double writhe(const Polyline& line) {
  const size_t n = line.mid.size();
  double pairs = 0.0;
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j) {
      const Vec3 d = line.mid[i] - line.mid[j];
      const double r = d.norm();
      pairs += line.tangent[i].cross(line.tangent[j]).dot(d) / (r * r * r) * line.length[i] * line.length[j];
    }
  double rays = 0.0;
  const Vec3& t = line.axis_tangent;
  for (size_t i = 0; i < n; ++i) {
    // The ray above the end goes along t. The one below the start is the ray from the start
    // along -t, but traversed along +t (from infinity up to the start): its tangent is the
    // opposite of its direction, which flips the sign of the integrand.
    rays += (ray_term(line.mid[i] - line.end, line.tangent[i], t) -
             ray_term(line.mid[i] - line.start, line.tangent[i], -t)) *
            line.length[i];
  }
  // Each unordered pair counts twice in the Gauss integral (1 / 4 pi): rod-rod and rod-ray.
  return (2.0 * pairs + 2.0 * rays) / (4.0 * kPi);
}

std::vector<double> uniform(double L, int n) {
  std::vector<double> s(n + 1);
  for (int i = 0; i <= n; ++i) s[i] = L * i / n;
  s.back() = L;
  return s;
}

}  // namespace

LinkCheck check_link(const ShootingProblem& problem, const Eigen::VectorXd& x) {
  LinkCheck out;
  const ProblemDefinition& d = problem.definition();
  const Parameters p = problem.parameters_at(x);
  const auto eq = problem.equations(p);
  auto refuse = [&](const std::string& why) {
    out.why_not = why;
    return out;
  };
  if (d.kind != RodKind::Spatial) return refuse("a planar rod has no link");
  if (eq->model().extensible) return refuse("the twist of a shearable rod's centreline is not u3");
  if (!d.contacts.empty()) return refuse("the check does not follow contact jumps");
  const std::optional<double> start_angle = angle_about_e3(d.start, p);
  if (!start_angle) return refuse("the start frame is not imposed as a rotation about e3");
  const Vec3 half_turn_axis = d.end.half_turn_director() == 1 ? d.end.half_turn_axis() : Vec3::Zero();
  std::optional<double> end_angle;
  if (half_turn_axis.squaredNorm() > 0) {
    // The image's end frame is the start's turned by the half-turn: the whole rod's ends differ
    // by -2 alpha about e3 (boundary_conditions.hpp, director 1).
    end_angle = -*start_angle;
  } else {
    end_angle = angle_about_e3(d.end, p);
  }
  if (!end_angle) return refuse("the end frame is not imposed as a rotation about e3, nor by a half-turn symmetry");
  out.imposed = (*end_angle - *start_angle) / (2.0 * kPi);

  const double L = eq->model().length;
  const auto ends = problem.sample(x, {0.0, L});
  const Vec3 t0 = ends.front().R.col(2), r0 = ends.front().r;
  // The whole rod's far end: the sampled end, or its image under the half-turn.
  Vec3 t1 = ends.back().R.col(2), r1 = ends.back().r;
  if (half_turn_axis.squaredNorm() > 0) {
    const Eigen::AngleAxisd image(kPi, half_turn_axis);
    r1 = image * r0;
    t1 = -(image * t0);
  }
  const double scale = L * (half_turn_axis.squaredNorm() > 0 ? 2.0 : 1.0);
  const double on_axis = 1e-8 * scale;
  if (r0.head<2>().norm() > on_axis || r1.head<2>().norm() > on_axis)
    return refuse("an end of the rod is not on the e3 axis");
  if (std::abs(std::abs(t0.z()) - 1.0) > 1e-8 || (t0 - t1).norm() > 1e-8)
    return refuse("the ends are not tangent to the e3 axis in the same sense");
  if ((r1 - r0).dot(t0) <= on_axis) return refuse("the end is not beyond the start along the axis");

  // Resolve Wr: double the samples until two estimates agree to 1e-3 of a turn (the midpoint
  // rule converges as h^2 once h is below the closest approach of distant parts of the rod).
  double previous = NAN;
  for (int n = 512; n <= kMaxSamples; n *= 2) {
    const std::vector<RodPoint> half = problem.sample(x, uniform(L, n));
    Polyline line = whole_rod(half, half_turn_axis);
    line.axis_tangent = t0;
    const double wr = writhe(line);
    double tw = 0.0;  // trapezoidal rule on u3 of the sampled rod
    for (size_t i = 0; i + 1 < half.size(); ++i) tw += 0.5 * (half[i].u.z() + half[i + 1].u.z()) * (half[i + 1].s - half[i].s);
    if (half_turn_axis.squaredNorm() > 0) tw *= 2.0;  // the image has the same twist density
    out.twist = tw / (2.0 * kPi);
    out.writhe = wr;
    out.link = out.twist + out.writhe;
    out.samples = static_cast<int>(line.mid.size());
    if (std::abs(out.link - previous) < 1e-3) {
      out.applies = true;
      return out;
    }
    previous = out.link;
  }
  return refuse("the writhe integral did not settle at " + std::to_string(kMaxSamples) + " samples");
}

std::string link_failure(const ShootingProblem& problem, const Eigen::VectorXd& x) {
  const LinkCheck check = check_link(problem, x);
  if (!check.applies || std::abs(check.link - check.imposed) < 0.25) return {};
  std::ostringstream os;
  os.precision(4);
  os << "the rod's link Tw + Wr = " << check.link << " turns differs from the imposed end rotation " << check.imposed
     << " turns by about " << std::lround(check.link - check.imposed)
     << " whole turns: the end frames match modulo whole turns only (reach this rotation by continuation from the "
        "case's value)";
  return os.str();
}

}  // namespace kirchhoff
