// Integration of the rod equations in arclength with Boost.Odeint, with or without the
// variational equations (state-transition matrix Phi = dy(s1)/dy(s0)).
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "kirchhoff/model/rod_model.hpp"

namespace kirchhoff {

struct IntegratorOptions {
  enum class Stepper {
    Dopri5,        // Dormand-Prince 5(4): cheap steps, for loose tolerances
    RungeKutta78,  // Runge-Kutta-Fehlberg 7(8): fewer steps at the tight tolerances we default to
  };
  // Default: RK78 at 1e-12, tight enough that H is flat to ~1e-10 of its scale on the test cases.
  Stepper stepper = Stepper::RungeKutta78;
  double abs_tol = 1e-12;   // absolute error per step (odeint's error checker)
  double rel_tol = 1e-12;   // relative error per step
  double initial_step = 1e-2;  // first trial step as a fraction of the segment length
  long max_steps = 200000;     // per segment; beyond this the integration is reported as failed
  // Tolerance (absolute and relative) of the variational equations alone; 0 (or anything not
  // looser than abs_tol): those of the state, in one pass.
  // When set, a flow with sensitivities is two integrations: the state at abs_tol/rel_tol (the
  // very computation a residual without sensitivities makes, so F is the same number either way)
  // and state plus Phi at this looser tolerance. Newton, chords and tangents need Phi to a few
  // digits only, and RK78 takes (tol ratio)^(1/8) fewer steps: at 1e-8 against 1e-13 about four
  // times fewer on the duals that are most of a long rod's cost. Branch-point location, whose
  // smallest singular values reach ~1e-12, needs Phi as accurate as the state: leave it 0 there.
  double sensitivity_tol = 0.0;
  // With sensitivity_tol looser than abs_tol: the looser pass alone, the flow's state that pass's
  // (to sensitivity_tol), without the state's own pass - for a caller that needs Phi and has F
  // (ShootingProblem::step_matrix).
  bool sensitivities_only = false;
  // Where the right-hand side jumps (a material property given piecewise; the equations set it
  // from RodModel::jumps, not the caller): every integration ends a stretch on a jump's `before`
  // and goes on from its `after`, so that no step straddles it. Null: none.
  std::shared_ptr<const std::vector<ProfileJump>> jumps;
  // The longest step (arclength); 0: none. RKF78's error estimate is h 41/840 (k1 + k11 - k12 -
  // k13), stages 12 and 13 taken where 1 and 11 are: it vanishes where the right-hand side
  // depends on s alone along the step, and then nothing holds the step back. A planar rod
  // without force whose curvature is constant is such a case (theta linear in s, the position
  // a quadrature of it): a ring closed by pinning both ends at one point had its closure off by
  // 6.7e-5 in a residual. The planar equations set it from the rotation rate (planar_equations.cpp).
  double max_step = 0.0;

  // A planar rod whose only load is the force at its ends (uniform, inextensible, no field,
  // constant natural curvature) is flowed in closed form, Jacobi's elliptic functions of the
  // pendulum its moment obeys (detail/elastica_flow.hpp), where its orbit oscillates and within
  // the limits there: the state to about 1e-13 of its size whatever the tolerances above, and
  // some forty times cheaper than a march. A ShootingProblem with obstacles sets it false. False:
  // always march (the stepper above), as a baseline or a cross-check.
  bool closed_form = true;

  // Returns an empty string when valid, else the reason.
  std::string validate() const;
};

// Thrown by the integrators; the shooting layer turns it into a status, never lets it escape.
struct IntegrationError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct SegmentFlow {
  Eigen::VectorXd y;    // state at the end of the segment
  Eigen::MatrixXd Phi;  // dy(s1)/dy(s0); empty unless sensitivities were requested
  // dy(s1)/dmu at fixed y(s0), mu the unfolding couple (RodModel::unfolding_sensitivity); empty
  // where the equations do not carry it (the caller differences instead).
  Eigen::VectorXd dy_dunfolding;
  long rhs_evaluations = 0;
  long steps = 0;
};

// The adaptive step sizes one integration proposes for its next step, handed from an interval to
// the next adjacent one (RodEquations::flow_directions): a sequence of short intervals is then one
// integration observed at their ends, instead of restarting each from a small trial step. Zero:
// not known yet (the first trial step is IntegratorOptions::initial_step of the interval).
struct CarriedSteps {
  double directions = 0.0;  // of the state integrated with the directions
  double state = 0.0;       // of the state alone (with IntegratorOptions::sensitivity_tol only)
};

// The state and given directions (state perturbations, columns) carried over an interval:
// directions(s1) = Phi directions(s0).
struct DirectionalFlow {
  Eigen::VectorXd y;
  Eigen::MatrixXd directions;
  long rhs_evaluations = 0;
  long steps = 0;
};

}  // namespace kirchhoff
