// `reproduce --full`'s hard-wall phase diagram (reproduce_steps.hpp, docs/sweeps.md):
// sweeps/wall_phase_diagram.toml beside the cases folder, run afresh into out_dir and drawn by
// make_figures.py.
#include "kirchhoff/reproduce/detail/reproduce_steps.hpp"
#include "kirchhoff/sweeps/sweep_run.hpp"

namespace kirchhoff::reproduce_steps {

void wall_phase_diagram(const Step& step, const fs::path& out_dir) {
  SweepRunOptions sweep;
  sweep.out_dir = out_dir.string();
  const ReproduceProgress progress = step.progress;
  sweep.progress = [progress](const std::string& line) { progress("  " + line); };
  fs::remove_all(sweep.out_dir);
  run_sweep(load_sweep((step.cases / ".." / "sweeps" / "wall_phase_diagram.toml").lexically_normal().string()), sweep);
}

}  // namespace kirchhoff::reproduce_steps
