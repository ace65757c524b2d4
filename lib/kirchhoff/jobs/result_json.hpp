// JSON views of solver results (nlohmann::json, header-only: a user of this header needs its
// headers): the blocks `kirchhoff solve --json`, `equilibria` and `vibrate` print, and Python's
// Solution.path.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "kirchhoff/analysis/discrete_stability.hpp"
#include "kirchhoff/analysis/solution.hpp"
#include "kirchhoff/analysis/stability.hpp"
#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/jobs/case_solve.hpp"

namespace kirchhoff {

nlohmann::json solution_json(const Case& c, const ShootingProblem& problem, const Solution& sol,
                             const StabilityReport& stability, const DiscreteStability* discrete = nullptr);
// {"index": k or null, "zero_modes", "stable", "conjugate_points", "method", "reason", ...}.
nlohmann::json stability_json(const StabilityReport& stability, const DiscreteStability* discrete = nullptr);
// A failed solve: status word, iterations, best residual, reason; no result fields.
nlohmann::json failure_json(const Case& c, const std::string& status, int iterations, double residual,
                            const std::string& message);
nlohmann::json parameters_json(const Parameters& p);
// How a solve reached its equilibrium (case_solve.hpp): method, and for a homotopy the values it
// went from and to, its points, the branch points it crossed and where it stopped.
nlohmann::json path_json(const SolvePath& path);

}  // namespace kirchhoff
