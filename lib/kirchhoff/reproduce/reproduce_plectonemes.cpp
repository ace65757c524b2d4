// `reproduce`'s Section 7.6 / Fig. 11 with the self-contact barrier (reproduce_steps.hpp):
// plectoneme branches for L/2R = 100 (to 6 turns) and 200 (to 13), from the untwisted rod into the
// ply (with `full`: the whole sweep of `kirchhoff plectonemes`, 100, 200, 500 to 10, 20, 20 turns
// and 1000 from the 500 ply to 50 and down to 4, ~9 minutes); at each branch's last ply point the
// helix formulas (58b) and (61) against the computed ply, with its helix radius rho (R plus the
// self-contact barrier's gap) and angle, and H_A = H_B (eqs. 59-60); across slendernesses, the
// 1/R^2 scaling of T_ext at a common helix angle.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "kirchhoff/reproduce/detail/reproduce_steps.hpp"
#include "kirchhoff/sweeps/plectoneme_sweep.hpp"

namespace kirchhoff::reproduce_steps {

namespace {

struct Run {
  double slenderness, turns;
  bool from_ply = false;  // reached from the previous run's ply (follow_from_ply)
  PlectonemeBranchSummary branch;
};

using PlyColumns = std::vector<std::map<std::string, double>>;

// (helix angle, column) along the established ply (turns > 3.5, where the branch is single-valued
// in the angle), by increasing angle.
std::vector<std::pair<double, double>> established_ply(const PlyColumns& ply, const std::string& column = "T_ext") {
  std::vector<std::pair<double, double>> points;
  for (const auto& p : ply)
    if (p.at("turns") > 3.5) points.push_back({p.at("helix_angle"), p.at(column)});
  std::sort(points.begin(), points.end());
  return points;
}

// The column interpolated at the helix angle theta; NaN outside the angles the ply covers.
double tension_at(const std::vector<std::pair<double, double>>& ply, double theta) {
  for (size_t k = 1; k < ply.size(); ++k)
    if (ply[k - 1].first <= theta && theta <= ply[k].first) {
      const double w = (theta - ply[k - 1].first) / (ply[k].first - ply[k - 1].first);
      return (1.0 - w) * ply[k - 1].second + w * ply[k].second;
    }
  return NAN;
}

std::string csv_of(const fs::path& out, double slenderness) {
  return (out / ("plectoneme_" + std::to_string(static_cast<int>(slenderness)) + ".csv")).string();
}

// Follows run k (from the untwisted rod, or from run k - 1's ply) into out/plectoneme_<L/2R>.csv.
void follow(const Step& step, std::vector<Run>& runs, size_t k) {
  Run& run = runs[k];
  const std::string case_path = (step.cases / "plectoneme.toml").string();
  PlectonemeRunOptions options;
  options.progress_every = step.full ? 250 : 0;
  options.progress = step.progress;
  run.branch = run.from_ply ? follow_from_ply(case_path, csv_of(step.out, runs[k - 1].slenderness) + ".state.json",
                                              runs[k - 1].slenderness, run.slenderness, 4.0, run.turns,
                                              csv_of(step.out, run.slenderness), options)
                            : follow_plectoneme_branch(case_path, run.slenderness, run.turns,
                                                       csv_of(step.out, run.slenderness), options);
}

// The helix formulas and H_A = H_B at the branch's last ply point, the self-distance over its ply.
void ply_rows(const Step& step, const Run& run, const std::string& name) {
  const auto& ply = run.branch.last;
  const double R = 1.0 / (2.0 * run.slenderness);  // the case's L = 1
  const std::string where = "L/2R = " + name + ", D = L/2, turns = " + format_short(ply.at("turns")) +
                            ", theta = " + format_short(ply.at("helix_angle") * 180.0 / M_PI) +
                            " deg, rho/R = " + format_short(ply.at("helix_radius") / R);
  auto* rows = step.rows;
  // The helix formulas idealise the middle of a long ply; these have a few to ~15 turns
  // between a tail and an end loop. Observed along the branches: (61) within 2-8 %, (58b) 0-3 %.
  rows->push_back({"Fig. 11, eq. (61)", "T_ext rho^2 / EI in the ply", {}, ply.at("eq61"), ply.at("T_rho2_over_EI"),
                   ply.at("eq61"), 0.12, where + "; the bar is the helical approximation's accuracy on a short ply"});
  rows->push_back({"Fig. 11, eq. (58b)", "m3 in the ply", {}, ply.at("m3_eq58b"), ply.at("m3"), ply.at("m3_eq58b"),
                   0.04, where});
  rows->push_back({"Fig. 11, eqs. (59)-(60)", "H_A (in the ply) vs H_B (clamped end)", {}, ply.at("H_B"),
                   ply.at("H_A"), std::abs(ply.at("H_B")), 1e-8, where + "; H conserved with the barrier's potential"});
  double smallest = INFINITY;
  for (const auto& p : run.branch.ply) smallest = std::min(smallest, p.at("self_distance"));
  rows->push_back({"Fig. 11", "smallest distance between cross-sections / 2R over the ply points (>= 1)", {}, {},
                   smallest, 1.0, 0.0,
                   where + "; over all pairs of the whole rod; " + std::to_string(run.branch.points) +
                       " branch points in " + format_short(run.branch.seconds) + " s"});
}

// 1/R^2: at the largest angle both plies reach, T_ext R^2 is the same for both slendernesses; with
// `full`, rho in place of R (the barrier's gap differs between slendernesses, up to rho/R = 1.20
// at 500 against 1.08 at 1000): T_ext rho^2 at equal helix angle, pair by pair.
void scaling_rows(const Step& step, const std::vector<Run>& runs) {
  const auto ply100 = established_ply(runs[0].branch.ply), ply200 = established_ply(runs[1].branch.ply);
  if (ply100.empty() || ply200.empty()) throw std::runtime_error("plectoneme: no established ply to compare");
  const double theta = std::min(ply100.back().first, ply200.back().first);
  const double T100 = tension_at(ply100, theta), T200 = tension_at(ply200, theta);
  step.rows->push_back({"Fig. 11, scaling", "T_ext(L/2R = 200) / T_ext(L/2R = 100) at equal helix angle", {}, 4.0,
                        T200 / T100, 4.0, 0.05,
                        "theta = " + format_short(theta * 180.0 / M_PI) +
                            " deg; 1/R^2 (eq. 61 with rho = R); the barrier's gap makes rho/R differ by up to ~4 % "
                            "between the two, hence the bar"});
  for (size_t k = 1; step.full && k < runs.size(); ++k) {
    const auto a = established_ply(runs[k - 1].branch.ply, "T_rho2_over_EI");
    const auto b = established_ply(runs[k].branch.ply, "T_rho2_over_EI");
    const double at = a.empty() || b.empty() ? NAN : std::min(a.back().first, b.back().first);
    const std::string pair = "L/2R = " + std::to_string(static_cast<int>(runs[k].slenderness)) + " / " +
                             std::to_string(static_cast<int>(runs[k - 1].slenderness));
    step.rows->push_back({"Fig. 11, scaling", "T_ext rho^2, " + pair + ", at equal helix angle", {}, 1.0,
                          tension_at(b, at) / tension_at(a, at), 1.0, 0.05,
                          "theta = " + format_short(at * 180.0 / M_PI) +
                              " deg; 1/rho^2 with rho the computed helix radius"});
  }
}

}  // namespace

void plectonemes(const Step& step) {
  std::vector<Run> runs = {{100.0, 6.0, false, {}}, {200.0, 13.0, false, {}}};
  if (step.full)
    runs = {{100.0, 10.0, false, {}}, {200.0, 20.0, false, {}}, {500.0, 20.0, false, {}}, {1000.0, 50.0, true, {}}};
  for (size_t k = 0; k < runs.size(); ++k) {
    const std::string name = std::to_string(static_cast<int>(runs[k].slenderness));
    if (step.full) step.progress("  L/2R = " + name);
    follow(step, runs, k);
    if (runs[k].branch.last.empty())
      throw std::runtime_error("plectoneme: no ply formed at L/2R = " + name + " (" + runs[k].branch.stop + ")");
    ply_rows(step, runs[k], name);
  }
  scaling_rows(step, runs);
}

}  // namespace kirchhoff::reproduce_steps
