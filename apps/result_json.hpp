// JSON views of solver results for the CLI (nlohmann::json).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "kirchhoff/case_file.hpp"
#include "kirchhoff/solution.hpp"

namespace kirchhoff::cli {

nlohmann::json solution_json(const Case& c, const ShootingProblem& problem, const Solution& sol);
// A failed solve: status word, iterations, best residual, reason; no result fields.
nlohmann::json failure_json(const Case& c, const std::string& status, int iterations, double residual,
                            const std::string& message);
nlohmann::json parameters_json(const Parameters& p);

}  // namespace kirchhoff::cli
