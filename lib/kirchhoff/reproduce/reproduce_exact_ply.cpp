// `reproduce`'s Fig. 11 with exact contact (reproduce_steps.hpp; `plectonemes --hard-from 5
// --from-ply 200`, with `full` also 500): the L/2R = 100 barrier branch handed to exact
// self-contact at 5 turns, each thinner rod reached from the thicker one's exact ply, each followed
// up from 5 turns (to 6, with `full` to the sweep's 10, 20, 20) and down (to 4.5, with `full` to 4)
// into profiles/exact/plectoneme_<L/2R>_ply.csv. At each ply's largest turns: (61) and (58b) with R
// itself, H_A = H_B; over all its points the self-distance; and the legs reaching their ends (a
// contact force or the line's pressure reaching 0 would have stopped them). L/2R = 1000 with exact
// contact is a CLI run (docs/plectonemes.md).
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "kirchhoff/reproduce/detail/reproduce_steps.hpp"
#include "kirchhoff/sweeps/plectoneme_sweep.hpp"

namespace kirchhoff::reproduce_steps {

namespace {

PlectonemesArguments exact_ply_sweep(const Step& step) {
  PlectonemesArguments args;
  args.case_path = (step.cases / "plectoneme.toml").string();
  args.out_dir = (step.out / "exact").string();
  args.hard_from = 5.0;
  args.slenderness = step.full ? std::vector<double>{100, 200, 500} : std::vector<double>{100, 200};
  args.turns = step.full ? std::vector<double>{10, 20, 20} : std::vector<double>{6, 6};
  args.from_ply = {200, 500};
  args.turns_min = step.full ? 4.0 : 4.5;
  args.progress_every = step.full ? 250 : 0;
  args.progress = step.progress;
  return args;
}

void ply_rows(const Step& step, const PlectonemeBranchSummary& branch, double turns, const std::string& name) {
  if (branch.hard_ply.empty()) throw std::runtime_error("plectoneme: no exact ply at L/2R = " + name);
  const auto& ply = *std::max_element(branch.hard_ply.begin(), branch.hard_ply.end(),
                                      [](const auto& a, const auto& b) { return a.at("turns") < b.at("turns"); });
  const std::string where = "L/2R = " + name + ", exact contact (rho = R), turns = " + format_short(ply.at("turns")) +
                            ", theta = " + format_short(ply.at("helix_angle") * 180.0 / M_PI) + " deg";
  auto* rows = step.rows;
  // Measured 0.2-0.4 % below (61) at 6 turns, <= 0.01 % from 9 turns: the helix formulas
  // idealise the middle of a long ply, these have a few pitches at 6 turns.
  rows->push_back({"Fig. 11, eq. (61), exact contact", "T_ext R^2 / EI in the ply", {}, ply.at("eq61"),
                   ply.at("T_rho2_over_EI"), ply.at("eq61"), 0.01, where});
  rows->push_back({"Fig. 11, eq. (58b), exact contact", "m3 in the ply", {}, ply.at("m3_eq58b"),
                   std::abs(ply.at("m3")), ply.at("m3_eq58b"), 0.01, where});
  rows->push_back({"Fig. 11, eqs. (59)-(60), exact contact", "H_A (in the ply) vs H_B (clamped end)", {},
                   ply.at("H_B"), ply.at("H_A"), std::abs(ply.at("H_B")), 1e-8, where});
  double smallest = INFINITY;
  for (const auto& p : branch.hard_ply) smallest = std::min(smallest, p.at("self_distance"));
  rows->push_back({"Fig. 11, exact contact", "smallest distance between cross-sections / 2R (>= 1 - 1e-9)", {}, 1.0,
                   smallest, 1.0, 1e-9,
                   "L/2R = " + name + ", over all " + std::to_string(branch.hard_ply.size()) +
                       " points of both legs; the contacts are at 1"});
  rows->push_back({"Fig. 11, exact contact", "turns reached with complementarity (forces and pressure > 0)", {}, turns,
                   ply.at("turns"), turns, 1e-9,
                   where + "; legs: " + branch.hard_ply_stop + "; " + std::to_string(branch.hard_ply_points) +
                       " points in " + format_short(branch.hard_ply_seconds) + " s"});
}

}  // namespace

void exact_plies(const Step& step) {
  const PlectonemesArguments args = exact_ply_sweep(step);
  std::ostringstream report;  // the sweep's per-slenderness lines: the rows say more
  const PlectonemeSweep sweep = sweep_plectonemes(args, report);
  for (size_t k = 0; k < sweep.branches.size(); ++k)
    ply_rows(step, sweep.branches[k].summary, args.turns[k], std::to_string(static_cast<int>(args.slenderness[k])));
}

}  // namespace kirchhoff::reproduce_steps
