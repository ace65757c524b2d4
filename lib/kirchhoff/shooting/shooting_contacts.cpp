// ShootingProblem's contact mechanics: the active contacts' unknowns, the residual across them
// (single shooting through the contact points; multiple shooting whose segments move with the
// contacts), the pieces' equations (the rod's, or a spatial rod lying on a cylinder), and the
// measures the contact continuation watches (g'' at a point contact, the margin of a flat part,
// the tension and smallest pressure of a wrap). The conditions themselves are in
// detail/contact_conditions.hpp.
#include <algorithm>
#include <cmath>
#include <optional>

#include "kirchhoff/equations/detail/rod_on_cylinder.hpp"
#include "kirchhoff/shooting/detail/contact_conditions.hpp"
#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

using detail::Breakpoint;
using detail::DiscWrap;
using detail::PointContactTerms;
using detail::SegmentSpan;
using detail::breakpoints;
using detail::contacts_in_order;
using detail::disc_wrap;
using detail::point_contact_rows;
using detail::point_contact_terms;
using detail::segment_spans;
using detail::support_of;

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
        workspace_.count_rhs(flow.rhs_evaluations);
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

namespace {

// Where a spatial rod enters or leaves a cylinder (the only extended contact of multiple
// shooting): entering, it is on the cylinder with g = g' = g'' = 0, and g''' = 0 once the edge
// force is applied (rod_on_cylinder.hpp); leaving, only the edge force. Both push along e: *jump
// is n's jump per unit edge force, and S (dy/dx at the breakpoint, with J) turns with e.
int cylinder_breakpoint_rows(const RodEquations& eq, const Obstacle& o, const Breakpoint& b, const Eigen::VectorXd& y,
                             Eigen::MatrixXd* S, Eigen::VectorXd* F, Eigen::MatrixXd* J, int row,
                             Eigen::VectorXd* jump) {
  const CylinderSupport c = support_of(o);
  const RodModel& model = eq.model();
  const Eigen::MatrixXd force = eq.slot_map(Slot::Force);
  Eigen::MatrixXd dG, de;
  if (b.kind == Breakpoint::ExtendedStart) {
    const Eigen::Vector4d G = cylinder_gap_derivatives(model, c, y, J ? &dG : nullptr);
    for (int k = 0; k < 3; ++k, ++row) {
      (*F)[row] = G[k];
      if (J) J->row(row) = dG.row(k) * *S;
    }
  }
  const Vec3 e = cylinder_normal(c, y, J ? &de : nullptr);
  if (J) *S -= b.force * force.transpose() * de * *S;
  *jump = -force.transpose() * e;
  if (b.kind == Breakpoint::ExtendedStart) {
    const Eigen::VectorXd after = y + b.force * *jump;
    const Eigen::Vector4d G = cylinder_gap_derivatives(model, c, after, J ? &dG : nullptr);
    (*F)[row] = G[3];
    if (J) {
      Eigen::MatrixXd S_after = *S;
      S_after.col(b.force_column) += *jump;
      J->row(row) = dG.row(3) * S_after;
    }
    ++row;
  }
  return row;
}

}  // namespace

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
  for (const auto& flow : flows) workspace_.count_rhs(flow.rhs_evaluations);

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
      row = cylinder_breakpoint_rows(*eq, o, b, y, J ? &S : nullptr, F, J, row, &jump);
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

}  // namespace kirchhoff
