// The checks a solution passes before it is called converged. Newton's own test (max |F| within
// the tolerance) is not enough on its own: a residual evaluated on a NaN state, a profile sampled
// wrongly, or a rod outside the domain of its soft wall's potential would all pass it. Each check
// returns "" when it passes, else the reason, which becomes the message of a CheckFailed status.
#pragma once

#include <string>
#include <vector>

#include "kirchhoff/rod_equations.hpp"
#include "kirchhoff/shooting.hpp"

namespace kirchhoff {

// The unknowns and parameters are finite, and the residual, evaluated afresh at the returned
// unknowns, is finite and within the tolerance Newton reported converging to (the residual
// tolerance, or 1e3 times it for a step that stopped at round-off: NewtonOptions::step_tolerance).
std::string unknowns_failure(const ShootingProblem& problem, const ShootingResult& result);

// Every sampled state is finite, and the rod stays strictly inside the domain of its external
// field's potential (a soft wall's W_ext = b / (a - y) is infinite at the wall and has no
// physical meaning beyond it: a solution there is a solution of the equations, not of the rod).
std::string profile_failure(const RodModel& model, const std::vector<RodPoint>& profile);

// Applies a check to a result Newton called converged: a failure turns it into CheckFailed with
// the reason. Results that did not converge are left as they are.
void mark_check_failure(ShootingResult* result, const std::string& failure);

}  // namespace kirchhoff
