// Where a material property given piecewise along the rod jumps ("EI*(1 - 0.9*(s > 0.4 && s < 0.5))",
// "s < a ? B1 : B2"). An adaptive integrator that is not told where a jump is can step across a
// short stretch of it without seeing it (a 0.1 % soft zone of the Euler column gave the uniform
// rod's answer, converged); the integrations land on each jump located here instead
// (IntegratorOptions::jumps).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "kirchhoff/model/rod_model.hpp"

namespace kirchhoff {

// Jumps are looked for between this many equal intervals of the rod: a stretch shorter than
// L / kJumpSamples can fall between two samples and is not seen (docs/case-files.md says so).
constexpr int kJumpSamples = 16384;

// Whether an expression's text can jump as s varies: a comparison, a logical or conditional
// operator, or muParser's sign or rint.
bool may_jump(const std::string& expression_text);

// The jumps of f on [0, length]: sampled at kJumpSamples + 1 points, each interval whose change
// stands out from its neighbours' is bisected down to two adjacent doubles, and kept where the
// change does not vanish with the interval (a smooth steep stretch does). Sorted by s.
std::vector<ProfileJump> locate_jumps(const std::function<double(double)>& f, double length);

// The arclengths at which a property is checked (positive, finite): kJumpSamples + 1 equally
// spaced ones and both sides of each jump.
std::vector<double> check_points(double length, const std::vector<ProfileJump>& jumps);

}  // namespace kirchhoff
