// The contact conditions of the shooting residual: where the internal force jumps (point contacts
// and the ends of extended ones), how multiple-shooting segments follow the contacts, what a point
// contact imposes on the state (closed-form gap and tangency, with their derivatives), and the
// exact solution along a wrap around a disc. ShootingProblem's contact members
// (shooting_contacts.cpp) build the residual from these; sample() and initial_unknowns() use them
// to cross the contacts.
#pragma once

#include <Eigen/Dense>
#include <vector>

#include "kirchhoff/equations/detail/rod_on_cylinder.hpp"
#include "kirchhoff/equations/rod_equations.hpp"
#include "kirchhoff/model/obstacle.hpp"
#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff::detail {

// A place where n jumps: a point contact, or either end of an extended one.
struct Breakpoint {
  double s;
  double force;
  int obstacle;
  int s_column, force_column;  // their unknowns
  enum Kind { Point, ExtendedStart, ExtendedEnd } kind;
};

// The breakpoints of the contacts, in their order, with the columns of their unknowns (columns[k]
// is contact k's first).
std::vector<Breakpoint> breakpoints(const std::vector<PointContact>& contacts, const std::vector<int>& columns);

// Whether the breakpoints increase inside (0, L): strictly, except that an extended contact may
// have zero length (when it forms), and a wrap a negative one (traversed backwards: not a rod, but
// the residual stays smooth where a wrap shrinks to a point, so that event is located by crossing).
// Flat contacts are kept >= 0: their legs are degenerate (see run_legs in contact.cpp), and allowed
// a negative length the first step after flattening goes that way.
bool contacts_in_order(const std::vector<Breakpoint>& points, const std::vector<Obstacle>& obstacles, double L);

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
                          Eigen::MatrixXd* d_state = nullptr, Eigen::VectorXd* d_length = nullptr) const;
};

// The wrap that starts where the rod, with tangent t, touches the disc o with reaction normal nu
// (pointing from the disc to the rod): the rod turns towards the centre, theta' = -(t x nu).e_z / radius.
DiscWrap disc_wrap(const Obstacle& o, const Vec3& tangent, const Vec3& normal);

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
                                       double L);

// What a point contact (or the entry of an extended one on a plane or disc) imposes, closed-form
// in the state y at arclength s, with the derivatives the Jacobian needs.
struct PointContactTerms {
  Obstacle::ContactConditions here;  // gap, tangency and the reaction's direction
  Eigen::MatrixXd d_rows;            // 2 x n: gap and tangency in the state
  Eigen::MatrixXd d_normal;          // 3 x n: the direction in the state
  Eigen::Vector2d d_s = Eigen::Vector2d::Zero();  // gap and tangency in s (r' depends on s where natural strains do)
};

PointContactTerms point_contact_terms(const RodEquations& eq, const Obstacle& o, const Eigen::VectorXd& y, double s,
                                      bool derivatives);

// A point contact's two rows at `row` (on the obstacle and tangent to it), with their Jacobian
// through S = dy/dx there and the contact arclength's own column (J null: the rows alone).
// Returns the next row.
int point_contact_rows(const PointContactTerms& t, const Eigen::MatrixXd& S, int s_column, Eigen::VectorXd* F,
                       Eigen::MatrixXd* J, int row);

// The cylinder a spatial rod lies on over an extended contact.
CylinderSupport support_of(const Obstacle& o);

}  // namespace kirchhoff::detail
