// The static rod equations as seen by the shooting method: a state vector y(s), its flow from
// one arclength to another (with the state-transition matrix when asked), and the maps from the
// state to the lab-frame quantities that boundary conditions talk about.
//
// Two implementations share this contract: SpatialEquations (the 3D Reissner/Kirchhoff rod, the
// core) and PlanarEquations (its restriction to the (x, y) plane, eq. 52 and B.3, a thin
// specialisation that keeps six unknowns instead of fourteen).
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <vector>

#include "kirchhoff/equations/integrator.hpp"
#include "kirchhoff/model/rod_model.hpp"

namespace kirchhoff {

// Everything known about the rod at one arclength, in the lab frame unless said otherwise.
struct RodPoint {
  double s = 0.0;
  Vec3 r = Vec3::Zero();      // centreline
  Mat3 R = Mat3::Identity();  // material frame, columns d1, d2, d3
  Vec3 n = Vec3::Zero();      // internal force
  Vec3 m = Vec3::Zero();      // internal moment
  Vec3 u = Vec3::Zero();      // curvatures and twist, material components (u1, u2, u3)
  Vec3 v = Vec3::Zero();      // shear and stretch, material components (v1, v2, v3)
  double turn_angle = 0.0;    // rotation of the frame about the turn axis, tracked continuously
};

// The four quantities an end condition can impose, each a 3-vector in the lab frame.
enum class Slot { Position, Orientation, Force, Moment };
const char* to_string(Slot slot);

// An imposed frame: the equations' reference frame rotated by `angle` about `axis` (lab frame).
// 3D reference: identity (d3 = e3). Planar reference: d3 = e_x, d2 = e_z (section 7 of the paper).
struct OrientationTarget {
  Vec3 axis = Vec3::UnitZ();
  double angle = 0.0;
};

// Fixed largest sizes (no heap) for what the end conditions read at every evaluation: at most 3
// lab directions (a 3 x k basis), and a 3 x state_size read-out of a slot. The largest state is
// the spatial rod's (14).
constexpr int kMaxStateSize = 14;
using LabDirections = Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::ColMajor, 3, 3>;
using SlotMap = Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::ColMajor, 3, kMaxStateSize>;
// One condition's row of a Jacobian with respect to the state (fixed capacity: no allocation).
using StateRow = Eigen::Matrix<double, 1, Eigen::Dynamic, Eigen::RowMajor, 1, kMaxStateSize>;
// The gauge conditions of a state representation (RodEquations::gauge_residual): at most two.
using GaugeRows = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, 2, 1>;

class RodEquations {
 public:
  virtual ~RodEquations() = default;

  virtual int state_size() const = 0;
  virtual const RodModel& model() const = 0;
  virtual bool is_planar() const = 0;

  // Flow over [s0, s1] into *out: the state, and with `sensitivities` Phi = dy(s1)/dy(s0) (and
  // dy/dmu where the equations carry it, SegmentFlow::dy_dunfolding); without, Phi and
  // dy_dunfolding are left empty. Its storage is reused, so that a residual or Jacobian
  // evaluation allocates nothing once its buffers have their sizes (ShootingWorkspace::buffers).
  // Throws IntegrationError when the integrator gives up.
  virtual void flow_into(const Eigen::VectorXd& y0, double s0, double s1, bool sensitivities,
                         const IntegratorOptions& options, SegmentFlow* out) const = 0;
  // flow_into a new SegmentFlow.
  SegmentFlow flow(const Eigen::VectorXd& y0, double s0, double s1, bool sensitivities,
                   const IntegratorOptions& options) const {
    SegmentFlow out;
    flow_into(y0, s0, s1, sensitivities, options, &out);
    return out;
  }
  // The state and the columns of `directions` (state perturbations at s0) carried to s1 by the
  // variational equations, Phi directions, without forming Phi when there are fewer directions
  // than Phi has non-trivial columns. *carried hands the adaptive step sizes from one call to the
  // next, so adjacent intervals make one integration observed at their ends. Throws
  // IntegrationError as flow() does.
  virtual DirectionalFlow flow_directions(const Eigen::VectorXd& y0, const Eigen::MatrixXd& directions, double s0,
                                          double s1, const IntegratorOptions& options,
                                          CarriedSteps* carried) const = 0;
  virtual std::vector<Eigen::VectorXd> sample(const Eigen::VectorXd& y0, const std::vector<double>& s,
                                              const IntegratorOptions& options) const = 0;

  // dy/ds at (y, s): the right-hand side itself (moving a segment end moves its end state along it).
  virtual Eigen::VectorXd derivative(const Eigen::VectorXd& y, double s) const = 0;

  virtual RodPoint point(const Eigen::VectorXd& y, double s) const = 0;
  // The state entry that is RodPoint::turn_angle: counted continuously along the rod (state()
  // sets it in (-pi, pi] from the frame alone).
  virtual int turn_angle_index() const = 0;
  // State from lab-frame data (used to build initial guesses); the frame must be admissible.
  virtual Eigen::VectorXd state(const RodPoint& p) const = 0;
  // state(p) for a point beside one whose state is `neighbour` (consecutive nodes of a guess):
  // where p's frame leaves its representation to round-off (a spatial rod's quaternion sign when
  // q0 is at round-off: state() picks q0 >= 0), the one continuous with the neighbour's.
  virtual Eigen::VectorXd state_beside(const RodPoint& p, const Eigen::VectorXd& /*neighbour*/) const {
    return state(p);
  }

  // Linear read-out of position, force and moment: value = M y, with M of size 3 x state_size.
  virtual SlotMap slot_map(Slot slot) const = 0;
  // Lab-frame rotation taking the target frame to the current one (zero iff they agree). With
  // track_turns, its component along target.axis is replaced by turn_angle - target.angle, which
  // counts whole turns instead of working modulo 2 pi.
  virtual Vec3 orientation_error(const Eigen::VectorXd& y, const OrientationTarget& target, bool track_turns,
                                 SlotMap* jacobian) const = 0;
  // Conditions internal to the state representation, imposed once at s = 0 (e.g. |q| = 1).
  // At most two rows (fixed-capacity storage: no allocation).
  virtual GaugeRows gauge_residual(const Eigen::VectorXd& y, Eigen::MatrixXd* jacobian) const = 0;
  // Orthonormal basis (3 x k) of the lab directions a slot can move in (all of R^3 in 3D; the
  // plane for positions and forces, e_z for orientations and moments in the planar case).
  virtual LabDirections admissible_directions(Slot slot) const = 0;
};

std::shared_ptr<const RodEquations> make_spatial_equations(RodModel model);
std::shared_ptr<const RodEquations> make_planar_equations(RodModel model);

// The planar reference frame as a 3D frame: d1 = e_y, d2 = e_z, d3 = e_x.
Mat3 planar_reference_frame();

}  // namespace kirchhoff
