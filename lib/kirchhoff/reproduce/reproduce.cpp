// The order of `reproduce`'s groups, with a progress line before each (reproduce.hpp).
#include "kirchhoff/reproduce/reproduce.hpp"

#include <chrono>
#include <filesystem>

#include "kirchhoff/reproduce/detail/reproduce_steps.hpp"

namespace kirchhoff {

int ReproduceResult::failed() const {
  int n = 0;
  for (const auto& r : rows) n += r.pass() ? 0 : 1;
  return n;
}

namespace {

using namespace reproduce_steps;

// The groups whose extent does not change with `full`.
void quick_groups(const Step& step) {
  step.progress("Fig. 3 / eq. (54): simply supported Elastica");
  simply_supported(step);
  step.progress("Fig. 9 / eq. (57): tapered rod");
  tapered(step);
  step.progress("Section 5: invariants of the twisted and heavy rods");
  invariants(step);
  step.progress("Continuation: Euler column and twisted rod bifurcations");
  continuation(step);
  step.progress("Stability: indices of the Euler column, the clamped rod and the twisted rod");
  stability(step);
  step.progress("Figs. 6-8: sliding sleeve and arm scale");
  sleeves(step);
  step.progress("Fig. 12: hard and soft walls");
  wall(step);
  step.progress("Section 9: vibrations about straight and buckled columns");
  vibrations(step);
  step.progress("Section 7.2 / Fig. 5: the Elastica in a cavity, hanging fold");
  cavity(step);
}

// Fig. 11, and with `full` the hard wall's phase diagram.
void plectoneme_groups(const Step& step, const fs::path& out) {
  step.progress(step.full ? "Section 7.6 / Fig. 11: plectonemes at L/2R = 100, 200, 500 and 1000 (about 9 minutes)"
                          : "Section 7.6 / Fig. 11: plectonemes at L/2R = 100 and 200, from the untwisted rod into "
                            "the ply (about 2 minutes; --full adds 500 and 1000)");
  plectonemes(step);
  step.progress(step.full
                    ? "Section 7.6 / Fig. 11: the ply with exact self-contact at L/2R = 100, 200 and 500 (about 7 minutes)"
                    : "Section 7.6 / Fig. 11: the ply with exact self-contact at L/2R = 100 and 200 (about a minute)");
  exact_plies(step);
  if (step.full) {
    step.progress("Hard-wall Elastica: contact states over (a, Delta), sweeps/wall_phase_diagram.toml (about 5 minutes)");
    wall_phase_diagram(step, out / "wall_phase");
  }
}

}  // namespace

ReproduceResult reproduce(const ReproduceRequest& request, const ReproduceProgress& progress) {
  const auto start = std::chrono::steady_clock::now();
  const fs::path out(request.out_dir);
  fs::create_directories(out / "profiles");
  ReproduceResult result;
  Step step{request.cases_dir, out / "profiles", request.full, progress, &result.rows};
  if (!step.progress) step.progress = [](const std::string&) {};
  quick_groups(step);
  plectoneme_groups(step, out);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  write_reproduce_report(request.out_dir, result.rows, result.seconds);
  return result;
}

}  // namespace kirchhoff
