#include "kirchhoff/jobs/case_equilibria.hpp"

#include <algorithm>
#include <chrono>
#include <sstream>

#include "kirchhoff/jobs/case_solve.hpp"

namespace kirchhoff {
namespace {

// Of the search's budget (max_seconds, max_newton_runs, max_equilibria), the share the search at
// the file's values may use: the search at the requested values, which lists the result, keeps
// the rest.
constexpr double kFileValuesShare = 0.25;
constexpr int kFileValuesMaxEquilibria = 8;
// A carried path is followed through folds (HomotopyOptions::through_folds) for at most this many
// points: one that turns away from the requested values for good ends there. On the wall from
// Delta = 0.026 to 0.05 one path turns at 0.0477 and again, and reaches a rod touching twice
// (index 1) that no starting point at 0.05 reached, and whose neighbours lead to the stable
// hanging fold (the eight carried paths there take 2 s together).
constexpr int kCarriedPathPoints = 600;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The equilibria at the file's values, each carried to the requested values along its own
// homotopy (homotopy.hpp), as known roots of the search there. A rod loaded far past its
// critical loads has its stable equilibria far from every starting point the search makes there
// (the first-mode rods of a cantilever under 12 times its critical load, looped back past the
// clamp), while at a moderate load the search finds them next to the straight rod, and they
// follow the load smoothly. Each path is followed as `solve` follows its own, but through its
// folds: one that turns back may turn again and reach the requested values.
// Returns the Newton runs of the search at the file's values.
int carry_from_file_values(const Case& c, const std::vector<ParameterChange>& changes, int samples,
                           const EquilibriaOptions& options, std::vector<EquilibriaOptions::KnownRoot>* roots,
                           std::vector<std::string>* log) {
  const auto t0 = std::chrono::steady_clock::now();
  const Case start = case_at_file_values(c);
  EquilibriaOptions at_file = options;
  at_file.known_roots.clear();
  // (Not the caller's --max, which bounds the list at the requested values: a small one kept the
  // equilibrium that carries to the stable one there from being found.)
  at_file.max_equilibria = kFileValuesMaxEquilibria;
  at_file.max_newton_runs = std::max(1, static_cast<int>(kFileValuesShare * options.max_newton_runs));
  at_file.max_seconds = kFileValuesShare * options.max_seconds;
  const EquilibriaSearch found = find_equilibria(start.definition, start.start_guess, start.derived, samples, at_file);
  std::ostringstream summary;
  summary << "at the file's values (" << describe_values(changes, 0.0) << "): " << found.equilibria.size()
          << " equilibria in " << found.newton_runs << " Newton runs (" << found.stopped_because << ")";
  log->push_back(summary.str());
  HomotopyOptions homotopy;
  homotopy.through_folds = true;
  homotopy.max_points = kCarriedPathPoints;
  if (options.max_seconds > 0)
    homotopy.deadline = t0 + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                 std::chrono::duration<double>(2 * kFileValuesShare * options.max_seconds));
  for (size_t k = 0; k < found.equilibria.size(); ++k) {
    const Equilibrium& e = found.equilibria[k];
    const std::string label = "homotopy from the file's values of their equilibrium #" + std::to_string(k + 1);
    try {
      const HomotopyResult h = follow_homotopy(e.problem->definition(), e.solution.result.x, changes, homotopy);
      // A path that reached the requested values but whose Newton there failed its checks (the
      // residual recomputed at 1.7e-9 for a tolerance of 1e-10, under a load of 150 on the
      // shallow arch) still ends next to a root: the search's own root test decides, as for any
      // other seed (the arch's only stable equilibrium at w = 150 came this way, and was lost).
      const bool at_requested = h.reached || (h.stop == "not_converged" && h.result.x.allFinite());
      if (h.reached && h.result.summary.converged())
        roots->push_back({h.definition.contacts, h.result.x, label});
      else if (at_requested)
        roots->push_back({h.definition.contacts, h.result.x, label + " (Newton's check failed there)"});
      else
        log->push_back(label + ": not carried (" + h.stop + (h.message.empty() ? "" : ": " + h.message) + ")");
    } catch (const std::exception& error) {
      log->push_back(label + ": " + error.what());
    }
  }
  log->push_back("carried to the requested values: " + std::to_string(roots->size()) + " of " +
                 std::to_string(found.equilibria.size()) + " (" + std::to_string(seconds_since(t0)) + " s)");
  return found.newton_runs;
}

}  // namespace

EquilibriaSearch find_case_equilibria(const Case& c, int samples, EquilibriaOptions options) {
  if (const std::string why = imposed_end_inside_obstacle(c.definition); !why.empty()) {
    EquilibriaSearch none;
    none.stopped_because = "infeasible";
    none.log.push_back(why);
    return none;
  }
  // Without changed values `solve` is Newton from the case's guess, which the search's first seed
  // is already: only a homotopy adds an equilibrium the search might not reach.
  const std::vector<ParameterChange> changes = homotopy_changes(c);
  if (changes.empty()) return find_equilibria(c.definition, c.start_guess, c.derived, samples, options);
  const auto t0 = std::chrono::steady_clock::now();
  CaseSolveOptions solve;
  solve.solution = solve.stability = solve.stability_check = false;
  const CaseSolve solved = solve_case(c, solve);
  if (solved.converged() && solved.solved.problem)
    options.known_roots.push_back({solved.solved.problem->definition().contacts, solved.solved.result.x,
                                   "solve (homotopy from the file's values)"});
  std::vector<EquilibriaOptions::KnownRoot> carried;
  std::vector<std::string> log;
  int runs_at_file_values = 0;
  try {
    runs_at_file_values = carry_from_file_values(c, changes, samples, options, &carried, &log);
  } catch (const std::exception& error) {
    log.push_back(std::string("the equilibria at the file's values: ") + error.what());
  }
  options.known_roots.insert(options.known_roots.end(), carried.begin(), carried.end());
  // The time spent before counts against the limit; the search keeps at least its share.
  if (options.max_seconds > 0)
    options.max_seconds = std::max((1 - 2 * kFileValuesShare) * options.max_seconds,
                                   options.max_seconds - seconds_since(t0));
  EquilibriaSearch out = find_equilibria(c.definition, c.start_guess, c.derived, samples, options);
  out.log.insert(out.log.begin(), log.begin(), log.end());
  out.newton_runs += runs_at_file_values;  // (the search's count: both searches' runs)
  return out;
}

}  // namespace kirchhoff
