// Boundary conditions as composable pieces. An end of the rod imposes, along chosen lab
// directions, one of each work-conjugate pair: position or force, orientation or moment.
// Presets (clamped, pinned, free, loaded, sliding) are just particular choices of directions.
//
// Loads are the *applied* force/moment at that end: at s = L the internal force is n(L) = F,
// at s = 0 it is n(0) = -F (n is the force exerted by the part s+ on the part s-).
//
// Extra conditions (e.g. the end slope theta0 of the simply supported Elastica, Fig. 3) are
// imposed on top of a complete set; each one must be balanced by an unknown parameter (there
// the load P), which the shooting problem checks.
#pragma once

#include <Eigen/Dense>
#include <functional>
#include <string>
#include <vector>

#include "kirchhoff/equations/rod_equations.hpp"
#include "kirchhoff/model/parameters.hpp"

namespace kirchhoff {

using VectorTarget = std::function<Vec3(const Parameters&)>;
using OrientationFunction = std::function<OrientationTarget(const Parameters&)>;

// How the constrained directions of a slot are chosen; resolved against the equations'
// admissible directions (so the same condition works in 3D and in the plane).
enum class Directions {
  All,             // every admissible direction
  AlongAxis,       // the axis only
  LateralToAxis,   // the admissible directions orthogonal to the axis
};

struct SlotCondition {
  Slot slot = Slot::Position;
  Directions directions = Directions::All;
  Vec3 axis = Vec3::UnitZ();   // for AlongAxis / LateralToAxis
  VectorTarget value;          // position / applied force / applied moment (unused for orientation)
  OrientationFunction orientation;  // orientation target (Slot::Orientation only)
  bool track_turns = false;    // orientation: count whole turns about the target axis
  bool extra = false;          // an extra condition balanced by an unknown parameter

  // Orthonormal 3 x k basis of the constrained lab directions.
  LabDirections basis(const RodEquations& eq) const;
};

class EndCondition {
 public:
  // Position and frame imposed.
  static EndCondition clamped(VectorTarget position, OrientationFunction orientation, bool track_turns = false);
  // Position imposed, no applied moment.
  static EndCondition pinned(VectorTarget position);
  // No applied force or moment.
  static EndCondition free();
  // Dead force and moment applied, position and frame free.
  static EndCondition loaded(VectorTarget force, VectorTarget moment);
  // Position imposed across `axis`, free along it under the applied force's axial component; the
  // frame is imposed when `orientation` is given, otherwise the end carries no moment.
  static EndCondition sliding(Vec3 axis, VectorTarget position, VectorTarget force,
                              OrientationFunction orientation = {}, bool track_turns = false);

  // The end s = L is the point where the rod meets its own image under a half-turn about `axis`
  // (through the origin): symmetric plectonemes (section 7.6) solved on half the rod. The image
  // of the rest of the rod continues it smoothly when the end lies on the axis, the director
  // d_director (1 or 2) lies along the axis (so d3 is across it), and the force and moment have
  // no component along the axis. Which director is along the axis sets the parity of the end
  // rotation: with the start clamped at angle alpha about e3 and director 1 the whole rod's ends
  // differ by -2 alpha.
  //
  // With `rotation`, the frame's turn about the axis is imposed as well (the angle by which the
  // frame is turned about the axis from the one with d_director along it and d3 = e3 x axis
  // rotated into place), and "no moment along the axis" becomes an extra condition balanced by
  // an unknown parameter such as the end rotation: the same equilibria, parameterised by how far
  // the end loop has turned about the axis instead of by the end rotation.
  static EndCondition half_turn_symmetry(Vec3 axis, int director,
                                         std::function<double(const Parameters&)> rotation = {});

  EndCondition& add(SlotCondition condition);
  // Extra condition: the frame's rotation about `axis` equals `angle` (e.g. theta(0) = theta0).
  EndCondition& impose_orientation_angle(Vec3 axis, std::function<double(const Parameters&)> angle);
  // Extra condition: the arclength Hamiltonian H = n.v + m.u - V (eq. 29) at this end equals
  // `value`. This is the configurational force balance of an end sliding out of a frictionless
  // sleeve: H is continuous across the exit (sections 6.3, 7.3), and inside the straight sleeve
  // it is the inner tension (e.g. -P for a rod pushed by P, 0 for an unloaded end: eq. 55, Fig. 8).
  EndCondition& impose_hamiltonian(std::function<double(const Parameters&)> value);
  // The value of the H condition imposed by impose_hamiltonian, empty when there is none.
  const std::function<double(const Parameters&)>& hamiltonian_condition() const { return hamiltonian_; }

  const std::vector<SlotCondition>& conditions() const { return conditions_; }
  // The half-turn symmetry this end imposes without a turn of its own (half_turn_symmetry without
  // `rotation`): its axis and director; director 0 for any other end. The link check
  // (link.hpp) builds the whole rod from it.
  const Vec3& half_turn_axis() const { return half_turn_axis_; }
  int half_turn_director() const { return half_turn_director_; }
  // Whether this end is a half-turn symmetry point (with or without a turn of its own): the
  // problem is then half of a symmetric rod.
  bool is_half_turn_symmetry() const { return half_turn_; }
  int extra_count() const;

  // Checks that each work-conjugate pair is imposed exactly once along every admissible
  // direction. Returns the reason when not (e.g. "position and force both imposed along
  // (1, 0, 0)"), empty when complete.
  std::string check(const RodEquations& eq) const;

  // Residuals and their Jacobian with respect to the state y at this end.
  void append_residuals(const RodEquations& eq, bool at_start, const Eigen::VectorXd& y, const Parameters& p,
                        std::vector<double>* residual, std::vector<StateRow>* jacobian) const;

  // A state satisfying the imposed values (used to complete an initial guess).
  void impose_on(const RodEquations& eq, bool at_start, const Parameters& p, RodPoint* point) const;

 private:
  std::vector<SlotCondition> conditions_;
  std::function<double(const Parameters&)> hamiltonian_;  // extra H condition, if any
  Vec3 half_turn_axis_ = Vec3::Zero();
  int half_turn_director_ = 0;
  bool half_turn_ = false;
};

VectorTarget constant(const Vec3& v);
OrientationFunction constant_orientation(const OrientationTarget& t);

}  // namespace kirchhoff
