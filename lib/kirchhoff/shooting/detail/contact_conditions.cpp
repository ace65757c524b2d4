#include "kirchhoff/shooting/detail/contact_conditions.hpp"

#include <cmath>

namespace kirchhoff::detail {

Eigen::VectorXd DiscWrap::advance(const RodEquations& eq, const Eigen::VectorXd& y, double length,
                                  Eigen::MatrixXd* d_state, Eigen::VectorXd* d_length) const {
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

CylinderSupport support_of(const Obstacle& o) {
  CylinderSupport c;
  c.point = o.point();
  c.axis = o.direction();
  c.radius = o.radius();
  return c;
}

}  // namespace kirchhoff::detail
