// JSON views of solver results for the CLI (nlohmann::json).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "kirchhoff/case_file.hpp"
#include "kirchhoff/solution.hpp"
#include "kirchhoff/stability.hpp"

namespace kirchhoff::cli {

nlohmann::json solution_json(const Case& c, const ShootingProblem& problem, const Solution& sol,
                             const StabilityReport& stability);
// {"index": k or null, "zero_modes", "stable", "conjugate_points", "method", "reason", ...}.
nlohmann::json stability_json(const StabilityReport& stability);
// A failed solve: status word, iterations, best residual, reason; no result fields.
nlohmann::json failure_json(const Case& c, const std::string& status, int iterations, double residual,
                            const std::string& message);
nlohmann::json parameters_json(const Parameters& p);

}  // namespace kirchhoff::cli
