// The checks a solution passes before it is called converged. Newton's own test (max |F| within
// the tolerance) is not enough on its own: a residual evaluated on a NaN state, a profile sampled
// wrongly, or a rod outside the domain of its soft wall's potential would all pass it. Each check
// returns "" when it passes, else the reason, which becomes the message of a CheckFailed status.
#pragma once

#include <string>
#include <vector>

#include "kirchhoff/equations/rod_equations.hpp"
#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

// The unknowns and parameters are finite, and the residual, evaluated afresh at the returned
// unknowns, is finite and within the tolerance Newton reported converging to (the residual
// tolerance, or 1e3 times it for a step that stopped at round-off: NewtonOptions::step_tolerance).
std::string unknowns_failure(const ShootingProblem& problem, const ShootingResult& result);

// A guess that already meets the residual tolerance (Newton converged after 0 iterations) is a
// solution only if the tolerance means something at the case's scale: the residual tolerance is
// absolute, so a rod of length 1e-100 meets it at any guess. One Newton correction from the
// solution, J^-1 F, must be small beside the unknowns (kGuessCorrectionTolerance (1 + |x|)); a
// correction that large says the residual is small only because the case's lengths, stiffnesses
// or loads are far from 1. Costs one Jacobian, and only for solves that took no Newton step (after
// a step, the step itself shows the scale).
std::string zero_iteration_failure(const ShootingProblem& problem, const ShootingResult& result);

// Whether a case's length and bending stiffness lie within three decades of 1, either way: where
// they do not, its absolute residual tolerance means something else and its matrices are
// ill-conditioned by its units alone (zero_iteration_failure's and a singular solve's messages).
bool of_unit_scale(double length, double bending);

// A correction below 1e-4 of the unknowns' size is far above what a converged residual gives (|F|
// <= 1e-10 through a Jacobian even as ill-conditioned as 1e-5 near a fold: 1e-5), and far below
// what a residual that is small only by scale gives (orders of magnitude beyond the unknowns).
inline constexpr double kGuessCorrectionTolerance = 1e-4;

// Every sampled state is finite, an extensible rod's stretch v3 = v.d3 stays positive (at v3 <= 0
// a section has been pushed onto or past its neighbour: Reissner's strains, like Antman's, require
// v3 > 0), and the rod stays strictly inside the domain of its external field's potential (a soft
// wall's W_ext = b / (a - y) is infinite at the wall and has no physical meaning beyond it: a
// solution there is a solution of the equations, not of the rod).
std::string profile_failure(const RodModel& model, const std::vector<RodPoint>& profile);

// Applies a check to a result Newton called converged: a failure turns it into CheckFailed with
// the reason. Results that did not converge are left as they are.
void mark_check_failure(ShootingResult* result, const std::string& failure);

}  // namespace kirchhoff
