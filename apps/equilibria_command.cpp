#include "equilibria_command.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "kirchhoff/jobs/case_equilibria.hpp"
#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/jobs/equilibria.hpp"
#include "kirchhoff/jobs/result_json.hpp"
#include "solve_command.hpp"

namespace kirchhoff::cli {
namespace {

// The index, and the zero modes beside it ("1 +1 zero"): an equilibrium with zero modes is not
// isolated (or sits at a bifurcation), which a count of equilibria must not hide.
std::string index_text(const StabilityReport& s) {
  if (!s.index) return s.unstable ? "unstable" : "-";
  const std::string index = s.stable() && s.zero_modes == 0 ? "0 (stable)" : std::to_string(*s.index);
  return s.zero_modes > 0 ? index + " +" + std::to_string(s.zero_modes) + " zero" : index;
}

int count(const EquilibriaSearch& search, const std::function<bool(const Equilibrium&)>& which) {
  return static_cast<int>(std::count_if(search.equilibria.begin(), search.equilibria.end(), which));
}

// One line per continuous family under the table: its members (table numbers) and what it is.
void print_family_notes(const EquilibriaSearch& search) {
  for (int family = 1; family <= search.families; ++family) {
    std::ostringstream members;
    int found = 0, zero_modes = 0;
    for (size_t i = 0; i < search.equilibria.size(); ++i) {
      if (search.equilibria[i].family != family) continue;
      members << (found++ ? ", #" : "#") << i + 1;
      zero_modes = search.equilibria[i].stability.zero_modes;
    }
    std::cout << "  family " << family << ": " << members.str() << " (" << zero_modes << " zero mode"
              << (zero_modes > 1 ? "s" : "") << "): "
              << (found > 1 ? std::to_string(found) + " points of one continuous family, the same rod moved rigidly"
                            : "one point of a continuous family, or a bifurcation point")
              << "\n";
  }
}

std::string contacts_text(const Solution& sol) {
  if (sol.contacts.empty()) return "none";
  std::ostringstream out;
  out << std::setprecision(4);
  for (size_t i = 0; i < sol.contacts.size(); ++i) {
    const PointContact& c = sol.contacts[i];
    out << (i ? "; " : "");
    if (c.extended)
      out << "flat [" << c.s << ", " << c.s_end << "]";
    else
      out << "s=" << c.s;
  }
  return out.str();
}

void print_table(const Case& c, const EquilibriaSearch& search) {
  std::cout << (c.title.empty() ? c.path : c.title) << "\n";
  std::cout << "  " << search.equilibria.size() << " distinct equilibria (" << search.stopped_because << ", "
            << search.newton_runs << " Newton runs)";
  if (search.families > 0) {
    const int isolated = count(search, [](const Equilibrium& e) { return e.stability.defined() && e.family == 0; });
    const int members = count(search, [](const Equilibrium& e) { return e.family > 0; });
    std::cout << ": " << isolated << " isolated, " << members << " with zero modes on " << search.families
              << " continuous famil" << (search.families > 1 ? "ies" : "y") << " (see below)";
    if (const int undefined = static_cast<int>(search.equilibria.size()) - isolated - members; undefined > 0)
      std::cout << ", " << undefined << " with the index undefined";
  }
  std::cout << ", ";
  const bool some_energy_undefined = std::any_of(search.equilibria.begin(), search.equilibria.end(),
                                                 [](const Equilibrium& e) { return std::isnan(e.energy); });
  std::cout << (some_energy_undefined
                    ? "energy not defined for some (see docs/equilibria.md), those in the order found:\n"
                    : "by increasing energy:\n");
  const bool families = search.families > 0;
  std::cout << "  " << std::setw(3) << "#" << std::setw(16) << "energy" << std::setw(12) << "index";
  if (families) std::cout << std::setw(8) << "family";
  std::cout << std::setw(11) << "residual" << std::setw(11) << "H spread";
  // (A space before each: a name of 15 characters or more would run into the one before.)
  for (const auto& name : c.derived) std::cout << ' ' << std::setw(14) << name;
  std::cout << "  contacts\n";
  for (size_t i = 0; i < search.equilibria.size(); ++i) {
    const Equilibrium& e = search.equilibria[i];
    const Solution& sol = e.solution;
    std::cout << "  " << std::setw(3) << i + 1 << std::setw(16) << std::setprecision(10) << e.energy << std::setw(12)
              << index_text(e.stability);
    if (families) std::cout << std::setw(8) << (e.family > 0 ? std::to_string(e.family) : "-");
    std::cout << std::setw(11) << std::setprecision(2) << sol.result.summary.residual_norm
              << std::setw(11) << sol.invariants.H.relative_spread() << std::setprecision(8);
    for (const auto& name : c.derived) std::cout << ' ' << std::setw(14) << sol.derived.at(name);
    std::cout << "  " << contacts_text(sol) << "\n";
  }
  print_family_notes(search);
  for (size_t i = 0; i < search.equilibria.size(); ++i) {
    const StabilityReport& s = search.equilibria[i].stability;
    if (!s.index) std::cout << "  #" << i + 1 << ": " << describe(s) << "\n";
    const NewtonSummary& summary = search.equilibria[i].solution.result.summary;
    if (!summary.message.empty())
      std::cout << "  #" << i + 1 << ": converged with " << summary.message
                << "; its residual is as low as this shooting's conditioning allows (more [solver] segments "
                   "lower it)\n";
  }
  if (!search.rejected.empty())
    std::cout << "  " << search.rejected.size() << " converged points rejected (not admissible or failed checks; "
              << "see --json)\n";
}

nlohmann::json search_json(const Case& c, const EquilibriaSearch& search) {
  nlohmann::json out;
  out["case"] = c.path;
  out["title"] = c.title;
  out["parameters"] = parameters_json(c.definition.parameters);
  out["stopped_because"] = search.stopped_because;
  out["newton_runs"] = search.newton_runs;
  out["families"] = search.families;
  out["equilibria"] = nlohmann::json::array();
  for (size_t i = 0; i < search.equilibria.size(); ++i) {
    const Equilibrium& e = search.equilibria[i];
    nlohmann::json j = solution_json(c, *e.problem, e.solution, e.stability);
    j["rank"] = i + 1;
    j["energy"] = std::isfinite(e.energy) ? nlohmann::json(e.energy) : nlohmann::json();
    j["found_by"] = e.found_by;
    // "step at round-off": the residual is above the tolerance, at the shooting's round-off.
    if (!e.solution.result.summary.message.empty()) j["message"] = e.solution.result.summary.message;
    // No zero mode: an isolated equilibrium; null where the stability analysis is not defined.
    j["isolated"] = e.stability.defined() ? nlohmann::json(e.stability.zero_modes == 0) : nlohmann::json();
    // The continuous family it is a point of (docs/equilibria.md), null when isolated.
    j["family"] = e.family > 0 ? nlohmann::json(e.family) : nlohmann::json();
    out["equilibria"].push_back(std::move(j));
  }
  out["rejected"] = nlohmann::json::array();
  for (const auto& r : search.rejected)
    out["rejected"].push_back({{"found_by", r.found_by},
                               {"reason", r.reason},
                               {"residual", std::isfinite(r.residual) ? nlohmann::json(r.residual) : nlohmann::json()}});
  out["log"] = search.log;
  return out;
}

// equilibrium_1.csv, ... in increasing energy, as the table numbers them.
void write_profiles(const std::string& dir, const EquilibriaSearch& search) {
  std::filesystem::create_directories(dir);
  for (size_t i = 0; i < search.equilibria.size(); ++i) {
    const Equilibrium& e = search.equilibria[i];
    const std::string path = (std::filesystem::path(dir) / ("equilibrium_" + std::to_string(i + 1) + ".csv")).string();
    write_profile_csv(path, e.problem->equations(e.solution.result.parameters)->model(), e.solution.profile,
                      e.problem->definition().kind);
  }
}

}  // namespace

int run_equilibria(const EquilibriaArguments& args) {
  Case c;
  EquilibriaOptions options;
  try {
    c = load_case(args.case_path, parse_overrides(args.case_path, args.overrides), "", parse_solver_overrides(args.solver));
    options.max_equilibria = args.max_equilibria;
    options.max_seconds = args.max_seconds;
    if (const std::string why = options.validate(); !why.empty()) throw CaseError(why);
  } catch (const CaseError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  }
  const EquilibriaSearch search = find_case_equilibria(c, c.samples, options);
  if (!args.profiles_dir.empty()) {
    try {
      write_profiles(args.profiles_dir, search);
    } catch (const std::exception& e) {
      std::cerr << "error: --profiles: " << e.what() << "\n";
      return kExitBadInput;
    }
  }
  if (args.json)
    std::cout << search_json(c, search).dump(2) << "\n";
  else
    print_table(c, search);
  if (search.equilibria.empty()) {
    std::cerr << "error: " << c.path << ": no equilibrium found (" << search.stopped_because << ")"
              << (search.log.empty() ? "" : "; the search's last line: " + search.log.back()) << "\n";
    return kExitNotConverged;
  }
  return kExitOk;
}

}  // namespace kirchhoff::cli
